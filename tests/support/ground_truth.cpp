#include "support/ground_truth.h"

#include <cmath>
#include <fstream>

#include "fit/roughness.h"
#include "io/rgl.h"
#include "io/utia.h"
#include "model/analytic.h"
#include "support/tensor_file.h"

namespace facetfit {

std::vector<GroundTruthCase> standard_ground_truth_cases() {
  const Fresnel gold = Fresnel::conductor({0.143, 0.374, 1.442}, {3.983, 2.385, 1.603});
  std::vector<GroundTruthCase> cases;
  for (NdfType type : {NdfType::ggx, NdfType::beckmann})
    for (Smith smith : {Smith::masking, Smith::correlated, Smith::separable})
      for (double alpha : {0.02, 0.05, 0.1, 0.2, 0.4, 0.7, 1.0}) cases.push_back({type, alpha, smith, gold});
  return cases;
}

GroundTruthError measure_ground_truth(const GroundTruthCase& c, const Fitter& fitter, const std::string& merl_path) {
  const Ndf ndf = Ndf::isotropic(c.type, c.alpha);
  HalfDiffTable table = HalfDiffTable::tabulate(MicrofacetBrdf(ndf, c.smith, c.fresnel));
  if (!merl_path.empty()) {
    table.write(merl_path);
    table = HalfDiffTable::read(merl_path);
  }
  const FitResult fit = fitter.fit(table);
  GroundTruthError e;
  e.problem = fit.problem;
  e.iterations = fit.extraction.iterations;
  e.residual = fit.extraction.residual;
  if (!fit.ok()) return e;
  e.alpha = c.type == NdfType::ggx ? fit.alpha_ggx : fit.alpha_beckmann;
  e.alpha_relative = e.alpha / c.alpha - 1.0;
  e.ndf_l1 = ndf_distance(
      fitter.quadrature(), [&](double theta) { return ndf.D(spherical_direction(theta, 0.0)); },
      [&](double theta) { return fit.ndf().D(theta); });
  for (int j = 0; j < FresnelCurve::kSize; ++j) {
    const double theta_d = FresnelCurve::theta_d(j);
    if (theta_d > 80.0 * kPi / 180.0 + 1e-9) break;
    const Rgb d = glm::abs(fit.fresnel().value[std::size_t(j)] - c.fresnel.eval(std::cos(theta_d)));
    e.fresnel_abs = std::max({e.fresnel_abs, d.r, d.g, d.b});
  }
  return e;
}

std::vector<AnisotropicCase> dense_anisotropic_cases() {
  return {{NdfType::ggx, 0.4, 0.15, 30.0, Smith::masking},       {NdfType::ggx, 0.4, 0.15, 30.0, Smith::correlated},
          {NdfType::ggx, 0.6, 0.2, -50.0, Smith::separable},     {NdfType::beckmann, 0.3, 0.12, 70.0, Smith::masking},
          {NdfType::beckmann, 0.5, 0.25, 10.0, Smith::correlated}};
}

std::vector<AnisotropicCase> utia_anisotropic_cases() {
  return {{NdfType::ggx, 0.5, 0.25, 30.0},      {NdfType::ggx, 0.8, 0.3, -60.0}, {NdfType::ggx, 0.3, 0.2, 45.0},
          {NdfType::beckmann, 0.5, 0.25, 30.0}, {NdfType::beckmann, 0.3, 0.2, -20.0}};
}

AnisotropicError measure_anisotropic(const AnisotropicCase& c, const Quadrature2D& quad, AnisotropicInput input,
                                     const std::string& path) {
  const Ndf ndf{c.type, c.alpha_x, c.alpha_y};
  const MicrofacetBrdf brdf(ndf, c.smith, Fresnel::one());
  const double angle = c.angle_degrees * kPi / 180.0;
  const RotatedBrdf turned(brdf, angle);
  Backscatter2D back;
  switch (input) {
    case AnisotropicInput::dense: back = backscatter_2d(turned, quad); break;
    case AnisotropicInput::utia:
      UtiaBrdf::tabulate(turned).write(path);
      back = backscatter_2d(UtiaBrdf::read(path).backscatter(), quad);
      break;
    case AnisotropicInput::rgl: {
      const std::vector<unsigned char> bytes = test::serialize(test::microfacet_tensor_fields(ndf, c.smith, angle, 25, 48, 64));
      std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
      back = backscatter_2d(RglBsdf::read(path).backscatter(90, quad.phi_count()), quad);
      break;
    }
  }
  const Extraction2D x = extract_ndf_2d(back, quad, {c.smith, 1e-10, 1000});
  AnisotropicError e;
  e.problem = x.problem;
  e.iterations = x.iterations;
  e.eigenvalue = x.eigenvalue;
  if (!x.problem.empty()) return e;
  e.fitted = c.type == NdfType::ggx ? alpha_ggx_2d(x.ndf, quad) : alpha_beckmann_2d(x.ndf, quad);
  e.alpha_x_relative = e.fitted.alpha_x / c.alpha_x - 1.0;
  e.alpha_y_relative = e.fitted.alpha_y / c.alpha_y - 1.0;
  e.angle_degrees = e.fitted.angle * 180.0 / kPi - c.angle_degrees;
  double diff = 0.0, norm = 0.0;
  for (int j = 0; j < quad.size(); ++j)
    for (int m = 0; m < quad.phi_count(); ++m) {
      const double truth = ndf.D(spherical_direction(quad.grid().theta(j), quad.phi(m) - angle));
      const double w = quad.area()[std::size_t(j)] / quad.phi_count();
      diff += w * std::abs(x.D(j, m) - truth);
      norm += w * truth;
    }
  e.ndf_l1 = norm > 0.0 ? diff / norm : 0.0;
  return e;
}

}  // namespace facetfit
