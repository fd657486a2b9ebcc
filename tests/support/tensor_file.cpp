#include "support/tensor_file.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "core/frame.h"

namespace facetfit::test {

TensorField f32(const std::string& name, std::vector<std::uint64_t> shape, const std::vector<float>& v) {
  TensorField f{name, kTensorF32, std::move(shape), std::vector<unsigned char>(v.size() * 4)};
  std::memcpy(f.payload.data(), v.data(), f.payload.size());  // test hosts are little-endian
  return f;
}

TensorField u8(const std::string& name, std::vector<std::uint64_t> shape, const std::vector<unsigned char>& v) {
  return TensorField{name, kTensorU8, std::move(shape), v};
}

TensorField& field(std::vector<TensorField>& fields, const std::string& name) {
  return *std::find_if(fields.begin(), fields.end(), [&](const TensorField& f) { return f.name == name; });
}

namespace {

void put(std::vector<unsigned char>& out, std::uint64_t v, int bytes) {
  for (int k = 0; k < bytes; ++k) out.push_back(static_cast<unsigned char>(v >> (8 * k)));
}

}  // namespace

std::vector<unsigned char> serialize(const std::vector<TensorField>& fields, unsigned char major, unsigned char minor) {
  std::vector<unsigned char> out = {'t', 'e', 'n', 's', 'o', 'r', '_', 'f', 'i', 'l', 'e', '\0', major, minor};
  put(out, fields.size(), 4);
  std::size_t table = out.size();
  for (const TensorField& f : fields) table += 2 + f.name.size() + 2 + 1 + 8 + 8 * f.shape.size();
  std::size_t at = (table + 7) / 8 * 8;
  std::vector<std::size_t> offsets;
  for (const TensorField& f : fields) {
    offsets.push_back(at);
    at = (at + f.payload.size() + 7) / 8 * 8;
  }
  for (std::size_t k = 0; k < fields.size(); ++k) {
    const TensorField& f = fields[k];
    put(out, f.name.size(), 2);
    out.insert(out.end(), f.name.begin(), f.name.end());
    put(out, f.shape.size(), 2);
    put(out, f.dtype, 1);
    put(out, f.offset_override ? f.offset_override : offsets[k], 8);
    for (const std::uint64_t n : f.shape) put(out, n, 8);
  }
  for (std::size_t k = 0; k < fields.size(); ++k) {
    out.resize(offsets[k], 0);
    out.insert(out.end(), fields[k].payload.begin(), fields[k].payload.end());
  }
  out.resize(at, 0);
  return out;
}

std::vector<TensorField> microfacet_tensor_fields(const Ndf& ndf, Smith smith, double angle, int phi_slices,
                                                  int theta_slices, int rgb_nodes) {
  const TurnedFrame axes(angle);
  // The format's maps: theta = (pi/2) u^2, phi = (2 u - 1) pi.
  const auto half_vector = [](double u0, double u1) { return spherical_direction(0.5 * kPi * u0 * u0, (2.0 * u1 - 1.0) * kPi); };

  constexpr std::uint64_t kNdfX = 128, kNdfY = 256;
  std::vector<float> ndf_table, sigma_table;
  for (std::uint64_t y = 0; y < kNdfY; ++y)
    for (std::uint64_t x = 0; x < kNdfX; ++x) {
      const Vec3 h = axes.to_frame(half_vector(double(x) / double(kNdfX - 1), double(y) / double(kNdfY - 1)));
      ndf_table.push_back(float(ndf.D(h)));
      // At the horizon Smith's projected area is the limit from above.
      sigma_table.push_back(float(ndf.sigma(h.z > 1e-6 ? h : glm::normalize(Vec3(h.x, h.y, 1e-6)))));
    }

  std::vector<float> phi_i, theta_i;
  for (int k = 0; k < phi_slices; ++k) phi_i.push_back(float(phi_slices == 1 ? 0.0 : (2.0 * k / (phi_slices - 1) - 1.0) * kPi));
  // Elevations closer together toward the horizon, where a microfacet lobe changes fastest with theta_i.
  for (int k = 0; k < theta_slices; ++k) {
    const double t = 1.0 - double(k) / (theta_slices - 1);
    theta_i.push_back(float((1.0 - t * t) * 89.0 * kPi / 180.0));
  }
  const bool isotropic = phi_slices <= 2;

  // The warp: a density over the half-vector square that grows toward the horizon (u_theta -> 1), the same
  // in every row and slice, linear between 33 columns. The sample square's uniform RGB nodes land where
  // it is high: near grazing half vectors, where the table changes fastest (G2 as the other direction
  // nears the horizon, moving twice as fast as h). Its conditional CDF, inverted here by bisection, gives
  // each node's half vector; rows are uniform, so u_phi is the sample's own.
  constexpr std::uint64_t kWarpX = 33;
  std::vector<float> warp_row(kWarpX);
  for (std::uint64_t x = 0; x < kWarpX; ++x) warp_row[x] = float(1.0 + 40.0 * std::pow(double(x) / double(kWarpX - 1), 6.0));
  std::vector<double> cdf(kWarpX, 0.0);  // at the columns, trapezoids of the linear density
  for (std::uint64_t x = 1; x < kWarpX; ++x) cdf[x] = cdf[x - 1] + 0.5 * (double(warp_row[x - 1]) + double(warp_row[x])) / double(kWarpX - 1);
  const auto cdf_at = [&](double u) {
    const double g = u * double(kWarpX - 1);
    const std::uint64_t k = std::min<std::uint64_t>(std::uint64_t(g), kWarpX - 2);
    const double t = g - double(k), d0 = warp_row[k], d1 = warp_row[k + 1];
    return cdf[k] + (t * d0 + 0.5 * t * t * (d1 - d0)) / double(kWarpX - 1);
  };
  const auto warped_u_theta = [&](double sample) {
    double lo = 0.0, hi = 1.0;
    for (int it = 0; it < 60; ++it) (cdf_at(0.5 * (lo + hi)) < sample * cdf.back() ? lo : hi) = 0.5 * (lo + hi);
    return 0.5 * (lo + hi);
  };
  std::vector<double> node_u_theta(static_cast<std::size_t>(rgb_nodes));
  for (int x = 0; x < rgb_nodes; ++x) node_u_theta[std::size_t(x)] = warped_u_theta(double(x) / double(rgb_nodes - 1));
  std::vector<float> vndf;
  for (std::size_t k = 0; k < phi_i.size() * theta_i.size() * 2; ++k) vndf.insert(vndf.end(), warp_row.begin(), warp_row.end());

  const std::uint64_t n = std::uint64_t(rgb_nodes), np = phi_i.size(), nt = theta_i.size();
  std::vector<float> rgb, luminance;
  for (std::uint64_t p = 0; p < np; ++p)
    for (std::uint64_t t = 0; t < nt; ++t) {
      const Vec3 i = spherical_direction(double(theta_i[t]), isotropic ? 0.0 : double(phi_i[p]));
      std::vector<float> plane(n * n);
      for (std::uint64_t y = 0; y < n; ++y)
        for (std::uint64_t x = 0; x < n; ++x) {
          // Isotropic files measure the half vector's azimuth from the slice's plane (i at phi 0 here).
          const Vec3 h = half_vector(node_u_theta[x], double(y) / double(n - 1));
          const Vec3 o = 2.0 * glm::dot(i, h) * h - i;
          // T 4 sigma / D = G2(i, o) sigma(i) / cos(i): D cancels. G2 falls to zero linearly as o reaches
          // the horizon; beyond it the table holds that line's continuation (-G2 of o mirrored), so
          // that interpolating across the horizon stays exact instead of averaging with zeros.
          const Vec3 mirrored(o.x, o.y, std::max(std::abs(o.z), 1e-9));
          const double g2 = smith_g2(smith, ndf.lambda(axes.to_frame(mirrored)), ndf.lambda(axes.to_frame(i)));
          plane[y * n + x] = float((o.z >= 0.0 ? g2 : -g2) * ndf.sigma(axes.to_frame(i)) / std::max(i.z, 1e-9));
        }
      for (int ch = 0; ch < 3; ++ch) rgb.insert(rgb.end(), plane.begin(), plane.end());
      luminance.insert(luminance.end(), plane.begin(), plane.end());
    }
  const std::string desc = "Analytic microfacet test material";
  return {
      u8("description", {desc.size()}, std::vector<unsigned char>(desc.begin(), desc.end())),
      f32("phi_i", {np}, phi_i),
      f32("theta_i", {nt}, theta_i),
      f32("ndf", {kNdfY, kNdfX}, ndf_table),
      f32("sigma", {kNdfY, kNdfX}, sigma_table),
      f32("vndf", {np, nt, 2, kWarpX}, vndf),
      f32("luminance", {np, nt, n, n}, luminance),
      f32("rgb", {np, nt, 3, n, n}, rgb),
      u8("jacobian", {1}, {1}),
  };
}

std::vector<TensorField> arbitrary_tensor_fields(unsigned seed, const std::vector<float>& phi_i) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.2f, 1.0f);
  const auto table = [&](std::size_t n) {
    std::vector<float> v(n);
    for (float& x : v) x = u(rng);
    return v;
  };
  const std::vector<float> theta_i = {0.0f, 0.7f, 1.4f};
  const std::uint64_t np = phi_i.size(), nt = theta_i.size();
  constexpr std::uint64_t kVx = 9, kVy = 7, kRx = 6, kRy = 6, kNx = 8, kNy = 6;  // Mitsuba wants the RGB square
  const std::string desc = "Arbitrary test tables";
  return {
      u8("description", {desc.size()}, std::vector<unsigned char>(desc.begin(), desc.end())),
      f32("phi_i", {np}, phi_i),
      f32("theta_i", {nt}, theta_i),
      f32("ndf", {kNy, kNx}, table(kNx * kNy)),
      f32("sigma", {kNy, kNx}, table(kNx * kNy)),
      f32("vndf", {np, nt, kVy, kVx}, table(np * nt * kVx * kVy)),
      f32("luminance", {np, nt, kRy, kRx}, table(np * nt * kRx * kRy)),
      f32("rgb", {np, nt, 3, kRy, kRx}, table(np * nt * 3 * kRx * kRy)),
      u8("jacobian", {1}, {1}),
  };
}

}  // namespace facetfit::test
