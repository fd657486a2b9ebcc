#include "fit/closure_fit.h"

#include <ceres/ceres.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <random>
#include <vector>

#include "fit/lobe_terms.h"
#include "fit/small_problem.h"
#include "fit/visible_moments.h"

namespace facetfit {

namespace {

using namespace lobe_terms;

// A view exponent below this is 0: the lobe is isotropic, and the artist's anisotropic controls apply to it.
constexpr double kIsotropicBelow = 0.05;
// Films measured so far take k of 0.9 to 3.6; beyond 4 a lobe's alpha across the view reaches 1 (Cycles'
// clamp) by 60 degrees for any alpha above 0.06.
constexpr double kMaxViewExponent = 4.0;

// The unknowns of a solve, in the blocks the cost function reads: body (3), coat (log alpha, f0), then per
// lobe its shape (log alpha, the weight of an F82-tint lobe or the exponent of a Schlick one, and the view
// exponent k), f0 (3) and the second colour (f82 or f90, 3). A Schlick lobe's weight is 1: f90 scales it.
struct Unknowns {
  struct Lobe {
    NdfType type = NdfType::ggx;
    ClosureLobe::Fresnel fresnel = ClosureLobe::Fresnel::f82_tint;
    std::array<double, 3> shape{};
    std::array<double, 3> f0{}, second{};
  };
  std::array<double, 3> body{};
  std::array<double, 2> coat{};
  bool with_coat = false;
  std::vector<Lobe> lobes;

  explicit Unknowns(const Closures& c) : with_coat(c.coat.present()) {
    body = {c.body.r, c.body.g, c.body.b};
    coat = {std::log(with_coat ? c.coat.alpha : 0.1), c.coat.f0};
    for (const ClosureLobe& l : c.lobes) {
      const bool tint = l.fresnel == ClosureLobe::Fresnel::f82_tint;
      const Rgb& second = tint ? l.f82 : l.f90;
      lobes.push_back({l.type, l.fresnel, {std::log(std::max(l.alpha_x, 1e-3)), tint ? l.weight : l.exponent, l.view_exponent},
                       {l.f0.r, l.f0.g, l.f0.b}, {second.r, second.g, second.b}});
    }
  }
  Closures closures() const {
    Closures c;
    c.body = Rgb(body[0], body[1], body[2]);
    if (with_coat) c.coat = Coat{std::exp(coat[0]), coat[1]};
    for (const Lobe& l : lobes) {
      ClosureLobe lobe;
      lobe.type = l.type;
      lobe.alpha_x = lobe.alpha_y = std::exp(l.shape[0]);
      lobe.view_exponent = l.shape[2] < kIsotropicBelow ? 0.0 : l.shape[2];
      lobe.fresnel = l.fresnel;
      lobe.f0 = Rgb(l.f0[0], l.f0[1], l.f0[2]);
      const Rgb second(l.second[0], l.second[1], l.second[2]);
      if (l.fresnel == ClosureLobe::Fresnel::f82_tint)
        lobe.weight = l.shape[1], lobe.f82 = second;
      else
        lobe.exponent = l.shape[1], lobe.f90 = second;
      c.lobes.push_back(lobe);
    }
    return c;
  }
  std::vector<double*> blocks() {
    std::vector<double*> b{body.data(), coat.data()};
    for (Lobe& l : lobes) b.insert(b.end(), {l.shape.data(), l.f0.data(), l.second.data()});
    return b;
  }
};

// A lobe's Fresnel in each channel, times its weight, and the derivatives in the lobe's unknowns: the
// second shape entry (weight or exponent), f0 and the second colour.
struct LobeFresnel {
  double value = 0.0, d_shape = 0.0, d_f0 = 0.0, d_second = 0.0;
};
using LobeFresnelRgb = std::array<LobeFresnel, 3>;
LobeFresnelRgb lobe_fresnel(ClosureLobe::Fresnel form, double shape, const double* f0, const double* second, double mu) {
  LobeFresnelRgb f;
  if (form == ClosureLobe::Fresnel::f82_tint) {  // w F82-tint(f0, f82)
    for (int e = 0; e < 3; ++e) {
      const FresnelTerms t = fresnel_terms(f0[e], second[e], mu, true);
      f[std::size_t(e)] = {shape * t.value, t.value, shape * t.d_f0, shape * t.d_f82};
    }
    return f;
  }
  // f0 + (f90 - f0) x, x = (1 - mu)^e: dF/de = (f90 - f0) x log(1 - mu).
  const double m = 1.0 - mu, x = m > 0.0 ? std::pow(m, shape) : 0.0, x_log = m > 0.0 ? x * std::log(m) : 0.0;
  for (int e = 0; e < 3; ++e) f[std::size_t(e)] = {f0[e] + (second[e] - f0[e]) * x, (second[e] - f0[e]) * x_log, 1.0 - x, x};
  return f;
}

// A view-aligned lobe (model/closures.h) at view cos theta_o: its alpha across the view from log alpha and
// k, and the derivatives of log of it in log alpha and k (0 where it is clamped).
struct AcrossView {
  double alpha = 0.0, d_log_alpha = 1.0, d_k = 0.0;
};
AcrossView across_view(double log_alpha, double k, double cos_o) {
  const double alpha = std::exp(log_alpha), across = alpha_across_view(alpha, k, cos_o);
  if (across >= std::max(alpha, 1.0)) return {across, 0.0, 0.0};  // clamped
  return {across, 1.0, -std::log(std::max(cos_o, 1e-3))};
}

// The residuals of one row of bins (3 per bin), with analytic derivatives:
//   m = body / pi + sum_k F_k(mu) D_k G2_k / (4 cos_i cos_o) + Schlick(coat_f0, mu) D_c G2_c / (4 cos_i cos_o),
// F_k the lobe's weighted Fresnel (lobe_fresnel), G2 height-correlated throughout (the closures'), each lobe
// D_k G2_k in the frame of the bin's view o (alpha along it, across_view across: ggx_anisotropic_terms).
class ClosureRowCost final : public ceres::CostFunction {
 public:
  ClosureRowCost(const MeasuredBins& bins, const MeasuredBins::Row& row, std::vector<Unknowns::Lobe> forms, bool with_coat)
      : bins_(bins), row_(row), forms_(std::move(forms)), with_coat_(with_coat) {
    set_num_residuals(int(3 * (row.end - row.begin)));
    for (int size : {3, 2}) mutable_parameter_block_sizes()->push_back(size);
    for (std::size_t k = 0; k < forms_.size(); ++k)
      for (int size : {3, 3, 3}) mutable_parameter_block_sizes()->push_back(size);
  }

