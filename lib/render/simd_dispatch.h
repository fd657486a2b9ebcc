// The call of a renderer kernel for the best SIMD target the CPU has (render/simd_targets.h), in each
// kernel file's HWY_ONCE part, after Highway's headers, or the one a test asks for (SimdTarget).
#pragma once

#include <hwy/highway.h>

#include "render/simd_targets.h"

#if HWY_TARGETS & HWY_AVX3
#define FACETFIT_IF_AVX3(call) call
#else
#define FACETFIT_IF_AVX3(call)
#endif
#if HWY_TARGETS & HWY_AVX2
#define FACETFIT_IF_AVX2(call) call
#else
#define FACETFIT_IF_AVX2(call)
#endif

#define FACETFIT_DISPATCH(target, kernel, ...)                                                                     \
  do {                                                                                                             \
    FACETFIT_IF_AVX3(if ((target) == SimdTarget::best && cpu_has_avx3()) return N_AVX3::kernel(__VA_ARGS__);)       \
    FACETFIT_IF_AVX2(if ((target) != SimdTarget::baseline && cpu_has_avx2()) return N_AVX2::kernel(__VA_ARGS__);)   \
    return HWY_STATIC_DISPATCH(kernel)(__VA_ARGS__);                                                               \
  } while (false)
