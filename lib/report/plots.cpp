#include "report/plots.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <sstream>

#include "core/error.h"
#include "fit/representations.h"
#include "model/closures.h"
#include "model/fresnel.h"

namespace facetfit {

std::string line_chart_svg(const std::string& title, const std::string& x_label, const std::string& y_label,
                           const std::vector<PlotSeries>& series, bool log_y) {
  constexpr double kW = 360, kH = 240, kLeft = 50, kRight = 10, kTop = 24, kBottom = 36;
  const auto y_of = [&](double y) { return log_y ? std::log10(y) : y; };
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (const PlotSeries& s : series)
    for (const auto& [x, y] : s.points) {
      if (!std::isfinite(y) || (log_y && y <= 0.0)) continue;
      x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y_of(y)), y1 = std::max(y1, y_of(y));
    }
  if (!(x0 < x1)) x0 = 0.0, x1 = 1.0;
  if (!(y0 < y1)) y0 = y0 > 1e299 ? 0.0 : y0 - 1.0, y1 = y0 + 1.0;
  if (!log_y) y0 = std::min(y0, 0.0);
  if (log_y) y0 = std::max(y0, y1 - 6.0);  // six decades: a Beckmann tail would otherwise reach 1e-300
  const auto px = [&](double x) { return kLeft + (kW - kLeft - kRight) * (x - x0) / (x1 - x0); };
  const auto py = [&](double y) { return kH - kBottom - (kH - kTop - kBottom) * (std::max(y_of(y), y0) - y0) / (y1 - y0); };
  std::ostringstream svg;
  svg.precision(4);
  svg << "<svg width='" << kW << "' height='" << kH << "' xmlns='http://www.w3.org/2000/svg' font-size='10'>"
      << "<text x='" << kLeft << "' y='14' font-weight='bold'>" << title << "</text>"
      << "<line x1='" << kLeft << "' y1='" << kH - kBottom << "' x2='" << kW - kRight << "' y2='" << kH - kBottom << "' stroke='black'/>"
      << "<line x1='" << kLeft << "' y1='" << kTop << "' x2='" << kLeft << "' y2='" << kH - kBottom << "' stroke='black'/>"
      << "<text x='" << kLeft << "' y='" << kH - kBottom + 12 << "'>" << x0 << "</text>"
      << "<text x='" << kW - kRight - 24 << "' y='" << kH - kBottom + 12 << "'>" << x1 << "</text>"
      << "<text x='" << (kW - kLeft) / 2 << "' y='" << kH - 6 << "'>" << x_label << "</text>"
      << "<text x='2' y='" << kTop + 4 << "'>" << (log_y ? std::pow(10.0, y1) : y1) << "</text>"
      << "<text x='2' y='" << kH - kBottom << "'>" << (log_y ? std::pow(10.0, y0) : y0) << "</text>"
      << "<text x='2' y='" << kTop - 8 << "'>" << y_label << "</text>";
  for (std::size_t k = 0; k < series.size(); ++k) {
    const PlotSeries& s = series[k];
    svg << "<polyline fill='none' stroke='" << s.colour << "'" << (s.dashed ? " stroke-dasharray='4 3'" : "") << " points='";
    for (const auto& [x, y] : s.points)
      if (std::isfinite(y) && !(log_y && y <= 0.0)) svg << px(x) << "," << py(y) << " ";
    svg << "'/><text x='" << kW - kRight - 90 << "' y='" << kTop + 12.0 * double(k + 1) << "' fill='" << s.colour << "'>" << s.label
        << "</text>";
  }
  svg << "</svg>";
  return svg.str();
}

std::vector<PlotSeries> incidence_plane(double theta_i_degrees, const std::vector<PlotBrdf>& brdfs) {
  const Vec3 i = spherical_direction(theta_i_degrees * kPi / 180.0, kPi);
  std::vector<PlotSeries> out;
  for (std::size_t k = 0; k < brdfs.size(); ++k) {
    PlotSeries s{brdfs[k].label, brdfs[k].colour, {}, k > 0};
    for (int d = -89; d <= 89; ++d) {
      // theta_o > 0: the mirror side (phi = 0); < 0: the side of i (phi = pi).
      const Vec3 o = spherical_direction(std::abs(d) * kPi / 180.0, d >= 0 ? 0.0 : kPi);
      const auto f = brdfs[k].brdf->eval(o, i);
      s.points.emplace_back(d, f ? std::cbrt(std::max(0.0, luminance(*f) * o.z)) : std::nan(""));
    }
    out.push_back(std::move(s));
  }
  return out;
}

