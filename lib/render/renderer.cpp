#include "render/renderer.h"

#include <OpenImageIO/imageio.h>
#include <embree3/rtcore.h>
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/error.h"
#include "core/memory_budget.h"
#include "io/image_file.h"
#include "io/input.h"
#include "model/tabulated.h"
#include "model/tabulated_anisotropic.h"
#include "render/environment.h"
#include "render/texture.h"

namespace facetfit {

namespace {

// SplitMix64: a counter-based generator, so each pixel's sequence depends on (seed, pixel) only.
struct Random {
  std::uint64_t state;
  double next() {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return double(z >> 11) * 0x1.0p-53;
  }
};

struct Frame {  // orthonormal basis around n (Duff et al. 2017)
  Vec3 t, b, n;
  explicit Frame(const Vec3& normal) : n(normal) {
    const double sign = std::copysign(1.0, n.z), a = -1.0 / (sign + n.z), c = n.x * n.y * a;
    t = Vec3(1.0 + sign * n.x * n.x * a, sign * c, -sign * n.x);
    b = Vec3(c, sign + n.y * n.y * a, -n.y);
  }
  // With its x axis along the projection of a given direction on the surface (an anisotropic lobe's axes
  // follow it); the frame above where that projection vanishes.
  Frame(const Vec3& normal, const Vec3& along) : Frame(normal) {
    const Vec3 projected = along - glm::dot(along, n) * n;
    const double len = glm::length(projected);
    if (!(len > 1e-9)) return;
    t = projected / len;
    b = glm::cross(n, t);
  }
  Vec3 to_local(const Vec3& v) const { return {glm::dot(v, t), glm::dot(v, b), glm::dot(v, n)}; }
  Vec3 to_world(const Vec3& v) const { return v.x * t + v.y * b + v.z * n; }
};

double power_heuristic(double a, double b) { return a * a / (a * a + b * b); }

struct EmbreeScene {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  ~EmbreeScene() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

struct Geometry {
  const ObjectDesc* object;
  int material;
};

// Texture coordinates of point p on a sphere (render/texture.h) or a plane (its square's axes, as its
// geometry is built below: 0 to 1 across it). Meshes carry none (the scene refuses textures on them).
TextureCoordinates texture_coordinates(const ObjectDesc& object, const Vec3& p) {
  if (object.kind == ObjectDesc::Kind::sphere) return sphere_texture_coordinates(glm::normalize(p - object.center));
  const Frame square(object.normal);
  return {glm::dot(p - object.point, square.t) / object.size + 0.5, glm::dot(p - object.point, square.b) / object.size + 0.5};
}

}  // namespace

void read_obj(const std::string& path, std::vector<float>& positions, std::vector<unsigned>& indices) {
  require_regular_file(path);  // /dev/zero is one endless line
  std::ifstream in(path);
  if (!in) fail(path, "cannot open mesh");
  std::string line;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    std::istringstream ls(line);
    std::string tag;
    ls >> tag;
    if (tag == "v") {
      double x, y, z;
      if (!(ls >> x >> y >> z)) fail(path, "line " + std::to_string(line_no) + ": bad vertex");
      positions.insert(positions.end(), {float(x), float(y), float(z)});
    } else if (tag == "f") {
      std::vector<unsigned> face;
      std::string corner;
      while (ls >> corner) {
        long k = std::strtol(corner.c_str(), nullptr, 10);  // "v", "v/t", "v/t/n", "v//n"
        const long count = long(positions.size() / 3);
        if (k < 0) k += count + 1;  // relative indices
        if (k < 1 || k > count) fail(path, "line " + std::to_string(line_no) + ": vertex index out of range");
        face.push_back(unsigned(k - 1));
      }
      if (face.size() < 3) fail(path, "line " + std::to_string(line_no) + ": face with fewer than 3 vertices");
      for (std::size_t c = 1; c + 1 < face.size(); ++c) indices.insert(indices.end(), {face[0], face[c], face[c + 1]});
    }
  }
  if (indices.empty()) fail(path, "no faces");
}

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
  std::map<std::string, int> material_index;
  for (const ObjectDesc& o : desc.objects) {
    if (material_index.count(o.material)) continue;
    material_index[o.material] = int(materials.size());
    const MaterialDesc& m = desc.materials.at(o.material);
    materials.push_back(load_material(desc, m));
    tangents.push_back(m.tangent);
    stretch_textures.emplace_back();
    if (!m.stretch_texture.empty()) {
      const auto* lobe = dynamic_cast<const TabulatedMicrofacet*>(&materials.back()->brdf());
      const auto* anisotropic = dynamic_cast<const TabulatedAnisotropic*>(&materials.back()->brdf());
      if (!lobe && !anisotropic) fail(m.file, "a stretch_texture needs a tabulated lobe");
      stretch_textures.back() = StretchTexture{Texture::load(resolve(desc, m.stretch_texture), left), lobe, anisotropic, m.stretch};
      left -= stretch_textures.back()->texture.bytes();
    }
  }
  std::optional<Environment> env;
  switch (desc.environment.kind) {
    case EnvironmentDesc::Kind::none: break;
    case EnvironmentDesc::Kind::builtin_sky: env = Environment::sky(); break;
    case EnvironmentDesc::Kind::constant: env = Environment::constant(desc.environment.constant * desc.environment.scale); break;
    case EnvironmentDesc::Kind::file: {
      Environment loaded = Environment::load(resolve(desc, desc.environment.file), left);
      if (desc.environment.scale != 1.0) {
        std::vector<float> px = loaded.pixels();
        for (float& v : px) v *= float(desc.environment.scale);
        loaded = Environment::from_pixels(loaded.width(), loaded.height(), std::move(px));
      }
      env = std::move(loaded);
      break;
    }
  }