  bool Evaluate(double const* const* p, double* residuals, double** jacobians) const override {
    const std::size_t n = row_.end - row_.begin, lobes = forms_.size();
    if (jacobians)
      for (std::size_t b = 0; b < parameter_block_sizes().size(); ++b)
        if (jacobians[b]) std::fill(jacobians[b], jacobians[b] + 3 * n * std::size_t(parameter_block_sizes()[b]), 0.0);
    const double coat_alpha = std::exp(p[1][0]), coat_f0 = p[1][1];
    std::array<double, Closures::kMaxLobes> lobe{}, lobe_slope{}, lobe_k{};
    for (std::size_t q = 0; q < n; ++q) {
      const std::size_t k = row_.begin + q;
      const double ci = bins_.i[k].z, co = bins_.o[k].z, mu = bins_.cos_d[k], ch = bins_.cos_h[k];
      const TurnedFrame view = TurnedFrame::of_azimuth(bins_.o[k]);
      const Vec3 o = view.to_frame(bins_.o[k]), i = view.to_frame(bins_.i[k]), h = glm::normalize(o + i);
      for (std::size_t l = 0; l < lobes; ++l) {  // D G2 / (4 cos_i cos_o) and its derivatives in log alpha and k
        const double* shape = p[2 + 3 * l];
        const AcrossView across = across_view(shape[0], shape[2], co);
        const AnisotropicLobeTerms t = ggx_anisotropic_terms(o, i, h, std::exp(shape[0]), across.alpha);
        lobe[l] = t.value;
        lobe_slope[l] = t.d_log_ax + t.d_log_ay * across.d_log_alpha;
        lobe_k[l] = t.d_log_ay * across.d_k;
      }
      const CoatTerms coat = with_coat_ ? coat_terms(coat_alpha, coat_f0, ch, ci, co, mu) : CoatTerms{};
      std::array<LobeFresnelRgb, Closures::kMaxLobes> fresnel;
      for (std::size_t l = 0; l < lobes; ++l) fresnel[l] = lobe_fresnel(forms_[l].fresnel, p[2 + 3 * l][1], p[3 + 3 * l], p[4 + 3 * l], mu);
      const double w = std::sqrt(bins_.weight[k]), c = bins_.cosine[k];
      const bool grazing = grazing_pair(bins_.o[k], bins_.i[k]);
      for (int e = 0; e < 3; ++e) {
        const std::size_t r = 3 * q + std::size_t(e);
        if (!(bins_.valid[k] >> e & 1u)) {
          residuals[r] = 0.0;
          continue;
        }
        double m = p[0][e] * kInvPi + coat.value;
        for (std::size_t l = 0; l < lobes; ++l) m += fresnel[l][std::size_t(e)].value * lobe[l];
        const MetricResidual res = metric_residual(m, c, bins_.lightness[k][e], grazing);
        residuals[r] = w * res.value;
        if (!jacobians || m < 0.0) continue;
        const double dm = w * res.slope;
        if (jacobians[0]) jacobians[0][3 * r + std::size_t(e)] = dm * kInvPi;
        if (jacobians[1]) jacobians[1][2 * r] = dm * coat.d_log_alpha, jacobians[1][2 * r + 1] = dm * coat.d_f0;
        for (std::size_t l = 0; l < lobes; ++l) {
          const LobeFresnel& f = fresnel[l][std::size_t(e)];
          if (double* j = jacobians[2 + 3 * l])
            j[3 * r] = dm * f.value * lobe_slope[l], j[3 * r + 1] = dm * f.d_shape * lobe[l], j[3 * r + 2] = dm * f.value * lobe_k[l];
          if (double* j = jacobians[3 + 3 * l]) j[3 * r + std::size_t(e)] = dm * f.d_f0 * lobe[l];
          if (double* j = jacobians[4 + 3 * l]) j[3 * r + std::size_t(e)] = dm * f.d_second * lobe[l];
        }
      }
    }
    return true;
  }

