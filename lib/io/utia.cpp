#include "io/utia.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "io/atomic_file.h"
#include "io/input.h"

namespace facetfit {

namespace {

constexpr double kThreshold = 0.0375, kScale = 100.0;

// One axis of the quadrilinear lookup: the two nodes and their weights. theta clamps its pair to the
// last interval (linear extrapolation past it), phi wraps.
struct Pair {
  int node[2];
  double weight[2];
};

Pair theta_pair(double degrees) {
  int lo = int(std::floor(degrees / UtiaBrdf::kThetaStep));
  lo = std::clamp(lo, 0, UtiaBrdf::kTheta - 2);
  const double t = degrees / UtiaBrdf::kThetaStep - lo;
  return {{lo, lo + 1}, {1.0 - t, t}};
}

Pair phi_pair(double degrees) {
  double x = std::fmod(degrees / UtiaBrdf::kPhiStep, double(UtiaBrdf::kPhi));
  if (x < 0.0) x += UtiaBrdf::kPhi;
  const int lo = std::min(int(x), UtiaBrdf::kPhi - 1);
  const double t = x - lo;
  return {{lo, (lo + 1) % UtiaBrdf::kPhi}, {1.0 - t, t}};
}

Vec3 node_direction(int theta, int phi) {
  return spherical_direction(theta * UtiaBrdf::kThetaStep * kPi / 180.0, phi * UtiaBrdf::kPhiStep * kPi / 180.0);
}

}  // namespace

double UtiaBrdf::decode(double x) {
  const double linear = x > kThreshold ? std::pow((x + 0.055) / 1.055, 2.4) : x / 12.92;
  return kScale * linear;
}

double UtiaBrdf::encode(double f) {
  const double y = f / kScale;
  if (y <= kThreshold / 12.92) return 12.92 * y;
  // The two branches do not meet at 0.0375: the power branch starts 0.04% above where the linear one
  // ends, so the values in between (f in (0.29025, 0.29036) / sr) take the power branch's first value.
  return std::max(1.055 * std::pow(y, 1.0 / 2.4) - 0.055, std::nextafter(kThreshold, 1.0));
}

UtiaBrdf UtiaBrdf::read(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) fail(path, "cannot open: no such file");
  require_regular_file(path);
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) fail(path, "cannot read its size: " + ec.message());
  if (size != kFileBytes)
    fail(path, "size is " + std::to_string(size) + " bytes; a UTIA BRDF file holds 3 x 6 x 48 x 6 x 48 doubles (" +
                   std::to_string(kFileBytes) + " bytes)");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, std::string("cannot open: ") + std::strerror(errno));
  auto f = std::make_shared<std::vector<double>>(3 * kPerPlane);
  if (!in.read(reinterpret_cast<char*>(f->data()), std::streamsize(kFileBytes))) fail(path, "cannot read: short read");
  for (std::size_t k = 0; k < f->size(); ++k) {
    const double x = (*f)[k], v = decode(x);
    if (!std::isfinite(v))  // a NaN, an infinity, or a finite value whose decoding overflows
      fail(path, "value at byte offset " + std::to_string(k * sizeof(double)) + " is not a finite number (" + std::to_string(x) + ")");
    (*f)[k] = v;
  }
  return UtiaBrdf(std::move(f));
}

UtiaBrdf UtiaBrdf::tabulate(const Brdf& brdf) {
  auto f = std::make_shared<std::vector<double>>(3 * kPerPlane, 0.0);
  tbb::parallel_for(0, kTheta, [&](int ti) {
    for (int pi = 0; pi < kPhi; ++pi)
      for (int tv = 0; tv < kTheta; ++tv)
        for (int pv = 0; pv < kPhi; ++pv) {
          const auto v = brdf.eval(node_direction(tv, pv), node_direction(ti, pi));
          const Rgb rgb = v ? *v : Rgb(0.0);
          for (int c = 0; c < 3; ++c) (*f)[std::size_t(c) * kPerPlane + index(ti, pi, tv, pv)] = rgb[c];
        }
  });
  return UtiaBrdf(std::move(f));
}

BackscatterLattice UtiaBrdf::backscatter() const {
  BackscatterLattice b;
  b.azimuths = kPhi;
  for (int p = 0; p < kTheta; ++p) {
    b.theta.push_back(p * kThetaStep * kPi / 180.0);
    for (int k = 0; k < kPhi; ++k) b.value.push_back(node(p, k, p, k));
  }
  return b;
}

