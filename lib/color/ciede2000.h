// CIEDE2000 colour difference (CIE 142-2001), as written out by Sharma, Wu and Dalal, "The CIEDE2000
// Color-Difference Formula: Implementation Notes, Supplementary Test Data, and Mathematical
// Observations", Color Research and Application 30(1), 2005. docs/colour.md says where it is used.
#pragma once

#include <array>
#include <string>

namespace facetfit {

// CIE 1976 L*a*b* (here always relative to the D65 white; see color/display.h).
struct Lab {
  double L, a, b;
};

// Delta E00 between x and y, with the parametric factors kL, kC, kH (1 for the reference conditions).
// Symmetric in x and y. Hue ties (hues exactly 180 degrees apart) and pairs where either chroma is zero
// follow the paper's rules for the hue difference and the mean hue to the letter: see ciede2000.cpp.
double ciede2000(const Lab& x, const Lab& y, double kL = 1, double kC = 1, double kH = 1);

// One line of a pair list (`facetfit deltae`): six finite numbers "L1 a1 b1 L2 a2 b2" separated by spaces
// or tabs, read locale-independently. Throws Error("<what>: <problem>") naming the offending token, cut
// to a printable excerpt.
std::array<double, 6> parse_lab_pair(const std::string& line, const std::string& what);

}  // namespace facetfit
