// The stream path: every pixel of a tile at once, one sample index after the other. Camera rays, shading,
// then shadow rays, as streams (Embree's for triangles; coherent camera rays travel together), and the
// evaluations of each material shaded in lanes in batches (render/wavefront.h).
#include <cstring>

#include "render/integrator.h"

namespace facetfit {

void Integrator::RenderTileStreams(const Tile& tile, int first, int last) {
  TileSpace& space = tile_spaces_.local();
  BeginTile(tile, space);
  const std::size_t n = space.samples.size();
  for (int s = first; s < last; ++s) {
    camera_sample_batch(camera_, seed_, s, space.samples, SimdTarget::best, numbers_read_);
    tracer_->intersect(RaysFromPoint{camera_.position, space.samples.dx.data(), space.samples.dy.data(), space.samples.dz.data(), n},
                       space.hits, true);
    space.shadows.rays.clear(), space.shadows.values.clear();
    // Each pixel's hit given to the lanes in the tile's columns, with alpha and the radiance of what no
    // shading changes (the environment seen past everything, as Place() has it).
    double* radiance[3] = {space.radiance[0].data(), space.radiance[1].data(), space.radiance[2].data()};
    take_hits(space.hits, objects_, constant_radiance_, space.tile_hits, space.alpha.data(), radiance);
    ShadeOneAtATime(space);
    ShadeInLanes(space);
    tracer_->occluded(space.shadows.rays, space.blocked);
    AddShadows(space);
    double* sum[4] = {space.sum[0].data(), space.sum[1].data(), space.sum[2].data(), space.sum[3].data()};
    add_samples(radiance, space.alpha.data(), sum, n);
  }
  EndTile(space);
}

// The tile's pixels, their sums read from the image, and the columns sized for them.
void Integrator::BeginTile(const Tile& tile, TileSpace& space) {
  const int tw = int(tile.cols().size()), count = tw * int(tile.rows().size());
  const std::size_t n = std::size_t(count);
  const std::size_t padded_n = Columns::padded(n);  // take_hits() writes the columns whole
  for (auto& column : space.radiance) column.resize(padded_n);
  space.alpha.resize(padded_n);
  for (auto& column : space.sum) column.resize(n);
  space.planned.resize(n), space.waves.resize(materials_.size());
  // At most two environment rays and one per light per sample: room for all from the start, so that the
  // first sample of a tile does not grow them piece by piece.
  const std::size_t most = n * (2 + lights_.size());
  space.shadows.rays.reserve(most), space.shadows.values.reserve(most), space.blocked.reserve(most);
  // Each pixel's coordinates and its part of the sequences once per tile; per sample index, the numbers
  // and camera rays of all in SIMD lanes.
  CameraSampleBatch& samples = space.samples;
  samples.clear();
  for (int k = 0; k < count; ++k) {
    const int x = tile.cols().begin() + k % tw, y = tile.rows().begin() + k / tw;
    samples.push(x, y);
    const double* sums = PixelSums(x, y);
    for (int c = 0; c < 4; ++c) space.sum[c][std::size_t(k)] = sums[c];
  }
  TileHits& tile_hits = space.tile_hits;
  tile_hits.resize_to(n);
  tile_hits.dx = samples.dx.data(), tile_hits.dy = samples.dy.data(), tile_hits.dz = samples.dz.data();
  tile_hits.u1 = samples.u[4].data(), tile_hits.u2 = samples.u[5].data(), tile_hits.u3 = samples.u[6].data();
  tile_hits.light_sampled = light_sampled_;
}

// Where the scene has them: the hits of materials without lanes, shaded here by Plan(); the environment
// seen past everything; and the environment's light samples for the lanes.
void Integrator::ShadeOneAtATime(TileSpace& space) {
  space.planned_pixels.clear();
  if (!one_at_a_time_ && !light_sampled_) return;
  const CameraSampleBatch& samples = space.samples;
  TileHits& tile_hits = space.tile_hits;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    if (space.hits.object[k] < 0.0) {
      if (light_sampled_) {
        const Rgb seen = Background(samples.d(k));
        for (int c = 0; c < 3; ++c) space.radiance[c][k] = seen[c];
      }
      continue;
    }
    const Hit hit = space.hits.at(k);
    if (!in_lanes_[std::size_t(object_material_[std::size_t(hit.object)])]) {
      Planned& pk = space.planned[k];
      Place(hit, samples.d(k), pk);
      const double u[5] = {samples.u[2][k], samples.u[3][k], samples.u[4][k], samples.u[5][k], samples.u[6][k]};
      Plan(hit, u, space.textured, pk, space.shadows);
      space.alpha[k] = pk.alpha;
      space.planned_pixels.push_back(std::uint32_t(k));
    } else if (light_sampled_) {
      const Environment::Sample ls = env_->sample(samples.u[2][k], samples.u[3][k]);
      tile_hits.lx[k] = ls.d.x, tile_hits.ly[k] = ls.d.y, tile_hits.lz[k] = ls.d.z, tile_hits.light_pdf[k] = ls.pdf;
      tile_hits.light_r[k] = ls.radiance.r, tile_hits.light_g[k] = ls.radiance.g, tile_hits.light_b[k] = ls.radiance.b;
    }
  }
}

