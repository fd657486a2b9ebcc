// The SIMD targets every Highway kernel of the renderer is compiled for, and the choice between them at
// run time. Included first by each kernel file, before any of Highway's headers.
//
// Two targets: AVX2 and the baseline. AVX3_DL, AVX3, SSE4 and SSSE3 are off (their bits in
// hwy/detect_targets.h; each kernel file checks them against Highway's names). AVX3 (AVX-512, eight doubles a
// vector) was tried on a CPU that has it: the GGX sphere of docs/render-speed.md rendered slower (64 spp
// 0.22 -> 0.24 s, 1024 spp 3.44 -> 3.61 s, medians of alternating runs; a one-off probe), so it stays off.
#pragma once

#define HWY_DISABLED_TARGETS ((1LL << 7) | (1LL << 8) | (1LL << 11) | (1LL << 12))

namespace facetfit {

// Whether the CPU has every feature Highway compiles its AVX2 code for. Highway's own run-time dispatch
// (HWY_DYNAMIC_DISPATCH) lives in libhwy.so, whose static initializer times a clock in every process that
// loads it: 4 ms more for every command's start-up (perf stat). With two targets the CPU's features pick.
bool cpu_has_avx2();

}  // namespace facetfit
