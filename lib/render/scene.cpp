#include "render/scene.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/input.h"
#include "io/rgl.h"
#include "lut/record.h"
#include "render/materials.h"

namespace facetfit {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Scene coordinates and sizes stay within this: beyond it, rays and their offsets stop being finite in
// the ray tracer's float arithmetic.
constexpr double kMaxCoordinate = 1e6;

Vec3 vec3(const json& j, const std::string& what, const std::string& path) {
  if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() || !j[2].is_number())
    fail(path, what + " must be an array of three numbers");
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

// A position: every coordinate within +-kMaxCoordinate.
Vec3 position(const json& j, const std::string& what, const std::string& path) {
  const Vec3 v = vec3(j, what, path);
  for (int k = 0; k < 3; ++k)
    if (!(std::abs(v[k]) <= kMaxCoordinate)) fail(path, what + " must have coordinates within +-1e6");
  return v;
}

// A direction: finite, not zero; returned unit.
Vec3 direction(const json& j, const std::string& what, const std::string& path) {
  const Vec3 v = position(j, what, path);
  if (!(glm::length(v) > 0.0)) fail(path, what + " must not be zero");
  return glm::normalize(v);
}

// A finite number >= 0 (NaN is not).
bool finite_nonnegative(double v) { return v >= 0.0 && v <= 1e30; }

// A colour or a radiometric value: three finite numbers >= 0.
Vec3 nonnegative(const json& j, const std::string& what, const std::string& path) {
  const Vec3 v = vec3(j, what, path);
  for (int k = 0; k < 3; ++k)
    if (!finite_nonnegative(v[k])) fail(path, what + " must be three finite numbers >= 0");
  return v;
}

// A length in the scene: within (0, kMaxCoordinate] (NaN is not).
bool scene_length(double v) { return v > 0.0 && v <= kMaxCoordinate; }

// Whether `s` is one of `names`.
bool one_of(const std::string& s, std::initializer_list<const char*> names) {
  return std::any_of(names.begin(), names.end(), [&](const char* n) { return s == n; });
}

template <class T>
T get(const json& j, const char* key, T fallback, const std::string& path) {
  if (!j.contains(key)) return fallback;
  try {
    return j.at(key).get<T>();
  } catch (const json::exception&) {
    fail(path, std::string("\"") + key + "\" has the wrong type");
  }
}

// An integer in [lo, hi]: a JSON integer, or a float with an integral value. nlohmann/json stores an
// integer too large for 64 bits as a float, and converting such a float (or a negative one to an
// unsigned type) is undefined behaviour (found by fuzz_scene): the range is checked first.
template <class T>
T get_integer(const json& j, const char* key, T fallback, long double lo, long double hi, const std::string& path) {
  if (!j.contains(key)) return fallback;
  const json& v = j.at(key);
  long double x = 0.0L;
  if (v.is_number_unsigned()) x = static_cast<long double>(v.get<std::uint64_t>());
  else if (v.is_number_integer()) x = static_cast<long double>(v.get<std::int64_t>());
  else if (v.is_number_float() && std::isfinite(v.get<double>()) && v.get<double>() == std::floor(v.get<double>())) x = v.get<double>();
  else fail(path, std::string("\"") + key + "\" must be an integer");
  if (!(x >= lo && x <= hi))
    fail(path, std::string("\"") + key + "\" must be an integer between " + std::to_string(static_cast<long long>(lo)) + " and " +
                   std::to_string(static_cast<unsigned long long>(hi)));
  return static_cast<T>(x);
}

// Every key of object `j` is one of `known`: a misspelt key ("fvo") is an error, not a silent default
// (Mitsuba 3 refuses unreferenced properties the same way).
void known_keys(const json& j, std::initializer_list<const char*> known, const std::string& where, const std::string& path) {
  if (!j.is_object()) fail(path, where + " must be an object");
  for (const auto& item : j.items()) {
    if (std::any_of(known.begin(), known.end(), [&](const char* k) { return item.key() == k; })) continue;
    std::string list;
    for (const char* k : known) list += std::string(list.empty() ? "" : ", ") + k;
    fail(path, where + ": unknown key \"" + excerpt(item.key(), 37) + "\" (known: " + list + ")");
  }
}

// The material's type, its file and its alpha; `what` is "material NAME".
void parse_material_kind(const json& j, const std::string& what, const std::string& path, MaterialDesc& m) {
  m.type = get<std::string>(j, "type", "", path);
  const MaterialType* type = find_material_type(m.type);
  if (!type) fail(path, what + ": type must be " + material_type_list());
  m.file = get<std::string>(j, "file", "", path);
  if (type->needs_file && m.file.empty()) fail(path, what + " needs a \"file\"");
  m.alpha = get<double>(j, "alpha", 0.0, path);
  if (!(m.alpha >= 0.0 && m.alpha <= 10.0)) fail(path, what + ": alpha must be in [0, 10]");
  if (one_of(m.type, {"ggx", "beckmann"}) && m.file.empty() && !(m.alpha > 0.0))
    fail(path, what + " needs \"alpha\" > 0 or a LUT \"file\"");
}

// f0, f82 (f0 when absent) and which Fresnel a LUT's parametric fit renders with.
void parse_material_fresnel(const json& j, const std::string& what, const std::string& path, MaterialDesc& m) {
  if (j.contains("f0")) m.f0 = nonnegative(j["f0"], what + ": f0", path);
  m.f82 = j.contains("f82") ? nonnegative(j["f82"], what + ": f82", path) : m.f0;
  m.fresnel = get<std::string>(j, "fresnel", "f82", path);
  if (m.fresnel != "curve" && m.fresnel != "f82") fail(path, what + ": fresnel must be curve or f82");
}

// A measured material's slices and proposal, and the Smith model.
void parse_material_sampling(const json& j, const std::string& what, const std::string& path, MaterialDesc& m) {
  m.slices = get<std::string>(j, "slices", "view", path);
  m.proposal = get<std::string>(j, "proposal", "", path);
  if (!m.proposal.empty() && m.type != "measured") fail(path, what + ": \"proposal\" is for measured materials");
  if (!parse_slices(m.slices)) fail(path, what + ": slices must be view, symmetric or light");
  const auto smith = parse_smith(get<std::string>(j, "smith", "correlated", path));
  if (!smith) fail(path, what + ": smith must be masking, correlated or separable");
  m.smith = *smith;
}

// The tangent and whether an anisotropic lobe renders as one.
void parse_material_orientation(const json& j, const std::string& what, const std::string& path, MaterialDesc& m) {
  if (j.contains("tangent") && !one_of(m.type, {"lut", "measured", "ggx", "closures", "material"}))
    fail(path, what + ": \"tangent\" is for lut, ggx, closures, material and measured materials (an anisotropic fit or measurement turns with it)");
  if (j.contains("tangent")) m.tangent = direction(j["tangent"], what + ": tangent", path);
  if (j.contains("anisotropic")) {
    if (!one_of(m.type, {"lut", "ggx"}) || !j["anisotropic"].is_boolean())
      fail(path, what + ": \"anisotropic\" is true or false, for lut and ggx materials");
    m.anisotropic = j["anisotropic"].get<bool>();
  }
}

// "stretch": [x, y], each in [Stretch::kMin, Stretch::kMax].
std::pair<double, double> parse_stretch_factors(const json& st, const std::string& what, const std::string& path) {
  if (!st.is_array() || st.size() != 2 || !st[0].is_number() || !st[1].is_number()) fail(path, what + ": stretch must be [x, y]");
  const double sx = st[0].get<double>(), sy = st[1].get<double>();
  if (!(sx >= Stretch::kMin && sx <= Stretch::kMax && sy >= Stretch::kMin && sy <= Stretch::kMax))
    fail(path, what + ": stretch must be in [0.01, 100]");
  return {sx, sy};
}

// The artist's stretch, rotation and stretch texture of a lut or closures material.
void parse_material_stretch(const json& j, const std::string& what, const std::string& path, MaterialDesc& m) {
  if (!one_of(m.type, {"lut", "closures", "material"}))
    fail(path, what + ": \"stretch\" and \"rotation\" are for lut, closures and material materials");
  if (m.type != "lut" && j.contains("stretch_texture")) fail(path, what + ": \"stretch_texture\" is for lut materials");
  m.stretch_texture = get<std::string>(j, "stretch_texture", "", path);
  if (j.contains("stretch_texture") && m.stretch_texture.empty()) fail(path, what + ": stretch_texture must name an image");
  const auto [sx, sy] = j.contains("stretch") ? parse_stretch_factors(j["stretch"], what, path) : std::pair{1.0, 1.0};
  const double degrees = get<double>(j, "rotation", 0.0, path);
  if (!(std::abs(degrees) <= 360.0)) fail(path, what + ": rotation must be in [-360, 360] degrees");
  m.stretch = Stretch(sx, sy, degrees * kPi / 180.0);
}

MaterialDesc parse_material(const std::string& name, const json& j, const std::string& path) {
  const std::string what = "material " + name;
  if (!j.is_object()) fail(path, what + " must be an object");
  known_keys(j, {"type", "file", "alpha", "f0", "f82", "fresnel", "slices", "proposal", "smith", "albedo", "tangent", "anisotropic",
                 "stretch", "rotation", "stretch_texture"},
             what, path);
  MaterialDesc m;
  parse_material_kind(j, what, path, m);
  parse_material_fresnel(j, what, path, m);
  parse_material_sampling(j, what, path, m);
  if (j.contains("albedo")) m.albedo = nonnegative(j["albedo"], what + ": albedo", path);
  parse_material_orientation(j, what, path, m);
  if (j.contains("stretch") || j.contains("rotation") || j.contains("stretch_texture")) parse_material_stretch(j, what, path, m);
  return m;
}

// A scene file's text: a regular file (a FIFO would block the read forever) of bounded size (a scene is
// kilobytes; a material list for bake --scene, at most megabytes).
std::string read_scene_text(const std::string& path) {
  constexpr std::uintmax_t kMaxBytes = std::uintmax_t(64) << 20;
  require_regular_file(path);
  std::error_code ec;
  if (const std::uintmax_t size = fs::file_size(path, ec); !ec && size > kMaxBytes)
    fail(path, "scene is " + std::to_string(size >> 20) + " MiB; the limit is 64 MiB");
  std::ifstream in(path);
  if (!in) fail(path, "cannot open scene");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) fail(path, "cannot read scene");
  return text;
}

