// facetfit.h: the tabulated microfacet model of a facetfit LUT in OSL (docs/lut-format.md, docs/osl.md).
//
// The same maths as lib/model/tabulated.cpp, reading the LUT only through texture lookups at texel
// centres with explicit "interp" "linear", "wrap" "clamp" (OSL's defaults would filter and fade a one-row
// table) and the metadata through gettextureinfo. Directions are in the local frame (z = normal), both
// pointing away from the surface: i toward the light, o toward the viewer (Cycles' I is o in world space).

#ifndef FACETFIT_H
#define FACETFIT_H

#define FACETFIT_PI 3.14159265358979323846

// Rows of the LUT image.
#define FACETFIT_NDF_ROW 0
#define FACETFIT_SIGMA_ROW 1
#define FACETFIT_FRESNEL_ROW 2
#define FACETFIT_SAMPLING_ROW 3

struct FacetfitLut {
  string file;
  int width;
  int height;
  int resolution;  // R: nodes 0..R
  int smith;       // 0 masking, 1 correlated, 2 separable
  int sampling;    // sampling rows present
  color body;      // the body's albedo at normal incidence (format 2; black in format 1)
  float body_exponent;  // its Minnaert exponent k (format 4; 1, Lambert, before): lib/model/body.h
  float coat_alpha;  // GGX clear coat over it, grey Schlick f0; alpha 0: none
  float coat_f0;
  float weight_lobe;  // probabilities of the sampler's parts: lobe, body, then coat (lib/model/tabulated.h)
  float weight_body;
  // The artist's stretch of the lobe (lib/model/stretch.h): slopes scaled by (stretch_x, stretch_y) along
  // axes turned by the rotation (its cosine and sine) about the normal; (1, 1): the LUT as fitted.
  float stretch_x;
  float stretch_y;
  float rotation_cos;
  float rotation_sin;
  int ok;
};

// The LUT's Smith model (0 masking, 1 correlated, 2 separable) and recommended representation (0
// tabulated, 1 ggx, 2 beckmann, 3 closures): the integer attributes, or the string ones for renderers that
// read strings (Cycles' OSL returns string attributes empty; LUTs before the integers have only strings);
// -1 when neither says.
int facetfit_code(string file, string attribute, string name0, string name1, string name2, string name3) {
  int code = -1;
  if (gettextureinfo(file, concat("facetfit:", attribute, "_code"), code)) return code;
  string name = "";
  gettextureinfo(file, concat("facetfit:", attribute), name);
  return name == name0 ? 0 : (name == name1 ? 1 : (name == name2 ? 2 : (name != "" && name == name3 ? 3 : -1)));
}

int facetfit_smith_code(string file) { return facetfit_code(file, "smith", "masking", "correlated", "separable", ""); }
int facetfit_representation_code(string file) { return facetfit_code(file, "representation", "tabulated", "ggx", "beckmann", "closures"); }


// ---- accurate angles ----
// OSL renderers may compile acos, atan2, sin and cos to fast approximations (Cycles' OSL: acos off by up
// to 9e-5 rad, cos by 6e-6), too coarse for the grid near the normal, where the first interval spans
// 1.9e-4 rad. These use only +, *, / and sqrt; they agree with the C++ library's double maths to float
// precision (tests/osl/test_osl_model.cpp).

// atan(x) for x in [0, 1]: Abramowitz & Stegun 4.4.49, |error| <= 2e-8.
float facetfit_atan_unit(float x) {
  float x2 = x * x;
  float p = 0.0028662257;
  p = p * x2 - 0.0161657367;
  p = p * x2 + 0.0429096138;
  p = p * x2 - 0.0752896400;
  p = p * x2 + 0.1065626393;
  p = p * x2 - 0.1420889944;
  p = p * x2 + 0.1999355085;
  p = p * x2 - 0.3333314528;
  return x * (1.0 + p * x2);
}