 private:
  const MeasuredBins& bins_;
  const MeasuredBins::Row& row_;
  std::vector<Unknowns::Lobe> forms_;  // each lobe's family and Fresnel form
  bool with_coat_;
};

// A lobe's directional albedo at one view of a VisibleMoments table, per channel, from its Fresnel's
// powers of 1 - mu (fit/visible_moments.h: alpha along the view, across_view across), and its derivatives in
// the lobe's unknowns:
//   F82-tint, w (f0 (M0 - M5) + M5 - a (M6 - M7)), a = f82_shift (mu (1 - mu)^6 = (1 - mu)^6 - (1 - mu)^7);
//   generalized Schlick, f0 M0 + (f90 - f0) Me.
struct LobeAlbedo {
  double value = 0.0, d_log_alpha = 0.0, d_shape = 0.0, d_k = 0.0, d_f0 = 0.0, d_second = 0.0;
};
std::array<LobeAlbedo, 3> lobe_albedo(const VisibleMoments& moments, std::size_t view, double cos_o, ClosureLobe::Fresnel form,
                                      const double* shape, const double* f0, const double* second) {
  const AcrossView across = across_view(shape[0], shape[2], cos_o);
  struct LobeMoment {
    double value, d_log_alpha, d_k, d_exponent;
  };
  const auto at = [&](double e) {
    const VisibleMoments::Moment m = moments.at(view, shape[0], std::log(across.alpha), e);
    return LobeMoment{m.value, m.d_log_alpha_x + m.d_log_alpha_y * across.d_log_alpha, m.d_log_alpha_y * across.d_k, m.d_exponent};
  };
  std::array<LobeAlbedo, 3> rho;
  const LobeMoment m0 = at(0.0);
  if (form == ClosureLobe::Fresnel::f82_tint) {
    const LobeMoment m5 = at(5.0), m6 = at(6.0), m7 = at(7.0);
    const double w = shape[1], s = m0.value - m5.value, b = m6.value - m7.value;
    const double s_slope = m0.d_log_alpha - m5.d_log_alpha, b_slope = m6.d_log_alpha - m7.d_log_alpha;
    const double s_k = m0.d_k - m5.d_k, b_k = m6.d_k - m7.d_k;
    for (std::size_t e = 0; e < 3; ++e) {
      const F82Shift a = f82_shift(f0[e], second[e]);
      const double bracket = f0[e] * s + m5.value - a.value * b;
      rho[e] = {w * bracket,
                w * (f0[e] * s_slope + m5.d_log_alpha - a.value * b_slope),
                bracket,
                w * (f0[e] * s_k + m5.d_k - a.value * b_k),
                w * (s - a.d_f0 * b),
                -w * a.d_f82 * b};
    }
    return rho;
  }
  const LobeMoment me = at(shape[1]);
  for (std::size_t e = 0; e < 3; ++e) {
    const double rise = second[e] - f0[e];
    rho[e] = {f0[e] * m0.value + rise * me.value, f0[e] * m0.d_log_alpha + rise * me.d_log_alpha, rise * me.d_exponent,
              f0[e] * m0.d_k + rise * me.d_k,     m0.value - me.value,                              me.value};
  }
  return rho;
}

// The residuals of the closures' directional albedo at the views of an AlbedoTarget, one per view and channel
// (albedo_residual), with rho = body + each lobe's and the coat's albedo (lobe_albedo; the coat a generalized
// Schlick of f90 = 1, e = 5).
class AlbedoCost final : public ceres::CostFunction {
 public:
  AlbedoCost(const AlbedoTarget& target, std::vector<Unknowns::Lobe> forms, bool with_coat)
      : target_(target), moments_(VisibleMoments::at_views(target.cos_o)), forms_(std::move(forms)), with_coat_(with_coat) {
    set_num_residuals(int(3 * target.cos_o.size()));
    for (int size : {3, 2}) mutable_parameter_block_sizes()->push_back(size);
    for (std::size_t k = 0; k < forms_.size(); ++k)
      for (int size : {3, 3, 3}) mutable_parameter_block_sizes()->push_back(size);
  }

