#include "lut/materialx.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include "model/closures.h"
#include "model/fresnel.h"

namespace facetfit {

namespace {

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

std::string colour(const Rgb& c) { return number(c.r) + ", " + number(c.g) + ", " + number(c.b); }

// One node: <category name type> with its inputs (name, type, value or nodename=).
struct Node {
  std::string category, name, type;
  std::vector<std::array<std::string, 3>> inputs;  // name, type, value ("@node" connects a node's output)

  void write(std::ostringstream& out) const {
    out << "  <" << category << " name=\"" << name << "\" type=\"" << type << "\">\n";
    for (const auto& [input, kind, value] : inputs) {
      out << "    <input name=\"" << input << "\" type=\"" << kind << "\" ";
      if (!value.empty() && value[0] == '@')
        out << "nodename=\"" << value.substr(1) << "\" />\n";
      else
        out << "value=\"" << value << "\" />\n";
    }
    out << "  </" << category << ">\n";
  }
};

// A view-aligned lobe's frame and alphas (model/closures.h) as nodes: the tangent NAME_tangent along the view's
// azimuth, normalize(v - n (n.v)) (either sign: the ellipse is symmetric), and NAME_roughness, (alpha_x,
// min(alpha_y max(cos theta_o, 1e-3)^-k, max(alpha_y, 1))) with cos theta_o = |n.v|: MaterialX's view direction
// points from the camera, OSL's I as Cycles gives it toward the camera, and the generated OSL reads I.
void view_frame_nodes(const std::string& name, const ClosureLobe& l, std::vector<Node>& nodes) {
  const auto at = [&](const std::string& suffix) { return "@" + name + suffix; };
  nodes.push_back({"normal", name + "_n", "vector3", {{"space", "string", "world"}}});
  nodes.push_back({"viewdirection", name + "_v", "vector3", {{"space", "string", "world"}}});
  nodes.push_back({"dotproduct", name + "_nv", "float", {{"in1", "vector3", at("_n")}, {"in2", "vector3", at("_v")}}});
  nodes.push_back({"multiply", name + "_n_nv", "vector3", {{"in1", "vector3", at("_n")}, {"in2", "float", at("_nv")}}});
  nodes.push_back({"subtract", name + "_along", "vector3", {{"in1", "vector3", at("_v")}, {"in2", "vector3", at("_n_nv")}}});
  nodes.push_back({"normalize", name + "_tangent", "vector3", {{"in", "vector3", at("_along")}}});
  nodes.push_back({"absval", name + "_cos", "float", {{"in", "float", at("_nv")}}});
  nodes.push_back({"max", name + "_cos_clamped", "float", {{"in1", "float", at("_cos")}, {"in2", "float", "0.001"}}});
  nodes.push_back({"power", name + "_grow", "float", {{"in1", "float", at("_cos_clamped")}, {"in2", "float", number(-l.view_exponent)}}});
  nodes.push_back({"multiply", name + "_across", "float", {{"in1", "float", at("_grow")}, {"in2", "float", number(l.alpha_y)}}});
  nodes.push_back({"min", name + "_across_clamped", "float",
                   {{"in1", "float", at("_across")}, {"in2", "float", number(std::max(l.alpha_y, 1.0))}}});
  nodes.push_back({"combine2", name + "_roughness", "vector2",
                   {{"in1", "float", number(l.alpha_x)}, {"in2", "float", at("_across_clamped")}}});
}

// The generalized_schlick_bsdf of a lobe (its tangent node when it is anisotropic, added to `nodes`).
Node lobe_node(const std::string& name, const ClosureLobe& lobe, bool color82, std::vector<Node>& nodes) {
  const ClosureLobe l = color82 ? lobe : without_f82(lobe);
  Node n{"generalized_schlick_bsdf", name, "BSDF", {}};
  const bool tint = l.fresnel == ClosureLobe::Fresnel::f82_tint;
  n.inputs.push_back({"weight", "float", number(l.weight)});
  n.inputs.push_back({"color0", "color3", colour(l.f0)});
  // F82-tint: the closure takes f82 as a tint of Schlick's value at mu = 1/7 (osl/facetfit_material.osl).
  n.inputs.push_back({"color82", "color3", tint ? colour(l.f82 / fresnel_schlick(l.f0, 1.0 / 7.0)) : colour(Rgb(1.0))});
  n.inputs.push_back({"color90", "color3", tint ? colour(Rgb(1.0)) : colour(l.f90)});
  n.inputs.push_back({"exponent", "float", number(tint ? 5.0 : l.exponent)});
  n.inputs.push_back({"scatter_mode", "string", "R"});
  if (l.view_aligned()) {
    view_frame_nodes(name, l, nodes);
    n.inputs.push_back({"roughness", "vector2", "@" + name + "_roughness"});
    n.inputs.push_back({"tangent", "vector3", "@" + name + "_tangent"});
    return n;
  }
  n.inputs.push_back({"roughness", "vector2", number(l.alpha_x) + ", " + number(l.alpha_y)});
  if (l.alpha_x != l.alpha_y && l.angle != 0.0) {
    nodes.push_back({"tangent", name + "_surface_tangent", "vector3", {{"space", "string", "world"}}});
    nodes.push_back({"normal", name + "_surface_normal", "vector3", {{"space", "string", "world"}}});
    nodes.push_back({"rotate3d", name + "_tangent", "vector3",
                     {{"in", "vector3", "@" + name + "_surface_tangent"}, {"amount", "float", number(l.angle * 180.0 / kPi)},
                      {"axis", "vector3", "@" + name + "_surface_normal"}}});
    n.inputs.push_back({"tangent", "vector3", "@" + name + "_tangent"});
  }
  return n;
}

}  // namespace

std::string materialx_colorspace(const std::string& space) {
  // MaterialX's standard colour spaces (its specification, "Color Spaces"), matched without case, '_' or ' '.
  static const char* const kStandard[] = {"lin_rec709", "acescg", "lin_ap1", "srgb_texture", "lin_adobergb", "lin_displayp3",
                                          "srgb_displayp3", "g22_rec709", "g18_rec709", "g22_ap1", "g22_adobergb", "adobergb"};
  const auto key = [](const std::string& s) {
    std::string k;
    for (char c : s)
      if (std::isalnum(static_cast<unsigned char>(c))) k += char(std::tolower(static_cast<unsigned char>(c)));
    return k;
  };
  for (const char* standard : kStandard)
    if (key(standard) == key(space)) return standard;
  return space;  // another (the studio config's name): kept as the LUT names it
}

namespace {

// A working space's name as USD names it (GfColorSpaceNames: lin_rec709_scene, lin_ap1_scene, ...) where it is
// one of USD's, else MaterialX's name for it.
std::string usd_colorspace(const std::string& space) {
  static const std::pair<const char*, const char*> kUsd[] = {
      {"lin_rec709", "lin_rec709_scene"}, {"acescg", "lin_ap1_scene"},       {"lin_ap1", "lin_ap1_scene"},
      {"lin_adobergb", "lin_adobergb_scene"}, {"lin_displayp3", "lin_p3d65_scene"}};
  const std::string mx = materialx_colorspace(space);
  for (const auto& [materialx, usd] : kUsd)
    if (mx == materialx) return usd;
  return mx;
}

// `text` as an XML attribute's value: the five special characters as entities, control characters dropped.
std::string xml_attribute(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '&') out += "&amp;";
    else if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '"') out += "&quot;";
    else if (c == '\'') out += "&apos;";
    else if (static_cast<unsigned char>(c) >= 0x20 && c != 0x7f) out += c;
  }
  return out;
}

