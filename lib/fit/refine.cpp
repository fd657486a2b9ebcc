#include "fit/refine.h"

#include <ceres/ceres.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <algorithm>
#include <array>
#include <map>
#include <memory>
#include <random>

#include "fit/small_problem.h"
#include "fit/visible_moments.h"
#include "model/body.h"
#include "model/visible_slopes.h"

namespace facetfit {

namespace {

// Unknowns whose weighted sum is a tabulated value at one angle (duplicates merged, zero weights left out).
struct NodeWeights {
  std::vector<int> node;
  std::vector<double> weight;
};

NodeWeights merged(const int* index, const double* weight, int n) {
  std::map<int, double> sum;
  for (int q = 0; q < n; ++q)
    if (weight[q] != 0.0) sum[index[q]] += weight[q];
  NodeWeights w;
  for (const auto& [k, x] : sum)
    if (std::abs(x) > 1e-12) w.node.push_back(k), w.weight.push_back(x);
  return w;
}

// The D nodes of the spline's stencil at theta_h.
NodeWeights ndf_nodes(const ThetaGrid& grid, double theta_h) {
  int j;
  double t;
  grid.locate(theta_h, &j, &t);
  const ThetaGrid::Stencil s = grid.stencil(j, t);
  return merged(s.index, s.weight, 4);
}

// The Fresnel entries at theta_d, linear between them (FresnelCurve::eval's interpolation): one entry
// on a MERL row, whose theta_d is an entry's, two between them (a UTIA node's).
NodeWeights fresnel_entries(double theta_d) {
  const double step = FresnelCurve::theta_d(1);
  double x = clamp(theta_d / step, 0.0, double(FresnelCurve::kSize - 1));
  if (std::abs(x - std::round(x)) < 1e-9) x = std::round(x);
  const int j = std::min(int(x), FresnelCurve::kSize - 2);
  const int index[2] = {j, j + 1};
  const double weight[2] = {j + 1 - x, x - j};
  return merged(index, weight, 2);
}

struct PassTerms {
  std::vector<double> g, coat, log_cosines;
};

// The residuals of one row (bins sharing theta_h and theta_d): 3 per bin. Parameter blocks: body (3),
// the body's exponent k (1), the row's Fresnel entries (3 each), then its D nodes (1 each), with the
// pass's fixed terms per bin.
class LobeRowCost final : public ceres::CostFunction {
 public:
  LobeRowCost(const MeasuredBins& bins, const MeasuredBins::Row& row, const PassTerms& terms, NodeWeights fresnel, NodeWeights nodes)
      : bins_(bins), row_(row), terms_(terms), fresnel_(std::move(fresnel)), nodes_(std::move(nodes)) {
    set_num_residuals(int(3 * (row.end - row.begin)));
    mutable_parameter_block_sizes()->push_back(3);
    mutable_parameter_block_sizes()->push_back(1);
    for (std::size_t e = 0; e < fresnel_.node.size(); ++e) mutable_parameter_block_sizes()->push_back(3);
    for (std::size_t q = 0; q < nodes_.node.size(); ++q) mutable_parameter_block_sizes()->push_back(1);
  }

  bool Evaluate(double const* const* p, double* residuals, double** jacobians) const override {
    const double* body = p[0];
    const double exponent = p[1][0];
    const std::size_t nf = fresnel_.node.size(), first_fresnel = 2, first_node = first_fresnel + nf;
    double fresnel[3] = {0.0, 0.0, 0.0};
    for (std::size_t e = 0; e < nf; ++e)
      for (int ch = 0; ch < 3; ++ch) fresnel[ch] += fresnel_.weight[e] * p[first_fresnel + e][ch];
    double d = 0.0;
    for (std::size_t q = 0; q < nodes_.node.size(); ++q) d += nodes_.weight[q] * p[first_node + q][0];
    const std::size_t n = row_.end - row_.begin;
    for (std::size_t b = 0; b < n; ++b) {
      const std::size_t k = row_.begin + b;
      const double s = std::sqrt(bins_.weight[k]), c = bins_.cosine[k], g = terms_.g[k];
      const bool grazing = grazing_pair(bins_.o[k], bins_.i[k]);
      const MinnaertFactor minnaert = minnaert_factor_of_log(exponent, terms_.log_cosines[k]);
      const double factor = minnaert.value, dfactor = minnaert.d_exponent;
      for (int ch = 0; ch < 3; ++ch) {
        const std::size_t r = 3 * b + std::size_t(ch);
        const bool valid = bins_.valid[k] >> ch & 1u;
        const double m = body[ch] * kInvPi * factor + fresnel[ch] * d * g + terms_.coat[k];
        const MetricResidual res = valid ? metric_residual(m, c, bins_.lightness[k][ch], grazing) : MetricResidual{};
        residuals[r] = s * res.value;
        if (!jacobians) continue;
        const double dm = s * res.slope;  // d/dm of the residual: the chain rule for every parameter below
        if (jacobians[0])
          for (int e = 0; e < 3; ++e) jacobians[0][3 * r + std::size_t(e)] = e == ch ? dm * kInvPi * factor : 0.0;
        if (jacobians[1]) jacobians[1][r] = dm * body[ch] * kInvPi * dfactor;
        for (std::size_t f = 0; f < nf; ++f)
          if (jacobians[first_fresnel + f])
            for (int e = 0; e < 3; ++e)
              jacobians[first_fresnel + f][3 * r + std::size_t(e)] = e == ch ? dm * fresnel_.weight[f] * d * g : 0.0;
        for (std::size_t q = 0; q < nodes_.node.size(); ++q)
          if (jacobians[first_node + q]) jacobians[first_node + q][r] = dm * fresnel[ch] * g * nodes_.weight[q];
      }
    }
    return true;
  }