// The deepest nesting of arrays and objects in JSON text, brackets inside strings skipped: one pass, so
// that the parse after it needs no callback (nlohmann's callback parser rescans a parent each time one of
// its members closes: 100k materials took minutes).
int json_nesting(const std::string& text) {
  int depth = 0, deepest = 0;
  bool in_string = false;
  for (std::size_t k = 0; k < text.size(); ++k) {
    const char c = text[k];
    if (in_string) {
      if (c == '\\') ++k;  // an escaped character, a quote included
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}

// Nesting is bounded before the text is parsed: a scene is 4 levels deep, and a deeply nested document
// would only exhaust the stack of everything that later copies or destroys it.
json parse_bounded_json(const std::string& text, const std::string& path) {
  constexpr int kMaxDepth = 32;
  if (json_nesting(text) > kMaxDepth) fail(path, "nested more than 32 levels deep");
  try {
    return json::parse(text);
  } catch (const json::exception& e) {
    fail(path, std::string("not valid JSON: ") + e.what());
  }
}

// The camera: where it is, where it looks, its field of view and image size.
void parse_camera(const json& c, const std::string& path, CameraDesc& camera) {
  known_keys(c, {"position", "look_at", "up", "fov", "width", "height"}, "camera", path);
  if (c.contains("position")) camera.position = position(c["position"], "camera.position", path);
  if (c.contains("look_at")) camera.look_at = position(c["look_at"], "camera.look_at", path);
  if (c.contains("up")) camera.up = direction(c["up"], "camera.up", path);
  camera.fov_degrees = get<double>(c, "fov", camera.fov_degrees, path);
  camera.width = get_integer<int>(c, "width", camera.width, 1, 16384, path);
  camera.height = get_integer<int>(c, "height", camera.height, 1, 16384, path);
  if (!(camera.fov_degrees > 0.0 && camera.fov_degrees < 180.0)) fail(path, "camera fov must be in (0, 180) degrees");
  // A camera needs a view direction, and an up that is not along it.
  const Vec3 view = camera.look_at - camera.position;
  if (!(glm::length(view) > 1e-9)) fail(path, "camera.look_at must differ from camera.position");
  if (!(glm::length(glm::cross(glm::normalize(view), glm::normalize(camera.up))) > 1e-6))
    fail(path, "camera.up must not be parallel to the view direction");
}

// The environment: one of an image file, a constant radiance and the built-in sky, scaled.
void parse_environment(const json& e, const std::string& path, EnvironmentDesc& environment) {
  known_keys(e, {"file", "constant", "builtin", "scale"}, "environment", path);
  if (int(e.contains("file")) + int(e.contains("constant")) + int(e.contains("builtin")) > 1)
    fail(path, "environment takes one of \"file\", \"constant\" and \"builtin\"");
  environment.scale = get<double>(e, "scale", 1.0, path);
  if (!finite_nonnegative(environment.scale)) fail(path, "environment.scale must be a finite number >= 0");
  if (e.contains("file")) {
    environment.kind = EnvironmentDesc::Kind::file;
    environment.file = get<std::string>(e, "file", "", path);
  } else if (e.contains("constant")) {
    environment.kind = EnvironmentDesc::Kind::constant;
    environment.constant = nonnegative(e["constant"], "environment.constant", path);
  } else if (get<std::string>(e, "builtin", "", path) == "sky") {
    environment.kind = EnvironmentDesc::Kind::builtin_sky;
  } else {
    fail(path, "environment needs \"file\", \"constant\" or \"builtin\": \"sky\"");
  }
}

LightDesc parse_light(const json& l, const std::string& path) {
  LightDesc d;
  const std::string type = get<std::string>(l, "type", "", path);
  if (type == "directional") {
    known_keys(l, {"type", "direction", "irradiance"}, "directional light", path);
    d.kind = LightDesc::Kind::directional;
    d.vector = direction(l.value("direction", json()), "directional light direction", path);
    d.value = nonnegative(l.value("irradiance", json()), "directional light irradiance", path);
  } else if (type == "point") {
    known_keys(l, {"type", "position", "intensity"}, "point light", path);
    d.kind = LightDesc::Kind::point;
    d.vector = position(l.value("position", json()), "point light position", path);
    d.value = nonnegative(l.value("intensity", json()), "point light intensity", path);
  } else {
    fail(path, "light type must be directional or point");
  }
  return d;
}

// An object's shape; its material is checked against the scene's by the caller.
ObjectDesc parse_object_shape(const json& o, const std::string& path) {
  ObjectDesc d;
  const std::string type = get<std::string>(o, "type", "", path);
  if (type == "sphere") {
    known_keys(o, {"type", "center", "radius", "material"}, "sphere", path);
    d.kind = ObjectDesc::Kind::sphere;
    d.center = position(o.value("center", json::array({0, 0, 0})), "sphere center", path);
    d.radius = get<double>(o, "radius", 1.0, path);
    if (!scene_length(d.radius)) fail(path, "sphere radius must be in (0, 1e6]");
  } else if (type == "plane") {
    known_keys(o, {"type", "point", "normal", "size", "material"}, "plane", path);
    d.kind = ObjectDesc::Kind::plane;
    d.point = position(o.value("point", json::array({0, 0, 0})), "plane point", path);
    d.normal = direction(o.value("normal", json::array({0, 1, 0})), "plane normal", path);
    d.size = get<double>(o, "size", 10.0, path);
    if (!scene_length(d.size)) fail(path, "plane size must be in (0, 1e6]");
  } else if (type == "mesh") {
    known_keys(o, {"type", "file", "material"}, "mesh", path);
    d.kind = ObjectDesc::Kind::mesh;
    d.file = get<std::string>(o, "file", "", path);
    if (d.file.empty()) fail(path, "mesh needs a \"file\"");
  } else {
    fail(path, "object type must be sphere, plane or mesh");
  }
  return d;
}

// An object: its shape and one of the scene's `materials`.
ObjectDesc parse_object(const json& o, const std::map<std::string, MaterialDesc>& materials, const std::string& path) {
  ObjectDesc d = parse_object_shape(o, path);
  d.material = get<std::string>(o, "material", "", path);
  if (!materials.count(d.material)) fail(path, "object references undefined material \"" + d.material + "\"");
  if (d.kind == ObjectDesc::Kind::mesh && !materials.at(d.material).stretch_texture.empty())
    fail(path, "a mesh has no texture coordinates: material \"" + d.material + "\" has a stretch_texture (spheres and planes have)");
  return d;
}

}  // namespace

SceneDesc parse_scene(const std::string& path) {
  const std::string text = read_scene_text(path);
  std::string base_dir = fs::path(path).parent_path().string();
  return parse_scene_text(text, path, base_dir.empty() ? "." : base_dir);
}

SceneDesc parse_scene_text(const std::string& text, const std::string& path, const std::string& base_dir) {
  const json j = parse_bounded_json(text, path);
  if (!j.is_object()) fail(path, "not a JSON object");
  known_keys(j, {"camera", "render", "environment", "lights", "materials", "objects"}, "the scene", path);
  SceneDesc s;
  s.base_dir = base_dir;
  s.source = path;
  if (j.contains("camera")) parse_camera(j["camera"], path, s.camera);
  if (j.contains("render")) {
    known_keys(j["render"], {"spp", "seed"}, "render", path);
    s.spp = get_integer<int>(j["render"], "spp", s.spp, 1, 1 << 20, path);
    s.seed = get_integer<std::uint64_t>(j["render"], "seed", s.seed, 0, 18446744073709551615.0L, path);
  }
  if (j.contains("environment")) parse_environment(j["environment"], path, s.environment);
  // Named copies, not temporaries: GCC 12 warns (wrongly) about iterating those.
  const json lights = j.contains("lights") ? j["lights"] : json::array();
  const json materials = j.contains("materials") ? j["materials"] : json::object();
  const json objects = j.contains("objects") ? j["objects"] : json::array();
  if (!lights.is_array() || !materials.is_object() || !objects.is_array())
    fail(path, "lights and objects must be lists, materials an object");
  for (const json& l : lights) s.lights.push_back(parse_light(l, path));
  for (const auto& [name, m] : materials.items()) s.materials[name] = parse_material(name, m, path);
  for (const json& o : objects) s.objects.push_back(parse_object(o, s.materials, path));
  if (s.objects.empty()) fail(path, "no objects");
  return s;
}

SceneDesc default_scene(const MaterialDesc& subject) {
  SceneDesc s;
  s.camera.position = Vec3(0, 0.6, 4.0);
  s.camera.look_at = Vec3(0, 0, 0);
  s.camera.fov_degrees = 30.0;
  s.environment.kind = EnvironmentDesc::Kind::builtin_sky;
  s.materials["subject"] = subject;
  ObjectDesc sphere;
  sphere.material = "subject";
  s.objects.push_back(sphere);
  return s;
}

std::vector<std::string> scene_materials(const std::string& scene_path) {
  const json scene = parse_bounded_json(read_scene_text(scene_path), scene_path);
  std::vector<std::string> out;
  const auto add = [&out](const std::string& file) {
    if (std::find(out.begin(), out.end(), file) == out.end()) out.push_back(file);
  };
  if (scene.is_object() && scene.contains("materials") && scene["materials"].is_object()) {
    const SceneDesc s = parse_scene(scene_path);
    for (const ObjectDesc& o : s.objects) {
      const MaterialDesc& m = s.materials.at(o.material);
      if (m.type == "measured") add(resolve(s, m.file));
    }
    return out;
  }
  const json list = scene.is_object() ? scene.value("materials", json()) : scene;
  if (!list.is_array())
    fail(scene_path, "not a scene: a renderer scene, a list of material paths, or an object with a \"materials\" list");
  const std::string base = fs::path(scene_path).parent_path().string();
  for (const auto& item : list) {
    std::string file;
    if (item.is_string()) file = item.get<std::string>();
    else if (item.is_object() && item.contains("file") && item["file"].is_string()) file = item["file"].get<std::string>();
    else fail(scene_path, "material entry " + excerpt(json_text(item), 57) + " is neither a path nor an object with \"file\"");
    add(resolve_source(base, file));
  }
  return out;
}

std::string resolve(const SceneDesc& scene, const std::string& file) {
  return resolve_source(scene.base_dir, file);
}

}  // namespace facetfit
