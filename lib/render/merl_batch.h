// A MERL-layout table's f(o, i) over a batch, in SIMD lanes (render/ggx_batch.h does GGX): HalfDiffTable::eval
// with its linear lookup, every term its own in the same order (half/diff angles, bin coordinates, the
// eight corners with missing neighbours dropped per channel), so the two agree to rounding
// (tests/render/test_shading_lanes.cpp). The arc cosines are render/lanes-inl.h's, the arc tangent Highway's.
#pragma once

#include <optional>

#include "render/shading_batch.h"
#include "render/simd_targets.h"

namespace facetfit {

class HalfDiffTable;

struct MerlBatchModel {
  const float* channel[3] = {nullptr, nullptr, nullptr};  // HalfDiffTable::channel(c), index() order

  // None unless the table reads between bins linearly (its nearest lookup stays one pair at a time).
  static std::optional<MerlBatchModel> of(const HalfDiffTable& table);
};

// Fills the batch's r, g and b for its padded_size() pairs (pdf untouched): zero where o or i is below the
// horizon or a channel has no measured neighbour (HalfDiffTable::eval's none). `target`: which SIMD code
// runs (render/simd_targets.h; the tests run each).
void eval_merl_batch(const MerlBatchModel& model, EvaluationBatch& batch, SimdTarget target = SimdTarget::best);

}  // namespace facetfit
