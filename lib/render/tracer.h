// The scene's geometry and its two ray queries: the closest hit, and whether anything blocks a segment.
//
// Spheres are intersected in closed form, in double precision; planes and meshes are triangles in an
// Embree scene, which is not built at all when a scene has none. Per shadow ray leaving a sphere, the
// closed form is several times faster than Embree's sphere primitive (BM_ShadowRay in bench/bench_fit.cpp).
// A scene holds a handful of spheres (look development: a subject, maybe a few props), so they are tested
// one after the other rather than through a hierarchy.
#pragma once

#include <limits>
#include <memory>
#include <vector>

#include "core/vec.h"
#include "render/scene.h"
#include "render/sphere_batch.h"

namespace facetfit {

struct Ray {
  Vec3 origin, dir;
  double tnear = 0.0;
  double tfar = std::numeric_limits<double>::infinity();
  Ray() = default;
  // A constructor rather than an aggregate, so that a vector builds a ray in place (emplace_back): a ray
  // built whole and copied in is written in 8-byte and read in 16-byte pieces, which stalls store
  // forwarding.
  Ray(const Vec3& o, const Vec3& d, double t0 = 0.0, double t1 = std::numeric_limits<double>::infinity())
      : origin(o), dir(d), tnear(t0), tfar(t1) {}
};

struct Hit {
  double t = std::numeric_limits<double>::infinity();
  int object = -1;  // index into SceneDesc::objects; -1: nothing
  Vec3 ng{0.0};     // triangles: the geometric normal, not normalized (spheres: unset)
  bool found() const { return object >= 0; }
};

// Hits of rays in columns (the stream path's camera rays): t (infinity for none), the object's index (-1
// for none) and, on a triangle, its geometric normal (not normalized; 0 on a sphere).
struct RayHits : Columns {
  std::vector<double> t, object, ngx, ngy, ngz;
  // n hits, written in place; columns padded as Columns has them.
  void resize_to(std::size_t n) {
    ensure(n, [this](std::size_t m) { resize({&t, &object, &ngx, &ngy, &ngz}, m, 0.0); });
    set_size(n);
  }
  Hit at(std::size_t k) const { return object[k] >= 0.0 ? Hit{t[k], int(object[k]), Vec3(ngx[k], ngy[k], ngz[k])} : Hit{}; }
};

// Nearest root t in (tnear, tfar) of |origin + t dir - center| = radius, or infinity. Written as
// Ray Tracing Gems I, ch. 7 recommends: the discriminant from the distance of the centre to the line and
// the smaller root from the larger one, which keeps both accurate for rays far from or grazing the sphere.
double intersect_sphere(const Vec3& center, double radius, const Ray& ray);

class Tracer {
 public:
  // Reads the scene's meshes (throws Error naming the file on a bad one, or on meshes that would take more
  // than `memory_budget` bytes together: mesh_bytes()).
  explicit Tracer(const SceneDesc& scene, std::uint64_t memory_budget = UINT64_MAX);
  ~Tracer();
  Tracer(const Tracer&) = delete;
  Tracer& operator=(const Tracer&) = delete;

  Hit intersect(const Ray& ray) const;
  bool occluded(const Ray& ray) const;
  // The same for many rays at once: triangles through Embree's ray streams (`coherent`: rays that travel
  // together, as camera rays do). Each result equals the one-ray query's up to Embree's float rounding.
  void intersect(const std::vector<Ray>& rays, std::vector<Hit>& hits, bool coherent) const;
  void occluded(const std::vector<Ray>& rays, std::vector<char>& blocked) const;
  // The same for rays in columns, the spheres in SIMD lanes (render/sphere_batch.h): what the renderer's
  // stream path asks.
  void intersect(const RayBatch& rays, RayHits& hits, bool coherent) const;
  void intersect(const RaysFromPoint& rays, RayHits& hits, bool coherent) const;
  void occluded(const RayBatch& rays, std::vector<char>& blocked) const;

 private:
  struct Sphere {
    Vec3 center;
    double radius;
    int object;
  };
  struct Embree;
  Hit nearest_sphere(const Ray& ray) const;
  template <class Rays, class RayAt>
  void nearest_hits(const Rays& rays, std::size_t n, const RayAt& ray_at, RayHits& hits, bool coherent) const;
  template <class RayAt>
  void add_triangle_hits(std::size_t n, const RayAt& ray_at, RayHits& hits, bool coherent) const;
  bool blocked_by_sphere(const Ray& ray) const;
  std::vector<Sphere> spheres_;
  SphereSet sphere_set_;  // the same spheres in columns, for the lanes
  std::unique_ptr<Embree> triangles_;  // null: no triangles in the scene
};

// Reads a Wavefront OBJ's vertices and faces (fans for polygons); throws Error naming the file and line, or
// naming the budget as soon as the mesh read so far would take more than `memory_budget` to render.
void read_obj(const std::string& path, std::vector<float>& positions, std::vector<unsigned>& indices,
              std::uint64_t memory_budget = UINT64_MAX);

// What a mesh of `vertices` and `triangles` takes to render: its arrays as read, Embree's copies and its BVH
// (about 108 bytes a triangle measured, maximum resident size, on a 1M-triangle grid).
std::uint64_t mesh_bytes(std::uint64_t vertices, std::uint64_t triangles);

}  // namespace facetfit
