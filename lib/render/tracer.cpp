#include "render/tracer.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "core/frame.h"
#include "core/memory_budget.h"
#include "io/input.h"

namespace facetfit {

double intersect_sphere(const Vec3& center, double radius, const Ray& ray) {
  const double inf = std::numeric_limits<double>::infinity();
  const Vec3 f = ray.origin - center;
  const double a = glm::dot(ray.dir, ray.dir), b = -glm::dot(f, ray.dir);  // half of the usual b, negated
  const double c = glm::dot(f, f) - radius * radius;
  // Starting outside and moving away, both roots are negative: every shadow ray leaving a sphere's lit
  // side ends here, without the square root.
  if (c > 0.0 && b <= 0.0 && ray.tnear >= 0.0) return inf;
  // r^2 - |f + (b/a) d|^2 = discriminant / a: the squared half-chord, from the point of the line nearest
  // the centre, instead of b^2 - ac, which cancels catastrophically far from the sphere.
  const Vec3 nearest = f + (b / a) * ray.dir;
  const double chord2 = radius * radius - glm::dot(nearest, nearest);
  if (!(chord2 >= 0.0)) return inf;
  const double q = b + std::copysign(std::sqrt(a * chord2), b);
  double t0 = q / a, t1 = q != 0.0 ? c / q : t0;  // the roots; the second from their product c / a
  if (t0 > t1) std::swap(t0, t1);
  if (t0 > ray.tnear && t0 < ray.tfar) return t0;
  if (t1 > ray.tnear && t1 < ray.tfar) return t1;
  return inf;
}

// The triangles: an Embree device and scene, and which object each of its geometries is.
struct Tracer::Embree {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<int> object;  // per geometry ID
  ~Embree() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

RTCRay embree_ray(const Ray& r) {
  RTCRay ray{};
  ray.org_x = float(r.origin.x), ray.org_y = float(r.origin.y), ray.org_z = float(r.origin.z);
  ray.dir_x = float(r.dir.x), ray.dir_y = float(r.dir.y), ray.dir_z = float(r.dir.z);
  ray.tnear = float(r.tnear);
  ray.tfar = std::isinf(r.tfar) ? std::numeric_limits<float>::infinity() : float(r.tfar);
  ray.mask = 0xFFFFFFFFu;
  return ray;
}

}  // namespace

std::uint64_t mesh_bytes(std::uint64_t vertices, std::uint64_t triangles) { return 24 * vertices + 96 * triangles; }

Tracer::Tracer(const SceneDesc& desc, std::uint64_t memory_budget) {
  for (std::size_t k = 0; k < desc.objects.size(); ++k) {
    const ObjectDesc& o = desc.objects[k];
    if (o.kind == ObjectDesc::Kind::sphere) {
      spheres_.push_back({o.center, o.radius, int(k)});
      sphere_set_.cx.push_back(o.center.x), sphere_set_.cy.push_back(o.center.y), sphere_set_.cz.push_back(o.center.z);
      sphere_set_.radius.push_back(o.radius), sphere_set_.id.push_back(double(spheres_.back().object));
      continue;
    }
    if (!triangles_) {
      triangles_ = std::make_unique<Embree>();
      triangles_->device = rtcNewDevice("threads=0");
      if (!triangles_->device) throw Error("embree: cannot create a device");
      triangles_->scene = rtcNewScene(triangles_->device);
    }
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
      read_obj(resolve(desc, o.file), p, idx, memory_budget);
    }
    // The meshes share the budget: what this one takes is not left for the next.
    memory_budget -= std::min(memory_budget, mesh_bytes(p.size() / 3, idx.size() / 3));
    RTCGeometry g = rtcNewGeometry(triangles_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), p.size() / 3));
    std::copy(p.begin(), p.end(), vb);
    auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), idx.size() / 3));
    std::copy(idx.begin(), idx.end(), ib);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(triangles_->scene, g, unsigned(triangles_->object.size()));
    rtcReleaseGeometry(g);
    triangles_->object.push_back(int(k));
  }
  if (triangles_) rtcCommitScene(triangles_->scene);
}

Tracer::~Tracer() = default;