 private:
  const MeasuredBins& bins_;
  const MeasuredBins::Row& row_;
  const PassTerms& terms_;
  NodeWeights fresnel_, nodes_;
};

// weight (sum_j area_j D_j - 1): keeps the NDF normalized, which fixes the scale shared by D and F.
class NormalizationCost final : public ceres::CostFunction {
 public:
  NormalizationCost(const std::vector<double>& area, double weight) : area_(area), weight_(weight) {
    set_num_residuals(1);
    for (std::size_t j = 0; j < area.size(); ++j) mutable_parameter_block_sizes()->push_back(1);
  }
  bool Evaluate(double const* const* p, double* residuals, double** jacobians) const override {
    double s = 0.0;
    for (std::size_t j = 0; j < area_.size(); ++j) s += area_[j] * p[j][0];
    residuals[0] = weight_ * (s - 1.0);
    if (jacobians)
      for (std::size_t j = 0; j < area_.size(); ++j)
        if (jacobians[j]) jacobians[j][0] = weight_ * area_[j];
    return true;
  }

 private:
  const std::vector<double>& area_;
  double weight_;
};

// a x_0 + b x_1 + c x_2 per component of N: a second difference, of the Fresnel curve's channels
// (N = 3) or of an NDF node (N = 1).
template <int N>
struct SecondDifference {
  double a, b, c;
  template <class T>
  bool operator()(const T* x0, const T* x1, const T* x2, T* r) const {
    for (int k = 0; k < N; ++k) r[k] = a * x0[k] + b * x1[k] + c * x2[k];
    return true;
  }
};

// The Fresnel curve's smoothness term over three consecutive knots at entry positions e0 < e1 < e2:
// sqrt((h0 + h1) / 2) F'' with F'' the divided second difference, so that the sum over knots
// approximates the integral of F''^2 whatever the knots' spacing (MERL rows: every 6th entry; a UTIA
// file's nodes: nearly every entry); scaled to weight (x0 - 2 x1 + x2) at a spacing of 6 entries.
SecondDifference<3> fresnel_smoothness(double weight, int e0, int e1, int e2) {
  const double h0 = e1 - e0, h1 = e2 - e1;
  const double k = weight * (36.0 / std::sqrt(6.0)) * std::sqrt(0.5 * (h0 + h1)) * 2.0 / (h0 + h1);
  return {k / h0, -k * (1.0 / h0 + 1.0 / h1), k / h1};
}

// The albedo of body + lobe + coat at the views of an AlbedoTarget, one residual per view and channel
// (albedo_residual), with what a pass holds fixed (G2, the coat) summed into coefficients:
//   rho_c(o) = body_c cos_o^(k - 1) + sum_n sum_m B[n][m] D_n F_m,c + coat(o),
// D_n the NDF's nodes and F_m the Fresnel knots (each a spline or linear weight of what a direction reads),
// B[n][m] the draws' sum of those weights times G2 cos_i / (4 cos_i cos_o pdf) over the lobe's visible
// normals. Parameter blocks: body (3), exponent (1), the knots (3 each), the nodes (1 each).
class AlbedoRefineCost final : public ceres::CostFunction {
 public:
  struct View {
    double cos_o = 1.0, coat = 0.0;
    std::vector<double> b;  // [node][knot]
  };
  AlbedoRefineCost(const AlbedoTarget& target, std::vector<View> views, std::size_t knots, std::size_t nodes)
      : target_(target), views_(std::move(views)), knots_(knots), nodes_(nodes) {
    set_num_residuals(int(3 * views_.size()));
    mutable_parameter_block_sizes()->push_back(3);
    mutable_parameter_block_sizes()->push_back(1);
    for (std::size_t m = 0; m < knots; ++m) mutable_parameter_block_sizes()->push_back(3);
    for (std::size_t n = 0; n < nodes; ++n) mutable_parameter_block_sizes()->push_back(1);
  }

