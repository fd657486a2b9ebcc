// GGX's D and Smith's Lambda, written once over a number type F (model/ggx_terms-inl.h): double for the
// library (model/ndf.h) and Highway's vectors in the renderer's SIMD lanes (render/lanes-inl.h), as
// Mitsuba writes a BSDF once over its Float. `Ops` gives what F's operators do not: division, the square
// root, constants and a choice by sign (ScalarOps, model/scalar_ops.h; LaneOps in render/lanes-inl.h).
#pragma once

#include "model/scalar_ops.h"

namespace facetfit::ggx {

#include "model/ggx_terms-inl.h"

}  // namespace facetfit::ggx
