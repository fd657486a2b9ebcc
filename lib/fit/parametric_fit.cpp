#include "fit/parametric_fit.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/frame.h"
#include "fit/lobe_terms.h"
#include "fit/small_problem.h"
#include "model/fresnel.h"
#include "model/parametric.h"
#include "model/rotated.h"

namespace facetfit {

namespace {

using namespace lobe_terms;

// The parametric fits' bounds: the first `alphas` entries of `log_alpha` within log [1e-3, 4], a nonnegative
// body, reflectances f0 and f82 in [0, 1] (the starts are clamped there by the callers).
void bound_lobe(SmallProblem& problem, double* log_alpha, int alphas, double* body, double* f0, double* f82) {
  for (int a = 0; a < alphas; ++a) {
    problem.set_lower_bound(log_alpha, a, std::log(1e-3));
    problem.set_upper_bound(log_alpha, a, std::log(4.0));
  }
  for (double* p : {body, f0, f82})
    for (int c = 0; c < 3; ++c) problem.set_lower_bound(p, c, 0.0);
  for (double* p : {f0, f82})
    for (int c = 0; c < 3; ++c) problem.set_upper_bound(p, c, 1.0);
}

// The parametric fits' solve: a dense problem of 8 to 14 unknowns (fit/small_problem.h).
void solve(SmallProblem& problem, int max_iterations) { problem.solve(max_iterations, 1e-6); }

// The derivatives of residual r (channel e) in the colour blocks, body (0), f0 (2) and f82 (3), of a model
// body / pi + F lobe + ...; dm is the residual's derivative in the model.
void colour_jacobians(double** jacobians, std::size_t r, int e, double dm, const FresnelTerms& f, double lobe) {
  if (jacobians[0]) jacobians[0][3 * r + std::size_t(e)] = dm * kInvPi;
  if (jacobians[2]) jacobians[2][3 * r + std::size_t(e)] = dm * f.d_f0 * lobe;
  if (jacobians[3]) jacobians[3][3 * r + std::size_t(e)] = dm * f.d_f82 * lobe;
}

// The residuals of one row of bins (3 per bin), with analytic derivatives: 5 to 8 times cheaper than
// automatic differentiation, which carried 12 derivatives through every transcendental. Parameter
// blocks: body (3), log alpha (1), f0 (3), f82 (3), coat (log alpha, f0). The model:
//   m = body / pi + F(mu) D G2 / (4 cos_i cos_o) + coat,  F = Schlick(f0, mu) - (Schlick(f0, 1/7) - f82)
//   mu (1 - mu)^6 / b82 (F82-tint; Schlick alone for the lsq baseline), the coat a GGX lobe with a grey
//   Schlick Fresnel and height-correlated masking; clamped at 0.
class RowCost final : public ceres::CostFunction {
 public:
  RowCost(const MeasuredBins& bins, const MeasuredBins::Row& row, NdfType type, Smith smith,
          ParametricFit::FresnelForm form, bool with_coat)
      : bins_(bins), row_(row), type_(type), smith_(smith), f82_(form == ParametricFit::FresnelForm::f82), with_coat_(with_coat) {
    set_num_residuals(int(3 * (row.end - row.begin)));
    for (int size : {3, 1, 3, 3, 2}) mutable_parameter_block_sizes()->push_back(size);
  }