  bool Evaluate(double const* const* p, double* residuals, double** jacobians) const override {
    const double* body = p[0];
    const double k = p[1][0];
    const std::size_t first_knot = 2, first_node = first_knot + knots_;
    std::vector<double> dn(nodes_ * 3), fm(knots_ * 3);  // d rho_c / d D_n and d rho_c / d F_m,c
    for (std::size_t j = 0; j < views_.size(); ++j) {
      const View& v = views_[j];
      std::fill(dn.begin(), dn.end(), 0.0), std::fill(fm.begin(), fm.end(), 0.0);
      double rho[3] = {v.coat, v.coat, v.coat};
      for (std::size_t n = 0; n < nodes_; ++n)
        for (std::size_t m = 0; m < knots_; ++m) {
          const double b = v.b[n * knots_ + m];
          if (b == 0.0) continue;
          for (std::size_t c = 0; c < 3; ++c) {
            rho[c] += b * p[first_node + n][0] * p[first_knot + m][c];
            dn[3 * n + c] += b * p[first_knot + m][c];
            fm[3 * m + c] += b * p[first_node + n][0];
          }
        }
      const double power = std::pow(v.cos_o, k - 1.0), log_cos = std::log(v.cos_o);
      for (std::size_t c = 0; c < 3; ++c) {
        rho[c] += body[c] * power;
        const std::size_t r = 3 * j + c;
        const MetricResidual res = albedo_residual(target_, j, int(c), rho[c]);
        residuals[r] = res.value;
        if (!jacobians) continue;
        for (std::size_t b = 0; b < parameter_block_sizes().size(); ++b)
          if (jacobians[b]) std::fill_n(jacobians[b] + r * std::size_t(parameter_block_sizes()[b]), parameter_block_sizes()[b], 0.0);
        if (res.slope == 0.0) continue;
        if (jacobians[0]) jacobians[0][3 * r + c] = res.slope * power;
        if (jacobians[1]) jacobians[1][r] = res.slope * body[c] * power * log_cos;
        for (std::size_t m = 0; m < knots_; ++m)
          if (jacobians[first_knot + m]) jacobians[first_knot + m][3 * r + c] = res.slope * fm[3 * m + c];
        for (std::size_t n = 0; n < nodes_; ++n)
          if (jacobians[first_node + n]) jacobians[first_node + n][r] = res.slope * dn[3 * n + c];
      }
    }
    return true;
  }

 private:
  const AlbedoTarget& target_;
  std::vector<View> views_;
  std::size_t knots_, nodes_;
};

// Per bin, what a pass holds fixed: G2 / (4 cos_i cos_o) of the lobe's NDF, its coat's f, and
// ln(cos_i cos_o) for the body's factor.
PassTerms pass_terms(const MeasuredBins& bins, Smith smith, const LobeFit& lobe) {
  const G1Table g1(lobe.ndf);
  PassTerms t;
  t.g.resize(bins.size()), t.coat.resize(bins.size()), t.log_cosines.resize(bins.size());
  for (std::size_t k = 0; k < bins.size(); ++k) {
    const double mi = bins.i[k].z, mo = bins.o[k].z;
    t.g[k] = smith_g2_from_g1(smith, g1(mo), g1(mi)) / (4.0 * mi * mo);
    t.coat[k] = lobe.coat.eval(bins.o[k], bins.i[k]);
    t.log_cosines[k] = std::log(mi * mo);
  }
  return t;
}

// The Fresnel unknowns: the entries the bins' theta_d reach (the knots). The entries between them are
// linear in between, those past the last knot equal it. The entries no bin sees carry no information of
// their own, and fewer unknowns make a faster solve.
struct FresnelKnots {
  std::vector<int> entry;  // sorted