// The nearest sphere in (tnear, tfar), and whether any sphere is there: what every query tests first.
Hit Tracer::nearest_sphere(const Ray& ray) const {
  Hit hit;
  Ray r = ray;
  for (const Sphere& s : spheres_) {
    const double t = intersect_sphere(s.center, s.radius, r);
    if (t < r.tfar) r.tfar = hit.t = t, hit.object = s.object;
  }
  return hit;
}

bool Tracer::blocked_by_sphere(const Ray& ray) const {
  for (const Sphere& s : spheres_)
    if (std::isfinite(intersect_sphere(s.center, s.radius, ray))) return true;
  return false;
}

namespace {

// Embree's query for the triangles nearer than `nearer` (the nearest sphere, or nothing), and its answer.
RTCRayHit embree_ray_hit(const Ray& ray, const Hit& nearer) {
  RTCRayHit rh{};
  Ray bounded = ray;
  bounded.tfar = std::min(ray.tfar, nearer.t);
  rh.ray = embree_ray(bounded);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  return rh;
}

void take_triangle_hit(const RTCRayHit& rh, const std::vector<int>& object, Hit& hit) {
  if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID)
    hit = Hit{double(rh.ray.tfar), object[rh.hit.geomID], Vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z)};
}

// Every ray of the columns (their padded size) finds nothing.
void miss_all(RayHits& hits) {
  std::fill_n(hits.t.begin(), hits.padded_size(), std::numeric_limits<double>::infinity());
  std::fill_n(hits.object.begin(), hits.padded_size(), -1.0);
}

}  // namespace

Hit Tracer::intersect(const Ray& ray) const {
  Hit hit = nearest_sphere(ray);
  if (triangles_) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh = embree_ray_hit(ray, hit);
    rtcIntersect1(triangles_->scene, &ctx, &rh);
    take_triangle_hit(rh, triangles_->object, hit);
  }
  return hit;
}

bool Tracer::occluded(const Ray& ray) const {
  if (blocked_by_sphere(ray)) return true;
  if (!triangles_) return false;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRay r = embree_ray(ray);
  rtcOccluded1(triangles_->scene, &ctx, &r);
  return r.tfar < 0.0f;  // Embree sets tfar to -inf where something blocks the ray
}

namespace {

RayBatch ray_batch(const std::vector<Ray>& rays) {
  RayBatch batch;
  for (const Ray& r : rays) batch.push(r.origin, r.dir, r.tnear, r.tfar);
  return batch;
}

Ray ray_at(const RayBatch& rays, std::size_t k) {
  return Ray(Vec3(rays.ox[k], rays.oy[k], rays.oz[k]), Vec3(rays.dx[k], rays.dy[k], rays.dz[k]), rays.tnear[k], rays.tfar[k]);
}

}  // namespace

void Tracer::intersect(const std::vector<Ray>& rays, std::vector<Hit>& hits, bool coherent) const {
  RayHits found;
  intersect(ray_batch(rays), found, coherent);
  hits.resize(rays.size());
  for (std::size_t k = 0; k < rays.size(); ++k) hits[k] = found.at(k);
}

void Tracer::occluded(const std::vector<Ray>& rays, std::vector<char>& blocked) const { occluded(ray_batch(rays), blocked); }

// The triangles nearer than the spheres' hits, through Embree's ray streams (no-op without triangles).
template <class RayAt>
void Tracer::add_triangle_hits(std::size_t n, const RayAt& ray_at, RayHits& hits, bool coherent) const {
  if (!triangles_ || n == 0) return;
  std::vector<RTCRayHit> rh(n);
  for (std::size_t k = 0; k < n; ++k) rh[k] = embree_ray_hit(ray_at(k), hits.at(k));
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  if (coherent) ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  rtcIntersect1M(triangles_->scene, &ctx, rh.data(), unsigned(rh.size()), sizeof(RTCRayHit));
  for (std::size_t k = 0; k < n; ++k) {
    Hit hit{hits.t[k], int(hits.object[k]), Vec3(0.0)};
    take_triangle_hit(rh[k], triangles_->object, hit);
    hits.t[k] = hit.t, hits.object[k] = double(hit.object), hits.ngx[k] = hit.ng.x, hits.ngy[k] = hit.ng.y, hits.ngz[k] = hit.ng.z;
  }
}