  bool Evaluate(double const* const* p, double* residuals, double** jacobians) const override {
    const double *body = p[0], *f0 = p[2], *f82 = p[3];
    const double alpha = std::exp(p[1][0]), coat_alpha = std::exp(p[4][0]), coat_f0 = p[4][1];
    const std::size_t n = row_.end - row_.begin;
    if (jacobians)
      for (int b = 0; b < 5; ++b)
        if (jacobians[b]) std::fill(jacobians[b], jacobians[b] + 3 * n * std::size_t(parameter_block_sizes()[std::size_t(b)]), 0.0);
    for (std::size_t q = 0; q < n; ++q) {
      const std::size_t k = row_.begin + q;
      const double ci = bins_.i[k].z, co = bins_.o[k].z, mu = bins_.cos_d[k], ch = bins_.cos_h[k];
      const double inv4 = 1.0 / (4.0 * ci * co);
      const WithSlope d = ndf_of(type_, alpha, ch);
      const WithSlope g = g2_of(smith_, lambda_of(type_, alpha, ci), lambda_of(type_, alpha, co));
      const double lobe = d.value * g.value * inv4;
      const double lobe_slope = (d.slope * g.value + d.value * g.slope) * inv4 * alpha;  // d/d log alpha
      const CoatTerms coat = with_coat_ ? coat_terms(coat_alpha, coat_f0, ch, ci, co, mu) : CoatTerms{};
      const double w = std::sqrt(bins_.weight[k]), c = bins_.cosine[k];
      const bool grazing = grazing_pair(bins_.o[k], bins_.i[k]);
      for (int e = 0; e < 3; ++e) {
        const std::size_t r = 3 * q + std::size_t(e);
        if (!(bins_.valid[k] >> e & 1u)) {
          residuals[r] = 0.0;
          continue;
        }
        const FresnelTerms fresnel = fresnel_terms(f0[e], f82[e], mu, f82_);
        const double m = body[e] * kInvPi + fresnel.value * lobe + coat.value;
        // F82-tint can dip below zero for extreme f82: no negative reflectance, and no slope there.
        const MetricResidual res = metric_residual(m, c, bins_.lightness[k][e], grazing);
        residuals[r] = w * res.value;
        if (!jacobians || m < 0.0) continue;
        const double dm = w * res.slope;
        colour_jacobians(jacobians, r, e, dm, fresnel, lobe);
        if (jacobians[1]) jacobians[1][r] = dm * fresnel.value * lobe_slope;
        if (jacobians[4]) jacobians[4][2 * r] = dm * coat.d_log_alpha, jacobians[4][2 * r + 1] = dm * coat.d_f0;
      }
    }
    return true;
  }