// The angle in [0, pi] of the point (c, s), s >= 0: atan2(s, c).
float facetfit_angle(float s, float c) {
  if (s <= 0.0 && c <= 0.0) return c < 0.0 ? FACETFIT_PI : 0.0;
  float a = abs(c) >= s ? facetfit_atan_unit(s / abs(c)) : 0.5 * FACETFIT_PI - facetfit_atan_unit(abs(c) / s);
  return c >= 0.0 ? a : FACETFIT_PI - a;
}

// Polar angle of a direction from +z (the normal).
float facetfit_theta(vector w) { return facetfit_angle(sqrt(w[0] * w[0] + w[1] * w[1]), w[2]); }

// acos(x): Abramowitz & Stegun 4.4.46 on [0, 1], |error| <= 2e-8, mirrored for x < 0.
float facetfit_acos(float x_in) {
  float x = clamp(abs(x_in), 0.0, 1.0);
  float p = -0.0012624911;
  p = p * x + 0.0066700901;
  p = p * x - 0.0170881256;
  p = p * x + 0.0308918810;
  p = p * x - 0.0501743046;
  p = p * x + 0.0889789874;
  p = p * x - 0.2145988016;
  p = p * x + 1.5707963050;
  float a = sqrt(1.0 - x) * p;
  return x_in >= 0.0 ? a : FACETFIT_PI - a;
}

// Azimuth in (-pi, pi] of (x, y).
float facetfit_azimuth(float x, float y) {
  float a = facetfit_angle(abs(y), x);
  return y >= 0.0 ? a : -a;
}

// sin and cos of x in [-2 pi, 2 pi]: reduced to [-pi/4, pi/4] by quarter turns, then Taylor series to
// x^11 and x^12 (error below 1e-11 before float rounding).
void facetfit_sincos(float x, output float s, output float c) {
  float k = floor(x / (0.5 * FACETFIT_PI) + 0.5);
  float r = x - k * (0.5 * FACETFIT_PI), r2 = r * r;
  float sr = r * (1.0 + r2 * (-1.0 / 6.0 + r2 * (1.0 / 120.0 + r2 * (-1.0 / 5040.0 + r2 * (1.0 / 362880.0 - r2 / 39916800.0)))));
  float cr = 1.0 + r2 * (-0.5 + r2 * (1.0 / 24.0 + r2 * (-1.0 / 720.0 + r2 * (1.0 / 40320.0 + r2 * (-1.0 / 3628800.0 + r2 / 479001600.0)))));
  int q = int(k) % 4;
  if (q < 0) q += 4;
  s = q == 0 ? sr : (q == 1 ? cr : (q == 2 ? -sr : -cr));
  c = q == 0 ? cr : (q == 1 ? -sr : (q == 2 ? -cr : sr));
}

// 1 - cos(theta) = 2 sin^2(theta / 2) for theta in [0, pi/2], without cancellation near 0.
float facetfit_one_minus_cos(float theta) {
  float s, c;
  facetfit_sincos(0.5 * theta, s, c);
  return 2.0 * s * s;
}

// The value stored at texel x of a row (the R channel), exactly: a lookup at the texel's centre.
float facetfit_texel(FacetfitLut lut, int row, int x) {
  float s = (x + 0.5) / lut.width, t = (row + 0.5) / lut.height;
  return texture(lut.file, s, t, "interp", "linear", "wrap", "clamp", "width", 0.0);
}

