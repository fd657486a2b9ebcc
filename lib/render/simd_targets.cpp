#include "render/simd_targets.h"

#include <hwy/highway.h>

#include <cstdlib>

#if HWY_ARCH_X86
#include <cpuid.h>
#endif

#ifdef FACETFIT_SIMD_BASELINE_ONLY
static_assert(HWY_DISABLED_TARGETS == (HWY_AVX3_DL | HWY_AVX3 | HWY_AVX2 | HWY_SSE4 | HWY_SSSE3), "Highway's target bits moved");
#else
static_assert(HWY_DISABLED_TARGETS == (HWY_AVX3_DL | HWY_SSE4 | HWY_SSSE3), "Highway's target bits moved");
#endif

namespace facetfit {

bool cpu_has_avx2() {
#if HWY_ARCH_X86 && (HWY_TARGETS & HWY_AVX2)
  static const bool yes = [] {
    __builtin_cpu_init();
    unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;  // F16C from CPUID itself: clang's builtin lacks its name
    const bool f16c = __get_cpuid(1, &eax, &ebx, &ecx, &edx) && (ecx & bit_F16C);
    return f16c && __builtin_cpu_supports("ssse3") && __builtin_cpu_supports("sse4.1") && __builtin_cpu_supports("sse4.2") &&
           __builtin_cpu_supports("pclmul") && __builtin_cpu_supports("aes") && __builtin_cpu_supports("avx") &&
           __builtin_cpu_supports("avx2") && __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2") &&
           __builtin_cpu_supports("fma");
  }();
  return yes;
#else
  return false;
#endif
}

bool cpu_has_avx3() {
#if HWY_ARCH_X86 && (HWY_TARGETS & HWY_AVX3)
  static const bool yes = cpu_has_avx2() && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                          __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw") && !std::getenv("FACETFIT_NO_AVX3");
  return yes;
#else
  return false;
#endif
}

}  // namespace facetfit
