// The lanes back-ends of ShadingModel: the kinds of model whose batches run in SIMD lanes, in the order a
// ShadingModel tries them; the first that recognises its BRDF and proposal runs its batches. Each is a
// type of its own NAME_batch.h with
//
//   static std::optional<T> recognise(const LanesInput&);  // the model, if this back-end runs it
//   bool f_in_lanes() const;                              // f itself too, not only the proposal's draws
//   void eval(EvaluationBatch&, const ShadingModel&) const;  // f and density of each pair (the model's
//                                                            // own f one pair at a time where not in lanes)
//   void sample(SampleBatch&) const;                      // the proposal's directions
//
// A type missing from this list never runs (Shading.EveryMaterialTypeRunsInTheLanesItDeclares fails); one
// in it without those members does not compile.
#pragma once

#include <optional>
#include <variant>

#include "render/ggx_batch.h"
#include "render/lambert_batch.h"
#include "render/tabulated_batch.h"

namespace facetfit {

using LanesBackend = std::variant<std::monostate, GgxLanes, TabulatedLanes, LambertLanes>;

// The first back-end of the list that recognises `in`, or none (std::monostate).
template <std::size_t K = 1>
LanesBackend recognise_lanes(const LanesInput& in) {
  if constexpr (K == std::variant_size_v<LanesBackend>) {
    return {};
  } else {
    using Backend = std::variant_alternative_t<K, LanesBackend>;
    if (std::optional<Backend> b = Backend::recognise(in)) return LanesBackend(std::in_place_index<K>, std::move(*b));
    return recognise_lanes<K + 1>(in);
  }
}

}  // namespace facetfit