// The uniform Catmull-Rom spline in u through the nodes of a row, at theta; ghost nodes as in
// ThetaGrid::stencil: node -1 mirrors node 1, node R+1 continues the last interval linearly.
float facetfit_spline(FacetfitLut lut, int row, float theta) {
  int R = lut.resolution;
  float x = min(sqrt(max(theta, 0.0) / (0.5 * FACETFIT_PI)), 1.0) * R;
  int j = min(int(floor(x)), R - 1);
  float t = x - j, t2 = t * t, t3 = t2 * t;
  float w0 = 0.5 * (-t + 2.0 * t2 - t3), w1 = 0.5 * (2.0 - 5.0 * t2 + 3.0 * t3);
  float w2 = 0.5 * (t + 4.0 * t2 - 3.0 * t3), w3 = 0.5 * (t3 - t2);
  int i0 = j == 0 ? 1 : j - 1;
  int i3 = j + 2;
  if (i3 > R) {
    w2 += 2.0 * w3;
    w1 -= w3;
    w3 = 0.0;
    i3 = R;
  }
  return w0 * facetfit_texel(lut, row, i0) + w1 * facetfit_texel(lut, row, j) + w2 * facetfit_texel(lut, row, j + 1) +
         w3 * facetfit_texel(lut, row, i3);
}

// ---- the artist's stretch (lib/model/stretch.h): the tables stay, directions are transformed ----

int facetfit_stretched(FacetfitLut lut) { return lut.stretch_x != 1.0 || lut.stretch_y != 1.0; }

// The LUT with its lobe's slopes stretched by (x, y) along axes at `rotation` radians from the tangent:
// roughness in proportion (textures may drive all three per shading point).
FacetfitLut facetfit_stretch(FacetfitLut lut_in, float x, float y, float rotation) {
  FacetfitLut lut = lut_in;
  lut.stretch_x = x;
  lut.stretch_y = y;
  facetfit_sincos(rotation, lut.rotation_sin, lut.rotation_cos);
  return lut;
}

// Into and out of the stretch's frame (its x axis at the rotation).
vector facetfit_to_stretch(FacetfitLut lut, vector v) {
  return vector(lut.rotation_cos * v[0] + lut.rotation_sin * v[1], -lut.rotation_sin * v[0] + lut.rotation_cos * v[1], v[2]);
}
vector facetfit_from_stretch(FacetfitLut lut, vector v) {
  return vector(lut.rotation_cos * v[0] - lut.rotation_sin * v[1], lut.rotation_sin * v[0] + lut.rotation_cos * v[1], v[2]);
}
// A direction as the measured lobe sees it; a stretched normal as the measured lobe's, and back.
vector facetfit_stretch_direction(FacetfitLut lut, vector w) {
  vector f = facetfit_to_stretch(lut, w);
  return normalize(vector(lut.stretch_x * f[0], lut.stretch_y * f[1], f[2]));
}
vector facetfit_measured_normal(FacetfitLut lut, vector h) {
  vector f = facetfit_to_stretch(lut, h);
  return normalize(vector(f[0] / lut.stretch_x, f[1] / lut.stretch_y, f[2]));
}
vector facetfit_stretched_normal(FacetfitLut lut, vector m) {
  return facetfit_from_stretch(lut, normalize(vector(lut.stretch_x * m[0], lut.stretch_y * m[1], m[2])));
}

// D of a unit half vector h: P(slopes / s) / (s_x s_y cos^4) when stretched.
float facetfit_D(FacetfitLut lut, vector h) {
  if (h[2] <= 0.0) return 0.0;
  if (!facetfit_stretched(lut)) return max(0.0, facetfit_spline(lut, FACETFIT_NDF_ROW, facetfit_theta(h)));
  vector m = facetfit_measured_normal(lut, h);
  float r = m[2] / h[2], r2 = r * r;
  return max(0.0, facetfit_spline(lut, FACETFIT_NDF_ROW, facetfit_theta(m))) * r2 * r2 / (lut.stretch_x * lut.stretch_y);
}

// Smith masking G1 = cos / sigma of a unit direction w (stretch-invariant: of the transformed direction).
float facetfit_G1(FacetfitLut lut, vector w_in) {
  if (w_in[2] <= 0.0) return 0.0;
  vector w = facetfit_stretched(lut) ? facetfit_stretch_direction(lut, w_in) : w_in;
  float s = facetfit_spline(lut, FACETFIT_SIGMA_ROW, facetfit_theta(w));
  return s > w[2] ? w[2] / s : 1.0;
}

