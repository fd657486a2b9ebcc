// The reference renderer's integrator (render/renderer.h is its entry point): direct lighting of the first
// hit, in named steps. The constructor loads and plans what the scene uses; Render() runs the passes over
// the tiles, each tile by one of two paths that give the same image:
//   - one ray and one evaluation at a time (integrator_scalar.cpp), the reference;
//   - a tile at a time, rays as streams and shading in SIMD lanes (integrator_streams.cpp).
// A sample is traced in three stages on both: its camera ray; shading at the hit, which yields the radiance
// no visibility test can change and the shadow rays whose value counts if nothing blocks them; the shadow
// rays. Each sample draws its numbers before its camera ray and sums its shadow rays in the same order on
// either path.
#pragma once

#include <tbb/blocked_range2d.h>
#include <tbb/enumerable_thread_specific.h>

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include "core/frame.h"
#include "model/tabulated.h"
#include "model/tabulated_anisotropic.h"
#include "render/camera_batch.h"
#include "render/environment.h"
#include "render/renderer.h"
#include "render/shading.h"
#include "render/texture.h"
#include "render/tracer.h"
#include "render/wavefront.h"

namespace facetfit {

class Integrator {
 public:
  // Loads the scene's environment and the materials its objects use, builds the tracer, and plans which
  // materials the stream path shades in lanes. Throws Error for anything it cannot load or hold.
  Integrator(const SceneDesc& desc, const RenderSettings& settings);

  RenderedImage Render();

  // One hit's shading, made one pair at a time (on the stream path: a lobe textured per hit, and models
  // without lanes).
  struct Planned {
    Rgb radiance;
    double alpha;
    Vec3 p, o;  // the hit and the direction toward the camera in its local frame (set by Place())
    Vec3 origin;
    Frame frame{Vec3(0.0, 0.0, 1.0)};
    std::size_t ray_first, ray_last;  // Plan()'s shadow rays
  };
  // A lobe reshaped by a stretch_texture at one hit, and its model: kept in a thread's scratch space, not
  // as locals (GCC cleared the empty optionals at every hit).
  struct Textured {
    std::optional<TabulatedMicrofacet> lobe;
    std::optional<TabulatedAnisotropic> anisotropic;
    std::optional<ShadingModel> model;
  };
  // Shadow rays and the values they carry if nothing blocks them, in slot order.
  struct Shadows {
    std::vector<Ray> rays;
    std::vector<Rgb> values;
  };

 private:
  // Per material with a stretch_texture: the texture, and the tabulated lobe it stretches per point.
  struct StretchTexture {
    Texture texture;
    const TabulatedMicrofacet* lobe;
    const TabulatedAnisotropic* anisotropic;
    Stretch stretch;
  };
  // Per material shaded in lanes, a tile's hits for one sample index and their slots.
  struct Wave {
    HitBatch hits;
    ShadowBatch shadows;
    SlotRanges ranges;
    std::vector<char> blocked;  // per entry of shadows
  };
  // A thread's space for the tiles it renders, kept from tile to tile (allocating it per tile mapped and
  // unmapped pages again and again, and unmapping stops the other threads).
  struct TileSpace {
    RayHits hits;
    std::vector<Planned> planned;
    Shadows shadows;  // of Plan()
    std::vector<char> blocked;
    Textured textured;
    std::vector<Wave> waves;
    CameraSampleBatch samples;
    TileHits tile_hits;
    // Per pixel of the tile, in columns: one sample's radiance and alpha, and the pixel's sums (read from
    // the image at the tile's start and written back at its end, so each sample adds to them in the same
    // order as on the one-ray path). Columns let the lanes' values land with no branch and the sums run in
    // SIMD.
    std::vector<double> radiance[3], alpha, sum[4];
    std::vector<std::uint32_t> planned_pixels;  // the pixels shaded by Plan(): their radiance is Planned's
  };
  using Tile = tbb::blocked_range2d<int>;

  // Construction.
  // `memory_left`: what the image buffers leave of the budget, for the textures and the environment map.
  // LoadMaterials returns each used material's index in materials_, by name.
  std::map<std::string, int> LoadMaterials(std::uint64_t& memory_left);
  void LoadEnvironment(std::uint64_t& memory_left);
  void PlanObjects(const std::map<std::string, int>& material_index);
  void PlanLanes();
  void SetCamera();

  // One hit, one pair at a time (integrator.cpp).
  Rgb Background(const Vec3& dir) const;
  void Place(const Hit& hit, const Vec3& dir, Planned& planned) const;
  void Plan(const Hit& hit, const double* u, Textured& textured, Planned& planned, Shadows& shadows) const;
  const ShadingModel& ModelAt(const Hit& hit, const Vec3& p, Textured& textured) const;
  void EnvironmentSlots(const ShadingModel& model, const Planned& planned, const double* u, Shadows& shadows) const;
  void LightSlots(const ShadingModel& model, const Planned& planned, Shadows& shadows) const;
  void SampleNumbers(int x, int y, int s, double* u) const;
  double* PixelSums(int x, int y) { return accum_.data() + (std::size_t(y) * std::size_t(width_) + std::size_t(x)) * 4; }

  // The one-ray path (integrator_scalar.cpp).
  void RenderTileScalar(const Tile& tile, int first, int last);

  // The stream path (integrator_streams.cpp).
  void RenderTileStreams(const Tile& tile, int first, int last);
  void BeginTile(const Tile& tile, TileSpace& space);
  void ShadeOneAtATime(TileSpace& space);
  void ShadeInLanes(TileSpace& space);
  void AddShadows(TileSpace& space) const;
  void EndTile(TileSpace& space);

  RenderedImage Finish(int done) const;

  const SceneDesc& desc_;
  std::vector<LightDesc> lights_;  // the scene's, in its working space
  const RenderSettings& settings_;
  int width_, height_, spp_;
  std::uint64_t seed_;

  std::vector<std::shared_ptr<const ShadingModel>> materials_;  // only those the objects use
  std::vector<std::optional<Vec3>> tangents_;  // per material: the world direction its tangent follows
  std::vector<std::optional<StretchTexture>> stretch_textures_;
  std::optional<Environment> env_;
  bool light_sampled_ = false;  // whether the environment gets a light sample per hit (a map)
  Rgb constant_radiance_{0.0};  // a constant environment's radiance; zero otherwise
  unsigned numbers_read_ = 0;

  std::optional<Tracer> tracer_;
  std::vector<int> object_material_;  // per object
  LaneObjects objects_;               // what the lanes read of an object per hit
  std::vector<char> in_lanes_;        // per material: whether the stream path shades its hits in lanes
  bool one_at_a_time_ = false;        // whether some object's hits are shaded by Plan()
  std::vector<LaneLight> lane_lights_;
  bool point_lights_ = false;  // whether the lanes' hits need their positions

  PinholeCamera camera_;
  double eps_ = 0.0;  // shadow rays' offset and near distance

  std::vector<double> accum_;  // per pixel: r, g, b, alpha sums
  tbb::enumerable_thread_specific<TileSpace> tile_spaces_;
};

}  // namespace facetfit
