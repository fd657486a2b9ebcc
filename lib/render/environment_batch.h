// A constant environment's light samples over a batch, in SIMD lanes (Google Highway, as
// render/ggx_batch.h): the directions of Environment::sample, uniform over the sphere, without a libm
// sine and cosine per sample (perf: 8% of a GGX sphere under a constant environment).
#pragma once

#include <vector>

#include "render/shading_batch.h"
#include "render/simd_targets.h"

namespace facetfit {

// The direction drawn with the numbers (u1, u2).
struct SphereSampleBatch : Columns {
  std::vector<double> u1, u2;  // in
  std::vector<double> x, y, z;  // out
  std::size_t push(double a, double b) {
    const std::size_t k = next([this](std::size_t n) { resize({&u1, &u2, &x, &y, &z}, n, 0.5); });
    u1[k] = a, u2[k] = b;
    return k;
  }
  // n entries, whose inputs the caller writes in place.
  void resize_to(std::size_t n) {
    ensure(n, [this](std::size_t m) { resize({&u1, &u2, &x, &y, &z}, m, 0.5); });
    set_size(n);
  }
  Vec3 d(std::size_t k) const { return {x[k], y[k], z[k]}; }
};

// Fills x, y, z for the batch's padded_size() entries as Environment::sample of a constant environment
// does: z' = 1 - 2 u1, r = sqrt(1 - z'^2), phi = 2 pi u2, d = (r cos phi, z', r sin phi). `target`: which
// SIMD code runs (render/simd_targets.h; the tests run each).
void sample_uniform_sphere_batch(SphereSampleBatch& batch, SimdTarget target = SimdTarget::best);

}  // namespace facetfit