  bool Evaluate(double const* const* p, double* residuals, double** jacobians) const override {
    const std::size_t views = target_.cos_o.size(), lobes = forms_.size();
    if (jacobians)
      for (std::size_t b = 0; b < parameter_block_sizes().size(); ++b)
        if (jacobians[b]) std::fill(jacobians[b], jacobians[b] + 3 * views * std::size_t(parameter_block_sizes()[b]), 0.0);
    for (std::size_t j = 0; j < views; ++j) {
      std::array<std::array<LobeAlbedo, 3>, Closures::kMaxLobes> lobe{};
      std::array<double, 3> rho{p[0][0], p[0][1], p[0][2]};
      for (std::size_t l = 0; l < lobes; ++l) {
        lobe[l] = lobe_albedo(*moments_, j, target_.cos_o[j], forms_[l].fresnel, p[2 + 3 * l], p[3 + 3 * l], p[4 + 3 * l]);
        for (std::size_t e = 0; e < 3; ++e) rho[e] += lobe[l][e].value;
      }
      std::array<LobeAlbedo, 3> coat{};
      if (with_coat_) {
        const std::array<double, 3> shape{p[1][0], 5.0, 0.0};
        const std::array<double, 3> f0{p[1][1], p[1][1], p[1][1]}, f90{1.0, 1.0, 1.0};
        coat = lobe_albedo(*moments_, j, target_.cos_o[j], ClosureLobe::Fresnel::schlick, shape.data(), f0.data(), f90.data());
        for (std::size_t e = 0; e < 3; ++e) rho[e] += coat[e].value;
      }
      for (std::size_t e = 0; e < 3; ++e) {
        const std::size_t r = 3 * j + e;
        const MetricResidual res = albedo_residual(target_, j, int(e), rho[e]);
        residuals[r] = res.value;
        if (!jacobians || res.slope == 0.0) continue;
        const double dm = res.slope;
        if (jacobians[0]) jacobians[0][3 * r + e] = dm;
        if (jacobians[1]) jacobians[1][2 * r] = dm * coat[e].d_log_alpha, jacobians[1][2 * r + 1] = dm * coat[e].d_f0;
        for (std::size_t l = 0; l < lobes; ++l) {
          const LobeAlbedo& a = lobe[l][e];
          if (double* jac = jacobians[2 + 3 * l]) jac[3 * r] = dm * a.d_log_alpha, jac[3 * r + 1] = dm * a.d_shape, jac[3 * r + 2] = dm * a.d_k;
          if (double* jac = jacobians[3 + 3 * l]) jac[3 * r + e] = dm * a.d_f0;
          if (double* jac = jacobians[4 + 3 * l]) jac[3 * r + e] = dm * a.d_second;
        }
      }
    }
    return true;
  }

