// Scenes for the reference renderer (docs/scene-format.md): a JSON description, parsed without loading
// anything, and the materials it references, loaded on demand.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/rgb_space.h"
#include "core/vec.h"
#include "model/smith.h"
#include "model/stretch.h"

namespace facetfit {

class ShadingModel;  // render/shading.h

struct CameraDesc {
  Vec3 position{0, 0, 4}, look_at{0, 0, 0}, up{0, 1, 0};
  double fov_degrees = 30.0;  // vertical
  int width = 256, height = 256;
};

struct EnvironmentDesc {
  enum class Kind { none, builtin_sky, constant, file } kind = Kind::none;
  Rgb constant{1.0};
  std::string file;
  double scale = 1.0;
};

struct LightDesc {
  enum class Kind { directional, point } kind = Kind::directional;
  Vec3 vector{0, 1, 0};  // directional: toward the light; point: position
  Rgb value{1.0};        // directional: irradiance (W/m^2 per unit area facing it); point: intensity
};

struct MaterialDesc {
  std::string type = "lambert";  // one of kMaterialTypes (render/materials.h)
  std::string file;       // measured: any facetfit input; lut: the LUT; ggx/beckmann: optional LUT to take alpha and Fresnel from
  double alpha = 0.0;     // ggx/beckmann without a LUT
  Rgb f0{0.04}, f82{0.04};
  std::string fresnel = "f82";  // ggx/beckmann with a LUT: "f82" (the fit's F82-tint) or "curve" (the LUT's RGB curve)
  // measured RGL files: which direction picks the file's slices (io/rgl.h): "view" (Mitsuba's
  // evaluation, the reference), "symmetric" (both one-sided estimates, reciprocal) or "light".
  std::string slices = "view";
  // measured: optional LUT of the same material (a bake's output) whose fit proposes directions; without
  // one the paper's fit is made on load.
  std::string proposal;
  Smith smith = Smith::correlated;
  Rgb albedo{0.8};
  // lut: the artist's stretch of the tabulated lobe (model/stretch.h): "stretch": [x, y] (roughness
  // grows with it), "rotation" of its x axis in degrees from the tangent (an anisotropic lobe: scaled along
  // its own axes and turned by the rotation, model/tabulated_anisotropic.h); "tangent": a world direction
  // whose projection on the surface is the tangent (else any tangent: fine for an isotropic lobe).
  Stretch stretch;
  std::optional<Vec3> tangent;
  // lut: an image whose R and G multiply the stretch's x and y per shading point (render/texture.h: its
  // coordinates, and how it is read), for spheres and planes.
  std::string stretch_texture;
  // lut: a LUT with an anisotropic lobe (version 3, from an anisotropic input) renders it, along the
  // tangent, and ggx with such a LUT its anisotropic GGX fit; false renders the isotropic representation.
  bool anisotropic = true;
};

struct ObjectDesc {
  enum class Kind { sphere, plane, mesh } kind = Kind::sphere;
  Vec3 center{0.0};
  double radius = 1.0;
  Vec3 point{0.0}, normal{0, 1, 0};
  double size = 10.0;  // plane: side of the square
  std::string file;    // mesh: Wavefront OBJ
  std::string material;
};

struct SceneDesc {
  CameraDesc camera;
  int spp = 64;
  std::uint64_t seed = 1;
  EnvironmentDesc environment;
  std::vector<LightDesc> lights;
  std::map<std::string, MaterialDesc> materials;
  std::vector<ObjectDesc> objects;
  std::string base_dir = ".";  // where relative file names resolve
  std::string source;          // the scene file (or what stands for it), named in errors; empty: made in code
  // The linear space the render is in (core/rgb_space.h) and its matrix from lin_rec709. The scene's
  // colours (lights, environment, plain materials) and measurements are lin_rec709 and converted by it;
  // a LUT from the space it records.
  std::string working_space = kRec709Space;
  ColorMatrix from_rec709{1.0};
};

// Throws Error("<path>: <problem>") for unreadable or inconsistent scenes.
SceneDesc parse_scene(const std::string& path);
// The same from the scene's text: `name` stands for the file in messages, relative files resolve against
// `base_dir`.
SceneDesc parse_scene_text(const std::string& text, const std::string& name, const std::string& base_dir);
// The embedded default: a sphere of `subject` under the built-in sky. Needs no asset.
SceneDesc default_scene(const MaterialDesc& subject);

// The measured sources a scene needs baked, resolved against the scene's folder: for a renderer scene,
// the files of the `measured` materials its objects use; a plain JSON list of paths (or an object with a
// "materials" list of paths or {"file": ...}) is taken as it is.
std::vector<std::string> scene_materials(const std::string& scene_path);

// Resolves a file name of the scene: relative names against the scene's folder, builtin: as is.
std::string resolve(const SceneDesc& scene, const std::string& file);

struct Lut;

// One of the parametric fits a LUT carries ("ggx", "beckmann" or "lsq") as a shading model, evaluated
// with `smith`, with the fit's F82-tint (lsq: Schlick) Fresnel or, with `fresnel_curve`, the LUT's curve.
// Throws Error for another family. With `anisotropic`, a version 3 LUT's ggx is its anisotropic GGX fit
// (LutMetadata::anisotropic_ggx), in the shading frame whose x axis is the tangent.
std::shared_ptr<const ShadingModel> lut_parametric_model(const Lut& lut, const std::string& family, Smith smith, bool fresnel_curve,
                                                         bool anisotropic = false);

// The shading model of a material: loads its file (and fits or tabulates what sampling needs), by the
// factory of its type's row of kMaterialTypes (render/materials.h). Throws Error for a type not there.
std::shared_ptr<const ShadingModel> load_material(const SceneDesc& scene, const MaterialDesc& m);

}  // namespace facetfit