 private:
  const MeasuredBins& bins_;
  const MeasuredBins::Row& row_;
  NdfType type_;
  Smith smith_;
  bool f82_, with_coat_;
};

}  // namespace

double parametric_jacobian_error(const MeasuredBins& bins, Smith smith, const ParametricFit& fit) {
  double body[3] = {fit.body.r, fit.body.g, fit.body.b}, log_alpha[1] = {std::log(fit.alpha)};
  double f0[3] = {fit.f0.r, fit.f0.g, fit.f0.b}, f82[3] = {fit.f82.r, fit.f82.g, fit.f82.b};
  double coat[2] = {std::log(fit.coat.present() ? fit.coat.alpha : 0.1), fit.coat.f0};
  double* blocks[5] = {body, log_alpha, f0, f82, coat};
  double worst = 0.0;
  for (const MeasuredBins::Row& row : bins.rows)
    worst = std::max(worst, jacobian_error(RowCost(bins, row, fit.type, smith, fit.fresnel, fit.coat.present()),
                                           std::vector<double*>(blocks, blocks + 5)));
  return worst;
}

double parametric_error(const MeasuredBins& bins, Smith smith, const ParametricFit& fit) {
  return measurement_error(bins, ParametricBrdf(Ndf::isotropic(fit.type, fit.alpha), smith, fit.f0, fit.f82, fit.body, fit.coat));
}

ParametricFit fit_parametric(const MeasuredBins& bins, const MeasuredBins& error_bins, Smith smith,
                             const ParametricFit& start, int max_iterations) {
  ParametricFit fit = start;
  double body[3] = {start.body.r, start.body.g, start.body.b};
  double log_alpha[1] = {std::log(std::max(start.alpha, 1e-3))};
  double f0[3] = {start.f0.r, start.f0.g, start.f0.b};
  double f82[3] = {start.f82.r, start.f82.g, start.f82.b};
  const bool with_coat = start.coat.present();
  double coat[2] = {std::log(with_coat ? start.coat.alpha : 0.1), start.coat.f0};
  SmallProblem problem;
  for (const MeasuredBins::Row& row : bins.rows) {
    problem.add_residual_block(new RowCost(bins, row, start.type, smith, start.fresnel, with_coat), body, log_alpha, f0, f82, coat);
  }
  if (bins.rows.empty()) return fit;
  bound_lobe(problem, log_alpha, 1, body, f0, f82);
  if (start.fresnel == ParametricFit::FresnelForm::schlick) problem.set_constant(f82);
  if (with_coat) {
    problem.set_lower_bound(coat, 0, std::log(1e-3));
    problem.set_upper_bound(coat, 0, std::log(1.0));
    problem.set_lower_bound(coat, 1, 0.0);
    problem.set_upper_bound(coat, 1, 1.0);
  } else {
    problem.set_constant(coat);
  }

  solve(problem, max_iterations);

  fit.body = Rgb(body[0], body[1], body[2]);
  fit.alpha = std::exp(log_alpha[0]);
  fit.f0 = Rgb(f0[0], f0[1], f0[2]);
  fit.f82 = fit.fresnel == ParametricFit::FresnelForm::f82 ? Rgb(f82[0], f82[1], f82[2])
                                                           : fresnel_schlick(fit.f0, 1.0 / 7.0);
  if (with_coat) fit.coat = Coat{std::exp(coat[0]), coat[1]};
  fit.error = parametric_error(error_bins, smith, fit);
  return fit;
}

namespace {

using namespace lobe_terms;

// The anisotropic lobe without its Fresnel, D(h') G2(o', i') / (4 cos theta_i cos theta_o), primes in the
// frame turned by `angle`: the library's own NDF and masking, so what is fitted is what is rendered.
double anisotropic_lobe(NdfType type, Smith smith, double alpha_x, double alpha_y, double angle, const Vec3& o, const Vec3& i) {
  const Ndf ndf{type, alpha_x, alpha_y};
  const TurnedFrame axes(angle);
  const Vec3 ti = axes.to_frame(i), to = axes.to_frame(o);
  return ndf.D(glm::normalize(ti + to)) * smith_g2(smith, ndf.lambda(to), ndf.lambda(ti)) / (4.0 * i.z * o.z);
}

// The anisotropic model's residuals over one row of bins (3 per bin). Parameter blocks: body (3), shape
// (log alpha_x, log alpha_y, angle), f0 (3), f82 (3). The colour parameters enter the model linearly and
// are differentiated by hand (as RowCost); the shape by central differences of the lobe, which is common
// to the three channels: 7 lobe evaluations per bin, where differencing all 12 unknowns would take 25.
class AnisotropicRowCost final : public ceres::CostFunction {
 public:
  AnisotropicRowCost(const MeasuredBins& bins, const MeasuredBins::Row& row, NdfType type, Smith smith)
      : bins_(bins), row_(row), type_(type), smith_(smith) {
    set_num_residuals(int(3 * (row.end - row.begin)));
    for (int size : {3, 3, 3, 3}) mutable_parameter_block_sizes()->push_back(size);
  }