std::vector<std::pair<std::string, std::string>> material_figures(const Brdf& measured, const Lut& lut) {
  // Each representation the LUT holds, in report order and colour (fit/representations.h): the parametric fits
  // by name (left out without an alpha: not fitted), the tabulated lobe and the closures.
  const TabulatedMicrofacet tabulated = lut.model();
  const ClosureBrdf closures(lut.closures());
  std::vector<ParametricBrdf> fits;
  fits.reserve(std::size(kRepresentations));  // the pointers into it below stay valid
  std::vector<PlotBrdf> brdfs{{"measured", "black", &measured}};
  for (const RepresentationRow& r : kRepresentations) {
    const std::string name = r.name;
    const Brdf* brdf = name == "tabulated" ? &tabulated : name == "closures" ? static_cast<const Brdf*>(&closures) : nullptr;
    if (r.parametric) {
      const auto p = lut.parametric(name, lut.meta.smith);
      if (!p || !(p->ndf().alpha_x > 0.0)) continue;
      brdf = &fits.emplace_back(*p);
    }
    if (!brdf) throw Error("material_figures: no BRDF for the representation " + name + " (report/plots.cpp)");
    brdfs.push_back({r.name, r.colour, brdf});
  }
  std::vector<std::pair<std::string, std::string>> out;
  for (const double theta_i : {0.0, 30.0, 60.0}) {
    out.emplace_back("lobes_" + std::to_string(int(theta_i)) + ".svg", line_chart_svg("incidence plane, theta_i " + std::to_string(int(theta_i)) + " deg", "theta_o (deg)",
                          "cbrt(f cos)", incidence_plane(theta_i, brdfs)));
  }
  // NDF: the tabulated one and the analytic D of the parametric fits.
  const auto colour = [](const char* name) { return find_representation(name)->colour; };
  std::vector<PlotSeries> ndf{{"tabulated", colour("tabulated"), {}, false}};
  const double a_ggx = lut.meta.ggx.alpha > 0.0 ? lut.meta.ggx.alpha : lut.meta.alpha_ggx;
  const double a_beckmann = lut.meta.beckmann.alpha > 0.0 ? lut.meta.beckmann.alpha : lut.meta.alpha_beckmann;
  PlotSeries ggx{"ggx", colour("ggx"), {}, true}, beckmann{"beckmann", colour("beckmann"), {}, true};
  for (int d = 0; d <= 88; ++d) {
    const double theta = d * kPi / 180.0;
    const Vec3 h = spherical_direction(theta, 0.0);
    ndf[0].points.emplace_back(d, lut.tables.ndf.D(theta));
    ggx.points.emplace_back(d, Ndf::isotropic(NdfType::ggx, a_ggx).D(h));
    beckmann.points.emplace_back(d, Ndf::isotropic(NdfType::beckmann, a_beckmann).D(h));
  }
  ndf.push_back(ggx);
  ndf.push_back(beckmann);
  out.emplace_back("ndf.svg", line_chart_svg("NDF", "theta_h (deg)", "D (1/sr)", ndf, true));
  // Fresnel: the RGB curve, and the GGX fit's F82-tint.
  std::vector<PlotSeries> fresnel{{"F red", "#d62728", {}, false}, {"F green", "#2ca02c", {}, false}, {"F blue", "#1f77b4", {}, false}};
  PlotSeries tint{"ggx F82-tint (green)", "#2ca02c", {}, true};
  for (int j = 0; j < FresnelCurve::kSize; ++j) {
    const double deg = FresnelCurve::theta_d(j) * 180.0 / kPi;
    for (int c = 0; c < 3; ++c) fresnel[std::size_t(c)].points.emplace_back(deg, lut.tables.fresnel.value[std::size_t(j)][c]);
    if (lut.meta.ggx.alpha > 0.0)
      tint.points.emplace_back(deg, fresnel_f82_tint(lut.meta.ggx.f0, lut.meta.ggx.f82, std::cos(FresnelCurve::theta_d(j))).g);
  }
  if (!tint.points.empty()) fresnel.push_back(tint);
  out.emplace_back("fresnel.svg", line_chart_svg("Fresnel", "theta_d (deg)", "F", fresnel));
  return out;
}

}  // namespace facetfit