  explicit FresnelKnots(const std::vector<NodeWeights>& row_entries) {
    for (const NodeWeights& e : row_entries) entry.insert(entry.end(), e.node.begin(), e.node.end());
    std::sort(entry.begin(), entry.end());
    entry.erase(std::unique(entry.begin(), entry.end()), entry.end());
  }
  std::size_t size() const { return entry.size(); }
  // The position of knot entry e among the knots.
  std::size_t index(int e) const { return std::size_t(std::lower_bound(entry.begin(), entry.end(), e) - entry.begin()); }

  // The two knots bracketing entry position x and their weights.
  void bracket(double x, int e[2], double w[2]) const {
    const auto above = std::upper_bound(entry.begin(), entry.end(), x);
    if (above == entry.begin() || above == entry.end()) {
      e[0] = e[1] = above == entry.begin() ? entry.front() : entry.back();
      w[0] = 1.0, w[1] = 0.0;
      return;
    }
    e[0] = *(above - 1), e[1] = *above;
    w[1] = (x - e[0]) / double(e[1] - e[0]), w[0] = 1.0 - w[1];
  }
};

// What the refinement solves for, in the layout of its parameter blocks.
struct LobeUnknowns {
  std::vector<double> d, body;
  double exponent;
  std::vector<std::array<double, 3>> fresnel;

