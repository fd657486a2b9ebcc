// The representations of a fit, each once, in report order: what the report's columns and plots, the JSON
// record, `info`, the plausibility checks and the Python module iterate, so that a new representation is a
// row here rather than an edit in each (docs/architecture.md, walk 3). Not installed.
#pragma once

#include <string>

#include "fit/fit.h"

namespace facetfit {

struct RepresentationRow {
  const char* name;           // the report's column, the record's and `info`'s key, the plots' label
  const char* material_type;  // the scene material type that renders it from a LUT (render/materials.h)
  const char* colour;         // its colour in the report's plots
  // A parametric fit (fit/parametric_fit.h): its member of FitResult, and of the LUT (LutMetadata::fit(name));
  // null for the tabulated lobe and the closures, which have their own records.
  ParametricFit FitResult::*parametric;
  // Its distance from the measurement (fit/measurement.h).
  double (*distance)(const FitResult& fit);
};

// lsq: the classical Lambert + GGX + Schlick least-squares fit, what users get today; closures: what the
// production OSL material renders (fit/closure_fit.h).
inline constexpr RepresentationRow kRepresentations[] = {
    {"tabulated", "lut", "#1f77b4", nullptr, [](const FitResult& f) { return f.error; }},
    {"ggx", "ggx", "#d62728", &FitResult::ggx, [](const FitResult& f) { return f.ggx.error; }},
    {"beckmann", "beckmann", "#2ca02c", &FitResult::beckmann, [](const FitResult& f) { return f.beckmann.error; }},
    {"lsq", "lsq", "#9467bd", &FitResult::lsq, [](const FitResult& f) { return f.lsq.error; }},
    {"closures", "closures", "#ff7f0e", nullptr, [](const FitResult& f) { return f.closures.error; }},
};

// The row named `name`; null for another name.
inline const RepresentationRow* find_representation(const std::string& name) {
  for (const RepresentationRow& r : kRepresentations)
    if (name == r.name) return &r;
  return nullptr;
}

// The parametric rows' names as prose, "ggx, beckmann or lsq", for messages.
inline std::string parametric_names() {
  std::string list, last;
  for (const RepresentationRow& r : kRepresentations) {
    if (!r.parametric) continue;
    if (!last.empty()) list += (list.empty() ? "" : ", ") + last;
    last = r.name;
  }
  return list.empty() ? last : list + " or " + last;
}

}  // namespace facetfit
