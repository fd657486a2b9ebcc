#include "io/rgl.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/frame.h"
#include "core/quadrature_rules.h"
#include "io/tensor_file.h"

namespace facetfit {

namespace fs = std::filesystem;

namespace {

// RGL's files are Mitsuba tensor files: io/tensor_file.h parses them, this file says what their fields mean.

// Far above any RGL material file (the RGB isotropic ones are 0.66 MB); guards the one allocation
// sized from outside, the file buffer.
constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t(1) << 30;

// The file's bytes, for io/tensor_file.h to parse.
std::vector<unsigned char> slurp(const std::string& path) {
  std::error_code ec;
  const auto status = fs::status(path, ec);
  if (!fs::exists(status)) fail(path, "cannot open: no such file");
  if (fs::is_directory(status)) fail(path, "is a folder, not an RGL .bsdf file");
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) fail(path, "cannot read its size: " + ec.message());
  if (size == 0) fail(path, "file is empty");
  if (size > kMaxFileBytes)
    fail(path, "file is " + std::to_string(size) + " bytes, larger than any RGL material file (limit " +
                   std::to_string(kMaxFileBytes) + ")");

  struct Closer {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::unique_ptr<std::FILE, Closer> file(std::fopen(path.c_str(), "rb"));
  if (!file) fail(path, std::string("cannot open: ") + std::strerror(errno));
  std::vector<unsigned char> bytes(static_cast<std::size_t>(size));
  if (std::fread(bytes.data(), 1, bytes.size(), file.get()) != bytes.size())
    fail(path, "read error (file changed while reading?)");
  return bytes;
}

// A field's shape as messages write it.
std::string dims(const TensorField& f) { return tensor_shape_string(f.shape); }

// A value table on the nodes of a uniform nx x ny grid over [0,1]^2, rows of nx along x.
struct Grid {
  std::size_t nx = 0, ny = 0;
  std::vector<double> v;
};

// Position between nodes k and k + 1 of a grid, t in [0, 1].
struct Segment {
  std::size_t k;
  double t;
};

Segment uniform_segment(double u, std::size_t n) {
  const double g = clamp(u, 0.0, 1.0) * double(n - 1);
  const std::size_t k = std::min(static_cast<std::size_t>(g), n - 2);
  return {k, g - double(k)};
}

// The patch of an nx x ny grid holding (u0, u1), and the point's place in it: found once, it
// interpolates any number of tables on the same grid.
struct Patch {
  std::size_t at, nx;  // the patch's first node, row-major; the row length
  Segment x, y;
  double operator()(const double* v) const {
    const double* r0 = v + at;
    const double* r1 = r0 + nx;
    return (1.0 - y.t) * ((1.0 - x.t) * r0[0] + x.t * r0[1]) + y.t * ((1.0 - x.t) * r1[0] + x.t * r1[1]);
  }
};

Patch patch_at(std::size_t nx, std::size_t ny, double u0, double u1) {
  const Segment x = uniform_segment(u0, nx), y = uniform_segment(u1, ny);
  return {y.k * nx + x.k, nx, x, y};
}

double bilinear(const Grid& g, double u0, double u1) { return patch_at(g.nx, g.ny, u0, u1)(g.v.data()); }

// The sample-space coordinate of an elevation: theta = (pi/2) u^2 concentrates resolution near the
// normal, where specular peaks live.
double theta_to_u(double theta) { return std::sqrt(std::max(0.0, theta) / (0.5 * kPi)); }

// Angle from +z of a unit vector; unlike acos(z), accurate near the normal.
double elevation(const Vec3& d) {
  const double chord = std::sqrt(d.x * d.x + d.y * d.y + (d.z - 1.0) * (d.z - 1.0));
  return 2.0 * std::asin(std::min(1.0, 0.5 * chord));
}

// Linear interpolation of values on the nodes of a uniform grid over [0, 1].
double lerp_nodes(const std::vector<double>& v, double u) {
  const Segment s = uniform_segment(u, v.size());
  return (1.0 - s.t) * v[s.k] + s.t * v[s.k + 1];
}

// Mean over the rows of a grid (the phi axis) of the bilinear interpolant: the trapezoid rule.
std::vector<double> phi_average(const Grid& g) {
  std::vector<double> out(g.nx, 0.0);
  for (std::size_t y = 0; y < g.ny; ++y) {
    const double w = (y == 0 || y + 1 == g.ny ? 0.5 : 1.0) / double(g.ny - 1);
    for (std::size_t x = 0; x < g.nx; ++x) out[x] += w * g.v[y * g.nx + x];
  }
  return out;
}

// A five-point Gauss-Legendre rule on [0, 1]: nodes x, weights w.
struct GaussRule {
  std::vector<double> x, w;
  GaussRule() { gauss_legendre(5, x, w); }
};

// Position of a parameter value among its nodes: nodes k and k + 1 and the weight of k + 1, clamped
// outside them (a single node: weight 0).
Segment node_segment(const std::vector<double>& nodes, double v) {
  if (nodes.size() == 1) return {0, 0.0};
  const auto it = std::upper_bound(nodes.begin(), nodes.end(), v);
  const std::size_t above = static_cast<std::size_t>(it - nodes.begin());
  const std::size_t k = std::min(above == 0 ? 0 : above - 1, nodes.size() - 2);
  return {k, clamp((v - nodes[k]) / (nodes[k + 1] - nodes[k]), 0.0, 1.0)};
}

// Bilinear blend of the slices at the parameters (phi_i, theta_i), as Mitsuba's conditioned Marginal2D
// interpolates every table (density and CDFs alike) between the bracketing parameter values; slices are
// stored phi_i-major. Up to four slices; one or two for the isotropic files of the database.
struct SliceBlend {
  std::array<std::size_t, 4> slice{};
  std::array<double, 4> weight{};
  int n = 0;