UtiaBrdf UtiaBrdf::azimuthal_mean() const {
  auto f = std::make_shared<std::vector<double>>(3 * kPerPlane, 0.0);
  for (int c = 0; c < 3; ++c) {
    const double* in = f_->data() + std::size_t(c) * kPerPlane;
    double* out = f->data() + std::size_t(c) * kPerPlane;
    for (int ti = 0; ti < kTheta; ++ti)
      for (int tv = 0; tv < kTheta; ++tv)
        for (int delta = 0; delta < kPhi; ++delta) {
          double sum = 0.0;
          for (int k = 0; k < kPhi; ++k) sum += in[index(ti, k, tv, (k + delta) % kPhi)];
          for (int pi = 0; pi < kPhi; ++pi) out[index(ti, pi, tv, (pi + delta) % kPhi)] = sum / kPhi;
        }
  }
  return UtiaBrdf(std::move(f));
}

namespace {

// The cell of polar node t spans theta +- half a step (the pole's: a cap of half a step) and one azimuth
// step; the pole's 48 nodes are one direction and share the cap.
double node_solid_angle(int t) {
  const double half = 0.5 * UtiaBrdf::kThetaStep * kPi / 180.0, theta = t * UtiaBrdf::kThetaStep * kPi / 180.0;
  return (std::cos(std::max(theta - half, 0.0)) - std::cos(theta + half)) * (2.0 * kPi / UtiaBrdf::kPhi);
}

// Node pair (ti, pi, tv, pv) as a measurement, weighted by its two cells' solid angles.
MeasuredSample node_sample(const UtiaBrdf& file, int ti, int pi, int tv, int pv) {
  return {node_direction(tv, pv), node_direction(ti, pi), file.node(ti, pi, tv, pv), node_solid_angle(ti) * node_solid_angle(tv)};
}

}  // namespace

std::vector<MeasuredSample> UtiaBrdf::samples_at_first_azimuth() const {
  std::vector<MeasuredSample> samples;
  samples.reserve(std::size_t(kTheta) * kTheta * kPhi);
  for (int ti = 0; ti < kTheta; ++ti)
    for (int tv = 0; tv < kTheta; ++tv)
      for (int pv = 0; pv < kPhi; ++pv)
        samples.push_back(node_sample(*this, ti, 0, tv, pv));
  return samples;
}

std::vector<MeasuredSample> UtiaBrdf::samples() const {
  std::vector<MeasuredSample> samples;
  samples.reserve(kPerPlane);
  for (int ti = 0; ti < kTheta; ++ti)
    for (int pi = 0; pi < kPhi; ++pi)
      for (int tv = 0; tv < kTheta; ++tv)
        for (int pv = 0; pv < kPhi; ++pv)
          samples.push_back(node_sample(*this, ti, pi, tv, pv));
  return samples;
}

void UtiaBrdf::write(const std::string& path) const {
  AtomicFile out(path);
  std::vector<double> encoded(f_->size());
  for (std::size_t k = 0; k < encoded.size(); ++k) encoded[k] = encode((*f_)[k]);
  std::FILE* file = std::fopen(out.temp_path().c_str(), "wb");
  if (!file) fail(path, std::string("cannot write: ") + std::strerror(errno));
  const bool ok = std::fwrite(encoded.data(), sizeof(double), encoded.size(), file) == encoded.size();
  if (std::fclose(file) != 0 || !ok) fail(path, "cannot write: short write (disk full?)");
  out.commit();
}

Rgb UtiaBrdf::node(int theta_i, int phi_i, int theta_v, int phi_v) const {
  const std::size_t k = index(theta_i, phi_i, theta_v, phi_v);
  return Rgb((*f_)[k], (*f_)[kPerPlane + k], (*f_)[2 * kPerPlane + k]);
}

std::optional<Rgb> UtiaBrdf::eval(const Vec3& o, const Vec3& i) const {
  if (i.z <= 0.0 || o.z <= 0.0) return Rgb(0.0);
  const auto degrees = [](double radians) { return radians * 180.0 / kPi; };
  const Pair ti = theta_pair(degrees(std::acos(std::min(i.z, 1.0)))), tv = theta_pair(degrees(std::acos(std::min(o.z, 1.0))));
  const Pair pi = phi_pair(degrees(std::atan2(i.y, i.x))), pv = phi_pair(degrees(std::atan2(o.y, o.x)));
  Rgb sum(0.0);
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (int c = 0; c < 2; ++c)
        for (int d = 0; d < 2; ++d)
          sum += node(ti.node[a], pi.node[b], tv.node[c], pv.node[d]) *
                 (ti.weight[a] * pi.weight[b] * tv.weight[c] * pv.weight[d]);
  return sum;
}

HalfDiffTable UtiaBrdf::table() const {
  const UtiaBrdf mean = azimuthal_mean();
  HalfDiffTable table = HalfDiffTable::tabulate(mean);
  table.set_source_samples(std::make_shared<const std::vector<MeasuredSample>>(mean.samples_at_first_azimuth()));
  table.set_source_backscatter(backscatter());
  table.set_source_anisotropic_samples(std::make_shared<const std::vector<MeasuredSample>>(samples()));
  return table;
}

}  // namespace facetfit