// Per material in lanes: its hits placed, their slots (lights, then the environment's BRDF samples),
// evaluated, valued and traced.
void Integrator::ShadeInLanes(TileSpace& space) {
  for (std::size_t m = 0; m < materials_.size(); ++m) {
    if (in_lanes_[m])
      place_hits(space.tile_hits, camera_.position, eps_, double(m), tangents_[m] ? &*tangents_[m] : nullptr, point_lights_,
                 space.waves[m].hits);
    else
      space.waves[m].hits.clear();
  }
  for (std::size_t m = 0; m < materials_.size(); ++m) {
    Wave& w = space.waves[m];
    if (w.hits.size() == 0) continue;
    light_slots(w.hits, lane_lights_, eps_, w.shadows, w.ranges);
    if (env_) {
      materials_[m]->sample_directions(w.hits.draws, true);
      const std::size_t brdf_begin = w.shadows.size();
      brdf_slots(w.hits, constant_radiance_, eps_, w.shadows);
      if (light_sampled_)
        for (std::size_t e = brdf_begin; e < w.shadows.size(); ++e) {
          const Environment::Sample ls = env_->lookup({w.shadows.rays.dx[e], w.shadows.rays.dy[e], w.shadows.rays.dz[e]});
          w.shadows.arriving_r[e] = ls.radiance.r, w.shadows.arriving_g[e] = ls.radiance.g, w.shadows.arriving_b[e] = ls.radiance.b;
          w.shadows.light_pdf[e] = ls.pdf;
        }
    }
    materials_[m]->eval(w.shadows, true);
    shadow_values(w.shadows, w.ranges);
    tracer_->occluded(w.shadows.rays, w.blocked);
  }
}

// The shadow rays that nothing blocks, added to their pixels. The lanes' rays slot by slot, in each hit's
// order of slots (environment light, BRDF sample, lights); a blocked ray or one cast for nothing adds
// zero with no branch: its bits and-ed with none (GCC may compile a choice to a branch, which mispredicts
// at the edges of shadows). A pixel has at most one entry per slot, so the additions of one slot do not
// wait on one another. Then the pixels Plan() shaded, with their own rays.
void Integrator::AddShadows(TileSpace& space) const {
  for (const Wave& w : space.waves) {
    if (w.hits.size() == 0) continue;
    const ShadowBatch& b = w.shadows;
    const double* value[3] = {b.value_r.data(), b.value_g.data(), b.value_b.data()};
    const auto add = [&](std::size_t begin, std::size_t end) {
      for (std::size_t e = begin; e < end; ++e) {
        const std::uint64_t keep = std::uint64_t(0) - std::uint64_t((b.casts[e] != 0.0) & (w.blocked[e] == 0));
        const std::size_t k = std::size_t(b.owner[e]);
        for (int c = 0; c < 3; ++c) {
          std::uint64_t bits;
          std::memcpy(&bits, &value[c][e], sizeof bits);
          bits &= keep;
          double v;
          std::memcpy(&v, &bits, sizeof v);
          space.radiance[c][k] += v;
        }
      }
    };
    add(0, w.ranges.lights_begin);
    add(w.ranges.brdf_begin, b.size());
    add(w.ranges.lights_begin, w.ranges.brdf_begin);
  }
  for (const std::uint32_t k : space.planned_pixels) {
    Planned& pk = space.planned[k];
    for (std::size_t q = pk.ray_first; q < pk.ray_last; ++q)
      if (!space.blocked[q]) pk.radiance += space.shadows.values[q];
    for (int c = 0; c < 3; ++c) space.radiance[c][k] = pk.radiance[c];
  }
}

// The tile's sums written back to the image.
void Integrator::EndTile(TileSpace& space) {
  const CameraSampleBatch& samples = space.samples;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    double* sums = PixelSums(int(samples.x[k]), int(samples.y[k]));
    for (int c = 0; c < 4; ++c) sums[c] = space.sum[c][k];
  }
}

}  // namespace facetfit
