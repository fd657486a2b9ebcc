#include "render/integrator.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/memory_budget.h"
#include "io/input.h"
#include "render/mis.h"

namespace facetfit {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Texture coordinates of point p on a sphere (render/texture.h) or a plane (its square's axes, as the
// tracer builds its geometry: 0 to 1 across it). Meshes carry none (the scene refuses textures on them).
TextureCoordinates texture_coordinates(const ObjectDesc& object, const Vec3& p) {
  if (object.kind == ObjectDesc::Kind::sphere) return sphere_texture_coordinates(glm::normalize(p - object.center));
  const Frame square(object.normal);
  return {glm::dot(p - object.point, square.t) / object.size + 0.5, glm::dot(p - object.point, square.b) / object.size + 0.5};
}

// An error in a file the scene references names the key that referenced it, after the file's own line.
template <typename Load>
auto referenced_by(const SceneDesc& desc, const std::string& key, const Load& load) {
  try {
    return load();
  } catch (const Error& e) {
    throw Error(std::string(e.what()) + " (" + key + (desc.source.empty() ? "" : " in " + desc.source) + ")");
  }
}

// The image buffers: float RGBA, double sums, and the RGB copy a caller takes.
std::uint64_t image_bytes(const CameraDesc& camera) {
  return std::uint64_t(camera.width) * std::uint64_t(camera.height) * (16u + 32u + 12u);
}

// The environment's radiance (lin_rec709) in the working space: L = M L_rec709.
Environment in_working_space(const Environment& env, const ColorMatrix& from_rec709) {
  if (env.is_constant()) return Environment::constant(from_rec709 * env.radiance(Vec3(0.0, 0.0, 1.0)));
  std::vector<float> px = env.pixels();
  convert_pixels(px.data(), px.size() / 3, 3, from_rec709);
  return Environment::from_pixels(env.width(), env.height(), std::move(px));
}

}  // namespace

Integrator::Integrator(const SceneDesc& desc, const RenderSettings& settings)
    : desc_(desc),
      settings_(settings),
      width_(desc.camera.width),
      height_(desc.camera.height),
      spp_(settings.spp > 0 ? settings.spp : desc.spp),
      seed_(settings.seed > 0 ? settings.seed : desc.seed) {
  // The image buffers before anything loads; the textures and the environment map get what they leave.
  const std::uint64_t budget = settings.max_memory > 0 ? settings.max_memory : default_memory_budget();
  check_memory("render", "a " + std::to_string(width_) + " x " + std::to_string(height_) + " image", image_bytes(desc.camera),
               budget);
  std::uint64_t memory_left = budget - image_bytes(desc.camera);
  for (LightDesc light : desc.lights) {
    light.value = desc.from_rec709 * light.value;
    lights_.push_back(light);
  }
  const std::map<std::string, int> material_index = LoadMaterials(memory_left);
  LoadEnvironment(memory_left);
  referenced_by(desc_, "a mesh object", [&] { return &tracer_.emplace(desc_, memory_left); });
  PlanObjects(material_index);
  PlanLanes();
  SetCamera();
  accum_.assign(std::size_t(width_) * std::size_t(height_) * 4, 0.0);
}

// Only the materials the objects use, each once, with its tangent and stretch texture.
std::map<std::string, int> Integrator::LoadMaterials(std::uint64_t& memory_left) {
  std::map<std::string, int> material_index;
  for (const ObjectDesc& o : desc_.objects) {
    if (material_index.count(o.material)) continue;
    material_index[o.material] = int(materials_.size());
    const MaterialDesc& m = desc_.materials.at(o.material);
    const std::string key = "material \"" + o.material + "\"";
    materials_.push_back(referenced_by(desc_, key, [&] { return load_material(desc_, m); }));
    tangents_.push_back(m.tangent);
    stretch_textures_.emplace_back();
    if (m.stretch_texture.empty()) continue;
    const auto* lobe = dynamic_cast<const TabulatedMicrofacet*>(&materials_.back()->brdf());
    const auto* anisotropic = dynamic_cast<const TabulatedAnisotropic*>(&materials_.back()->brdf());
    if (!lobe && !anisotropic) fail(m.file, "a stretch_texture needs a tabulated lobe");
    Texture texture = referenced_by(desc_, key + " stretch_texture",
                                    [&] { return Texture::load(resolve(desc_, m.stretch_texture), memory_left); });
    memory_left -= texture.bytes();
    stretch_textures_.back() = StretchTexture{std::move(texture), lobe, anisotropic, m.stretch};
  }
  return material_index;
}

void Integrator::LoadEnvironment(std::uint64_t& memory_left) {
  const EnvironmentDesc& e = desc_.environment;
  switch (e.kind) {
    case EnvironmentDesc::Kind::none: break;
    case EnvironmentDesc::Kind::builtin_sky: env_ = Environment::sky(); break;
    case EnvironmentDesc::Kind::constant: env_ = Environment::constant(e.constant * e.scale); break;
    case EnvironmentDesc::Kind::file: {
      Environment loaded = referenced_by(desc_, "environment file", [&] { return Environment::load(resolve(desc_, e.file), memory_left); });
      if (e.scale != 1.0) {
        std::vector<float> px = loaded.pixels();
        for (float& v : px) v *= float(e.scale);
        loaded = Environment::from_pixels(loaded.width(), loaded.height(), std::move(px));
      }
      env_ = std::move(loaded);
      break;
    }
  }
  if (env_ && desc_.working_space != kRec709Space) env_ = in_working_space(*env_, desc_.from_rec709);
  // A map gets a light sample per hit, weighted against the BRDF's by multiple importance sampling. A
  // constant environment is lit by the BRDF sample alone: a light sample, uniform over the sphere, adds
  // nothing the BRDF's proposal does not already draw better (every model's proposal holds the cosine, so
  // the estimate stays unbiased), and weighted against it, it adds noise (docs/render-speed.md).
  light_sampled_ = env_ && !env_->is_constant();
  constant_radiance_ = env_ && env_->is_constant() ? env_->radiance(Vec3(0.0, 0.0, 1.0)) : Rgb(0.0);
  numbers_read_ = sample_numbers_read(env_.has_value(), light_sampled_);
}

// Per object, its material and what the lanes read of it per hit (a sphere's centre and the reciprocal of
// its radius, 0 for a mesh), so that the tile loops do not reach into the scene's description.
void Integrator::PlanObjects(const std::map<std::string, int>& material_index) {
  for (const ObjectDesc& o : desc_.objects) {
    object_material_.push_back(material_index.at(o.material));
    const bool sphere = o.kind == ObjectDesc::Kind::sphere;
    const Vec3 c = sphere ? o.center : Vec3(0.0);
    objects_.cx.push_back(c.x), objects_.cy.push_back(c.y), objects_.cz.push_back(c.z);
    objects_.inv_radius.push_back(sphere ? 1.0 / o.radius : 0.0);
  }
}

// Which materials the stream path shades in lanes (a model with lanes and no per-hit texture), and the
// lights as the lanes read them.
void Integrator::PlanLanes() {
  for (std::size_t m = 0; m < materials_.size(); ++m) in_lanes_.push_back(materials_[m]->has_lanes() && !stretch_textures_[m]);
  for (const int m : object_material_) {
    objects_.material.push_back(in_lanes_[std::size_t(m)] ? double(m) : -1.0);
    one_at_a_time_ = one_at_a_time_ || !in_lanes_[std::size_t(m)];
  }
  for (const LightDesc& light : lights_) {
    lane_lights_.push_back({light.kind == LightDesc::Kind::directional, light.vector.x, light.vector.y, light.vector.z,
                            light.value.r, light.value.g, light.value.b});
    point_lights_ = point_lights_ || light.kind != LightDesc::Kind::directional;
  }
}

void Integrator::SetCamera() {
  const CameraDesc& cam = desc_.camera;
  camera_.position = cam.position;
  camera_.forward = glm::normalize(cam.look_at - cam.position);
  camera_.right = glm::normalize(glm::cross(camera_.forward, cam.up));
  camera_.up = glm::cross(camera_.right, camera_.forward);
  camera_.tan_half = std::tan(0.5 * cam.fov_degrees * kPi / 180.0), camera_.aspect = double(width_) / height_;
  camera_.to_sx = 2.0 / width_, camera_.to_sy = 2.0 / height_;
  double scene_scale = 1.0;
  for (const ObjectDesc& o : desc_.objects) scene_scale = std::max({scene_scale, glm::length(o.center) + o.radius, o.size});
  // Shadow rays start off the surface and ignore hits closer than this: Embree intersects triangles in
  // float, and a ray leaving a surface at a grazing angle can otherwise find the surface it starts on.
  eps_ = 2e-4 * scene_scale;
}

// The radiance of a ray that hits nothing.
Rgb Integrator::Background(const Vec3& dir) const { return light_sampled_ ? env_->radiance(dir) : constant_radiance_; }

// The camera ray's hit, its shading frame and the shadow rays' origin; the radiance of a ray that hits
// nothing. On the stream path a loop of its own over the tile, for the hits Plan() shades.
void Integrator::Place(const Hit& hit, const Vec3& dir, Planned& planned) const {
  planned.radiance = Rgb(0.0);
  planned.alpha = 1.0;
  planned.ray_first = planned.ray_last = 0;
  if (!hit.found()) {
    planned.radiance = Background(dir);
    planned.alpha = 0.0;
    return;
  }
  const Vec3 p = camera_.position + hit.t * dir;
  // On a sphere p lies at its radius: (p - centre) / radius is the unit normal, as the lanes have it.
  const std::size_t o = std::size_t(hit.object);
  const double inv_radius = objects_.inv_radius[o];
  Vec3 n = inv_radius != 0.0 ? (p - Vec3(objects_.cx[o], objects_.cy[o], objects_.cz[o])) * inv_radius : glm::normalize(hit.ng);
  if (glm::dot(n, dir) > 0.0) n = -n;  // shade the side the camera sees
  const std::optional<Vec3>& tangent = tangents_[std::size_t(object_material_[o])];
  planned.frame = tangent ? Frame(n, *tangent) : Frame(n);
  planned.p = p;
  planned.o = planned.frame.to_local(-dir);
  planned.origin = p + eps_ * n;
}

// The shadow rays of a hit placed by Place(), with u[0..4], and their values, in slot order: the
// environment's light sample and a BRDF sample, then each light.
void Integrator::Plan(const Hit& hit, const double* u, Textured& textured, Planned& planned, Shadows& shadows) const {
  planned.ray_first = planned.ray_last = shadows.rays.size();
  if (!hit.found()) return;
  const ShadingModel& model = ModelAt(hit, planned.p, textured);
  if (env_ && planned.o.z > 0.0) EnvironmentSlots(model, planned, u, shadows);
  LightSlots(model, planned, shadows);
  planned.ray_last = shadows.rays.size();
}

// The hit's material, or its lobe reshaped by a stretch_texture at p: a copy sharing the tables (the
// shading model refers to it without owning it).
const ShadingModel& Integrator::ModelAt(const Hit& hit, const Vec3& p, Textured& textured) const {
  const std::size_t material = std::size_t(object_material_[std::size_t(hit.object)]);
  textured.model.reset();
  const auto& st = stretch_textures_[material];
  if (!st) return *materials_[material];
  const Rgb scale = st->texture.lookup(texture_coordinates(desc_.objects[std::size_t(hit.object)], p));
  const auto clamped = [](double a, double b) { return clamp(a * b, Stretch::kMin, Stretch::kMax); };
  const Stretch stretch(clamped(st->stretch.x, scale.r), clamped(st->stretch.y, scale.g), st->stretch.rotation());
  const auto unowned = [](const auto& lobe) { return std::shared_ptr<const std::decay_t<decltype(lobe)>>(std::shared_ptr<void>(), &lobe); };
  if (st->lobe) {
    const auto lobe = unowned(textured.lobe.emplace(st->lobe->stretched(stretch)));
    return textured.model.emplace(lobe, lobe);
  }
  const auto lobe = unowned(textured.anisotropic.emplace(st->anisotropic->stretched(stretch)));
  return textured.model.emplace(lobe, lobe);
}

// The environment's slots (the lanes' twin: light_slots' map sample and brdf_slots, render/wavefront.h):
// a light sample of a map, weighted against the BRDF's proposal, and a BRDF sample, weighted against the
// map's light sampling (alone for a constant environment).
void Integrator::EnvironmentSlots(const ShadingModel& model, const Planned& planned, const double* u, Shadows& shadows) const {
  const Vec3& o = planned.o;
  const auto cast = [&](const Vec3& d, const Rgb& value) {
    shadows.rays.emplace_back(planned.origin, d, eps_, kInfinity);
    shadows.values.push_back(value);
  };
  if (light_sampled_) {
    const Environment::Sample ls = env_->sample(u[0], u[1]);
    const Vec3 il = planned.frame.to_local(ls.d);
    if (il.z > 0.0 && ls.pdf > 0.0) {
      const ShadingModel::Evaluation e = model.eval(o, il, true);
      cast(ls.d, e.f * ls.radiance * power_heuristic_factor(il.z, ls.pdf, e.pdf));
    }
  }
  if (const auto i = model.sample_direction(o, u[2], u[3], u[4])) {
    const Environment::Sample at = env_->lookup(planned.frame.to_world(*i));  // its d: the world direction
    const ShadingModel::Evaluation e = model.eval(o, *i, true);
    if (e.pdf > 0.0) cast(at.d, e.f * at.radiance * (light_sampled_ ? power_heuristic_factor(i->z, e.pdf, at.pdf) : i->z / e.pdf));
  }
}

// One slot per light that lights the hit's side (the lanes' twin: light_slots).
void Integrator::LightSlots(const ShadingModel& model, const Planned& planned, Shadows& shadows) const {
  const Vec3& o = planned.o;
  for (const LightDesc& light : lights_) {
    Vec3 d;
    double dist = kInfinity;
    Rgb e = light.value;
    if (light.kind == LightDesc::Kind::directional) {
      d = light.vector;
    } else {
      const Vec3 to = light.vector - planned.p;
      dist = glm::length(to);
      d = to / dist;
      e /= dist * dist;
      dist *= 1.0 - 1e-6;
    }
    const Vec3 il = planned.frame.to_local(d);
    if (il.z > 0.0 && o.z > 0.0) {
      shadows.rays.emplace_back(planned.origin, d, eps_, dist);
      shadows.values.push_back(model.eval(o, il, false).f * e * il.z);
    }
  }
}

// The numbers of sample s of pixel (x, y) (render/camera_batch.h): independent of passes, tiles, threads
// and paths.
void Integrator::SampleNumbers(int x, int y, int s, double* u) const {
  const std::uint64_t sequence = SampleSequence::start(seed_, SampleSequence::pixel_key(x, y), s);
  for (int k = 0; k < kSampleNumbers; ++k) u[k] = SampleSequence::number(sequence, k);
}

RenderedImage Integrator::Render() {
  const int passes = std::max(1, std::min(settings_.passes, spp_));
  int done = 0;
  for (int pass = 0; pass < passes; ++pass) {
    const int first = spp_ * pass / passes, last = spp_ * (pass + 1) / passes;
    tbb::parallel_for(Tile(0, height_, 16, 0, width_, 16), [&](const Tile& tile) {
      if (settings_.ray_streams)
        RenderTileStreams(tile, first, last);
      else
        RenderTileScalar(tile, first, last);
    });
    done = last;
    if (settings_.progress) settings_.progress(pass + 1, passes);
  }
  return Finish(done);
}

// The image from the sums of `done` samples per pixel, over the threads. A radiance past float's range
// (lights or an environment scaled to 1e30 and more) is refused, never written as an infinite pixel.
RenderedImage Integrator::Finish(int done) const {
  RenderedImage image;
  image.width = width_, image.height = height_, image.spp = spp_;
  image.colorspace = desc_.working_space, image.from_rec709 = desc_.from_rec709;
  image.rgba.assign(accum_.size(), 0.0f);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, accum_.size(), 1 << 14), [&](const tbb::blocked_range<std::size_t>& part) {
    for (std::size_t k = part.begin(); k < part.end(); ++k) image.rgba[k] = float(accum_[k] / done);
  });
  const auto overflow = std::find_if(image.rgba.begin(), image.rgba.end(), [](float v) { return !std::isfinite(v); });
  if (overflow != image.rgba.end()) {
    const std::size_t p = std::size_t(overflow - image.rgba.begin()) / 4;
    fail(desc_.source.empty() ? "render" : desc_.source,
         "pixel (" + std::to_string(p % std::size_t(width_)) + ", " + std::to_string(p / std::size_t(width_)) +
             ") is brighter than an image holds (a float): the lights or the environment are too bright");
  }
  return image;
}

}  // namespace facetfit