// The n rays' nearest hits: the spheres in lanes (nearest_spheres() of either kind of rays), then the
// triangles, the k-th ray as ray_at(k).
template <class Rays, class RayAt>
void Tracer::nearest_hits(const Rays& rays, std::size_t n, const RayAt& ray_at, RayHits& hits, bool coherent) const {
  hits.resize_to(n);
  if (!spheres_.empty()) {
    nearest_spheres(sphere_set_, rays, hits.t, hits.object);
  } else {
    miss_all(hits);
  }
  add_triangle_hits(n, ray_at, hits, coherent);
}

void Tracer::intersect(const RayBatch& rays, RayHits& hits, bool coherent) const {
  nearest_hits(rays, rays.size(), [&rays](std::size_t k) { return ray_at(rays, k); }, hits, coherent);
}

void Tracer::intersect(const RaysFromPoint& rays, RayHits& hits, bool coherent) const {
  nearest_hits(rays, rays.size, [&rays](std::size_t k) { return Ray(rays.origin, Vec3(rays.dx[k], rays.dy[k], rays.dz[k])); }, hits, coherent);
}

void Tracer::occluded(const RayBatch& rays, std::vector<char>& blocked) const {
  const std::size_t n = rays.size();
  blocked.assign(n, 0);
  if (!spheres_.empty()) blocked_by_spheres(sphere_set_, rays, blocked);
  if (!triangles_ || n == 0) return;
  // Only the rays no sphere blocks go to Embree.
  std::vector<RTCRay> open;
  std::vector<std::size_t> which;
  for (std::size_t k = 0; k < n; ++k)
    if (!blocked[k]) open.push_back(embree_ray(ray_at(rays, k))), which.push_back(k);
  if (open.empty()) return;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  rtcOccluded1M(triangles_->scene, &ctx, open.data(), unsigned(open.size()), sizeof(RTCRay));
  for (std::size_t q = 0; q < open.size(); ++q)
    if (open[q].tfar < 0.0f) blocked[which[q]] = 1;
}

void read_obj(const std::string& path, std::vector<float>& positions, std::vector<unsigned>& indices, std::uint64_t memory_budget) {
  const auto check_budget = [&] {  // at every line, as the file is read: a 21 MB file took 1.1 GB
    const std::uint64_t need = mesh_bytes(positions.size() / 3, indices.size() / 3);
    if (need > memory_budget) check_memory(path, "a mesh of " + std::to_string(indices.size() / 3) + " triangles so far", need, memory_budget);
  };
  require_regular_file(path);  // /dev/zero is one endless line
  std::ifstream in(path);
  if (!in) fail(path, "cannot open mesh");
  std::string line;
  std::size_t line_no = 0;
  // Lines are bounded as they are read: a file of NULs is one endless line (2 GiB of them took 6 GiB).
  constexpr std::streamsize kMaxLine = 1 << 16;
  while (in.peek() != std::char_traits<char>::eof()) {
    ++line_no;
    line.resize(std::size_t(kMaxLine));
    in.getline(line.data(), kMaxLine);
    if (in.fail() && !in.eof()) fail(path, "line " + std::to_string(line_no) + " is longer than 64 KiB");
    line.resize(std::size_t(std::max<std::streamsize>(in.gcount() - (in.eof() ? 0 : 1), 0)));
    in.clear(in.rdstate() & ~std::ios::failbit);
    std::istringstream ls(line);
    std::string tag;
    ls >> tag;
    if (tag == "v") {
      double x, y, z;
      if (!(ls >> x >> y >> z)) fail(path, "line " + std::to_string(line_no) + ": bad vertex");
      // The scene's coordinate limit (docs/scene-format.md): beyond it Embree's float arithmetic loses
      // the triangle, which then silently vanishes from the image.
      if (!(std::abs(x) <= 1e6 && std::abs(y) <= 1e6 && std::abs(z) <= 1e6))
        fail(path, "line " + std::to_string(line_no) + ": vertex coordinate outside +-1e6");
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
    check_budget();
  }
  if (indices.empty()) fail(path, "no faces");
  check_budget();
}

}  // namespace facetfit