  double operator()(const double* table, std::size_t slice_size, std::size_t index) const {
    double v = 0.0;
    for (int k = 0; k < n; ++k) v += weight[std::size_t(k)] * table[slice[std::size_t(k)] * slice_size + index];
    return v;
  }
};

SliceBlend blend_for(const std::vector<double>& phi_nodes, double phi, const std::vector<double>& theta_nodes, double theta) {
  const Segment p = node_segment(phi_nodes, phi), t = node_segment(theta_nodes, theta);
  SliceBlend b;
  for (int a = 0; a < 2; ++a)
    for (int c = 0; c < 2; ++c) {
      const double w = (a ? p.t : 1.0 - p.t) * (c ? t.t : 1.0 - t.t);
      if (w == 0.0) continue;
      b.slice[std::size_t(b.n)] = (p.k + std::size_t(a)) * theta_nodes.size() + t.k + std::size_t(c);
      b.weight[std::size_t(b.n++)] = w;
    }
  return b;
}

// Builds the CDFs of one slice of bilinear density (in units of grid patches) and normalizes all
// three arrays; returns the total before normalization.
double build_warp_slice(double* pdf, double* cond, double* marg, std::size_t nx, std::size_t ny) {
  for (std::size_t y = 0; y < ny; ++y) {
    const double* row = pdf + y * nx;
    double* c = cond + y * nx;
    c[0] = 0.0;
    for (std::size_t x = 1; x < nx; ++x) c[x] = c[x - 1] + 0.5 * (row[x - 1] + row[x]);
  }
  marg[0] = 0.0;
  for (std::size_t y = 1; y < ny; ++y) marg[y] = marg[y - 1] + 0.5 * (cond[y * nx - 1] + cond[(y + 1) * nx - 1]);
  const double total = marg[ny - 1];
  if (!(total > 0.0)) return total;
  const double inv = 1.0 / total;
  for (std::size_t k = 0; k < nx * ny; ++k) {
    pdf[k] *= inv;
    cond[k] *= inv;
  }
  for (std::size_t y = 0; y < ny; ++y) marg[y] *= inv;
  return total;
}

// The slices' parameter `name` (phi_i or theta_i), in radians: not empty, every value within [lo, hi]
// (`interval`, as messages write it), strictly increasing.
std::vector<double> read_slice_angles(const TensorFile& in, const std::string& name, double lo, double hi, const char* interval) {
  const TensorField& f = in.get(name, kTensorFloat32, 1);
  in.check(f.count >= 1, "field '" + name + "' is empty");
  std::vector<double> angles = in.floats(name, f);
  for (std::size_t k = 0; k < angles.size(); ++k) {
    const double v = angles[k];
    in.check(v >= lo && v <= hi, "field '" + name + "' has " + std::to_string(v) + " at element " + std::to_string(k) +
                                     ", outside " + interval);
    in.check(k == 0 || v > angles[k - 1], "field '" + name + "' is not strictly increasing at element " + std::to_string(k));
  }
  return angles;
}

// The symmetry an anisotropic file declares by the span of its phi_i (RglBsdf::Tables::reduction): 2 pi
// over the span, one of 1, 2 and 4.
int phi_reduction(const TensorFile& in, const std::vector<double>& phi_i) {
  const double span = phi_i.back() - phi_i.front();
  const int reduction = int(std::lround(2.0 * kPi / span));
  in.check(reduction == 1 || reduction == 2 || reduction == 4,
           "field 'phi_i' spans " + std::to_string(span) + " radians; an anisotropic file spans 2 pi, pi or pi/2");
  return reduction;
}

// The largest slice elevation below the horizon (RglBsdf::measured_elevation_limit); 0 without one.
double largest_below_horizon(const std::vector<double>& theta_i) {
  double limit = 0.0;
  for (const double v : theta_i)
    if (v < 0.5 * kPi - 1e-6) limit = std::max(limit, v);
  return limit;
}

// The file's description, without the NULs that pad it.
std::string read_description(const TensorFile& in) {
  const TensorField& desc = in.get("description", kTensorUInt8, 1);
  std::string text(reinterpret_cast<const char*>(in.data(desc)), desc.count);
  while (!text.empty() && text.back() == '\0') text.pop_back();
  return text;
}

// A table over the sample square of at least 2 x 2 nodes (interpolation needs them), its values all > 0
// (`positive`) or all >= 0.
Grid read_grid(const TensorFile& in, const char* name, bool positive) {
  const TensorField& f = in.get(name, kTensorFloat32, 2);
  in.check(f.shape[0] >= 2 && f.shape[1] >= 2,
           std::string("field '") + name + "' has shape " + dims(f) + "; interpolation needs at least 2 x 2");
  Grid g;
  g.ny = static_cast<std::size_t>(f.shape[0]);
  g.nx = static_cast<std::size_t>(f.shape[1]);
  g.v = in.floats(name, f);
  for (std::size_t k = 0; k < g.v.size(); ++k) {
    if (positive ? g.v[k] > 0.0 : g.v[k] >= 0.0) continue;
    fail(in.path(), std::string("field '") + name + "' has " + (positive ? "a non-positive" : "a negative") +
                        " value at element " + std::to_string(k));
  }
  return g;
}

// The optional luminance table: unused by eval (it drives importance sampling), but a file whose
// luminance disagrees in shape with its RGB table (`rgb`, already checked) is inconsistent.
void check_luminance(const TensorFile& in, const TensorField& rgb, const std::string& params) {
  if (!in.has("luminance")) return;
  const TensorField& lum = in.get("luminance", kTensorFloat32, 4);
  in.check(lum.shape[0] == rgb.shape[0] && lum.shape[1] == rgb.shape[1] && lum.shape[2] == rgb.shape[3] &&
               lum.shape[3] == rgb.shape[4],
           "field 'luminance' has shape " + dims(lum) + ", expected " + params + " x " + std::to_string(rgb.shape[3]) + " x " +
               std::to_string(rgb.shape[4]) + " to match 'rgb'");
}

// integral D cos d(omega) of a phi-averaged NDF on the nodes of u_theta, linear in u between them:
// 2 pi int_0^1 D(u) cos(theta) sin(theta) (d theta / du) du with theta = (pi/2) u^2, by a Gauss rule on
// each interval.
double projected_ndf_integral(const std::vector<double>& ndf_iso) {
  double integral = 0.0;
  const double du = 1.0 / double(ndf_iso.size() - 1);
  const GaussRule gauss;
  for (std::size_t x = 0; x + 1 < ndf_iso.size(); ++x) {
    for (std::size_t q = 0; q < gauss.x.size(); ++q) {
      const double s = gauss.x[q];
      const double u = (double(x) + s) * du;
      const double theta = 0.5 * kPi * u * u;
      const double d = (1.0 - s) * ndf_iso[x] + s * ndf_iso[x + 1];
      integral += du * gauss.w[q] * d * std::cos(theta) * std::sin(theta) * kPi * u;
    }
  }
  return 2.0 * kPi * integral;
}

}  // namespace

struct RglBsdf::Tables {
  std::string description;
  bool jacobian = true;
  std::vector<double> theta_i;  // incident elevations of the slices, strictly increasing
  double measured_limit = 0.0;  // the largest of them below pi/2 (RglBsdf::measured_elevation_limit)
  std::vector<double> phi_i;    // incident azimuths of the slices, strictly increasing
  // Mitsuba's reading of phi_i: more than two entries make the file anisotropic, its half-vector
  // azimuth absolute rather than measured from the slice direction's plane. phi_i spanning 2 pi / r
  // declares a symmetry: r = 2 a half turn about the normal, r = 4 mirrors about both axes; both
  // directions are carried into the span (by that turn or those mirrors) before the lookup.
  bool isotropic = true;
  int reduction = 1;

