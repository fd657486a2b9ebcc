// facetfit info LUT.exr : the metadata and the tables of a LUT, to read or to plot.
#include <cstdio>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "core/error.h"
#include "fit/representations.h"
#include "io/input.h"
#include "lut/lut.h"
#include "lut/record.h"

namespace facetfit::cli {

namespace {

nlohmann::json info_json(const Lut& lut) {
  const LutMetadata& m = lut.meta;
  const auto rgb = [](const Rgb& c) { return nlohmann::json{c.r, c.g, c.b}; };
  nlohmann::json j;
  j["metadata"] = {{"format_version", m.format_version}, {"facetfit_version", m.facetfit_version}, {"source", m.source},
                   {"source_sha256", m.source_sha256}, {"resolution", m.resolution}, {"smith", to_string(m.smith)},
                   {"iterations", m.iterations}, {"residual", m.residual}, {"alpha_ggx", m.alpha_ggx},
                   {"alpha_beckmann", m.alpha_beckmann}, {"f0", rgb(m.f0)}, {"f82", rgb(m.f82)},
                   {"ndf_error_ggx", m.ndf_error_ggx}, {"ndf_error_beckmann", m.ndf_error_beckmann},
                   {"representation", to_string(m.representation)}, {"tolerance", m.tolerance}, {"sampling", m.sampling},
                   {"body", rgb(m.body)}, {"body_exponent", m.body_exponent}, {"coat", coat_json(m.coat)}, {"error", m.error},
                   {"error_extraction", m.error_extraction}, {"warnings", m.warnings},
                   {"recommended", recommended_json(recommended_parameters(m), m.tolerance)}, {"colorspace", m.colorspace}};
  const auto parametric = [](const LutMetadata::Parametric& p, double error) {
    return parametric_json(p.alpha, p.body, p.f0, p.f82, p.coat, error);
  };
  for (const RepresentationRow& r : kRepresentations)  // ggx, beckmann, lsq (fit/representations.h)
    if (r.parametric) j["metadata"][r.name] = parametric(*m.fit(r.name), m.distance(r.name));
  // What the production OSL material renders: version 5's closures, or an older LUT's one lobe.
  j["metadata"]["closures"] = closures_json(lut.closures(), m.error_closures);
  j["metadata"]["anisotropic"] = nullptr;
  if (const auto& a = lut.anisotropic)  // the anisotropic lobe's table and the GGX fit whose angle is its axis (record.h)
    j["metadata"]["anisotropic"] = {{"resolution", a->grid.resolution}, {"phi_count", a->phi_count},
                                    {"ggx", anisotropic_lobe_json(m.anisotropic_ggx)}};
  const TabulatedNdf& ndf = lut.tables.ndf;
  nlohmann::json& t = j["ndf"];
  for (int k = 0; k < ndf.grid.size(); ++k) {
    const double theta = ndf.grid.theta(k);
    t["u"].push_back(ndf.grid.u(k));
    t["theta"].push_back(theta);
    t["ndf"].push_back(ndf.ndf[std::size_t(k)]);
    t["slope_pdf"].push_back(ndf.slope_pdf(theta));
    t["sigma"].push_back(ndf.sigma[std::size_t(k)]);
  }
  for (int k = 0; k < FresnelCurve::kSize; ++k) {
    j["fresnel"]["theta_d"].push_back(FresnelCurve::theta_d(k));
    j["fresnel"]["rgb"].push_back(rgb(lut.tables.fresnel.value[std::size_t(k)]));
  }
  return j;
}

// The closures the material shader emits, a line a part.
void print_closures(const Closures& c, double error, bool fitted) {
  std::printf("closures        %s, distance %.4f, body %.4f %.4f %.4f", fitted ? "fitted" : "the older LUT's one lobe", error, c.body.r, c.body.g,
              c.body.b);
  if (c.coat.present()) std::printf(", coat alpha %.5f f0 %.4f", c.coat.alpha, c.coat.f0);
  std::printf("\n");
  for (const ClosureLobe& l : c.lobes) {
    if (l.view_aligned())
      std::printf("  lobe          %s alpha %.5f x %.5f / cos(theta_o)^%.3f along the view, weight %.4f, f0 %.4f %.4f %.4f", to_string(l.type),
                  l.alpha_x, l.alpha_y, l.view_exponent, l.weight, l.f0.r, l.f0.g, l.f0.b);
    else
      std::printf("  lobe          %s alpha %.5f x %.5f at %.1f deg, weight %.4f, f0 %.4f %.4f %.4f", to_string(l.type), l.alpha_x, l.alpha_y,
                  l.angle * 180.0 / kPi, l.weight, l.f0.r, l.f0.g, l.f0.b);
    if (l.fresnel == ClosureLobe::Fresnel::f82_tint)
      std::printf(", F82-tint f82 %.4f %.4f %.4f\n", l.f82.r, l.f82.g, l.f82.b);
    else
      std::printf(", Schlick f90 %.4f %.4f %.4f exponent %.3f\n", l.f90.r, l.f90.g, l.f90.b, l.exponent);
  }
}

// The recommended representation and its own parameters (fit/recommend.h).
void print_recommended(const RepresentationParameters& p, double tolerance) {
  std::printf("recommended     %s (tolerance %.4f): ", to_string(p.representation), tolerance);
  if (p.alpha)
    std::printf("alpha %.5f, ", *p.alpha);
  else
    std::printf("tabulated NDF, ");
  std::printf("f0 %.4f %.4f %.4f, f82 %.4f %.4f %.4f, body %.4f %.4f %.4f", p.f0.r, p.f0.g, p.f0.b, p.f82.r, p.f82.g, p.f82.b,
              p.body.r, p.body.g, p.body.b);
  if (p.coat.present()) std::printf(", coat alpha %.5f f0 %.4f", p.coat.alpha, p.coat.f0);
  std::printf(", distance %.4f\n", p.error);
}

void print_info(const Lut& lut) {
  const LutMetadata& m = lut.meta;
  // The file's strings as printable ASCII: a newline or a terminal escape in an edited LUT stays text.
  std::printf("source          %s\nsource_sha256   %s\nfacetfit        %s (LUT format %d)\n", excerpt(m.source, 4096).c_str(),
              excerpt(m.source_sha256, 64).c_str(), excerpt(m.facetfit_version, 64).c_str(), m.format_version);
  std::printf("fit             resolution %d, smith %s, %d iterations, residual %.2e\n", m.resolution, to_string(m.smith),
              m.iterations, m.residual);
  print_recommended(recommended_parameters(m), m.tolerance);
  std::printf("moment alphas   ggx %.5f, beckmann %.5f (the paper's estimates from the tabulated NDF)\n", m.alpha_ggx, m.alpha_beckmann);
  std::printf("NDF distance    ggx %.4f, beckmann %.4f (of each fit's NDF from the tabulated one)\n", m.ndf_error_ggx, m.ndf_error_beckmann);
  std::printf("tabulated       body %.4f %.4f %.4f (Minnaert exponent %.3f), f0 %.4f %.4f %.4f, f82 %.4f %.4f %.4f", m.body.r,
              m.body.g, m.body.b, m.body_exponent, m.f0.r, m.f0.g, m.f0.b, m.f82.r, m.f82.g, m.f82.b);
  if (m.coat.present()) std::printf(", coat alpha %.5f f0 %.4f", m.coat.alpha, m.coat.f0);
  std::printf("\n");
  // Distances from the measurement (fit/measurement.h); a LUT baked before fit revision 9 with --refine none has 0.
  std::printf("distance        tabulated %.4f (paper's fit %.4f)", m.error, m.error_extraction);
  for (const RepresentationRow& r : kRepresentations)
    if (r.parametric) std::printf(", %s %.4f", r.name, m.distance(r.name));
  std::printf("\n");
  const auto parametric = [](const char* name, const LutMetadata::Parametric& p) {
    std::printf("%-15s alpha %.5f, body %.4f %.4f %.4f, f0 %.4f %.4f %.4f, f82 %.4f %.4f %.4f", name, p.alpha, p.body.r,
                p.body.g, p.body.b, p.f0.r, p.f0.g, p.f0.b, p.f82.r, p.f82.g, p.f82.b);
    if (p.coat.present()) std::printf(", coat alpha %.5f f0 %.4f", p.coat.alpha, p.coat.f0);
    std::printf("\n");
  };
  for (const RepresentationRow& r : kRepresentations)
    if (r.parametric) parametric(r.name, *m.fit(r.name));
  print_closures(lut.closures(), m.error_closures, m.format_version >= kLutClosuresVersion);
  if (const auto& a = lut.anisotropic) {
    const AnisotropicParametricFit& g = m.anisotropic_ggx;
    std::printf("anisotropic     tabulated lobe on %d x %d nodes; ggx alpha %.5f x %.5f at %.1f deg (the lobe's axis), body %.4f %.4f %.4f, "
                "f0 %.4f %.4f %.4f, f82 %.4f %.4f %.4f, distance %.4f\n",
                a->grid.resolution, a->phi_count, g.alpha.alpha_x, g.alpha.alpha_y, g.alpha.angle * 180.0 / kPi,
                g.body.r, g.body.g, g.body.b, g.f0.r, g.f0.g, g.f0.b, g.f82.r, g.f82.g, g.f82.b, g.error);
  }
  std::printf("sampling tables %s\n", m.sampling ? "yes" : "no (--eval-only)");
  // Text from the file, printed without its control characters (an escape sequence reaches no terminal).
  std::printf("colour space    %s (of every colour above)\n", excerpt(m.colorspace, 256).c_str());
  for (const std::string& w : m.warnings) std::printf("warning         %s\n", excerpt(w, 1024).c_str());
  std::printf("\n");
  std::printf("%4s %8s %10s %14s %14s %10s\n", "node", "u", "theta_deg", "ndf", "slope_pdf", "sigma");
  const TabulatedNdf& ndf = lut.tables.ndf;
  for (int k = 0; k < ndf.grid.size(); ++k) {
    const double theta = ndf.grid.theta(k);
    std::printf("%4d %8.5f %10.5f %14.6g %14.6g %10.6f\n", k, ndf.grid.u(k), theta * 180 / kPi, ndf.ndf[std::size_t(k)],
                ndf.slope_pdf(theta), ndf.sigma[std::size_t(k)]);
  }
  std::printf("\n%10s %9s %9s %9s\n", "theta_d", "F_r", "F_g", "F_b");
  for (int k = 0; k < FresnelCurve::kSize; ++k) {
    const Rgb& f = lut.tables.fresnel.value[std::size_t(k)];
    std::printf("%10.1f %9.5f %9.5f %9.5f\n", FresnelCurve::theta_d(k) * 180 / kPi, f.r, f.g, f.b);
  }
}

}  // namespace

void add_info_command(CLI::App& app, Context& ctx) {
  auto path = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  CLI::App* cmd = app.add_subcommand("info", "Print the metadata and tables of a LUT");
  cmd->add_option("lut", *path, "LUT .exr written by facetfit bake")->required();
  cmd->add_flag("--json", *json, "As one JSON object");
  cmd->callback([path, json, &ctx] {
    try {
      // A measurement named where a LUT is expected: say what to run instead of the image reader's complaint.
      if (is_measurement(*path))
        throw Error(*path + ": a measurement, not a LUT: `facetfit fit` it, or `facetfit bake` it and run info on the LUT");
      const Lut lut = read_lut(*path);
      if (*json) std::printf("%s\n", json_text(info_json(lut)).c_str());
      else print_info(lut);
    } catch (const Error& e) {
      report_error(e.what());
      ctx.status = 1;
    }
  });
}

}  // namespace facetfit::cli
