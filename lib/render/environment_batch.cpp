// Compiled once per SIMD target by Highway's foreach_target (this file includes itself), as
// render/ggx_batch.cpp.
#include "render/simd_targets.h"  // before any of Highway's headers
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "render/environment_batch.cpp"
#include <hwy/foreach_target.h>  // before highway.h

#include <hwy/highway.h>
#include <hwy/contrib/math/math-inl.h>

#include "render/environment_batch.h"
#include "render/lanes-inl.h"

HWY_BEFORE_NAMESPACE();
namespace facetfit {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

void SampleUniformSphereBatch(SphereSampleBatch& batch) {
  using D = hn::ScalableTag<double>;
  using V = hn::Vec<D>;
  const D d;
  const V one = hn::Set(d, 1.0), two = hn::Set(d, 2.0);
  for (std::size_t k = 0; k < batch.padded_size(); k += hn::Lanes(d)) {
    const V z = one - two * hn::LoadU(d, batch.u1.data() + k);
    const V r = hn::Sqrt(hn::Max(hn::Zero(d), one - z * z));
    const lanes::CosSin phi = lanes::cos_sin_turn(d, hn::LoadU(d, batch.u2.data() + k));
    hn::StoreU(r * phi.c, d, batch.x.data() + k);
    hn::StoreU(z, d, batch.y.data() + k);
    hn::StoreU(r * phi.s, d, batch.z.data() + k);
  }
}

// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace facetfit
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "render/simd_dispatch.h"
namespace facetfit {

void sample_uniform_sphere_batch(SphereSampleBatch& batch, SimdTarget target) {
  FACETFIT_DISPATCH(target, SampleUniformSphereBatch, batch);
}

}  // namespace facetfit
#endif
