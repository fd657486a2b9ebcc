// The one-ray path: one ray and one evaluation at a time, the reference the stream path must match.
#include <limits>

#include "render/integrator.h"

namespace facetfit {

namespace {

// A sample added to a pixel's sums (r, g, b, alpha): a radiance that is not finite adds nothing (x - x is
// 0 for a finite x, NaN otherwise), as add_samples does in lanes on the stream path.
void accumulate(double* sums, const Rgb& radiance, double alpha) {
  const bool finite = (radiance.r - radiance.r) + (radiance.g - radiance.g) + (radiance.b - radiance.b) == 0.0;
  for (int c = 0; c < 3; ++c) sums[c] += finite ? radiance[c] : 0.0;
  sums[3] += alpha;
}

}  // namespace

void Integrator::RenderTileScalar(const Tile& tile, int first, int last) {
  Shadows shadows;
  Textured textured;
  Planned planned;
  for (int y = tile.rows().begin(); y < tile.rows().end(); ++y)
    for (int x = tile.cols().begin(); x < tile.cols().end(); ++x)
      for (int s = first; s < last; ++s) {
        double u[kSampleNumbers];
        SampleNumbers(x, y, s, u);
        Ray ray;  // written into its place, not copied in (see Ray in render/tracer.h)
        ray.origin = camera_.position, ray.dir = camera_.direction(x, y, u[0], u[1]);
        ray.tnear = 0.0, ray.tfar = std::numeric_limits<double>::infinity();
        shadows.rays.clear(), shadows.values.clear();
        const Hit hit = tracer_->intersect(ray);
        Place(hit, ray.dir, planned);
        Plan(hit, u + 2, textured, planned, shadows);
        for (std::size_t q = 0; q < shadows.rays.size(); ++q)
          if (!tracer_->occluded(shadows.rays[q])) planned.radiance += shadows.values[q];
        accumulate(PixelSums(x, y), planned.radiance, planned.alpha);
      }
}

}  // namespace facetfit
