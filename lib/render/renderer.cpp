#include "render/renderer.h"

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>
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
#include "render/environment_batch.h"
#include "render/shading_batch.h"
#include "render/texture.h"
#include "render/tracer.h"

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
  std::vector<int> object_material;  // per object
  for (const ObjectDesc& o : desc.objects) object_material.push_back(material_index.at(o.material));

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

  // Shading at a hit is planned, sampled, evaluated, then finished. plan() draws the light directions of
  // the shadow rays and queues, per material, the BRDF sample directions to draw; sample() draws them;
  // evaluate() makes the evaluations of f (and the density) every shadow ray's value needs; finish() turns
  // each into its shadow ray and value. The middle steps are one call per material, in SIMD lanes (GGX, LUT, MERL),
  // for one sample on the one-ray path and for a whole tile on the stream path; a model without lanes is
  // sampled and evaluated inside plan().
  struct Request {
    // none: a BRDF sample that found no direction.
    enum class Kind : std::uint8_t { environment_light, brdf_sample, light, pending_sample, none };
    Kind kind;
    std::uint32_t material;  // whose batches
    std::size_t slot;        // of its evaluation (pending_sample: of its direction)
    Vec3 d;                  // the shadow ray's direction and length
    double tfar;
    double cos_i;            // of the light direction in the local frame
    Rgb radiance;            // what arrives along d if nothing blocks it
    double light_pdf;        // the environment's density of d, for multiple importance sampling
    // Built in place (emplace_back), as a Ray (render/tracer.h).
    Request(Kind k, int m, std::size_t s, const Vec3& direction, double length, double cosine, const Rgb& arriving, double density)
        : kind(k), material(std::uint32_t(m)), slot(s), d(direction), tfar(length), cos_i(cosine), radiance(arriving), light_pdf(density) {}
  };
  // The value of a shadow ray if nothing blocks it, from the evaluation at its direction (cosine cos_i in
  // the local frame), the radiance arriving along it and the environment's density there; none for a BRDF
  // sample of zero density (as ShadingModel::sample).
  const auto shadow_value = [](typename Request::Kind kind, const ShadingModel::Evaluation& e, double cos_i, const Rgb& radiance,
                               double light_pdf) -> std::optional<Rgb> {
    switch (kind) {
      case Request::Kind::environment_light: return e.f * radiance * (cos_i * power_heuristic(light_pdf, e.pdf) / light_pdf);
      case Request::Kind::brdf_sample:
        if (!(e.pdf > 0.0)) return std::nullopt;
        return e.f * (cos_i / e.pdf) * radiance * power_heuristic(e.pdf, light_pdf);
      case Request::Kind::light: return e.f * radiance * cos_i;
      case Request::Kind::pending_sample:
      case Request::Kind::none: break;
    }
    return std::nullopt;
  };
  // Per sample: what shading found, the requests [first, last) it made and its shadow rays [ray_first,
  // ray_last), made by plan() where it evaluated at once (`deferred` false) and by finish() otherwise.
  struct Planned {
    Rgb radiance;
    double alpha;
    Vec3 p, o;  // the hit and the direction toward the camera in its local frame (set by place())
    Vec3 origin;
    Frame frame{Vec3(0.0, 0.0, 1.0)};
    std::size_t first, last;
    std::size_t ray_first, ray_last;
    bool deferred;
  };
  struct Shading {
    // Per material.
    std::vector<SampleBatch> samples;
    std::vector<EvaluationBatch> evaluations;
    std::vector<Request> requests;
    // plan()'s textured lobe and model, while it shades one hit.
    std::optional<TabulatedMicrofacet> textured_lobe;
    std::optional<TabulatedAnisotropic> textured_anisotropic;
    std::optional<ShadingModel> textured;
    explicit Shading(std::size_t materials) : samples(materials), evaluations(materials) {}
    void clear() {
      for (SampleBatch& b : samples) b.clear();
      for (EvaluationBatch& b : evaluations) b.clear();
      requests.clear();
    }
  };
  const double infinity = std::numeric_limits<double>::infinity();

  // The camera ray's hit, its shading frame and the shadow rays' origin. Apart from plan(): on the stream
  // path a loop of its own over the tile, whose square roots and divisions overlap from one hit to the next
  // (inside plan() each waited on the last: perf put 11% of a GGX render on them).
  const auto place = [&](const Hit& hit, const Vec3& dir, Planned& planned) {
    if (!hit.found()) return;
    const ObjectDesc& object = desc.objects[std::size_t(hit.object)];
    const Vec3 p = cam.position + hit.t * dir;
    Vec3 n = object.kind == ObjectDesc::Kind::sphere ? glm::normalize(p - object.center) : glm::normalize(hit.ng);
    if (glm::dot(n, dir) > 0.0) n = -n;  // shade the side the camera sees
    const std::optional<Vec3>& tangent = tangents[std::size_t(object_material[std::size_t(hit.object)])];
    planned.frame = tangent ? Frame(n, *tangent) : Frame(n);
    planned.p = p;
    planned.o = planned.frame.to_local(-dir);
    planned.origin = p + eps * n;
  };
  // Plans the camera ray's hit, placed by place(), with u[2..6]; `light_d`, where not null, is the
  // environment's sample drawn with u[2..3] beforehand (a constant environment's, in SIMD lanes on the
  // stream path).
  const auto plan = [&](const Hit& hit, const Vec3& dir, const double* u, const Vec3* light_d, Shading& shading, Planned& planned,
                        std::vector<Ray>& rays, std::vector<Rgb>& values) {
    planned.radiance = Rgb(0.0);
    planned.alpha = 1.0;
    planned.first = planned.last = shading.requests.size();
    planned.ray_first = planned.ray_last = rays.size();
    planned.deferred = false;
    if (!hit.found()) {
      planned.radiance = env ? env->radiance(dir) : Rgb(0.0);
      planned.alpha = 0.0;
      return;
    }
    const ObjectDesc& object = desc.objects[std::size_t(hit.object)];
    const int material = object_material[std::size_t(hit.object)];
    const Vec3 p = planned.p, o = planned.o;
    const Frame& frame = planned.frame;
    // A stretch_texture reshapes the lobe here: a copy sharing its tables, held in the tile's scratch
    // space (the shading model refers to it without owning it). Not a local: GCC cleared the empty
    // optionals' 216 bytes at every hit (perf: 8% of plan() on a GGX sphere).
    std::optional<TabulatedMicrofacet>& textured_lobe = shading.textured_lobe;
    std::optional<TabulatedAnisotropic>& textured_anisotropic = shading.textured_anisotropic;
    std::optional<ShadingModel>& textured = shading.textured;
    textured.reset();
    if (const auto& st = stretch_textures[std::size_t(material)]) {
      const Rgb scale = st->texture.lookup(texture_coordinates(object, p));
      const auto clamped = [](double a, double b) { return clamp(a * b, Stretch::kMin, Stretch::kMax); };
      const Stretch stretch(clamped(st->stretch.x, scale.r), clamped(st->stretch.y, scale.g), st->stretch.rotation());
      const auto unowned = [](const auto& lobe) { return std::shared_ptr<const std::decay_t<decltype(lobe)>>(std::shared_ptr<void>(), &lobe); };
      if (st->lobe) {
        const auto lobe = unowned(textured_lobe.emplace(st->lobe->stretched(stretch)));
        textured.emplace(lobe, lobe);
      } else {
        const auto lobe = unowned(textured_anisotropic.emplace(st->anisotropic->stretched(stretch)));
        textured.emplace(lobe, lobe);
      }
    }
    const ShadingModel& model = textured ? *textured : *materials[std::size_t(material)];
    // Evaluated and sampled at once, its shadow rays made here: a lobe textured here (this call owns it),
    // and a model without SIMD lanes (queuing its work would only add the queue's cost: 6% more
    // instructions on a LUT sphere).
    const bool at_once = textured || !model.has_lanes();
    planned.deferred = !at_once;
    const auto request = [&](typename Request::Kind kind, const Vec3& i, const Vec3& d, double tfar, const Rgb& radiance,
                             double light_pdf) {
      const bool density = kind != Request::Kind::light;
      if (at_once) {
        if (const auto value = shadow_value(kind, model.eval(o, i, density), i.z, radiance, light_pdf)) {
          rays.emplace_back(planned.origin, d, eps, tfar);
          values.push_back(*value);
        }
        return;
      }
      const std::size_t slot = shading.evaluations[std::size_t(material)].push(o, i, density);
      shading.requests.emplace_back(kind, material, slot, d, tfar, i.z, radiance, light_pdf);
    };
    if (env && o.z > 0.0) {
      // Light sampling, weighted against the BRDF's proposal.
      const Environment::Sample ls = light_d ? env->lookup(*light_d) : env->sample(u[0], u[1]);
      const Vec3 il = frame.to_local(ls.d);
      if (il.z > 0.0 && ls.pdf > 0.0) request(Request::Kind::environment_light, il, ls.d, infinity, ls.radiance, ls.pdf);
      // BRDF sampling, weighted against the environment's: drawn by sample() unless at once.
      if (!at_once) {
        const std::size_t slot = shading.samples[std::size_t(material)].push(o, u[2], u[3], u[4]);
        shading.requests.emplace_back(Request::Kind::pending_sample, material, slot, Vec3(0.0), infinity, 0.0, Rgb(0.0), 0.0);
      } else if (const auto i = model.sample_direction(o, u[2], u[3], u[4])) {
        const Environment::Sample e = env->lookup(frame.to_world(*i));  // its d: the world direction
        request(Request::Kind::brdf_sample, *i, e.d, infinity, e.radiance, e.pdf);
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
      if (il.z > 0.0 && o.z > 0.0) request(Request::Kind::light, il, d, dist, e, 0.0);
    }
    planned.last = shading.requests.size();
    planned.ray_last = rays.size();
  };
  // Draws the BRDF sample directions plan() queued, and queues their evaluations: in SIMD lanes where a
  // material has them, unless `simd` is false.
  const auto sample = [&](const std::vector<Planned>& planned, Shading& shading, bool simd) {
    bool any = false;  // a tile of models without lanes queued none: no pass over its requests
    for (std::size_t m = 0; m < materials.size(); ++m) {
      if (shading.samples[m].size() == 0) continue;
      materials[m]->sample_directions(shading.samples[m], simd);
      any = true;
    }
    if (!any) return;
    for (const Planned& p : planned)
      for (std::size_t q = p.first; q < p.last; ++q) {
        Request& r = shading.requests[q];
        if (r.kind != Request::Kind::pending_sample) continue;
        const SampleBatch& b = shading.samples[r.material];
        if (b.found[r.slot] == 0.0) {
          r.kind = Request::Kind::none;
          continue;
        }
        const Vec3 i = b.i(r.slot);
        r.kind = Request::Kind::brdf_sample;
        const Environment::Sample e = env->lookup(p.frame.to_world(i));
        r.d = e.d, r.radiance = e.radiance, r.light_pdf = e.pdf, r.cos_i = i.z;
        r.slot = shading.evaluations[r.material].push(b.o(r.slot), i);
      }
  };
  // Evaluates what plan() and sample() queued.
  const auto evaluate = [&](Shading& shading, bool simd) {
    for (std::size_t m = 0; m < materials.size(); ++m)
      if (shading.evaluations[m].size() > 0) materials[m]->eval(shading.evaluations[m], simd);
  };
  // Appends the shadow rays of a deferred sample and their values, in the order of its requests.
  const auto finish = [&](Planned& planned, const Shading& shading, std::vector<Ray>& rays, std::vector<Rgb>& values) {
    if (!planned.deferred) return;
    planned.ray_first = rays.size();
    for (std::size_t q = planned.first; q < planned.last; ++q) {
      const Request& r = shading.requests[q];
      if (r.kind == Request::Kind::none) continue;
      const EvaluationBatch& b = shading.evaluations[r.material];
      if (const auto value = shadow_value(r.kind, {b.f(r.slot), b.pdf[r.slot]}, r.cos_i, r.radiance, r.light_pdf)) {
        rays.emplace_back(planned.origin, r.d, eps, r.tfar);
        values.push_back(*value);
      }
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
  const auto accumulate = [](double* acc, Rgb radiance, double alpha) {
    if (!std::isfinite(radiance.r) || !std::isfinite(radiance.g) || !std::isfinite(radiance.b)) radiance = Rgb(0.0);
    acc[0] += radiance.r, acc[1] += radiance.g, acc[2] += radiance.b, acc[3] += alpha;
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
    std::vector<char> blocked;
    Shading shading(materials.size());
    std::vector<Planned> planned(1);
    for (int y = tile.rows().begin(); y < tile.rows().end(); ++y)
      for (int x = tile.cols().begin(); x < tile.cols().end(); ++x)
        for (int s = first; s < last; ++s) {
          double u[kSampleNumbers];
          sample_numbers(x, y, s, u);
          Ray ray;
          camera_ray(camera.direction(x, y, u[0], u[1]), ray);
          rays.clear(), values.clear(), blocked.clear();
          shading.clear();
          const Hit hit = tracer.intersect(ray);
          place(hit, ray.dir, planned[0]);
          plan(hit, ray.dir, u + 2, nullptr, shading, planned[0], rays, values);
          sample(planned, shading, false);
          evaluate(shading, false);
          finish(planned[0], shading, rays, values);
          for (const Ray& r : rays) blocked.push_back(tracer.occluded(r));
          add_unblocked(blocked, values, 0, rays.size(), planned[0].radiance);
          accumulate(pixel_accum(x, y), planned[0].radiance, planned[0].alpha);
        }
  };
  // Every pixel of the tile at once, one sample index after the other: camera rays, shading, then shadow
  // rays, as streams (Embree's for triangles; coherent camera rays travel together) and evaluations in
  // batches.
  const auto render_tile_streams = [&](const tbb::blocked_range2d<int>& tile, int first, int last) {
    const int tw = int(tile.cols().size()), count = tw * int(tile.rows().size());
    const std::size_t n = std::size_t(count);
    std::vector<Ray> cameras(n);
    std::vector<Hit> hits;
    std::vector<Planned> planned(n);
    std::vector<Ray> rays;
    std::vector<Rgb> values;
    std::vector<char> blocked;
    Shading shading(materials.size());
    // A constant environment's light samples, drawn in SIMD lanes for the whole tile.
    const bool sphere_lanes = env && env->is_constant();
    SphereSampleBatch light_samples;
    // At most two environment rays and one per light per sample: room for all from the start, so that the
    // first sample of a tile does not grow them piece by piece.
    const std::size_t most = n * (2 + desc.lights.size());
    shading.requests.reserve(most), rays.reserve(most), values.reserve(most), blocked.reserve(most);
    // Each pixel's coordinates and its part of the sequences once per tile; per sample index, the numbers
    // and camera rays of all in SIMD lanes.
    CameraSampleBatch samples;
    for (int k = 0; k < count; ++k) samples.push(tile.cols().begin() + k % tw, tile.rows().begin() + k / tw);
    for (int s = first; s < last; ++s) {
      camera_sample_batch(camera, seed, s, samples);
      for (std::size_t k = 0; k < n; ++k) camera_ray(samples.d(k), cameras[k]);
      tracer.intersect(cameras, hits, true);
      if (sphere_lanes) {
        light_samples.clear();
        for (std::size_t k = 0; k < n; ++k) light_samples.push(samples.u[2][k], samples.u[3][k]);
        sample_uniform_sphere_batch(light_samples);
      }
      for (std::size_t k = 0; k < n; ++k) place(hits[k], cameras[k].dir, planned[k]);
      shading.clear();
      rays.clear(), values.clear();
      for (std::size_t k = 0; k < n; ++k) {
        const Vec3 light_d = sphere_lanes ? light_samples.d(k) : Vec3(0.0);
        const double u[5] = {samples.u[2][k], samples.u[3][k], samples.u[4][k], samples.u[5][k], samples.u[6][k]};
        plan(hits[k], cameras[k].dir, u, sphere_lanes ? &light_d : nullptr, shading, planned[k], rays, values);
      }
      sample(planned, shading, true);
      evaluate(shading, true);
      for (Planned& p : planned) finish(p, shading, rays, values);
      tracer.occluded(rays, blocked);
      for (std::size_t k = 0; k < n; ++k) {
        add_unblocked(blocked, values, planned[k].ray_first, planned[k].ray_last, planned[k].radiance);
        accumulate(pixel_accum(int(samples.x[k]), int(samples.y[k])), planned[k].radiance, planned[k].alpha);
      }
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
    for (std::size_t k = 0; k < accum.size(); ++k) image.rgba[k] = float(accum[k] / done);
    if (settings.progress) settings.progress(pass + 1, passes);
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