  Grid ndf;    // D over (u_theta, u_phi) of the half vector
  Grid sigma;  // projected microfacet area over (u_theta, u_phi) of i

  // VNDF warp per theta_i slice, over (u_theta, u_phi) of the half vector: the density normalized
  // to integrate to 1 over the square, its conditional CDF along x within each row, and the
  // marginal CDF over rows, both integrating the bilinear density exactly.
  std::size_t vx = 0, vy = 0;
  std::vector<double> vndf_pdf, vndf_cond, vndf_marg;

  // RGB over the sample square, per theta_i slice and channel: [slice][channel][ry][rx].
  std::size_t rx = 0, ry = 0;
  std::vector<double> rgb;

  std::vector<double> ndf_iso;    // D averaged over u_phi, at the nx nodes of u_theta
  double ndf_integral = 0.0;      // integral D cos d(omega) of ndf_iso
  std::vector<double> sigma_iso;  // sigma averaged over u_phi, at the nx nodes of u_theta

  std::array<double, 2> invert_vndf(const SliceBlend& b, double u0, double u1) const;

  // Steps of RglBsdf::read, once phi_i and theta_i are read; `params` writes their counts as the
  // messages give them.
  void read_vndf(const TensorFile& in, const std::string& params);
  void read_rgb(const TensorFile& in, const std::string& params);
  void average_over_phi(const TensorFile& in);
};

// The point of the sample square that the VNDF warp of slice blend b maps to u (the inverse of
// sampling rows from the marginal CDF, then the column from the conditional CDF, each under the
// bilinear density). Monotone in both coordinates; corners map to corners.
std::array<double, 2> RglBsdf::Tables::invert_vndf(const SliceBlend& b, double u0, double u1) const {
  const std::size_t nx = vx, ny = vy, slice = nx * ny;
  const Segment x = uniform_segment(u0, nx), y = uniform_segment(u1, ny);
  const std::size_t at = y.k * nx + x.k;
  const double* pdf = vndf_pdf.data();
  const double* cond = vndf_cond.data();

  // Density along this row's x, linear in x within the patch.
  const double c0 = (1.0 - y.t) * b(pdf, slice, at) + y.t * b(pdf, slice, at + nx);
  const double c1 = (1.0 - y.t) * b(pdf, slice, at + 1) + y.t * b(pdf, slice, at + 1 + nx);
  // Mass left of u0 in the (interpolated) row, over the row's total.
  const double left = (1.0 - y.t) * b(cond, slice, at) + y.t * b(cond, slice, at + nx);
  const double r0 = b(cond, slice, y.k * nx + nx - 1), r1 = b(cond, slice, (y.k + 1) * nx + nx - 1);
  const double row_total = (1.0 - y.t) * r0 + y.t * r1;
  const double within = x.t * (c0 + 0.5 * x.t * (c1 - c0));
  const double s0 = row_total > 0.0 ? (left + within) / row_total : clamp(u0, 0.0, 1.0);
  // Mass below u1: whole rows from the marginal CDF, plus the part of this patch row.
  const double s1 = b(vndf_marg.data(), ny, y.k) + y.t * (r0 + 0.5 * y.t * (r1 - r0));
  return {clamp(s0, 0.0, 1.0), clamp(s1, 0.0, 1.0)};
}


RglBsdf::RglBsdf(std::shared_ptr<const Tables> tables) : t_(std::move(tables)) {}

const std::string& RglBsdf::description() const { return t_->description; }
bool RglBsdf::jacobian() const { return t_->jacobian; }
double RglBsdf::measured_ndf_stored_integral() const { return t_->ndf_integral; }

// The VNDF of each slice (phi_i x theta_i x rows x columns, at least 2 x 2), no density negative, and
// its warp; every slice must have mass.
void RglBsdf::Tables::read_vndf(const TensorFile& in, const std::string& params) {
  const std::uint64_t n_phi = phi_i.size(), n_theta = theta_i.size();
  const TensorField& vndf = in.get("vndf", kTensorFloat32, 4);
  in.check(vndf.shape[0] == n_phi && vndf.shape[1] == n_theta && vndf.shape[2] >= 2 && vndf.shape[3] >= 2,
           "field 'vndf' has shape " + dims(vndf) + ", expected " + params + " x rows x columns, at least 2 x 2");
  vy = static_cast<std::size_t>(vndf.shape[2]);
  vx = static_cast<std::size_t>(vndf.shape[3]);
  vndf_pdf = in.floats("vndf", vndf);
  for (std::size_t k = 0; k < vndf_pdf.size(); ++k)
    if (vndf_pdf[k] < 0.0) fail(in.path(), "field 'vndf' has a negative density at element " + std::to_string(k));
  vndf_cond.resize(vndf_pdf.size());
  const std::size_t slices = static_cast<std::size_t>(n_phi * n_theta);
  vndf_marg.resize(slices * vy);
  for (std::size_t s = 0; s < slices; ++s) {
    const std::size_t slice = vx * vy;
    const double total = build_warp_slice(vndf_pdf.data() + s * slice, vndf_cond.data() + s * slice,
                                          vndf_marg.data() + s * vy, vx, vy);
    in.check(total > 0.0 && std::isfinite(total),
             "field 'vndf' slice " + std::to_string(s) + " (phi_i " + std::to_string(phi_i[s / n_theta]) + ", theta_i " +
                 std::to_string(theta_i[s % n_theta]) + ") has no mass");
  }
}

// The RGB of each slice (phi_i x theta_i x 3 x rows x columns, at least 2 x 2) and the luminance's
// shape against it.
void RglBsdf::Tables::read_rgb(const TensorFile& in, const std::string& params) {
  const std::uint64_t n_phi = phi_i.size(), n_theta = theta_i.size();
  const TensorField& f = in.get("rgb", kTensorFloat32, 5);
  in.check(f.shape[0] == n_phi && f.shape[1] == n_theta && f.shape[2] == 3 && f.shape[3] >= 2 && f.shape[4] >= 2,
           "field 'rgb' has shape " + dims(f) + ", expected " + params + " x 3 x rows x columns, at least 2 x 2");
  ry = static_cast<std::size_t>(f.shape[3]);
  rx = static_cast<std::size_t>(f.shape[4]);
  rgb = in.floats("rgb", f);  // negative values (noise, out-of-gamut colour) are kept
  check_luminance(in, f, params);
}

// Phi-averaged NDF and sigma: the mean of the bilinear interpolant over u_phi is the trapezoid rule over
// rows. The NDF's integral normalizes measured_ndf.
void RglBsdf::Tables::average_over_phi(const TensorFile& in) {
  ndf_iso = phi_average(ndf);
  sigma_iso = phi_average(sigma);
  ndf_integral = projected_ndf_integral(ndf_iso);
  in.check(ndf_integral > 0.0, "field 'ndf' is zero everywhere");
}

// Every check runs before anything trusts what it checks, in the order of the file's fields as the
// messages name them.
RglBsdf RglBsdf::read(const std::string& path) {
  const std::vector<unsigned char> bytes = slurp(path);
  const TensorFile in(path, bytes);
  auto t = std::make_shared<Tables>();

  t->phi_i = read_slice_angles(in, "phi_i", -(kPi + 1e-4), kPi + 1e-4, "[-pi, pi]");
  t->isotropic = t->phi_i.size() <= 2;
  if (!t->isotropic) t->reduction = phi_reduction(in, t->phi_i);
  t->description = read_description(in);
  t->theta_i = read_slice_angles(in, "theta_i", 0.0, 0.5 * kPi + 1e-4, "[0, pi/2]");
  t->measured_limit = largest_below_horizon(t->theta_i);

  t->ndf = read_grid(in, "ndf", false);
  t->sigma = read_grid(in, "sigma", true);  // eval divides by it
  const std::string params = std::to_string(t->phi_i.size()) + " (phi_i) x " + std::to_string(t->theta_i.size()) + " (theta_i)";
  t->read_vndf(in, params);
  t->read_rgb(in, params);

  const TensorField& jac = in.get("jacobian", kTensorUInt8, 1);
  in.check(jac.count == 1, "field 'jacobian' has shape " + dims(jac) + ", expected 1");
  t->jacobian = in.data(jac)[0] != 0;

  t->average_over_phi(in);
  return RglBsdf(std::move(t));
}

double RglBsdf::measured_ndf(double theta) const {
  if (!(theta >= 0.0 && theta <= 0.5 * kPi)) return 0.0;
  return lerp_nodes(t_->ndf_iso, theta_to_u(theta)) / t_->ndf_integral;
}

double RglBsdf::measured_sigma(double theta) const {
  if (!(theta >= 0.0 && theta <= 0.5 * kPi)) return 0.0;
  return lerp_nodes(t_->sigma_iso, theta_to_u(theta));
}

const std::vector<double>& RglBsdf::slice_elevations() const { return t_->theta_i; }
bool RglBsdf::anisotropic() const { return !t_->isotropic; }

BackscatterLattice RglBsdf::backscatter(int thetas, int azimuths) const {
  BackscatterLattice lattice;
  lattice.azimuths = azimuths;
  for (int p = 0; p < thetas; ++p) {
    // Nodes at the middle of equal steps below 89.5 degrees: the table has no slice at the horizon.
    const double theta = (double(p) + 0.5) / double(thetas) * (89.5 * kPi / 180.0);
    lattice.theta.push_back(theta);
    for (int k = 0; k < azimuths; ++k) {
      const Vec3 d = spherical_direction(theta, 2.0 * kPi * double(k) / double(azimuths));
      lattice.value.push_back(*eval(d, d));  // both one-sided estimates coincide at k = k
    }
  }
  return lattice;
}

RglBsdf::Consistency RglBsdf::self_consistency() const {
  const Tables& t = *t_;
  Consistency c;

  // sigma(theta_k) = integral max(0, k.h) D(h) dw_h of the normalized, phi-averaged ndf. The phi
  // integral is closed-form; theta runs through u (theta = (pi/2) u^2, d theta = pi u du) with a
  // Gauss rule on quarters of each ndf interval, where D is linear in u.
  const std::size_t intervals = 4 * (t.ndf_iso.size() - 1);
  const double du = 1.0 / double(intervals);
  const std::size_t nodes = t.sigma_iso.size();
  const GaussRule gauss;
  for (std::size_t j = 0; j < nodes; ++j) {
    const double u_k = double(j) / double(nodes - 1);
    const double theta_k = 0.5 * kPi * u_k * u_k;
    double sigma = 0.0;
    for (std::size_t x = 0; x < intervals; ++x)
      for (std::size_t q = 0; q < gauss.x.size(); ++q) {
        const double u = (double(x) + gauss.x[q]) * du;
        const double theta = 0.5 * kPi * u * u;
        const double phi_integral =
            positive_phi_integral(std::sin(theta_k) * std::sin(theta), std::cos(theta_k) * std::cos(theta));
        sigma += du * gauss.w[q] * lerp_nodes(t.ndf_iso, u) * phi_integral * std::sin(theta) * kPi * u;
      }
    sigma /= t.ndf_integral;
    c.sigma_error = std::max(c.sigma_error, std::abs(sigma - t.sigma_iso[j]) / t.sigma_iso[j]);
  }

  // The VNDF of slice theta_i over (u_theta, u_phi) of the half vector m, phi measured from the
  // slice's plane: D(m) max(0, i.m) / sigma(i) d(omega)/d(u) with d(omega) = 2 pi^2 u_theta sin(theta_m) du.
  // Constant factors cancel in the normalization, so the model is D(m) max(0, i.m) u_theta sin(theta_m).
  // Anisotropic files: the azimuths absolute, i at the slice's phi_i, D read off the whole table.
  const std::size_t slice = t.vx * t.vy;
  std::vector<double> model(slice);
  for (std::size_t s = 0; s < t.phi_i.size() * t.theta_i.size(); ++s) {
    const std::size_t n_theta = t.theta_i.size();
    const Vec3 i = spherical_direction(t.theta_i[s % n_theta], t.isotropic ? 0.0 : t.phi_i[s / n_theta]);
    double model_total = 0.0, table_total = 0.0;
    for (std::size_t y = 0; y < t.vy; ++y)
      for (std::size_t x = 0; x < t.vx; ++x) {
        const double u0 = double(x) / double(t.vx - 1), u1 = double(y) / double(t.vy - 1);
        const double theta_m = 0.5 * kPi * u0 * u0;
        const Vec3 m = spherical_direction(theta_m, (2.0 * u1 - 1.0) * kPi);
        const double d = t.isotropic ? lerp_nodes(t.ndf_iso, u0) : bilinear(t.ndf, u0, u1);
        const double v = d * std::max(0.0, glm::dot(i, m)) * u0 * std::sin(theta_m);
        model[y * t.vx + x] = v;
        model_total += v;
        table_total += t.vndf_pdf[s * slice + y * t.vx + x];
      }
    if (!(model_total > 0.0)) {
      c.vndf_error = 1.0;
      continue;
    }
    double tv = 0.0;
    for (std::size_t k = 0; k < slice; ++k)
      tv += std::abs(t.vndf_pdf[s * slice + k] / table_total - model[k] / model_total);
    c.vndf_error = std::max(c.vndf_error, 0.5 * tv);
  }
  return c;
}

Rgb RglBsdf::table_value(const Vec3& p_in, const Vec3& q_in) const {
  const Tables& t = *t_;
  Vec3 p = p_in, q = q_in;
  if (t.reduction >= 2) {
    // Into the span of phi_i, as Mitsuba does: p to y <= 0 (r = 4: and x <= 0), q moved alike. For
    // r = 2 both axes follow the sign of p.y, a half turn.
    const auto into_span = [](double& a, double& b, double sign_of) {
      if (!std::signbit(sign_of)) a = -a, b = -b;
    };
    const double sy = p.y, sx = t.reduction == 4 ? p.x : sy;
    into_span(p.x, q.x, sx);
    into_span(p.y, q.y, sy);
  }
  const Vec3 h = glm::normalize(p + q);
  const double theta_p = elevation(p), phi_p = std::atan2(p.y, p.x);
  const double theta_h = elevation(h), phi_h = std::atan2(h.y, h.x);
  // Isotropic tables measure the half vector's azimuth from the plane of the slice direction.
  double u_h1 = (phi_h - (t.isotropic ? phi_p : 0.0) + kPi) / (2.0 * kPi);
  u_h1 -= std::floor(u_h1);
  const double u_h0 = theta_to_u(theta_h);

  const SliceBlend b = blend_for(t.phi_i, phi_p, t.theta_i, theta_p);
  const std::array<double, 2> s = t.invert_vndf(b, u_h0, u_h1);

  Rgb v(0.0);
  const std::size_t plane = t.rx * t.ry;
  const Patch patch = patch_at(t.rx, t.ry, s[0], s[1]);
  for (int k = 0; k < b.n; ++k)  // negative entries kept, as Mitsuba does
    for (int c = 0; c < 3; ++c)
      v[c] += b.weight[std::size_t(k)] * patch(t.rgb.data() + (b.slice[std::size_t(k)] * 3 + std::size_t(c)) * plane);
  if (!t.jacobian) return v;
  const double u_p1 = (phi_p + kPi) / (2.0 * kPi);
  return v * (bilinear(t.ndf, u_h0, u_h1) / (4.0 * bilinear(t.sigma, theta_to_u(theta_p), u_p1)));
}

std::optional<Rgb> RglBsdf::eval(const Vec3& o_in, const Vec3& i_in) const {
  if (!(i_in.z > 0.0) || !(o_in.z > 0.0)) return Rgb(0.0);
  const Vec3 i = glm::normalize(i_in), o = glm::normalize(o_in);
  switch (slices_) {
    case Slices::light: return table_value(i, o) / o.z;
    case Slices::view: return table_value(o, i) / i.z;
    case Slices::symmetric: break;
  }
  // Each one-sided value is f times the other cosine, so their sum is f (cos i + cos o).
  return (table_value(i, o) + table_value(o, i)) / (i.z + o.z);
}

std::optional<Rgb> RglBsdf::one_sided(const Vec3& p_in, const Vec3& q_in) const {
  if (!(p_in.z > 0.0) || !(q_in.z > 0.0)) return Rgb(0.0);
  const Vec3 p = glm::normalize(p_in), q = glm::normalize(q_in);
  if (elevation(p) > measured_elevation_limit() + 1e-9) return std::nullopt;
  return table_value(p, q);
}

double RglBsdf::measured_elevation_limit() const { return t_->measured_limit; }

std::optional<RglBsdf::Slices> parse_slices(const std::string& name) {
  if (name == "view") return RglBsdf::Slices::view;
  if (name == "symmetric") return RglBsdf::Slices::symmetric;
  if (name == "light") return RglBsdf::Slices::light;
  return std::nullopt;
}

namespace {

// The mean of a BRDF over turns of both directions about the normal: what an isotropic table holds of an
// anisotropic measurement that has no lattice of its own to average on (RGL files; UTIA files average at
// their nodes instead). 32 turns: on an analytic anisotropic GGX a 16-turn mean was 3.1% off the exact
// one, 32 turns 1e-4.
class AzimuthalMean final : public Brdf {
 public:
  static constexpr int kTurns = 32;
  explicit AzimuthalMean(const Brdf& source) : source_(source) {
    for (int k = 0; k < kTurns; ++k) turns_[std::size_t(k)] = TurnedFrame(2.0 * kPi * k / kTurns);
  }
  std::optional<Rgb> eval(const Vec3& o, const Vec3& i) const override {
    Rgb sum(0.0);
    for (const TurnedFrame& turn : turns_) {
      const auto f = source_.eval(turn.from_frame(o), turn.from_frame(i));
      if (!f) return std::nullopt;
      sum += *f;
    }
    return sum / double(kTurns);
  }

 private:
  const Brdf& source_;
  std::array<TurnedFrame, kTurns> turns_;  // computed once: eval runs per bin
};

}  // namespace

HalfDiffTable RglBsdf::table() const {
  if (anisotropic()) {
    HalfDiffTable table = HalfDiffTable::tabulate(AzimuthalMean(*this));
    table.set_source_backscatter(backscatter(90, 64));
    table.set_source_half_diff(HalfDiffLattice::of(*this));
    return table;
  }
  // Copies of the file share its tables.
  HalfDiffTable table = HalfDiffTable::tabulate(*this);
  table.set_source_one_sided(std::make_shared<RglBsdf>(*this));
  return table;
}

}  // namespace facetfit
