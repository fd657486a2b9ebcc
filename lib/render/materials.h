// The material types a scene names (docs/scene-format.md), each once, with the factory of its shading
// model: the scene parser (render/scene.cpp), load_material, `render --material-type` and the lanes test
// (tests/render/test_shading_lanes.cpp) read this list. Not installed: load_material (render/scene.h) is the public way
// from a material to its shading model.
#pragma once

#include <memory>
#include <string>

namespace facetfit {

class ShadingModel;  // render/shading.h
struct SceneDesc;    // render/scene.h
struct MaterialDesc;

// The shading model of a material of one type: loads its file (and fits or tabulates what sampling needs).
using MaterialFactory = std::shared_ptr<const ShadingModel> (*)(const SceneDesc& scene, const MaterialDesc& m);

// The factories of the types (render/materials.cpp), as docs/scene-format.md describes each.
std::shared_ptr<const ShadingModel> measured_material(const SceneDesc& scene, const MaterialDesc& m);
std::shared_ptr<const ShadingModel> lut_material(const SceneDesc& scene, const MaterialDesc& m);
// ggx, beckmann and lsq: a LUT's fit of that family, or (ggx, beckmann) the family of alpha, f0 and f82.
std::shared_ptr<const ShadingModel> parametric_material(const SceneDesc& scene, const MaterialDesc& m);
std::shared_ptr<const ShadingModel> closures_material(const SceneDesc& scene, const MaterialDesc& m);
// `material`: the closures the production material emits of a LUT (Lut::production_closures).
std::shared_ptr<const ShadingModel> production_material(const SceneDesc& scene, const MaterialDesc& m);
std::shared_ptr<const ShadingModel> lambert_material(const SceneDesc& scene, const MaterialDesc& m);
std::shared_ptr<const ShadingModel> analytic_material(const SceneDesc& scene, const MaterialDesc& m);

struct MaterialType {
  const char* name;
  bool needs_file;  // a "file" is required
  bool reads_lut;   // the file is a LUT (`render --material` bakes a measurement first)
  // How the stream path shades its plain form (unstretched, isotropic; ShadingModel::has_lanes, f_in_lanes):
  // every part in SIMD lanes (f, density, sampling), or its density and sampling there and f one pair at
  // a time. Tested for each type (tests/render/test_shading_lanes.cpp): a type that leaves the lanes fails there.
  enum class Lanes { all, sampling } lanes;
  MaterialFactory make;  // what load_material calls
};
inline constexpr MaterialType kMaterialTypes[] = {
    {"measured", true, false, MaterialType::Lanes::sampling, measured_material},  // MERL tables' f in lanes too; RGL's and UTIA's not
    {"lut", true, true, MaterialType::Lanes::all, lut_material},
    {"ggx", false, true, MaterialType::Lanes::sampling, parametric_material},
    {"beckmann", false, true, MaterialType::Lanes::sampling, parametric_material},
    {"lsq", true, true, MaterialType::Lanes::sampling, parametric_material},
    {"closures", true, true, MaterialType::Lanes::sampling, closures_material},
    {"material", true, true, MaterialType::Lanes::sampling, production_material},  // closures, as the production material picks them
    {"lambert", false, false, MaterialType::Lanes::all, lambert_material},
    {"analytic", true, false, MaterialType::Lanes::sampling, analytic_material},
};
// A row without its factory does not compile: -Wmissing-field-initializers (-Wextra) under FACETFIT_WERROR.
// (A static_assert that each `make` is not null is not a constant expression under -fsanitize=undefined.)

// The named type, or null.
const MaterialType* find_material_type(const std::string& name);
// "measured, lut, ... or analytic", for messages and help.
std::string material_type_list();

}  // namespace facetfit