 private:
  const AlbedoTarget& target_;
  std::shared_ptr<const VisibleMoments> moments_;
  std::vector<Unknowns::Lobe> forms_;
  bool with_coat_;
};

// Every unknown solved from `start` on `bins`, within the bounds: alphas in [1e-3, 1] (Cycles clamps a
// closure's alpha to 1), weights and colours in [0, 1], exponents in [0.25, 10], view exponents in [0,
// kMaxViewExponent], a nonnegative body, the coat as fit/parametric_fit.cpp bounds it.
// A solve's closures and its objective, 1/2 the sum of the squared residuals of the bins and the albedo.
struct Solved {
  Closures closures;
  double cost = 0.0;
};

Solved solve(const MeasuredBins& bins, const AlbedoTarget* albedo, const Closures& start, int max_iterations) {
  Unknowns u(start);
  SmallProblem problem;
  for (const MeasuredBins::Row& row : bins.rows) problem.add_residual_block(new ClosureRowCost(bins, row, u.lobes, u.with_coat), u.blocks());
  if (albedo && !albedo->cos_o.empty()) problem.add_residual_block(new AlbedoCost(*albedo, u.lobes, u.with_coat), u.blocks());
  if (bins.rows.empty()) return {start, 0.0};
  for (int c = 0; c < 3; ++c) problem.set_lower_bound(u.body.data(), c, 0.0);
  if (u.with_coat) {
    problem.set_lower_bound(u.coat.data(), 0, std::log(1e-3));
    problem.set_upper_bound(u.coat.data(), 0, 0.0);
    problem.set_lower_bound(u.coat.data(), 1, 0.0);
    problem.set_upper_bound(u.coat.data(), 1, 1.0);
  } else {
    problem.set_constant(u.coat.data());
  }
  for (Unknowns::Lobe& l : u.lobes) {
    const bool tint = l.fresnel == ClosureLobe::Fresnel::f82_tint;
    problem.set_lower_bound(l.shape.data(), 0, std::log(1e-3));
    problem.set_upper_bound(l.shape.data(), 0, 0.0);
    problem.set_lower_bound(l.shape.data(), 1, tint ? 0.0 : 0.25);
    problem.set_upper_bound(l.shape.data(), 1, tint ? 1.0 : 10.0);
    problem.set_lower_bound(l.shape.data(), 2, 0.0);
    problem.set_upper_bound(l.shape.data(), 2, kMaxViewExponent);
    for (double* block : {l.f0.data(), l.second.data()})
      for (int c = 0; c < 3; ++c) problem.set_lower_bound(block, c, 0.0), problem.set_upper_bound(block, c, 1.0);
  }
  const double cost = problem.solve(max_iterations, 1e-6).final_cost;
  return {u.closures(), cost};
}

// `fit` with one more GGX lobe of Fresnel `form`, `scale` times the alpha of its strongest lobe (by weight
// times the luminance of F at 60 degrees), of its colour, taking a quarter of every lobe's weight. At the
// same alpha (scale 1) a Schlick lobe's F falls to 0 at grazing: beside a rising lobe it makes a colour that
// dips and rises again with theta_d, as a thin film's does (cc_nothern_aurora's red falls from 0.10 to 0.06 at
// 24 degrees and rises to 0.28 at 64), which no one Schlick lobe follows.
Closures with_lobe(const Closures& fit, ClosureLobe::Fresnel form, double scale) {
  Closures c = fit;
  const auto strength = [](const ClosureLobe& l) { return l.weight * luminance(l.fresnel_at(0.5)); };
  const ClosureLobe strongest = *std::max_element(c.lobes.begin(), c.lobes.end(),
                                                  [&](const ClosureLobe& a, const ClosureLobe& b) { return strength(a) < strength(b); });
  for (ClosureLobe& l : c.lobes) l.weight *= 0.75;
  ClosureLobe lobe;
  lobe.alpha_x = lobe.alpha_y = std::clamp(strongest.alpha_x * scale, 2e-3, 1.0);
  lobe.fresnel = form;
  lobe.f0 = strongest.f0;
  if (form == ClosureLobe::Fresnel::f82_tint) {
    lobe.weight = 0.25;
    lobe.f82 = strongest.f82;
  } else if (scale != 1.0) {  // a quarter of the strongest's F at normal incidence, rising as (1 - mu)^2 to a quarter of it at 82 degrees
    lobe.f0 = 0.25 * strongest.fresnel_at(1.0);
    lobe.f90 = 0.25 * strongest.fresnel_at(1.0 / 7.0);
    lobe.exponent = 2.0;
  } else {  // at the strongest's alpha, a quarter of its F at normal incidence falling to 0 at grazing
    lobe.f0 = 0.25 * strongest.fresnel_at(1.0);
    lobe.f90 = Rgb(0.0);
    lobe.exponent = 1.0;
  }
  c.lobes.push_back(lobe);
  return c;
}

// Three generalized-Schlick lobes spread about `start`'s first: a third, once and three times its alpha, each
// with a third of its Fresnel at 0 and 82 degrees, following the view a little (k = 0.5).
Closures spread_lobes(const Closures& start) {
  Closures spread = start;
  spread.lobes.clear();
  const ClosureLobe& first = start.lobes.front();
  for (double scale : {1.0 / 3.0, 1.0, 3.0}) {
    ClosureLobe l;
    l.alpha_x = l.alpha_y = std::clamp(first.alpha_x * scale, 2e-3, 1.0);
    l.fresnel = ClosureLobe::Fresnel::schlick;
    l.f0 = first.fresnel_at(1.0) / 3.0;
    l.f90 = first.fresnel_at(1.0 / 7.0) / 3.0;
    l.view_exponent = 0.5;
    spread.lobes.push_back(l);
  }
  return spread;
}

// Whether `after` pays for the lobes it has beyond `before`'s: the objective's distance, sqrt(2 cost) (the bins'
// weights sum to 1), nearer by `lobe_gain` of itself and at least `min_gain` for each of them.
bool pays(const Solved& before, const Solved& after, const ClosureFitOptions& options) {
  const int more = int(after.closures.lobes.size()) - int(before.closures.lobes.size());
  const double d0 = std::sqrt(2.0 * before.cost), d1 = std::sqrt(2.0 * after.cost);
  return d1 < d0 - std::max(0, more) * std::max(options.lobe_gain * d0, options.min_gain) || (more <= 0 && d1 < d0);
}

}  // namespace

Rgb closure_albedo(const Closures& closures, double cos_o) {
  Rgb rho = closures.body;
  for (const ClosureLobe& l : closures.lobes)
    VisibleMoments::for_each_visible_normal(cos_o, l.alpha_x, l.ndf(cos_o).alpha_y,
                                            [&](double mu, double ratio) { rho += l.weight * l.fresnel_at(mu) * ratio; });
  const Coat& coat = closures.coat;
  if (coat.present())
    VisibleMoments::for_each_visible_normal(cos_o, coat.alpha, coat.alpha,
                                            [&](double mu, double ratio) { rho += fresnel_schlick(Rgb(coat.f0), mu) * ratio; });
  return rho;
}

double closure_error(const MeasuredBins& bins, const Closures& closures) { return measurement_error(bins, ClosureBrdf(closures)); }

ClosureFit fit_closures(const MeasuredBins& bins, const AlbedoTarget* albedo, const MeasuredBins& error_bins,
                        const ParametricFit& start, const ClosureFitOptions& options) {
  return fit_closures(bins, albedo, error_bins, closures_of(start), options);
}

ClosureFit fit_closures(const MeasuredBins& bins, const AlbedoTarget* albedo, const MeasuredBins& error_bins,
                        const Closures& start, const ClosureFitOptions& options) {
  // Lobes are chosen on a third of the rows; the choice is solved on all of them.
  const MeasuredBins screen = every_nth_row(bins, 3);
  Closures first = start;
  if (options.fresnel == ClosureLobe::Fresnel::schlick)
    for (ClosureLobe& l : first.lobes) l = without_f82(l);
  Solved current = solve(screen, albedo, first, options.max_iterations);
  while (int(current.closures.lobes.size()) < options.max_lobes) {
    // A sharper and a broader generalized-Schlick lobe and one of the same alpha (with_lobe), solved
    // concurrently. (On the six RGL materials the Schlick candidates were taken over F82-tint ones of the
    // same alpha, or within 0.1% of them: their exponent bends the colour over the middle angles, where the
    // first lobe's F82-tint is flat.)
    constexpr std::array<double, 3> kScales{0.5, 2.0, 1.0};
    std::array<Solved, kScales.size()> tried;
    tbb::parallel_for(std::size_t(0), kScales.size(), [&](std::size_t t) {
      tried[t] = solve(screen, albedo, with_lobe(current.closures, ClosureLobe::Fresnel::schlick, kScales[t]), options.max_iterations);
    });
    const Solved& best = *std::min_element(tried.begin(), tried.end(), [](const Solved& a, const Solved& b) { return a.cost < b.cost; });
    // Below the gain a lobe only takes over what a solve of fewer lobes had left unconverged.
    if (!pays(current, best, options)) break;
    current = best;
  }
  // The choice made, its solve carried on to convergence.
  current = solve(bins, albedo, current.closures, options.polish_iterations);
  ClosureFit fit{current.closures, closure_error(error_bins, current.closures)};
  // A second start, three lobes at once: lobe by lobe, a lobe added where the first one stood can settle in a
  // compromise that no single added lobe leaves. Both solved to convergence, the one `options.judge` (else the
  // objective) finds nearer is kept.
  if (options.max_lobes >= 3 && start.lobes.size() == 1 && !start.lobes.front().view_aligned()) {
    Solved spread = solve(screen, albedo, spread_lobes(start), options.max_iterations);
    spread = solve(bins, albedo, spread.closures, options.polish_iterations);
    const bool nearer = options.judge ? options.judge(spread.closures) < options.judge(current.closures) : pays(current, spread, options);
    if (nearer) fit = {spread.closures, closure_error(error_bins, spread.closures)};
  }
  return fit;
}

Closures closures_of(const ParametricFit& fit) {
  Closures c;
  c.body = fit.body;
  c.coat = fit.coat;
  c.lobes.push_back({fit.type, fit.alpha, fit.alpha, 0.0, 1.0, ClosureLobe::Fresnel::f82_tint, fit.f0, fit.f82});
  return c;
}

Closures closures_of(const AnisotropicParametricFit& fit) {
  Closures c;
  c.body = fit.body;
  c.lobes.push_back({fit.type, fit.alpha.alpha_x, fit.alpha.alpha_y, fit.alpha.angle, 1.0, ClosureLobe::Fresnel::f82_tint, fit.f0, fit.f82});
  return c;
}

double closure_jacobian_error(const MeasuredBins& bins, const Closures& at, const AlbedoTarget* albedo) {
  Unknowns u(at);
  double worst = 0.0;
  for (const MeasuredBins::Row& row : bins.rows) worst = std::max(worst, jacobian_error(ClosureRowCost(bins, row, u.lobes, u.with_coat), u.blocks()));
  if (albedo) worst = std::max(worst, jacobian_error(AlbedoCost(*albedo, u.lobes, u.with_coat), u.blocks()));
  return worst;
}

}  // namespace facetfit