  explicit LobeUnknowns(const LobeFit& fit)
      : d(fit.ndf.ndf), body{fit.body.r, fit.body.g, fit.body.b}, exponent(clamp(fit.body_exponent, 1.0, kMaxBodyExponent)),
        fresnel(FresnelCurve::kSize) {
    for (int j = 0; j < FresnelCurve::kSize; ++j)
      for (int c = 0; c < 3; ++c) fresnel[std::size_t(j)][std::size_t(c)] = clamp(fit.fresnel.value[std::size_t(j)][c], 0.0, 1.0);
  }
  std::vector<double*> node_blocks() {
    std::vector<double*> all;
    for (double& v : d) all.push_back(&v);
    return all;
  }
};

// The albedo's coefficients B[n][m] of one view (AlbedoRefineCost): the lobe's visible normals drawn on a
// jittered 32 x 32 grid, each direction's spline weights on the nodes times its linear weights on the
// knots (through the Fresnel entries between them).
AlbedoRefineCost::View albedo_view(double cos_o, std::uint64_t seed, const LobeFit& lobe, Smith smith, const ThetaGrid& grid,
                                   const VisibleSlopeProposal& proposal, const G1Table& g1, const FresnelKnots& knots) {
  constexpr int kGrid = 32;
  const double step = FresnelCurve::theta_d(1);
  AlbedoRefineCost::View v;
  v.cos_o = cos_o;
  v.b.assign(lobe.ndf.ndf.size() * knots.size(), 0.0);
  const Vec3 o(std::sqrt(std::max(0.0, 1.0 - v.cos_o * v.cos_o)), 0.0, v.cos_o);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> jitter(0.0, 1.0);
  for (int a = 0; a < kGrid; ++a)
    for (int c = 0; c < kGrid; ++c) {
      const auto i = proposal.sample_direction(o, (a + jitter(rng)) / kGrid, (c + jitter(rng)) / kGrid);
      const double pdf = i ? proposal.pdf(o, *i) : 0.0;
      if (!(pdf > 0.0)) continue;
      const Vec3 h = glm::normalize(*i + o);
      const double g = smith_g2_from_g1(smith, g1(o.z), g1(i->z)) / (4.0 * o.z * pdf * kGrid * kGrid);
      const NodeWeights nodes = ndf_nodes(grid, std::acos(clamp(h.z, -1.0, 1.0)));
      // F at theta_d: linear between entries x0 and x0 + 1, each linear between its bracketing knots.
      const double x = clamp(std::acos(clamp(glm::dot(*i, h), 0.0, 1.0)) / step, 0.0, double(FresnelCurve::kSize - 1));
      const int x0 = std::min(int(x), FresnelCurve::kSize - 2);
      for (int side = 0; side < 2; ++side) {
        const double along = side == 0 ? x0 + 1 - x : x - x0;
        int e[2];
        double w[2];
        knots.bracket(x0 + side, e, w);
        for (int q = 0; q < 2; ++q) {
          const std::size_t m = knots.index(e[q]);
          for (std::size_t t = 0; t < nodes.node.size(); ++t)
            v.b[std::size_t(nodes.node[t]) * knots.size() + m] += g * along * w[q] * nodes.weight[t];
        }
      }
    }
  const Coat& coat = lobe.coat;
  if (coat.present())
    VisibleMoments::for_each_visible_normal(v.cos_o, coat.alpha, coat.alpha,
                                            [&](double mu, double ratio) { v.coat += fresnel_schlick(Rgb(coat.f0), mu).r * ratio; });
  return v;
}

// The albedo views of the current lobe, one per view of the target (seeded by its index).
std::vector<AlbedoRefineCost::View> albedo_views(const AlbedoTarget& target, const LobeFit& lobe, Smith smith, const ThetaGrid& grid,
                                                 const FresnelKnots& knots) {
  std::vector<AlbedoRefineCost::View> views(target.cos_o.size());
  const VisibleSlopeProposal proposal(lobe.tables(smith));
  const G1Table g1(lobe.ndf);
  tbb::parallel_for(std::size_t(0), views.size(),
                    [&](std::size_t j) { views[j] = albedo_view(target.cos_o[j], j + 1, lobe, smith, grid, proposal, g1, knots); });
  return views;
}

// The smoothness penalties: second differences of the Fresnel knots and of the NDF nodes.
void add_smoothness(SmallProblem& problem, const FresnelKnots& knots, LobeUnknowns& x, const RefineOptions& options) {
  const std::vector<int>& k = knots.entry;
  for (std::size_t j = 1; j + 1 < k.size(); ++j)
    problem.add_residual_block(new ceres::AutoDiffCostFunction<SecondDifference<3>, 3, 3, 3, 3>(
                                 new SecondDifference<3>(fresnel_smoothness(options.fresnel_smoothness, k[j - 1], k[j], k[j + 1]))), x.fresnel[std::size_t(k[j - 1])].data(), x.fresnel[std::size_t(k[j])].data(),
                             x.fresnel[std::size_t(k[j + 1])].data());
  std::vector<double>& d = x.d;
  for (std::size_t j = 1; j + 1 < d.size(); ++j) {
    const double scale = std::max(d[j], 1e-3 * d[0] + 1e-6);
    problem.add_residual_block(new ceres::AutoDiffCostFunction<SecondDifference<1>, 1, 1, 1, 1>(
                                 new SecondDifference<1>{options.ndf_smoothness / scale, -2.0 * options.ndf_smoothness / scale,
                                                         options.ndf_smoothness / scale}), &d[j - 1], &d[j], &d[j + 1]);
  }
}

// Bounds, not a clamp afterwards: left free, the solve trades negative nodes against each other. A
// Fresnel factor is a reflectance: in [0, 1] (above 1 the fit would trade the NDF's scale for it).
void set_bounds(SmallProblem& problem, const FresnelKnots& knots, LobeUnknowns& x) {
  for (int c = 0; c < 3; ++c) problem.set_lower_bound(x.body.data(), c, 0.0);
  problem.set_lower_bound(&x.exponent, 0, 1.0), problem.set_upper_bound(&x.exponent, 0, kMaxBodyExponent);
  for (int j : knots.entry)
    for (int c = 0; c < 3; ++c)
      problem.set_lower_bound(x.fresnel[std::size_t(j)].data(), c, 0.0),
          problem.set_upper_bound(x.fresnel[std::size_t(j)].data(), c, 1.0);
  for (double& v : x.d) problem.set_lower_bound(&v, 0, 0.0);
}

// The fit the unknowns stand for: the body, its exponent (Lambert's where it does nothing visible: within
// 1e-3 of 1, f_body moves by under 0.5% even where both cosines are 0.01, or over a body too faint to see;
// the LUT then stays version 2 or 3), the Fresnel entries from the knots.
void store(const LobeUnknowns& x, const FresnelKnots& knots, LobeFit& fit) {
  const std::vector<double>& body = x.body;
  fit.body = Rgb(body[0], body[1], body[2]);
  fit.body_exponent = std::abs(x.exponent - 1.0) < 1e-3 || std::max({body[0], body[1], body[2]}) < 1e-3 ? 1.0 : x.exponent;
  for (int j = 0; j < FresnelCurve::kSize; ++j) {
    int e[2];
    double w[2];
    knots.bracket(j, e, w);
    for (int c = 0; c < 3; ++c)
      fit.fresnel.value[std::size_t(j)][c] =
          w[0] * x.fresnel[std::size_t(e[0])][std::size_t(c)] + w[1] * x.fresnel[std::size_t(e[1])][std::size_t(c)];
  }
}

}  // namespace

double normalize_ndf(TabulatedNdf& ndf, const Quadrature& quad) {
  const std::vector<double>& area = quad.projected_area();
  double s = 0.0;
  for (std::size_t j = 0; j < area.size(); ++j) s += area[j] * ndf.ndf[j];
  if (s > 0.0)
    for (double& v : ndf.ndf) v /= s;
  ndf.sigma.resize(ndf.ndf.size());
  for (int k = 0; k < quad.size(); ++k) {
    const double* row = quad.positive_row(k);
    double sigma = 0.0;
    for (std::size_t j = 0; j < ndf.ndf.size(); ++j) sigma += row[j] * ndf.ndf[j];
    ndf.sigma[std::size_t(k)] = sigma;
  }
  return s;
}

LobeFit refine_lobe(const MeasuredBins& bins, const Quadrature& quad, Smith smith, const LobeFit& start,
                    const RefineOptions& options) {
  LobeFit fit = start;
  if (bins.size() == 0) return fit;
  normalize_ndf(fit.ndf, quad);
  LobeUnknowns x(fit);
  std::vector<NodeWeights> row_nodes, row_entries;
  for (const MeasuredBins::Row& row : bins.rows)
    row_nodes.push_back(ndf_nodes(quad.grid(), row.theta_h)), row_entries.push_back(fresnel_entries(row.theta_d));
  const FresnelKnots knots(row_entries);
  const bool albedo = options.albedo && !options.albedo->cos_o.empty();

  for (int pass = 0; pass < options.passes; ++pass) {
    const PassTerms terms = pass_terms(bins, smith, fit);  // G2 of the current NDF (the coat is held: the same every pass)
    SmallProblem problem;
    for (std::size_t r = 0; r < bins.rows.size(); ++r) {
      std::vector<double*> blocks{x.body.data(), &x.exponent};
      for (int e : row_entries[r].node) blocks.push_back(x.fresnel[std::size_t(e)].data());
      for (int n : row_nodes[r].node) blocks.push_back(&x.d[std::size_t(n)]);
      problem.add_residual_block(new LobeRowCost(bins, bins.rows[r], terms, row_entries[r], row_nodes[r]), blocks);
    }
    const std::vector<double*> all_nodes = x.node_blocks();
    problem.add_residual_block(new NormalizationCost(quad.projected_area(), 10.0), all_nodes);
    if (albedo) {
      std::vector<double*> blocks{x.body.data(), &x.exponent};
      for (int e : knots.entry) blocks.push_back(x.fresnel[std::size_t(e)].data());
      blocks.insert(blocks.end(), all_nodes.begin(), all_nodes.end());
      problem.add_residual_block(new AlbedoRefineCost(*options.albedo, albedo_views(*options.albedo, fit, smith, quad.grid(), knots),
                                                    knots.size(), x.d.size()), blocks);
    }
    add_smoothness(problem, knots, x, options);
    set_bounds(problem, knots, x);
    problem.solve(options.max_iterations, options.function_tolerance);

    fit.ndf.ndf = x.d;
    const double area = normalize_ndf(fit.ndf, quad);  // F D stays what the solve found
    x.d = fit.ndf.ndf;
    for (auto& f : x.fresnel)
      for (double& v : f) v = std::min(v * area, 1.0);
  }
  store(x, knots, fit);
  return fit;
}

double refine_jacobian_error(const MeasuredBins& bins, const Quadrature& quad, Smith smith, const LobeFit& at) {
  const PassTerms terms = pass_terms(bins, smith, at);
  std::vector<double> d = at.ndf.ndf, body = {at.body.r, at.body.g, at.body.b};
  double exponent = at.body_exponent;
  std::vector<std::array<double, 3>> fresnel(FresnelCurve::kSize);
  for (int j = 0; j < FresnelCurve::kSize; ++j)
    for (int c = 0; c < 3; ++c) fresnel[std::size_t(j)][std::size_t(c)] = at.fresnel.value[std::size_t(j)][c];
  double worst = 0.0;
  for (const MeasuredBins::Row& row : bins.rows) {
    NodeWeights entries = fresnel_entries(row.theta_d), nodes = ndf_nodes(quad.grid(), row.theta_h);
    std::vector<double*> blocks{body.data(), &exponent};
    for (int e : entries.node) blocks.push_back(fresnel[std::size_t(e)].data());
    for (int n : nodes.node) blocks.push_back(&d[std::size_t(n)]);
    worst = std::max(worst, jacobian_error(LobeRowCost(bins, row, terms, std::move(entries), std::move(nodes)), blocks));
  }
  return worst;
}

}  // namespace facetfit