// `text` as a USD string literal's content: quotes and backslashes escaped, control characters dropped.
std::string usd_string(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) >= 0x20 && c != 0x7f) out += c;
  }
  return out;
}

}  // namespace

std::string usd_document(const std::string& name, const std::string& mtlx_file, const Lut& lut) {
  const Closures c = lut.production_closures();
  Rgb specular(0.0);
  for (const ClosureLobe& l : c.lobes) specular += l.weight * l.fresnel_at(1.0);
  specular = glm::clamp(specular, Rgb(0.0), Rgb(1.0));
  const ClosureLobe& first = c.lobes.front();
  const double roughness = std::sqrt(std::sqrt(first.alpha_x * first.alpha_y));
  const std::string space = usd_string(usd_colorspace(lut.meta.colorspace));
  const auto colour = [&](const Rgb& v) {
    std::ostringstream s;
    s << "(" << float(v.r) << ", " << float(v.g) << ", " << float(v.b) << ") (\n            colorSpace = \"" << space << "\"\n        )";
    return s.str();
  };
  std::ostringstream out;
  out << "#usda 1.0\n(\n    defaultPrim = \"" << name << "\"\n    metersPerUnit = 1\n    upAxis = \"Y\"\n)\n\n"
      << "def Material \"" << name << "\" (\n    prepend references = @" << mtlx_file << "@</MaterialX/Materials/" << name << ">\n)\n{\n"
      << "    token outputs:surface.connect = </" << name << "/PreviewSurface.outputs:surface>\n\n"
      << "    def Shader \"PreviewSurface\"\n    {\n"
      << "        uniform token info:id = \"UsdPreviewSurface\"\n"
      << "        color3f inputs:diffuseColor = " << colour(glm::clamp(c.body, Rgb(0.0), Rgb(1.0))) << "\n"
      << "        color3f inputs:specularColor = " << colour(specular) << "\n"
      << "        float inputs:roughness = " << float(std::min(roughness, 1.0)) << "\n"
      << "        int inputs:useSpecularWorkflow = 1\n"
      << "        float inputs:clearcoat = " << (c.coat.present() ? 1 : 0) << "\n"
      << "        float inputs:clearcoatRoughness = " << float(std::min(std::sqrt(c.coat.alpha), 1.0)) << "\n"
      << "        token outputs:surface\n    }\n}\n";
  return out.str();
}