  EmbreeScene es;
  es.device = rtcNewDevice("threads=0");
  if (!es.device) throw Error("embree: cannot create a device");
  es.scene = rtcNewScene(es.device);
  std::vector<Geometry> geometries;
  for (const ObjectDesc& o : desc.objects) {
    RTCGeometry g = nullptr;
    if (o.kind == ObjectDesc::Kind::sphere) {
      g = rtcNewGeometry(es.device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
      auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), 1));
      v[0] = float(o.center.x), v[1] = float(o.center.y), v[2] = float(o.center.z), v[3] = float(o.radius);
    } else {
      std::vector<float> p;
      std::vector<unsigned> idx;
      if (o.kind == ObjectDesc::Kind::plane) {
        const Frame f(o.normal);
        const double h = 0.5 * o.size;
        for (const auto& [a, b] : {std::pair{-h, -h}, {h, -h}, {h, h}, {-h, h}}) {
          const Vec3 q = o.point + a * f.t + b * f.b;
          p.insert(p.end(), {float(q.x), float(q.y), float(q.z)});
        }
        idx = {0, 1, 2, 0, 2, 3};
      } else {
        read_obj(resolve(desc, o.file), p, idx);
      }
      g = rtcNewGeometry(es.device, RTC_GEOMETRY_TYPE_TRIANGLE);
      auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), p.size() / 3));
      std::copy(p.begin(), p.end(), vb);
      auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), idx.size() / 3));
      std::copy(idx.begin(), idx.end(), ib);
    }
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(es.scene, g, unsigned(geometries.size()));
    rtcReleaseGeometry(g);
    geometries.push_back({&o, material_index.at(o.material)});
  }
  rtcCommitScene(es.scene);

  const CameraDesc& cam = desc.camera;
  const int width = cam.width, height = cam.height;
  const int spp = settings.spp > 0 ? settings.spp : desc.spp;
  const std::uint64_t seed = settings.seed > 0 ? settings.seed : desc.seed;
  const Vec3 forward = glm::normalize(cam.look_at - cam.position);
  const Vec3 right = glm::normalize(glm::cross(forward, cam.up));
  const Vec3 up = glm::cross(right, forward);
  const double tan_half = std::tan(0.5 * cam.fov_degrees * kPi / 180.0), aspect = double(width) / height;
  double scene_scale = 1.0;
  for (const ObjectDesc& o : desc.objects) scene_scale = std::max({scene_scale, glm::length(o.center) + o.radius, o.size});
  // Shadow rays start off the surface and ignore hits closer than this: Embree intersects in float, and
  // a ray leaving a sphere at a grazing angle can otherwise find the sphere it starts on.
  const double eps = 2e-4 * scene_scale;

  // A sample is traced in three stages shared by both paths below: its camera ray; shading at the hit,
  // which yields the radiance no visibility test can change and the shadow rays whose value counts if
  // nothing blocks them; the shadow rays. The one-ray-at-a-time path runs them per sample, the stream
  // path per tile, through Embree's ray streams. Each sample draws its seven numbers before its camera ray
  // and sums its shadow rays in the same order either way, so both give the same image.
  const auto camera_ray = [&](int x, int y, const double u[2], Vec3& dir) {
    const double sx = (2.0 * (x + u[0]) / width - 1.0) * tan_half * aspect;
    const double sy = (1.0 - 2.0 * (y + u[1]) / height) * tan_half;
    dir = glm::normalize(forward + sx * right + sy * up);
    RTCRayHit rh{};
    rh.ray.org_x = float(cam.position.x), rh.ray.org_y = float(cam.position.y), rh.ray.org_z = float(cam.position.z);
    rh.ray.dir_x = float(dir.x), rh.ray.dir_y = float(dir.y), rh.ray.dir_z = float(dir.z);
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = std::numeric_limits<float>::infinity();
    rh.ray.mask = 0xFFFFFFFFu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    return rh;
  };
  const auto shadow_ray = [&](const Vec3& origin, const Vec3& dir, double tfar) {
    RTCRay ray{};
    ray.org_x = float(origin.x), ray.org_y = float(origin.y), ray.org_z = float(origin.z);
    ray.dir_x = float(dir.x), ray.dir_y = float(dir.y), ray.dir_z = float(dir.z);
    ray.tnear = float(eps);
    ray.tfar = float(tfar);
    ray.mask = 0xFFFFFFFFu;
    return ray;
  };

  // Shades the camera ray's hit with u[2..6]: radiance and coverage, and appends the shadow rays and their
  // values (rtcOccluded sets tfar to -inf where something blocks the ray).
  const auto shade = [&](const RTCRayHit& rh, const Vec3& dir, const double* u, Rgb& radiance, double& alpha,
                         std::vector<RTCRay>& rays, std::vector<Rgb>& values) {
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
      radiance = env ? env->radiance(dir) : Rgb(0.0);
      alpha = 0.0;
      return;
    }
    radiance = Rgb(0.0);
    alpha = 1.0;
    const Geometry& geo = geometries[rh.hit.geomID];
    const Vec3 p = cam.position + double(rh.ray.tfar) * dir;
    Vec3 n = geo.object->kind == ObjectDesc::Kind::sphere ? glm::normalize(p - geo.object->center)
                                                          : glm::normalize(Vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z));
    if (glm::dot(n, dir) > 0.0) n = -n;  // shade the side the camera sees
    const std::optional<Vec3>& tangent = tangents[std::size_t(geo.material)];
    const Frame frame = tangent ? Frame(n, *tangent) : Frame(n);
    const Vec3 o = frame.to_local(-dir);
    // A stretch_texture reshapes the lobe here: a copy sharing its tables, owned by this call (the
    // shading model refers to it without owning it).
    std::optional<TabulatedMicrofacet> textured_lobe;
    std::optional<TabulatedAnisotropic> textured_anisotropic;
    std::optional<ShadingModel> textured;
    if (const auto& st = stretch_textures[std::size_t(geo.material)]) {
      const Rgb scale = st->texture.lookup(texture_coordinates(*geo.object, p));
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
    const ShadingModel& model = textured ? *textured : *materials[std::size_t(geo.material)];
    const Vec3 origin = p + eps * n;
    const auto visible_if_unblocked = [&](const Vec3& d, double tfar, const Rgb& value) {
      rays.push_back(shadow_ray(origin, d, tfar));
      values.push_back(value);
    };
    const double infinity = std::numeric_limits<float>::infinity();
    if (env && o.z > 0.0) {
      // Light sampling, weighted against the BRDF's proposal.
      const Environment::Sample ls = env->sample(u[0], u[1]);
      const Vec3 il = frame.to_local(ls.d);
      if (il.z > 0.0 && ls.pdf > 0.0) {
        const double w = power_heuristic(ls.pdf, model.pdf(o, il));
        visible_if_unblocked(ls.d, infinity, model.f(o, il) * ls.radiance * (il.z * w / ls.pdf));
      }
      // BRDF sampling, weighted against the environment's.
      if (const auto bs = model.sample(o, u[2], u[3], u[4])) {
        const Vec3 d = frame.to_world(bs->i);
        const Environment::Sample e = env->lookup(d);
        visible_if_unblocked(d, infinity, bs->weight * e.radiance * power_heuristic(bs->pdf, e.pdf));
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
      if (il.z > 0.0 && o.z > 0.0) visible_if_unblocked(d, dist, model.f(o, il) * e * il.z);
    }
  };
  // The radiance of shadow rays [first, last) that nothing blocks, added in order.
  const auto add_unblocked = [](const std::vector<RTCRay>& rays, const std::vector<Rgb>& values, std::size_t first,
                                std::size_t last, Rgb& radiance) {
    for (std::size_t q = first; q < last; ++q)
      if (!(rays[q].tfar < 0.0f)) radiance += values[q];
  };
  // The sequence of sample s of pixel (x, y): independent of passes, tiles, threads and paths.
  const auto sample_numbers = [&](int x, int y, int s, double u[7]) {
    Random rng{seed * 0x100000001B3ull ^ (std::uint64_t(y) * 73856093u + std::uint64_t(x) * 19349663u) * 0x9E3779B97F4A7C15ull ^
               std::uint64_t(s) << 40};
    for (int k = 0; k < 7; ++k) u[k] = rng.next();
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

  // One ray at a time.
  const auto render_tile_scalar = [&](const tbb::blocked_range2d<int>& tile, int first, int last) {
    std::vector<RTCRay> rays;
    std::vector<Rgb> values;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (int y = tile.rows().begin(); y < tile.rows().end(); ++y)
      for (int x = tile.cols().begin(); x < tile.cols().end(); ++x)
        for (int s = first; s < last; ++s) {
          double u[7];
          sample_numbers(x, y, s, u);
          Vec3 dir;
          RTCRayHit rh = camera_ray(x, y, u, dir);
          rtcIntersect1(es.scene, &ctx, &rh);
          Rgb radiance;
          double alpha;
          rays.clear(), values.clear();
          shade(rh, dir, u + 2, radiance, alpha, rays, values);
          for (RTCRay& ray : rays) rtcOccluded1(es.scene, &ctx, &ray);
          add_unblocked(rays, values, 0, rays.size(), radiance);
          accumulate(pixel_accum(x, y), radiance, alpha);
        }
  };
  // Every pixel of the tile at once, one sample index after the other: camera rays, then shadow rays, as
  // Embree ray streams (coherent camera rays travel together).
  const auto render_tile_streams = [&](const tbb::blocked_range2d<int>& tile, int first, int last) {
    const int tw = int(tile.cols().size()), count = tw * int(tile.rows().size());
    const std::size_t n = std::size_t(count);
    std::vector<RTCRayHit> hits(n);
    std::vector<Vec3> dirs(n);
    std::vector<double> numbers(n * 7);
    std::vector<Rgb> radiance(n);
    std::vector<double> alpha(n);
    std::vector<std::size_t> owned(n + 1);  // shadow rays of pixel k: [owned[k], owned[k + 1])
    std::vector<RTCRay> rays;
    std::vector<Rgb> values;
    for (int s = first; s < last; ++s) {
      for (int k = 0; k < count; ++k) {
        const int x = tile.cols().begin() + k % tw, y = tile.rows().begin() + k / tw;
        double* u = numbers.data() + std::size_t(k) * 7;
        sample_numbers(x, y, s, u);
        hits[std::size_t(k)] = camera_ray(x, y, u, dirs[std::size_t(k)]);
      }
      RTCIntersectContext coherent;
      rtcInitIntersectContext(&coherent);
      coherent.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
      rtcIntersect1M(es.scene, &coherent, hits.data(), unsigned(count), sizeof(RTCRayHit));
      rays.clear(), values.clear();
      for (int k = 0; k < count; ++k) {
        owned[std::size_t(k)] = rays.size();
        shade(hits[std::size_t(k)], dirs[std::size_t(k)], numbers.data() + std::size_t(k) * 7 + 2, radiance[std::size_t(k)],
              alpha[std::size_t(k)], rays, values);
      }
      owned[std::size_t(count)] = rays.size();
      RTCIntersectContext incoherent;
      rtcInitIntersectContext(&incoherent);
      if (!rays.empty()) rtcOccluded1M(es.scene, &incoherent, rays.data(), unsigned(rays.size()), sizeof(RTCRay));
      for (int k = 0; k < count; ++k) {
        add_unblocked(rays, values, owned[std::size_t(k)], owned[std::size_t(k) + 1], radiance[std::size_t(k)]);
        accumulate(pixel_accum(tile.cols().begin() + k % tw, tile.rows().begin() + k / tw), radiance[std::size_t(k)],
                   alpha[std::size_t(k)]);
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
  OIIO::ImageSpec spec(image.width, image.height, 4, OIIO::TypeDesc::FLOAT);
  spec.channelnames = {"R", "G", "B", "A"};
  spec.alpha_channel = 3;
  spec.attribute("compression", "zip");
  spec.attribute("oiio:ColorSpace", "Linear");
  for (const auto& [k, v] : metadata) spec.attribute("facetfit:" + k, v);
  write_image_atomic(path, spec, image.rgba.data());
}

}  // namespace facetfit
