// The report's figures as SVG line charts, the way the paper validates its fits: the BRDF in the plane
// of incidence (cube root of f cos(theta_o), measured against each representation), the NDF and the
// Fresnel curves.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "core/brdf.h"
#include "lut/lut.h"

namespace facetfit {

struct PlotSeries {
  std::string label;
  std::string colour;  // any SVG colour
  std::vector<std::pair<double, double>> points;
  bool dashed = false;
};

// A line chart: axes with their ranges, the series, a legend. `log_y`: a logarithmic y axis (points at
// or below zero are left out).
std::string line_chart_svg(const std::string& title, const std::string& x_label, const std::string& y_label,
                           const std::vector<PlotSeries>& series, bool log_y = false);

// A BRDF to plot, with its legend and colour.
struct PlotBrdf {
  std::string label;
  std::string colour;  // any SVG colour
  const Brdf* brdf;
};

// In the plane of incidence at theta_i (degrees): cbrt(luminance(f) cos(theta_o)) for theta_o from -89 to
// 89 degrees (negative: on the side of i, back-scattering), one series per BRDF, the first solid, the others
// dashed.
std::vector<PlotSeries> incidence_plane(double theta_i_degrees, const std::vector<PlotBrdf>& brdfs);

// The figures of one material as (file name, SVG): the incidence plane at 0, 30 and 60 degrees
// (lobes_0.svg, ...), the NDF (tabulated against the GGX and Beckmann fits: ndf.svg), Fresnel (RGB curve
// of the tabulated representation, the GGX fit's F82-tint: fresnel.svg).
std::vector<std::pair<std::string, std::string>> material_figures(const Brdf& measured, const Lut& lut);

}  // namespace facetfit