  bool Evaluate(double const* const* p, double* residuals, double** jacobians) const override {
    const double *body = p[0], *shape = p[1], *f0 = p[2], *f82 = p[3];
    constexpr double kStep = 1e-5;
    const std::size_t n = row_.end - row_.begin;
    if (jacobians)
      for (int b = 0; b < 4; ++b)
        if (jacobians[b]) std::fill(jacobians[b], jacobians[b] + 9 * n, 0.0);
    const auto lobe_at = [&](const double* q, std::size_t k) {
      return anisotropic_lobe(type_, smith_, std::exp(q[0]), std::exp(q[1]), q[2], bins_.o[k], bins_.i[k]);
    };
    for (std::size_t q = 0; q < n; ++q) {
      const std::size_t k = row_.begin + q;
      const double lobe = lobe_at(shape, k);
      double lobe_slope[3] = {0.0, 0.0, 0.0};  // d lobe / d shape
      if (jacobians && jacobians[1])
        for (int e = 0; e < 3; ++e) {
          double plus[3] = {shape[0], shape[1], shape[2]}, minus[3] = {shape[0], shape[1], shape[2]};
          plus[e] += kStep, minus[e] -= kStep;
          lobe_slope[e] = (lobe_at(plus, k) - lobe_at(minus, k)) / (2.0 * kStep);
        }
      const double w = std::sqrt(bins_.weight[k]), c = bins_.cosine[k];
      const bool grazing = grazing_pair(bins_.o[k], bins_.i[k]);
      for (int e = 0; e < 3; ++e) {
        const std::size_t r = 3 * q + std::size_t(e);
        if (!(bins_.valid[k] >> e & 1u)) {
          residuals[r] = 0.0;
          continue;
        }
        const FresnelTerms fresnel = fresnel_terms(f0[e], f82[e], bins_.cos_d[k], true);
        const double m = body[e] * kInvPi + fresnel.value * lobe;
        const MetricResidual res = metric_residual(m, c, bins_.lightness[k][e], grazing);
        residuals[r] = w * res.value;
        if (!jacobians || m < 0.0) continue;
        const double dm = w * res.slope;
        colour_jacobians(jacobians, r, e, dm, fresnel, lobe);
        if (jacobians[1])
          for (int a = 0; a < 3; ++a) jacobians[1][3 * r + std::size_t(a)] = dm * fresnel.value * lobe_slope[a];
      }
    }
    return true;
  }

 private:
  const MeasuredBins& bins_;
  const MeasuredBins::Row& row_;
  NdfType type_;
  Smith smith_;
};

// The same axes named so that alpha_x >= alpha_y, the angle in (-pi/2, pi/2].
AnisotropicAlpha principal(double alpha_x, double alpha_y, double angle) {
  if (alpha_y > alpha_x) std::swap(alpha_x, alpha_y), angle += 0.5 * kPi;
  angle = std::remainder(angle, kPi);  // [-pi/2, pi/2]
  if (angle <= -0.5 * kPi) angle += kPi;
  return {alpha_x, alpha_y, angle};
}

}  // namespace

double parametric_error(const MeasuredBins& bins, Smith smith, const AnisotropicParametricFit& fit) {
  const ParametricBrdf lobe(Ndf{fit.type, fit.alpha.alpha_x, fit.alpha.alpha_y}, smith, fit.f0, fit.f82, fit.body);
  return measurement_error(bins, RotatedBrdf(lobe, fit.alpha.angle));
}

AnisotropicParametricFit fit_parametric_anisotropic(const MeasuredBins& bins, const MeasuredBins& error_bins, Smith smith,
                                                    const AnisotropicParametricFit& start, int max_iterations) {
  AnisotropicParametricFit fit = start;
  double body[3] = {start.body.r, start.body.g, start.body.b};
  double shape[3] = {std::log(std::max(start.alpha.alpha_x, 1e-3)), std::log(std::max(start.alpha.alpha_y, 1e-3)), start.alpha.angle};
  double f0[3] = {start.f0.r, start.f0.g, start.f0.b};
  double f82[3] = {start.f82.r, start.f82.g, start.f82.b};
  if (bins.rows.empty()) return fit;
  SmallProblem problem;
  for (const MeasuredBins::Row& row : bins.rows) {
    problem.add_residual_block(new AnisotropicRowCost(bins, row, start.type, smith), body, shape, f0, f82);
  }
  bound_lobe(problem, shape, 2, body, f0, f82);  // log alpha_x, log alpha_y; the angle is free

  solve(problem, max_iterations);

  fit.body = Rgb(body[0], body[1], body[2]);
  fit.alpha = principal(std::exp(shape[0]), std::exp(shape[1]), shape[2]);
  fit.f0 = Rgb(f0[0], f0[1], f0[2]);
  fit.f82 = Rgb(f82[0], f82[1], f82[2]);
  fit.error = parametric_error(error_bins, smith, fit);
  return fit;
}

}  // namespace facetfit