float facetfit_G2(FacetfitLut lut, float g1_i, float g1_o) {
  if (lut.smith == 0) return min(g1_i, g1_o);
  if (lut.smith == 2) return g1_i * g1_o;
  float den = g1_i + g1_o - g1_i * g1_o;
  return den > 0.0 ? g1_i * g1_o / den : 0.0;
}

// The RGB Fresnel curve: 90 texels at theta_d = x degrees, linear between them, constant past 89.
color facetfit_fresnel(FacetfitLut lut, float theta_d) {
  float x = clamp(theta_d / (0.5 * FACETFIT_PI) * 90.0, 0.0, 89.0);
  float s = (x + 0.5) / lut.width, t = (FACETFIT_FRESNEL_ROW + 0.5) / lut.height;
  return texture(lut.file, s, t, "interp", "linear", "wrap", "clamp", "width", 0.0);
}

// Rec.709 relative luminance, as core/vec.h's luminance().
float facetfit_luminance(color c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

// Opens a LUT (format 1 or 2): its size and metadata, the body and coat of format 2. ok = 0 when the
// file is missing, is not a facetfit LUT, or does not say its Smith model in a way this renderer can read.
FacetfitLut facetfit_open(string file) {
  FacetfitLut lut;
  lut.file = file;
  lut.ok = 0;
  lut.body = color(0);
  lut.body_exponent = 1.0;
  lut.coat_alpha = 0.0;
  lut.coat_f0 = 0.0;
  lut.weight_lobe = 1.0;
  lut.weight_body = 0.0;
  lut.stretch_x = 1.0;
  lut.stretch_y = 1.0;
  lut.rotation_cos = 1.0;
  lut.rotation_sin = 0.0;
  int res[2] = {0, 0};
  int version = 0, resolution = 0, sampling = 0;
  if (gettextureinfo(file, "resolution", res) && gettextureinfo(file, "facetfit:format_version", version) &&
      gettextureinfo(file, "facetfit:resolution", resolution) && version >= 1 && version <= 6) {
    // Version 3 appends the anisotropic lobe's rows below version 2's, which read as before: the shaders
    // render the isotropic representation (the rows' t comes from the image's height, read here). Version
    // 4 adds the body's exponent, version 5 the closures (the material shader's), version 6 their lobes along the view.
    gettextureinfo(file, "facetfit:sampling", sampling);
    lut.width = res[0];
    lut.height = res[1];
    lut.resolution = resolution;
    lut.sampling = sampling;
    lut.smith = facetfit_smith_code(file);
    lut.ok = lut.smith >= 0 && lut.smith <= 2;
    if (version >= 2) {
      gettextureinfo(file, "facetfit:body", lut.body);
      if (version >= 4) {
        gettextureinfo(file, "facetfit:body_exponent", lut.body_exponent);
        if (!(lut.body_exponent >= 1.0 && lut.body_exponent <= 3.0)) lut.ok = 0;  // the C++ reader refuses it too
      }
      gettextureinfo(file, "facetfit:coat_alpha", lut.coat_alpha);
      gettextureinfo(file, "facetfit:coat_f0", lut.coat_f0);
      if (!(lut.coat_alpha > 0.0 && lut.coat_f0 > 0.0)) lut.coat_alpha = lut.coat_f0 = 0.0;
    }
    // The sampler's parts by albedo, as the library weighs them: lobe F(0), body, coat f0; the lobe and
    // the coat at least 0.1.
    float lobe = max(facetfit_luminance(facetfit_fresnel(lut, 0.0)), 0.1);
    float body = max(facetfit_luminance(lut.body), 0.0);
    float coat = lut.coat_alpha > 0.0 ? max(lut.coat_f0, 0.1) : 0.0;
    lut.weight_lobe = lobe / (lobe + body + coat);
    lut.weight_body = body / (lobe + body + coat);
  }
  return lut;
}

// ---- the clear coat: GGX, grey Schlick Fresnel, height-correlated Smith (lib/model/coat.h) ----

// sin^2 as x^2 + y^2, not 1 - z^2: near the normal, where a sharp coat lives, float has no digits left
// in 1 - z^2 (the arguments are unit vectors).
float facetfit_coat_D(float alpha, vector h) {
  if (h[2] <= 0.0) return 0.0;
  float a2 = alpha * alpha, den = a2 * h[2] * h[2] + (h[0] * h[0] + h[1] * h[1]);  // cos^2 (a^2 + tan^2)
  return a2 / (FACETFIT_PI * den * den);
}

float facetfit_coat_lambda(float alpha, vector w) {
  return 0.5 * (sqrt(1.0 + alpha * alpha * (w[0] * w[0] + w[1] * w[1]) / (w[2] * w[2])) - 1.0);
}

float facetfit_coat_eval(FacetfitLut lut, vector o, vector i) {
  if (lut.coat_alpha <= 0.0 || i[2] <= 0.0 || o[2] <= 0.0) return 0.0;
  vector h = normalize(i + o);
  float m = 1.0 - clamp(dot(i, h), 0.0, 1.0), m5 = m * m * m * m * m;
  float fresnel = lut.coat_f0 + (1.0 - lut.coat_f0) * m5;
  float g2 = 1.0 / (1.0 + facetfit_coat_lambda(lut.coat_alpha, i) + facetfit_coat_lambda(lut.coat_alpha, o));
  return fresnel * facetfit_coat_D(lut.coat_alpha, h) * g2 / (4.0 * i[2] * o[2]);
}

// f(o, i) in 1/sr: body + lobe + coat (o toward the viewer, i toward the light, as every function here).
color facetfit_eval(FacetfitLut lut, vector o, vector i) {
  if (i[2] <= 0.0 || o[2] <= 0.0) return color(0);
  vector h = normalize(i + o);
  float g2 = facetfit_G2(lut, facetfit_G1(lut, i), facetfit_G1(lut, o));
  float theta_d = facetfit_angle(length(cross(i, h)), dot(i, h));
  // Minnaert's body: (k + 1) / 2 (cos_i cos_o)^(k - 1) times Lambert's
  float k = lut.body_exponent, minnaert = k == 1.0 ? 1.0 : 0.5 * (k + 1.0) * pow(i[2] * o[2], k - 1.0);
  return lut.body * (minnaert / FACETFIT_PI) + facetfit_fresnel(lut, theta_d) * (facetfit_D(lut, h) * g2 / (4.0 * i[2] * o[2])) +
         color(facetfit_coat_eval(lut, o, i));
}

// ---- sampling the visible normals (docs/sampling.md) ----

// Interval j and fraction t of the polar angle of w on the grid.
void facetfit_locate(FacetfitLut lut, vector w, output int j, output float t) {
  float x = min(sqrt(facetfit_theta(w) / (0.5 * FACETFIT_PI)), 1.0) * lut.resolution;
  j = min(int(floor(x)), lut.resolution - 1);
  t = x - j;
}

// 1 - cos(theta_j) of grid node j: the sampling works in it, as cos itself has no float resolution left
// near the normal.
float facetfit_node_one_minus_cos(FacetfitLut lut, int j) {
  float u = float(j) / lut.resolution;
  return facetfit_one_minus_cos(u * u * 0.5 * FACETFIT_PI);
}

float facetfit_cdf(FacetfitLut lut, int slice, int node) { return facetfit_texel(lut, FACETFIT_SAMPLING_ROW + slice, node); }

float facetfit_phi_integral(float a, float b) {
  if (a <= b) return 2.0 * FACETFIT_PI * b;
  return 2.0 * (sqrt(a * a - b * b) + b * facetfit_acos(-b / a));
}

// Density of the measured lobe's visible normals h seen from o, per steradian of h.
float facetfit_measured_visible_normal_pdf(FacetfitLut lut, vector o, vector h) {
  float oh = dot(o, h);
  if (o[2] <= 0.0 || h[2] <= 0.0 || oh <= 0.0 || !lut.sampling) return 0.0;
  int vj, nj;
  float vt, nt;
  facetfit_locate(lut, o, vj, vt);
  facetfit_locate(lut, h, nj, nt);
  float band = facetfit_node_one_minus_cos(lut, nj + 1) - facetfit_node_one_minus_cos(lut, nj);
  if (band <= 0.0) return 0.0;
  float m0 = facetfit_cdf(lut, vj, nj + 1) - facetfit_cdf(lut, vj, nj);
  float m1 = facetfit_cdf(lut, vj + 1, nj + 1) - facetfit_cdf(lut, vj + 1, nj);
  float mass = (1.0 - vt) * m0 + vt * m1;
  float sin_o = sqrt(o[0] * o[0] + o[1] * o[1]), sin_h = sqrt(h[0] * h[0] + h[1] * h[1]);
  float total = facetfit_phi_integral(sin_o * sin_h, o[2] * h[2]);
  return total > 0.0 ? mass / band * oh / total : 0.0;
}

// Density of the visible normals h seen from o, per steradian of h; stretched, the measured lobe's seen
// from the transformed view at the measured normal, times the normals' Jacobian.
float facetfit_visible_normal_pdf(FacetfitLut lut, vector o, vector h) {
  if (!facetfit_stretched(lut)) return facetfit_measured_visible_normal_pdf(lut, o, h);
  if (o[2] <= 0.0 || h[2] <= 0.0 || dot(o, h) <= 0.0) return 0.0;
  vector m = facetfit_measured_normal(lut, h);
  float r = m[2] / h[2];
  return facetfit_measured_visible_normal_pdf(lut, facetfit_stretch_direction(lut, o), m) * r * r * r / (lut.stretch_x * lut.stretch_y);
}

// Density of the lobe's part of facetfit_sample alone, per steradian of i.
float facetfit_lobe_pdf(FacetfitLut lut, vector o, vector i) {
  if (i[2] <= 0.0 || o[2] <= 0.0) return 0.0;
  vector h = normalize(o + i);
  float oh = dot(o, h);
  return oh > 0.0 ? facetfit_visible_normal_pdf(lut, o, h) / (4.0 * oh) : 0.0;
}

// The coat's visible normals: G1(o) D(h) / (4 cos(theta_o)) per steradian of i.
float facetfit_coat_pdf(FacetfitLut lut, vector o, vector i) {
  if (lut.coat_alpha <= 0.0 || i[2] <= 0.0 || o[2] <= 0.0) return 0.0;
  vector h = normalize(o + i);
  if (dot(o, h) <= 0.0) return 0.0;
  return facetfit_coat_D(lut.coat_alpha, h) / ((1.0 + facetfit_coat_lambda(lut.coat_alpha, o)) * 4.0 * o[2]);
}

// Density of facetfit_sample per steradian of i: the mixture of its three parts.
float facetfit_pdf(FacetfitLut lut, vector o, vector i) {
  if (i[2] <= 0.0 || o[2] <= 0.0 || !lut.sampling) return 0.0;
  return lut.weight_lobe * facetfit_lobe_pdf(lut, o, i) + lut.weight_body * i[2] / FACETFIT_PI +
         (1.0 - lut.weight_lobe - lut.weight_body) * facetfit_coat_pdf(lut, o, i);
}

// phi in (-pi, pi] with density proportional to max(0, a cos(phi) + b).
float facetfit_sample_phi(float a, float b, float u_in) {
  float phi_max = a <= b ? FACETFIT_PI : facetfit_acos(-b / a);
  float sgn = u_in < 0.5 ? -1.0 : 1.0;
  float u = u_in < 0.5 ? 2.0 * u_in : 2.0 * u_in - 1.0;
  // The CDF a sin(phi) + b phi at phi_max; sin(phi_max) = sqrt(1 - (b / a)^2) where a > b.
  float total = a <= b ? b * phi_max : a * sqrt(max(0.0, 1.0 - (b / a) * (b / a))) + b * phi_max;
  if (total <= 0.0) return sgn * u * FACETFIT_PI;
  float target = u * total, lo = 0.0, hi = phi_max, phi = u * phi_max;
  for (int it = 0; it < 40; ++it) {
    float sp, cp;
    facetfit_sincos(phi, sp, cp);
    float f = a * sp + b * phi - target;
    if (f > 0.0) hi = phi; else lo = phi;
    float df = a * cp + b;
    float next = df > 0.0 ? phi - f / df : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    float step = abs(next - phi);
    phi = next;
    if (step < 1e-7) break;
  }
  return sgn * phi;
}

// A visible normal of the measured lobe seen from o.
vector facetfit_measured_visible_normal(FacetfitLut lut, vector o, float u1_in, float u2) {
  int vj;
  float vt;
  facetfit_locate(lut, o, vj, vt);
  int slice = vj;
  float u1 = u1_in;
  if (u1 < 1.0 - vt) {
    u1 /= 1.0 - vt;
  } else {
    u1 = (u1 - (1.0 - vt)) / vt;
    slice = vj + 1;
  }
  u1 = clamp(u1, 0.0, 0.99999994);
  // The last node whose CDF is <= u1: binary search over nodes 0..R.
  int lo = 0, hi = lut.resolution;
  while (hi - lo > 1) {
    int mid = (lo + hi) / 2;
    if (facetfit_cdf(lut, slice, mid) <= u1) lo = mid; else hi = mid;
  }
  int j = lo;
  float c0 = facetfit_cdf(lut, slice, j), m = facetfit_cdf(lut, slice, j + 1) - c0;
  float frac = m > 0.0 ? clamp((u1 - c0) / m, 0.0, 1.0) : 0.5;
  float om0 = facetfit_node_one_minus_cos(lut, j);
  float om_h = om0 + frac * (facetfit_node_one_minus_cos(lut, j + 1) - om0);  // 1 - cos(theta_h)
  float cos_h = 1.0 - om_h, sin_h = sqrt(max(0.0, om_h * (2.0 - om_h)));
  float sin_o = sqrt(o[0] * o[0] + o[1] * o[1]);
  float phi = facetfit_sample_phi(sin_o * sin_h, o[2] * cos_h, u2) + (sin_o > 0.0 ? facetfit_azimuth(o[0], o[1]) : 0.0);
  float sin_phi, cos_phi;
  facetfit_sincos(phi, sin_phi, cos_phi);
  return vector(sin_h * cos_phi, sin_h * sin_phi, cos_h);
}

// The lobe's part: its visible normals (stretched: the measured lobe's seen from the transformed view,
// stretched back), o reflected about them.
int facetfit_sample_lobe(FacetfitLut lut, vector o, float u1, float u2, output vector i) {
  vector h = facetfit_stretched(lut) ? facetfit_stretched_normal(lut, facetfit_measured_visible_normal(lut, facetfit_stretch_direction(lut, o), u1, u2))
                                     : facetfit_measured_visible_normal(lut, o, u1, u2);
  i = 2.0 * dot(o, h) * h - o;
  return i[2] > 0.0;
}

// The coat's part: GGX visible normals (Heitz 2018, as lib/model/coat.h), o reflected about them.
int facetfit_sample_coat(FacetfitLut lut, vector o, float u1, float u2, output vector i) {
  float a = lut.coat_alpha;
  vector v = normalize(vector(a * o[0], a * o[1], o[2]));
  float len2 = v[0] * v[0] + v[1] * v[1];
  vector t1 = len2 > 0.0 ? vector(-v[1], v[0], 0.0) / sqrt(len2) : vector(1, 0, 0);
  vector t2 = cross(v, t1);
  float sp, cp;
  facetfit_sincos(2.0 * FACETFIT_PI * u2, sp, cp);
  float r = sqrt(u1), p1 = r * cp, s = 0.5 * (1.0 + v[2]);
  float p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * r * sp;
  vector n = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * v;
  vector h = normalize(vector(a * n[0], a * n[1], max(0.0, n[2])));
  i = 2.0 * dot(o, h) * h - o;
  return i[2] > 0.0;
}

// Draws i for o from two uniform numbers: u1 picks the part (lobe, body, coat) with the LUT's weights
// and is rescaled within it. Returns 0 when no direction (below the horizon, no tables).
int facetfit_sample(FacetfitLut lut, vector o, float u1_in, float u2, output vector i, output float pdf) {
  if (o[2] <= 0.0 || !lut.sampling) return 0;
  float u1 = u1_in;
  int found = 0;
  if (u1 < lut.weight_lobe) {
    found = facetfit_sample_lobe(lut, o, u1 / lut.weight_lobe, u2, i);
  } else if (u1 - lut.weight_lobe < lut.weight_body) {
    float r = sqrt((u1 - lut.weight_lobe) / lut.weight_body), sp, cp;  // the cosine
    facetfit_sincos(2.0 * FACETFIT_PI * u2, sp, cp);
    i = vector(r * cp, r * sp, sqrt(max(0.0, 1.0 - r * r)));
    found = i[2] > 0.0;
  } else {
    float w = 1.0 - lut.weight_lobe - lut.weight_body;
    found = facetfit_sample_coat(lut, o, clamp((u1 - lut.weight_lobe - lut.weight_body) / w, 0.0, 0.99999994), u2, i);
  }
  if (!found) return 0;
  pdf = facetfit_pdf(lut, o, i);
  return pdf > 0.0;
}

// The local frame of a shading point: z = N, x = T, where no tangent is given: core/frame.h's Frame(n)
// (Duff et al. 2017's branchless basis), computed on the normal written in facetfit's y-up world, so that a
// stretched or anisotropic lobe without a tangent lies as in facetfit's renderer. The shader's world is
// taken z-up (Blender's: its (x, y, z) is facetfit's (x, z, -y)); in a y-up renderer pass `tangent`.
void facetfit_frame(normal Nn, output vector T, output vector B) {
  vector n = vector(Nn[0], Nn[2], -Nn[1]);  // facetfit's world
  float sign = n[2] >= 0.0 ? 1.0 : -1.0;  // copysign(1, n.z), as std::copysign (-0 aside)
  float a = -1.0 / (sign + n[2]), c = n[0] * n[1] * a;
  vector t = vector(1.0 + sign * n[0] * n[0] * a, sign * c, -sign * n[0]);
  vector b = vector(c, sign + n[1] * n[1] * a, -n[1]);
  T = vector(t[0], -t[2], t[1]);  // back to the shader's world
  B = vector(b[0], -b[2], b[1]);
}

// The local frame with x along the surface projection of `along` (world space; an anisotropic or
// stretched lobe's axes follow it), or facetfit_frame's where that projection vanishes.
void facetfit_frame_along(normal Nn, vector along, output vector T, output vector B) {
  vector projected = along - Nn * dot(along, Nn);
  if (length(projected) > 1e-6) {
    T = normalize(projected);
    B = cross(Nn, T);
  } else {
    facetfit_frame(Nn, T, B);
  }
}

vector facetfit_to_local(vector v, vector T, vector B, normal Nn) { return vector(dot(v, T), dot(v, B), dot(v, Nn)); }
vector facetfit_to_world(vector v, vector T, vector B, normal Nn) { return v[0] * T + v[1] * B + v[2] * Nn; }

#endif  // FACETFIT_H
