// Compiled once per SIMD target by Highway's foreach_target (this file includes itself), as
// render/ggx_batch.cpp.
#include "render/simd_targets.h"  // before any of Highway's headers
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "render/camera_batch.cpp"
#include <hwy/foreach_target.h>  // before highway.h

#include <hwy/highway.h>
#include <hwy/contrib/math/math-inl.h>

#include "render/camera_batch.h"
#include "render/lanes-inl.h"

HWY_BEFORE_NAMESPACE();
namespace facetfit {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

namespace {

using D = hn::ScalableTag<double>;
using DU = hn::RebindToUnsigned<D>;
using VU = hn::Vec<DU>;

// The low 64 bits of a x c: AVX2 multiplies 32 x 32 bits, so from the halves (the high halves' product
// lies above bit 63). One lane (the baseline) multiplies them whole, and so does AVX-512 (vpmullq: 3 uops
// against the halves' 8).
VU mul(VU a, std::uint64_t c) {
  const DU du;
#if HWY_TARGET == HWY_SCALAR
  return a * hn::Set(du, c);
#elif HWY_TARGET == HWY_AVX3
  return VU{_mm512_mullo_epi64(a.raw, hn::Set(du, c).raw)};
#else
  const hn::Repartition<std::uint32_t, DU> d32;
  const auto c_lo = hn::BitCast(d32, hn::Set(du, c & 0xFFFFFFFFull)), c_hi = hn::BitCast(d32, hn::Set(du, c >> 32));
  const auto a32 = hn::BitCast(d32, a);
  const VU cross = hn::MulEven(hn::BitCast(d32, hn::ShiftRight<32>(a)), c_lo) + hn::MulEven(a32, c_hi);
  return hn::MulEven(a32, c_lo) + hn::ShiftLeft<32>(cross);
#endif
}

}  // namespace

void DrawCameraSamples(const PinholeCamera& camera, std::uint64_t seed, int s, CameraSampleBatch& batch, unsigned numbers) {
  const D d;
  const DU du;
  const std::uint64_t seed_part = SampleSequence::start(seed, 0, s);
  const auto one = hn::Set(d, 1.0);
  const VU one_bits = hn::Set(du, SampleSequence::kOne), half_mantissa = hn::Set(du, SampleSequence::kHalfMantissa);
  const auto to_sx = hn::Set(d, camera.to_sx), to_sy = hn::Set(d, camera.to_sy);
  const auto tan_half = hn::Set(d, camera.tan_half), aspect = hn::Set(d, camera.aspect);
  for (std::size_t k = 0; k < batch.padded_size(); k += hn::Lanes(d)) {
    const VU start = hn::Xor(hn::Set(du, seed_part), hn::LoadU(du, batch.key.data() + k));
    for (int pair = 0; 2 * pair < kSampleNumbers; ++pair) {
      const int j = 2 * pair;
      const bool even = numbers >> j & 1u, odd = j + 1 < kSampleNumbers && (numbers >> (j + 1) & 1u);
      if (!even && !odd) continue;
      VU z = start + hn::Set(du, std::uint64_t(pair + 1) * SampleSequence::kStep);
      z = mul(hn::Xor(z, hn::ShiftRight<30>(z)), SampleSequence::kMix1);
      z = mul(hn::Xor(z, hn::ShiftRight<27>(z)), SampleSequence::kMix2);
      z = hn::Xor(z, hn::ShiftRight<31>(z));
      if (even) hn::StoreU(hn::BitCast(d, hn::Or(hn::And(hn::ShiftRight<12>(z), half_mantissa), one_bits)) - one, d, batch.u[j].data() + k);
      if (odd) hn::StoreU(hn::BitCast(d, hn::Or(hn::ShiftRight<12>(hn::ShiftLeft<32>(z)), one_bits)) - one, d, batch.u[j + 1].data() + k);
    }
    const auto sx = ((hn::LoadU(d, batch.x.data() + k) + hn::LoadU(d, batch.u[0].data() + k)) * to_sx - one) * tan_half * aspect;
    const auto sy = (one - (hn::LoadU(d, batch.y.data() + k) + hn::LoadU(d, batch.u[1].data() + k)) * to_sy) * tan_half;
    const auto x = hn::Set(d, camera.forward.x) + sx * hn::Set(d, camera.right.x) + sy * hn::Set(d, camera.up.x);
    const auto y = hn::Set(d, camera.forward.y) + sx * hn::Set(d, camera.right.y) + sy * hn::Set(d, camera.up.y);
    const auto z = hn::Set(d, camera.forward.z) + sx * hn::Set(d, camera.right.z) + sy * hn::Set(d, camera.up.z);
    const auto inv_len = lanes::inverse_sqrt(d, x * x + y * y + z * z);
    hn::StoreU(x * inv_len, d, batch.dx.data() + k);
    hn::StoreU(y * inv_len, d, batch.dy.data() + k);
    hn::StoreU(z * inv_len, d, batch.dz.data() + k);
  }
}

// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace facetfit
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "render/simd_dispatch.h"
namespace facetfit {

void camera_sample_batch(const PinholeCamera& camera, std::uint64_t seed, int s, CameraSampleBatch& batch, SimdTarget target, unsigned numbers) {
  numbers |= 3u;  // the camera ray's
  FACETFIT_DISPATCH(target, DrawCameraSamples, camera, seed, s, batch, numbers);
}

}  // namespace facetfit
#endif
