// A LUT's production closures (Lut::production_closures: what osl/facetfit_material.osl emits) as a
// MaterialX document (MaterialX 1.39, pbrlib nodes only): what a renderer that takes MaterialX or USD shades
// with (docs/osl.md).
//
// The body is `oren_nayar_diffuse_bsdf` at roughness 0 (Lambert); each lobe a `generalized_schlick_bsdf`
// with the lobe's alphas as its roughness and its weight: a generalized Schlick lobe with color0 = f0,
// color90 = f90 and its exponent; an F82-tint lobe as the generalized Schlick lobe nearest it
// (without_f82, model/closures.h), since MaterialX's OSL generator drops color82, or, with `color82`,
// exactly: color0 = f0, color82 = the closure's tint (f82 over Schlick's value at acos(1/7)), color90 = 1,
// exponent 5. An anisotropic lobe's tangent is the surface tangent turned about the normal by the lobe's
// angle (`rotate3d`); a lobe that follows the view (format 6) has its tangent and its alpha across the view
// from `viewdirection` and `normal` nodes, as the OSL material computes them. The coat is one more
// generalized_schlick_bsdf (grey f0, Schlick). All summed by `add` into a `surface` and a `surfacematerial`
// named after the material. The document's `colorspace` is the LUT's working space (MaterialX's standard name
// where it is one of them, lin_rec709 for a LUT baked without --working-space).
#pragma once

#include <string>

#include "lut/lut.h"

namespace facetfit {

// The document's text. `name` must be a valid MaterialX name (letters, digits, underscores; not starting
// with a digit): materialx_name() makes one.
std::string materialx_document(const std::string& name, const Lut& lut, bool color82 = false);

// `stem` as a MaterialX element name: other characters become underscores, a leading digit gets one before it.
std::string materialx_name(const std::string& stem);

// A UsdShade material (USD ASCII) named `name` that references the MaterialX document `mtlx_file` (a path
// relative to the USD file) at </MaterialX/Materials/NAME>, where USD's MaterialX file format (usdMtlx) puts
// its material, and carries a UsdPreviewSurface fallback for renderers without MaterialX: the production
// closures' body as diffuse colour, their lobes' summed F(0) as specular colour (specular workflow), the
// first lobe's roughness (sqrt of its alpha: the preview surface squares it) and the coat. Colours carry
// the LUT's working space as their colorSpace, USD's name for it where USD has one (lin_rec709_scene,
// lin_ap1_scene for ACEScg, ...), else MaterialX's (materialx_colorspace).
std::string usd_document(const std::string& name, const std::string& mtlx_file, const Lut& lut);

// A working space's name as a MaterialX document names it: MaterialX's standard name where the space is one of
// them (matched without case and punctuation: "ACEScg" is "acescg"), else as given.
std::string materialx_colorspace(const std::string& space);

}  // namespace facetfit
