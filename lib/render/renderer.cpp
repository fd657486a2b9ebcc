#include "render/renderer.h"

#include <tbb/blocked_range.h>
#include <tbb/blocked_range2d.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "core/error.h"
#include "core/frame.h"
#include "core/memory_budget.h"
#include "io/image_file.h"
#include "io/input.h"
#include "model/tabulated.h"
#include "model/tabulated_anisotropic.h"
#include "render/camera_batch.h"
#include "render/environment.h"
#include "render/shading_batch.h"
#include "render/texture.h"
#include "render/tracer.h"
#include "render/wavefront.h"

namespace facetfit {

namespace {

double power_heuristic(double a, double b) { return a * a / (a * a + b * b); }

// Texture coordinates of point p on a sphere (render/texture.h) or a plane (its square's axes, as its
// geometry is built below: 0 to 1 across it). Meshes carry none (the scene refuses textures on them).
TextureCoordinates texture_coordinates(const ObjectDesc& object, const Vec3& p) {
  if (object.kind == ObjectDesc::Kind::sphere) return sphere_texture_coordinates(glm::normalize(p - object.center));
  const Frame square(object.normal);
  return {glm::dot(p - object.point, square.t) / object.size + 0.5, glm::dot(p - object.point, square.b) / object.size + 0.5};
}

}  // namespace

RenderedImage render(const SceneDesc& desc, const RenderSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  // The image buffers (float RGBA, double accumulation, the RGB copy a caller takes) before anything loads;
  // the environment map gets what they leave.
  const std::uint64_t budget = settings.max_memory > 0 ? settings.max_memory : default_memory_budget();
  const std::uint64_t image_bytes = std::uint64_t(desc.camera.width) * std::uint64_t(desc.camera.height) * (16u + 32u + 12u);
  check_memory("render", "a " + std::to_string(desc.camera.width) + " x " + std::to_string(desc.camera.height) + " image",
               image_bytes, budget);
  // Only what the scene uses is loaded.
  std::vector<std::shared_ptr<const ShadingModel>> materials;
  std::vector<std::optional<Vec3>> tangents;  // per material: the world direction its tangent follows
  // Per material with a stretch_texture: the texture, and the tabulated lobe it stretches per point (the
  // isotropic or the anisotropic one).
  struct StretchTexture {
    Texture texture;
    const TabulatedMicrofacet* lobe;
    const TabulatedAnisotropic* anisotropic;
    Stretch stretch;
  };
  std::vector<std::optional<StretchTexture>> stretch_textures;
  std::uint64_t left = budget - image_bytes;  // for the textures and the environment map together
  // An error in a file the scene references names the key that referenced it, after the file's own line.
  const auto referenced_by = [&desc](const std::string& key, const auto& load) {
    try {
      return load();
    } catch (const Error& e) {
      throw Error(std::string(e.what()) + " (" + key + (desc.source.empty() ? "" : " in " + desc.source) + ")");
    }
  };
  std::map<std::string, int> material_index;
  for (const ObjectDesc& o : desc.objects) {
    if (material_index.count(o.material)) continue;
    material_index[o.material] = int(materials.size());
    const MaterialDesc& m = desc.materials.at(o.material);
    materials.push_back(referenced_by("material \"" + o.material + "\"", [&] { return load_material(desc, m); }));
    tangents.push_back(m.tangent);
    stretch_textures.emplace_back();
    if (!m.stretch_texture.empty()) {
      const auto* lobe = dynamic_cast<const TabulatedMicrofacet*>(&materials.back()->brdf());
      const auto* anisotropic = dynamic_cast<const TabulatedAnisotropic*>(&materials.back()->brdf());
      if (!lobe && !anisotropic) fail(m.file, "a stretch_texture needs a tabulated lobe");
      stretch_textures.back() = StretchTexture{
          referenced_by("material \"" + o.material + "\" stretch_texture", [&] { return Texture::load(resolve(desc, m.stretch_texture), left); }),
          lobe, anisotropic, m.stretch};
      left -= stretch_textures.back()->texture.bytes();
    }
  }
  std::optional<Environment> env;
  switch (desc.environment.kind) {
    case EnvironmentDesc::Kind::none: break;
    case EnvironmentDesc::Kind::builtin_sky: env = Environment::sky(); break;
    case EnvironmentDesc::Kind::constant: env = Environment::constant(desc.environment.constant * desc.environment.scale); break;
    case EnvironmentDesc::Kind::file: {
      Environment loaded = referenced_by("environment file", [&] { return Environment::load(resolve(desc, desc.environment.file), left); });
      if (desc.environment.scale != 1.0) {
        std::vector<float> px = loaded.pixels();
        for (float& v : px) v *= float(desc.environment.scale);
        loaded = Environment::from_pixels(loaded.width(), loaded.height(), std::move(px));
      }
      env = std::move(loaded);
      break;
    }
  }

  const Tracer tracer = referenced_by("a mesh object", [&] { return Tracer(desc); });
  // Per object: its material, and what the lanes read of it per hit (its material where the lanes shade
  // it, set below; a sphere's centre and the reciprocal of its radius, 0 for a mesh), so that the tile loop
  // does not reach into the scene's description.
  std::vector<int> object_material;
  LaneObjects objects;
  for (const ObjectDesc& o : desc.objects) {
    object_material.push_back(material_index.at(o.material));
    const bool sphere = o.kind == ObjectDesc::Kind::sphere;
    const Vec3 c = sphere ? o.center : Vec3(0.0);
    objects.cx.push_back(c.x), objects.cy.push_back(c.y), objects.cz.push_back(c.z), objects.inv_radius.push_back(sphere ? 1.0 / o.radius : 0.0);
  }

  const CameraDesc& cam = desc.camera;
  const int width = cam.width, height = cam.height;
  const int spp = settings.spp > 0 ? settings.spp : desc.spp;
  const std::uint64_t seed = settings.seed > 0 ? settings.seed : desc.seed;
  PinholeCamera camera;
  camera.position = cam.position;
  camera.forward = glm::normalize(cam.look_at - cam.position);
  camera.right = glm::normalize(glm::cross(camera.forward, cam.up));
  camera.up = glm::cross(camera.right, camera.forward);
  camera.tan_half = std::tan(0.5 * cam.fov_degrees * kPi / 180.0), camera.aspect = double(width) / height;
  camera.to_sx = 2.0 / width, camera.to_sy = 2.0 / height;
  double scene_scale = 1.0;
  for (const ObjectDesc& o : desc.objects) scene_scale = std::max({scene_scale, glm::length(o.center) + o.radius, o.size});
  // Shadow rays start off the surface and ignore hits closer than this: Embree intersects triangles in
  // float, and a ray leaving a surface at a grazing angle can otherwise find the surface it starts on.
  const double eps = 2e-4 * scene_scale;

  // A sample is traced in three stages shared by both paths below: its camera ray; shading at the hit,
  // which yields the radiance no visibility test can change and the shadow rays whose value counts if
  // nothing blocks them; the shadow rays. The one-ray-at-a-time path runs them per sample, the stream
  // path per tile, through the tracer's streams. Each sample draws its seven numbers before its camera ray
  // and sums its shadow rays in the same order either way, so both give the same image.
  // Written into its place, not copied in (see Ray in render/tracer.h).
  const auto camera_ray = [&](const Vec3& dir, Ray& ray) {
    ray.origin = cam.position, ray.dir = dir;
    ray.tnear = 0.0, ray.tfar = std::numeric_limits<double>::infinity();
  };

  // Shading at a hit yields its shadow rays and their values, in slot order: the environment's light
  // sample and a BRDF sample (each weighted against the other by multiple importance sampling), then each
  // light. A constant environment is lit by the BRDF sample alone: a light sample, uniform over the sphere,
  // adds nothing the BRDF's proposal does not already draw better (every model's proposal holds the
  // cosine, so the estimate stays unbiased), and weighted against it, it added noise (docs/render-speed.md).
  // plan() makes them for one hit, evaluating one pair at a time: the one-ray path for every hit,
  // the stream path for a lobe textured per hit and for models without SIMD lanes (queuing their work
  // would only add the queue's cost). The stream path makes the slots of a tile's other hits material by
  // material in SIMD lanes (render/wavefront.h).
  struct Planned {
    Rgb radiance;
    double alpha;
    Vec3 p, o;  // the hit and the direction toward the camera in its local frame (set by place())
    Vec3 origin;
    Frame frame{Vec3(0.0, 0.0, 1.0)};
    std::size_t ray_first, ray_last;  // plan()'s shadow rays
  };
  // plan()'s textured lobe and model, while it shades one hit: in the tile's scratch space, not locals
  // (GCC cleared the empty optionals' 216 bytes at every hit: perf, 8% of plan() on a GGX sphere).
  struct Textured {
    std::optional<TabulatedMicrofacet> lobe;
    std::optional<TabulatedAnisotropic> anisotropic;
    std::optional<ShadingModel> model;
  };
  const double infinity = std::numeric_limits<double>::infinity();
  // Whether the environment gets a light sample per hit (a map), or the BRDF sample alone (constant).
  const bool light_sampled = env && !env->is_constant();
  // A constant environment's radiance in every direction (the lanes' BRDF samples take it); zero otherwise,
  // where the lanes' BRDF samples look the map up.
  const Rgb constant_radiance = env && env->is_constant() ? env->radiance(Vec3(0.0, 0.0, 1.0)) : Rgb(0.0);
  // The radiance of a ray that hits nothing.
  const auto background = [&](const Vec3& dir) { return light_sampled ? env->radiance(dir) : constant_radiance; };
  const unsigned numbers_read = sample_numbers_read(env.has_value(), light_sampled);
  // Per material: whether the stream path shades its hits in lanes.
  std::vector<char> in_lanes;
  for (std::size_t m = 0; m < materials.size(); ++m) in_lanes.push_back(materials[m]->has_lanes() && !stretch_textures[m]);
  bool one_at_a_time = false;  // whether some object's hits are shaded by plan()
  for (const int m : object_material) {
    objects.material.push_back(in_lanes[std::size_t(m)] ? double(m) : -1.0);
    one_at_a_time = one_at_a_time || !in_lanes[std::size_t(m)];
  }
  std::vector<LaneLight> lane_lights;
  bool point_lights = false;  // whether the lanes' hits need their positions
  for (const LightDesc& light : desc.lights) {
    lane_lights.push_back({light.kind == LightDesc::Kind::directional, light.vector.x, light.vector.y, light.vector.z, light.value.r,
                           light.value.g, light.value.b});
    point_lights = point_lights || light.kind != LightDesc::Kind::directional;
  }

  // The camera ray's hit, its shading frame and the shadow rays' origin; the radiance of a ray that hits
  // nothing. On the stream path a loop of its own over the tile, whose square roots and divisions overlap
  // from one hit to the next (inside plan() each waited on the last: perf put 11% of a GGX render on them).
  const auto place = [&](const Hit& hit, const Vec3& dir, Planned& planned) {
    planned.radiance = Rgb(0.0);
    planned.alpha = 1.0;
    planned.ray_first = planned.ray_last = 0;
    if (!hit.found()) {
      planned.radiance = background(dir);
      planned.alpha = 0.0;
      return;
    }
    const Vec3 p = cam.position + hit.t * dir;
    // On a sphere p lies at its radius: (p - centre) / radius is the unit normal, as the lanes have it.
    const std::size_t o = std::size_t(hit.object);
    const double inv_radius = objects.inv_radius[o];
    Vec3 n = inv_radius != 0.0 ? (p - Vec3(objects.cx[o], objects.cy[o], objects.cz[o])) * inv_radius : glm::normalize(hit.ng);
    if (glm::dot(n, dir) > 0.0) n = -n;  // shade the side the camera sees
    const std::optional<Vec3>& tangent = tangents[std::size_t(object_material[std::size_t(hit.object)])];
    planned.frame = tangent ? Frame(n, *tangent) : Frame(n);
    planned.p = p;
    planned.o = planned.frame.to_local(-dir);
    planned.origin = p + eps * n;
  };
  // The shadow rays of a hit placed by place(), with u[2..6], and their values.
  const auto plan = [&](const Hit& hit, const double* u, Textured& textured, Planned& planned,
                        std::vector<Ray>& rays, std::vector<Rgb>& values) {
    planned.ray_first = planned.ray_last = rays.size();
    if (!hit.found()) return;
    const ObjectDesc& object = desc.objects[std::size_t(hit.object)];
    const int material = object_material[std::size_t(hit.object)];
    const Vec3 p = planned.p, o = planned.o;
    const Frame& frame = planned.frame;
    // A stretch_texture reshapes the lobe here: a copy sharing its tables (the shading model refers to it
    // without owning it).
    textured.model.reset();
    if (const auto& st = stretch_textures[std::size_t(material)]) {
      const Rgb scale = st->texture.lookup(texture_coordinates(object, p));
      const auto clamped = [](double a, double b) { return clamp(a * b, Stretch::kMin, Stretch::kMax); };
      const Stretch stretch(clamped(st->stretch.x, scale.r), clamped(st->stretch.y, scale.g), st->stretch.rotation());
      const auto unowned = [](const auto& lobe) { return std::shared_ptr<const std::decay_t<decltype(lobe)>>(std::shared_ptr<void>(), &lobe); };
      if (st->lobe) {
        const auto lobe = unowned(textured.lobe.emplace(st->lobe->stretched(stretch)));
        textured.model.emplace(lobe, lobe);
      } else {
        const auto lobe = unowned(textured.anisotropic.emplace(st->anisotropic->stretched(stretch)));
        textured.model.emplace(lobe, lobe);
      }
    }
    const ShadingModel& model = textured.model ? *textured.model : *materials[std::size_t(material)];
    const auto cast = [&](const Vec3& d, double tfar, const Rgb& value) {
      rays.emplace_back(planned.origin, d, eps, tfar);
      values.push_back(value);
    };
    if (env && o.z > 0.0) {
      // Light sampling of a map, weighted against the BRDF's proposal.
      if (light_sampled) {
        const Environment::Sample ls = env->sample(u[0], u[1]);
        const Vec3 il = frame.to_local(ls.d);
        if (il.z > 0.0 && ls.pdf > 0.0) {
          const ShadingModel::Evaluation e = model.eval(o, il, true);
          cast(ls.d, infinity, e.f * ls.radiance * (il.z * power_heuristic(ls.pdf, e.pdf) / ls.pdf));
        }
      }
      // BRDF sampling, weighted against the map's light sampling.
      if (const auto i = model.sample_direction(o, u[2], u[3], u[4])) {
        const Environment::Sample at = env->lookup(frame.to_world(*i));  // its d: the world direction
        const ShadingModel::Evaluation e = model.eval(o, *i, true);
        if (e.pdf > 0.0) cast(at.d, infinity, e.f * (i->z / e.pdf) * at.radiance * (light_sampled ? power_heuristic(e.pdf, at.pdf) : 1.0));
      }
    }
    for (const LightDesc& light : desc.lights) {
      Vec3 d;
      double dist = infinity;
      Rgb e = light.value;
      if (light.kind == LightDesc::Kind::directional) {
        d = light.vector;
      } else {
        const Vec3 to = light.vector - p;
        dist = glm::length(to);
        d = to / dist;
        e /= dist * dist;
        dist *= 1.0 - 1e-6;
      }
      const Vec3 il = frame.to_local(d);
      if (il.z > 0.0 && o.z > 0.0) cast(d, dist, model.eval(o, il, false).f * e * il.z);
    }
    planned.ray_last = rays.size();
  };
  // The radiance of shadow rays [first, last) that nothing blocks, added in order.
  const auto add_unblocked = [](const std::vector<char>& blocked, const std::vector<Rgb>& values, std::size_t first,
                                std::size_t last, Rgb& radiance) {
    for (std::size_t q = first; q < last; ++q)
      if (!blocked[q]) radiance += values[q];
  };
  // The numbers of sample s of pixel (x, y) (render/camera_batch.h): independent of passes, tiles, threads
  // and paths.
  const auto sample_numbers = [&](int x, int y, int s, double u[kSampleNumbers]) {
    const std::uint64_t sequence = SampleSequence::start(seed, SampleSequence::pixel_key(x, y), s);
    for (int k = 0; k < kSampleNumbers; ++k) u[k] = SampleSequence::number(sequence, k);
  };
  // A sample added to a pixel's sums (r, g, b, alpha): a radiance that is not finite adds nothing (x - x
  // is 0 for a finite x, NaN otherwise). The stream path adds a tile's in lanes (add_samples: GCC left
  // this loop scalar, with a branch).
  const auto accumulate = [](double& r, double& g, double& b, double& a, double sr, double sg, double sb, double alpha) {
    const bool finite = (sr - sr) + (sg - sg) + (sb - sb) == 0.0;
    r += finite ? sr : 0.0, g += finite ? sg : 0.0, b += finite ? sb : 0.0, a += alpha;
  };

  RenderedImage image;
  image.width = width;
  image.height = height;
  image.spp = spp;
  image.rgba.assign(std::size_t(width) * height * 4, 0.0f);
  std::vector<double> accum(std::size_t(width) * height * 4, 0.0);
  const int passes = std::max(1, std::min(settings.passes, spp));
  const auto pixel_accum = [&](int x, int y) { return accum.data() + (std::size_t(y) * width + x) * 4; };

  // One ray at a time, and each evaluation one pair at a time: the reference the stream path must match.
  const auto render_tile_scalar = [&](const tbb::blocked_range2d<int>& tile, int first, int last) {
    std::vector<Ray> rays;
    std::vector<Rgb> values;
    Textured textured;
    Planned planned;
    for (int y = tile.rows().begin(); y < tile.rows().end(); ++y)
      for (int x = tile.cols().begin(); x < tile.cols().end(); ++x)
        for (int s = first; s < last; ++s) {
          double u[kSampleNumbers];
          sample_numbers(x, y, s, u);
          Ray ray;
          camera_ray(camera.direction(x, y, u[0], u[1]), ray);
          rays.clear(), values.clear();
          const Hit hit = tracer.intersect(ray);
          place(hit, ray.dir, planned);
          plan(hit, u + 2, textured, planned, rays, values);
          for (std::size_t q = 0; q < rays.size(); ++q)
            if (!tracer.occluded(rays[q])) planned.radiance += values[q];
          double* acc = pixel_accum(x, y);
          accumulate(acc[0], acc[1], acc[2], acc[3], planned.radiance.r, planned.radiance.g, planned.radiance.b, planned.alpha);
        }
  };
  // Per material shaded in lanes, a tile's hits for one sample index and their slots.
  struct Wave {
    HitBatch hits;
    ShadowBatch shadows;
    SlotRanges ranges;
    std::vector<char> blocked;  // per entry of shadows
  };
  // A thread's space for the tiles it renders, kept from tile to tile: allocated per tile, its columns'
  // pages were mapped and unmapped again and again, and unmapping stops the other threads (TLB shootdowns:
  // perf put 16% of a two-thread GGX render in the kernel).
  struct TileSpace {
    RayHits hits;
    std::vector<Planned> planned;
    std::vector<Ray> rays;
    std::vector<Rgb> values;  // of plan()'s rays
    std::vector<char> blocked;
    Textured textured;
    std::vector<Wave> waves;
    CameraSampleBatch samples;
    TileHits tile_hits;
    // Per pixel of the tile, in columns: one sample's radiance and alpha, and the pixel's sums (the image's,
    // read at the tile's start and written back at its end, so each sample adds to them in the same order
    // as on the one-ray path). Added in columns, not through Planned, so that the lanes' values land with
    // no branch and the sums run in SIMD (perf: a third of the tile loop's time was these additions).
    std::vector<double> radiance[3], alpha, sum[4];
    // The pixels shaded by plan() (models without lanes): their radiance is Planned's.
    std::vector<std::uint32_t> planned_pixels;
  };
  tbb::enumerable_thread_specific<TileSpace> tile_spaces;
  // Every pixel of the tile at once, one sample index after the other: camera rays, shading, then shadow
  // rays, as streams (Embree's for triangles; coherent camera rays travel together) and evaluations in
  // batches.
  const auto render_tile_streams = [&](const tbb::blocked_range2d<int>& tile, int first, int last) {
    const int tw = int(tile.cols().size()), count = tw * int(tile.rows().size());
    const std::size_t n = std::size_t(count);
    TileSpace& space = tile_spaces.local();
    RayHits& hits = space.hits;
    std::vector<Planned>& planned = space.planned;
    std::vector<Ray>& rays = space.rays;
    std::vector<Rgb>& values = space.values;
    std::vector<char>& blocked = space.blocked;
    Textured& textured = space.textured;
    std::vector<Wave>& waves = space.waves;
    TileHits& tile_hits = space.tile_hits;
    std::vector<std::uint32_t>& planned_pixels = space.planned_pixels;
    double* radiance[3];
    // Padded as the tile's columns, which take_hits() writes whole.
    const std::size_t padded_n = Columns::padded(n);
    for (int c = 0; c < 3; ++c) space.radiance[c].resize(padded_n), radiance[c] = space.radiance[c].data();
    space.alpha.resize(padded_n);
    double* const alpha = space.alpha.data();
    double* sum[4];
    for (int c = 0; c < 4; ++c) space.sum[c].resize(n), sum[c] = space.sum[c].data();
    planned.resize(n), waves.resize(materials.size());
    // At most two environment rays and one per light per sample: room for all from the start, so that the
    // first sample of a tile does not grow them piece by piece.
    const std::size_t most = n * (2 + desc.lights.size());
    rays.reserve(most), values.reserve(most), blocked.reserve(most);
    // Each pixel's coordinates and its part of the sequences once per tile; per sample index, the numbers
    // and camera rays of all in SIMD lanes.
    CameraSampleBatch& samples = space.samples;
    samples.clear();
    for (int k = 0; k < count; ++k) {
      const int x = tile.cols().begin() + k % tw, y = tile.rows().begin() + k / tw;
      samples.push(x, y);
      const double* acc = pixel_accum(x, y);
      for (int c = 0; c < 4; ++c) sum[c][k] = acc[c];
    }
    tile_hits.resize_to(n);
    tile_hits.dx = samples.dx.data(), tile_hits.dy = samples.dy.data(), tile_hits.dz = samples.dz.data();
    tile_hits.u1 = samples.u[4].data(), tile_hits.u2 = samples.u[5].data(), tile_hits.u3 = samples.u[6].data();
    tile_hits.light_sampled = light_sampled;
    for (int s = first; s < last; ++s) {
      camera_sample_batch(camera, seed, s, samples, SimdTarget::best, numbers_read);
      tracer.intersect(RaysFromPoint{cam.position, samples.dx.data(), samples.dy.data(), samples.dz.data(), n}, hits, true);
      rays.clear(), values.clear();
      // Each pixel's hit given to the lanes in the tile's columns, with alpha and the radiance of what no
      // shading changes (the environment seen past everything, as place() has it); then, where the scene
      // has them, the hits shaded here one at a time (materials without lanes) and the environment's
      // light samples.
      take_hits(hits, objects, constant_radiance, tile_hits, alpha, radiance);
      planned_pixels.clear();
      if (one_at_a_time || light_sampled)
        for (std::size_t k = 0; k < n; ++k) {
          if (hits.object[k] < 0.0) {
            if (light_sampled) {
              const Rgb seen = background(samples.d(k));
              for (int c = 0; c < 3; ++c) radiance[c][k] = seen[c];
            }
            continue;
          }
          const Hit hit = hits.at(k);
          if (!in_lanes[std::size_t(object_material[std::size_t(hit.object)])]) {
            Planned& pk = planned[k];
            place(hit, samples.d(k), pk);
            const double u[5] = {samples.u[2][k], samples.u[3][k], samples.u[4][k], samples.u[5][k], samples.u[6][k]};
            plan(hit, u, textured, pk, rays, values);
            alpha[k] = pk.alpha;
            planned_pixels.push_back(std::uint32_t(k));
          } else if (light_sampled) {
            const Environment::Sample ls = env->sample(samples.u[2][k], samples.u[3][k]);
            tile_hits.lx[k] = ls.d.x, tile_hits.ly[k] = ls.d.y, tile_hits.lz[k] = ls.d.z, tile_hits.light_pdf[k] = ls.pdf;
            tile_hits.light_r[k] = ls.radiance.r, tile_hits.light_g[k] = ls.radiance.g, tile_hits.light_b[k] = ls.radiance.b;
          }
        }
      for (std::size_t m = 0; m < materials.size(); ++m) {
        if (in_lanes[m])
          place_hits(tile_hits, cam.position, eps, double(m), tangents[m] ? &*tangents[m] : nullptr, point_lights, waves[m].hits);
        else
          waves[m].hits.clear();
      }
      for (std::size_t m = 0; m < materials.size(); ++m) {
        Wave& w = waves[m];
        if (w.hits.size() == 0) continue;
        light_slots(w.hits, lane_lights, eps, w.shadows, w.ranges);
        if (env) {
          materials[m]->sample_directions(w.hits.draws, true);
          const std::size_t brdf_begin = w.shadows.size();
          brdf_slots(w.hits, constant_radiance, eps, w.shadows);
          if (light_sampled)
            for (std::size_t e = brdf_begin; e < w.shadows.size(); ++e) {
              const Environment::Sample ls = env->lookup({w.shadows.rays.dx[e], w.shadows.rays.dy[e], w.shadows.rays.dz[e]});
              w.shadows.arriving_r[e] = ls.radiance.r, w.shadows.arriving_g[e] = ls.radiance.g, w.shadows.arriving_b[e] = ls.radiance.b;
              w.shadows.light_pdf[e] = ls.pdf;
            }
        }
        materials[m]->eval(w.shadows, true);
        shadow_values(w.shadows, w.ranges);
        tracer.occluded(w.shadows.rays, w.blocked);
      }
      tracer.occluded(rays, blocked);
      // The lanes' rays, added to their hits slot by slot: environment light, BRDF sample, lights, which is
      // each hit's order of slots. A blocked ray or one cast for nothing adds zero, with no branch (a pixel
      // has at most one entry per slot, so the additions of one slot do not wait on one another).
      for (const Wave& w : waves) {
        if (w.hits.size() == 0) continue;
        const ShadowBatch& b = w.shadows;
        const double* value[3] = {b.value_r.data(), b.value_g.data(), b.value_b.data()};
        // The value's bits and-ed with all ones or none: GCC made the choice a branch, mispredicted at the
        // edges of shadows and of the lit side.
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
              radiance[c][k] += v;
            }
          }
        };
        add(0, w.ranges.lights_begin);
        add(w.ranges.brdf_begin, b.size());
        add(w.ranges.lights_begin, w.ranges.brdf_begin);
      }
      for (const std::uint32_t k : planned_pixels) {
        Planned& pk = planned[k];
        if (pk.ray_last > pk.ray_first) add_unblocked(blocked, values, pk.ray_first, pk.ray_last, pk.radiance);
        for (int c = 0; c < 3; ++c) radiance[c][k] = pk.radiance[c];
      }
      add_samples(radiance, alpha, sum, n);
    }
    for (std::size_t k = 0; k < n; ++k) {
      double* acc = pixel_accum(int(samples.x[k]), int(samples.y[k]));
      for (int c = 0; c < 4; ++c) acc[c] = sum[c][k];
    }
  };

  int done = 0;
  for (int pass = 0; pass < passes; ++pass) {
    const int first = spp * pass / passes, last = spp * (pass + 1) / passes;
    tbb::parallel_for(tbb::blocked_range2d<int>(0, height, 16, 0, width, 16), [&](const tbb::blocked_range2d<int>& tile) {
      if (settings.ray_streams)
        render_tile_streams(tile, first, last);
      else
        render_tile_scalar(tile, first, last);
    });
    done = last;
    if (settings.progress) settings.progress(pass + 1, passes);
  }
  // The image once, at the end (the progress callback does not see it), over the threads.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, accum.size(), 1 << 14), [&](const tbb::blocked_range<std::size_t>& part) {
    for (std::size_t k = part.begin(); k < part.end(); ++k) image.rgba[k] = float(accum[k] / done);
  });
  // A radiance past float's range (lights or an environment scaled to 1e30 and more) is refused, never
  // written as an infinite pixel.
  const auto overflow = std::find_if(image.rgba.begin(), image.rgba.end(), [](float v) { return !std::isfinite(v); });
  if (overflow != image.rgba.end()) {
    const std::size_t p = std::size_t(overflow - image.rgba.begin()) / 4;
    fail(desc.source.empty() ? "render" : desc.source,
         "pixel (" + std::to_string(p % std::size_t(width)) + ", " + std::to_string(p / std::size_t(width)) +
             ") is brighter than an image holds (a float): the lights or the environment are too bright");
  }
  image.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return image;
}

std::vector<float> RenderedImage::rgb() const {
  std::vector<float> out(std::size_t(width) * height * 3);
  for (std::size_t p = 0; p < out.size() / 3; ++p)
    for (int c = 0; c < 3; ++c) out[3 * p + c] = rgba[4 * p + c];
  return out;
}

void write_exr(const std::string& path, const RenderedImage& image, const std::vector<std::pair<std::string, std::string>>& metadata) {
  ImageSpec spec(image.width, image.height, {"R", "G", "B", "A"});
  for (const auto& [k, v] : metadata) spec.set("facetfit:" + k, v);
  write_image_atomic(path, spec, image.rgba.data());
}

}  // namespace facetfit
