// A tile's camera samples in SIMD lanes (Google Highway, as render/ggx_batch.h): each pixel's numbers for
// one sample index and its camera ray's direction. In lanes because, one sample at a time inside the tile
// loop, their 64-bit hashes, square roots and divisions would be a large share of every sample's work.
#pragma once

#include <cstdint>
#include <cstring>
#include <vector>

#include "render/shading_batch.h"
#include "render/simd_targets.h"

namespace facetfit {

// The numbers a sample draws: two for the pixel's jitter, five for its shading (render/integrator.h).
constexpr int kSampleNumbers = 7;

// SplitMix64, a counter-based generator: the sequence of sample s of pixel (x, y) starts at a state that
// depends on (seed, x, y, s) only, so an image does not depend on passes, tiles, threads or paths.
struct SampleSequence {
  static constexpr std::uint64_t kStep = 0x9E3779B97F4A7C15ull;
  static constexpr std::uint64_t kMix1 = 0xBF58476D1CE4E5B9ull, kMix2 = 0x94D049BB133111EBull;  // the finalizer's
  static std::uint64_t pixel_key(int x, int y) {
    return (std::uint64_t(y) * 73856093u + std::uint64_t(x) * 19349663u) * kStep;
  }
  // Seed and sample index xor pixel_key: the lanes take start(seed, 0, s) once per batch.
  static std::uint64_t start(std::uint64_t seed, std::uint64_t pixel_key, int s) {
    return seed * 0x100000001B3ull ^ pixel_key ^ std::uint64_t(s) << 40;
  }
  // Number j of the sequence from `start`: state j / 2 + 1, mixed, gives numbers j and j + 1 (even j), its
  // top 32 bits and its low 32 bits; a double in [0, 1) as the mantissa of a number in [1, 2) less 1 (exact;
  // the lanes form it with an or, where AVX2 has no conversion of 64-bit integers). 32 bits a number, not
  // 52: two numbers per mix make a sample's hashes three, not five, each two 64-bit multiplications,
  // emulated on AVX2.
  static std::uint64_t state(std::uint64_t start, int pair) {
    std::uint64_t z = start + std::uint64_t(pair + 1) * kStep;
    z = (z ^ (z >> 30)) * kMix1;
    z = (z ^ (z >> 27)) * kMix2;
    return z ^ (z >> 31);
  }
  // The 32 bits of number j (even: the state's top half, odd: its low half) placed as a mantissa's top.
  static constexpr std::uint64_t kHalfMantissa = 0x000FFFFFFFF00000ull;
  static double number(std::uint64_t start, int j) {
    const std::uint64_t z = state(start, j / 2);
    const std::uint64_t bits = ((j % 2 == 0 ? z >> 12 : z << 20) & kHalfMantissa) | kOne;
    double x;
    std::memcpy(&x, &bits, sizeof x);
    return x - 1.0;
  }
  static constexpr std::uint64_t kOne = 0x3FF0000000000000ull;  // 1.0's bits
};

// A pinhole camera: image point (x + u0, y + u1), in pixels from the top left, to a unit direction.
struct PinholeCamera {
  Vec3 position, forward, right, up;
  double tan_half = 1.0, aspect = 1.0;
  double to_sx = 1.0, to_sy = 1.0;  // 2 / width, 2 / height: products, not quotients (a division per axis
                                    // and sample would wait on the one before)
  Vec3 direction(double x, double y, double u0, double u1) const {
    const double sx = ((x + u0) * to_sx - 1.0) * tan_half * aspect;
    const double sy = (1.0 - (y + u1) * to_sy) * tan_half;
    return glm::normalize(forward + sx * right + sy * up);
  }
};

// Per pixel of a tile: in, its coordinates and SampleSequence::pixel_key; out, for one sample index, the
// seven numbers (u[j]) and the camera ray's direction.
struct CameraSampleBatch : Columns {
  std::vector<double> x, y;
  std::vector<std::uint64_t> key;
  std::vector<double> u[kSampleNumbers];
  std::vector<double> dx, dy, dz;
  std::size_t push(int px, int py) {
    const std::size_t k = next([this](std::size_t n) {
      resize({&x, &y, &dx, &dy, &dz}, n, 0.0);
      for (std::vector<double>& c : u) c.resize(n, 0.0);
      key.resize(n, 0);
    });
    x[k] = px, y[k] = py, key[k] = SampleSequence::pixel_key(px, py);
    return k;
  }
  Vec3 d(std::size_t k) const { return {dx[k], dy[k], dz[k]}; }
};

// Which of a sample's numbers a scene reads (bit j for number j): the jitter always, the environment's
// light sample (2, 3) under a map, the BRDF sample (4 to 6) with an environment.
constexpr unsigned kAllSampleNumbers = (1u << kSampleNumbers) - 1;
inline unsigned sample_numbers_read(bool environment, bool light_sampled) {
  return 3u | (light_sampled ? 12u : 0u) | (environment ? 112u : 0u);
}

// Fills u and d for the batch's padded_size() entries: SampleSequence::number j of each pixel's sample s
// for each j in `numbers` (the others are not written: a third of a constant environment's draws are
// never read), and PinholeCamera::direction with the first two. `target`: which SIMD code runs
// (render/simd_targets.h; the tests run each).
void camera_sample_batch(const PinholeCamera& camera, std::uint64_t seed, int s, CameraSampleBatch& batch, SimdTarget target = SimdTarget::best,
                         unsigned numbers = kAllSampleNumbers);

}  // namespace facetfit