std::string materialx_name(const std::string& stem) {
  std::string out;
  for (char c : stem) out += std::isalnum(static_cast<unsigned char>(c)) || c == '_' ? c : '_';
  if (out.empty() || std::isdigit(static_cast<unsigned char>(out[0]))) out = "m_" + out;
  return out;
}

std::string materialx_document(const std::string& name, const Lut& lut, bool color82) {
  const Closures c = lut.production_closures();
  std::vector<Node> nodes;
  std::vector<std::string> parts;
  if (c.body.r > 0.0 || c.body.g > 0.0 || c.body.b > 0.0) {
    nodes.push_back({"oren_nayar_diffuse_bsdf", name + "_body", "BSDF", {{"color", "color3", colour(c.body)}, {"roughness", "float", "0"}}});
    parts.push_back(name + "_body");
  }
  for (std::size_t k = 0; k < c.lobes.size(); ++k) {
    const Node lobe = lobe_node(name + "_lobe" + std::to_string(k), c.lobes[k], color82, nodes);
    nodes.push_back(lobe);
    parts.push_back(lobe.name);
  }
  if (c.coat.present()) {
    ClosureLobe coat;
    coat.alpha_x = coat.alpha_y = c.coat.alpha;
    coat.fresnel = ClosureLobe::Fresnel::schlick;
    coat.f0 = Rgb(c.coat.f0);
    coat.f90 = Rgb(1.0);
    coat.exponent = 5.0;
    nodes.push_back(lobe_node(name + "_coat", coat, color82, nodes));
    parts.push_back(name + "_coat");
  }
  // The sum, a chain of adds.
  std::string sum = parts.front();
  for (std::size_t k = 1; k < parts.size(); ++k) {
    const std::string add = name + "_sum" + std::to_string(k);
    nodes.push_back({"add", add, "BSDF", {{"in1", "BSDF", "@" + sum}, {"in2", "BSDF", "@" + parts[k]}}});
    sum = add;
  }
  nodes.push_back({"surface", name + "_surface", "surfaceshader", {{"bsdf", "BSDF", "@" + sum}}});
  nodes.push_back({"surfacematerial", name, "material", {{"surfaceshader", "surfaceshader", "@" + name + "_surface"}}});
  std::ostringstream out;
  // The colours' space, as the LUT was baked (MaterialX's own name where the space is one of its standard ones).
  out << "<?xml version=\"1.0\"?>\n<materialx version=\"1.39\" colorspace=\"" << xml_attribute(materialx_colorspace(lut.meta.colorspace)) << "\">\n";
  for (const Node& n : nodes) n.write(out);
  out << "</materialx>\n";
  return out.str();
}

}  // namespace facetfit
