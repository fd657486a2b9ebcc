#include "fit/parametric_fit.h"

#include <ceres/ceres.h>

#include <cmath>

#include "model/fresnel.h"
#include "model/parametric.h"

namespace facetfit {

namespace {

// Smith's Lambda and D of the two families at cos(theta) = c, written once for doubles and Jets.
template <class T>
T lambda_of(NdfType type, const T& alpha, double c) {
  const double s2 = std::max(0.0, 1.0 - c * c);
  if (type == NdfType::ggx) return 0.5 * (sqrt(1.0 + alpha * alpha * (s2 / (c * c))) - 1.0);
  // Beckmann: sigma / cos - 1 with sigma's closed form (model/ndf.cpp), a = cot(theta) / alpha.
  const double s = std::sqrt(s2);
  if (s <= 0.0) return T(0.0);
  const T a = c / (alpha * s);
  return 0.5 * (erf(a) - 1.0) + alpha * s * exp(-a * a) / (2.0 * std::sqrt(kPi) * c);
}

template <class T>
T ndf_of(NdfType type, const T& alpha, double c) {
  const double c2 = c * c, t2 = (1.0 - c2) / c2;
  const T a2 = alpha * alpha;
  if (type == NdfType::ggx) {
    const T den = a2 + t2;
    return a2 / (kPi * c2 * c2 * den * den);
  }
  return exp(-t2 / a2) / (kPi * a2 * c2 * c2);
}

template <class T>
T schlick(const T& f0, double mu) {
  const double m = 1.0 - mu, m5 = m * m * m * m * m;
  return f0 + (1.0 - f0) * m5;
}

// mu (1 - mu)^6: the shape of the F82-tint correction.
inline double f82_basis(double mu) {
  const double m = 1.0 - mu, m3 = m * m * m;
  return mu * m3 * m3;
}

// The residuals of one row of bins (3 per bin). Parameters: body (3), log alpha (1), f0 (3), f82 (3),
// coat (log alpha, f0).
struct RowResiduals {
  const MeasuredBins* bins;
  const MeasuredBins::Row* row;
  NdfType type;
  Smith smith;
  ParametricFit::FresnelForm form;
  bool with_coat;

  template <class T>
  bool operator()(const T* body, const T* log_alpha, const T* f0, const T* f82, const T* coat_p, T* r) const {
    const T alpha = exp(log_alpha[0]);
    const T coat_alpha = exp(coat_p[0]);
    const T coat_f0 = coat_p[1];
    constexpr double mu82 = 1.0 / 7.0;
    const double basis82 = f82_basis(mu82);
    for (std::size_t k = row->begin; k < row->end; ++k) {
      const Vec3& wi = bins->i[k];
      const Vec3& wo = bins->o[k];
      const double mu = bins->cos_d[k], cos_h = bins->cos_h[k], basis = f82_basis(mu);
      const T lobe = ndf_of(type, alpha, cos_h) *
                     g2(lambda_of(type, alpha, wi.z), lambda_of(type, alpha, wo.z)) / (4.0 * wi.z * wo.z);
      const T coat = with_coat ? schlick(coat_f0, mu) * ndf_of(NdfType::ggx, coat_alpha, cos_h) /
                                     (1.0 + lambda_of(NdfType::ggx, coat_alpha, wi.z) + lambda_of(NdfType::ggx, coat_alpha, wo.z)) /
                                     (4.0 * wi.z * wo.z)
                               : T(0.0);
      const double s = std::sqrt(bins->weight[k]), c = bins->cos_mean[k];
      for (int ch = 0; ch < 3; ++ch) {
        T fresnel = schlick(f0[ch], mu);
        if (form == ParametricFit::FresnelForm::f82)
          fresnel -= (schlick(f0[ch], mu82) - f82[ch]) / basis82 * basis;
        T m = body[ch] / kPi + fresnel * lobe + coat;
        if (m < 0.0) m = T(0.0);  // F82-tint can dip below zero for extreme f82: no negative reflectance
        T& out = r[3 * (k - row->begin) + std::size_t(ch)];
        if (bins->valid[k] >> ch & 1u)
          out = s * (metric_transform(m * c) - bins->lightness[k][ch]);
        else
          out = T(0.0);
      }
    }
    return true;
  }

  template <class T>
  T g2(const T& li, const T& lo) const {
    switch (smith) {
      case Smith::masking: return 1.0 / (1.0 + (li > lo ? li : lo));
      case Smith::correlated: return 1.0 / (1.0 + li + lo);
      case Smith::separable: return 1.0 / ((1.0 + li) * (1.0 + lo));
    }
    return T(0.0);
  }
};

}  // namespace

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
  ceres::Problem problem;
  for (const MeasuredBins::Row& row : bins.rows) {
    // Fixed parameter sizes: one pass of 12-wide Jets per row (a dynamic cost needs two).
    auto* cost = new ceres::AutoDiffCostFunction<RowResiduals, ceres::DYNAMIC, 3, 1, 3, 3, 2>(
        new RowResiduals{&bins, &row, start.type, smith, start.fresnel, with_coat}, int(3 * (row.end - row.begin)));
    problem.AddResidualBlock(cost, nullptr, body, log_alpha, f0, f82, coat);
  }
  if (bins.rows.empty()) return fit;
  problem.SetParameterLowerBound(log_alpha, 0, std::log(1e-3));
  problem.SetParameterUpperBound(log_alpha, 0, std::log(4.0));
  for (double* p : {body, f0, f82})
    for (int c = 0; c < 3; ++c) problem.SetParameterLowerBound(p, c, 0.0);
  for (double* p : {f0, f82})  // reflectances: at most 1 (the start is clamped to [0, 1] by the caller)
    for (int c = 0; c < 3; ++c) problem.SetParameterUpperBound(p, c, 1.0);
  if (start.fresnel == ParametricFit::FresnelForm::schlick) problem.SetParameterBlockConstant(f82);
  if (with_coat) {
    problem.SetParameterLowerBound(coat, 0, std::log(1e-3));
    problem.SetParameterUpperBound(coat, 0, std::log(1.0));
    problem.SetParameterLowerBound(coat, 1, 0.0);
    problem.SetParameterUpperBound(coat, 1, 1.0);
  } else {
    problem.SetParameterBlockConstant(coat);
  }

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  options.max_num_iterations = max_iterations;
  options.function_tolerance = 1e-6;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  if (max_iterations > 0) ceres::Solve(options, &problem, &summary);

  fit.body = Rgb(body[0], body[1], body[2]);
  fit.alpha = std::exp(log_alpha[0]);
  fit.f0 = Rgb(f0[0], f0[1], f0[2]);
  fit.f82 = fit.fresnel == ParametricFit::FresnelForm::f82 ? Rgb(f82[0], f82[1], f82[2])
                                                           : fresnel_schlick(fit.f0, 1.0 / 7.0);
  if (with_coat) fit.coat = Coat{std::exp(coat[0]), coat[1]};
  fit.error = parametric_error(error_bins, smith, fit);
  return fit;
}

}  // namespace facetfit
