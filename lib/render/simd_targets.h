// The SIMD targets every Highway kernel of the renderer is compiled for, and the choice between them at
// run time. Included first by each kernel file, before any of Highway's headers.
//
// Three targets: AVX3 (AVX-512, eight doubles a vector), AVX2 (four) and the baseline; AVX3_DL, SSE4 and
// SSSE3 are off (their bits in hwy/detect_targets.h, checked against Highway's names in simd_targets.cpp).
// A build with FACETFIT_SIMD_BASELINE_ONLY (the fuzz build, which never times a kernel) compiles the
// baseline alone: each kernel file then compiles once instead of three times.
#pragma once

#ifdef FACETFIT_SIMD_BASELINE_ONLY
#define HWY_DISABLED_TARGETS ((1LL << 7) | (1LL << 8) | (1LL << 9) | (1LL << 11) | (1LL << 12))
#else
#define HWY_DISABLED_TARGETS ((1LL << 7) | (1LL << 11) | (1LL << 12))
#endif

namespace facetfit {

// Whether the CPU has every feature Highway compiles its AVX2 code for. Highway's own run-time dispatch
// (HWY_DYNAMIC_DISPATCH) lives in libhwy.so, whose static initializer times a clock in every process that
// loads it, which delays every command's start-up. With two targets the CPU's features pick.
bool cpu_has_avx2();
// And every feature of its AVX3 (AVX-512: F, VL, DQ, BW) code, unless the environment variable
// FACETFIT_NO_AVX3 is set: a benchmark's way to time the AVX2 code on the same CPU (bench/render_compare.py).
bool cpu_has_avx3();

// Which code a kernel runs: the best the CPU has (the renderer's), or, for the tests, AVX2 (where the CPU has
// it) or the baseline, for CPUs without AVX2.
enum class SimdTarget { best, avx2, baseline };
constexpr SimdTarget kSimdTargets[] = {SimdTarget::best, SimdTarget::avx2, SimdTarget::baseline};
inline const char* simd_target_name(SimdTarget t) { return t == SimdTarget::best ? "best" : t == SimdTarget::avx2 ? "avx2" : "baseline"; }

}  // namespace facetfit
