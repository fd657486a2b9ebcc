#include "fit/visible_moments.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>

#include "model/ggx_visible.h"
#include "model/ndf.h"
#include "model/smith.h"

namespace facetfit {

namespace {

constexpr double kLogMinAlpha = -6.907755278982137;  // log 1e-3

// Catmull-Rom weights at x in [0, intervals] of a table whose node n stands for x = n - 1 (one node
// beyond each end): the value is sum w[k] table[first + k], its derivative in x sum dw[k] table[first + k]
// (0 where x is clamped).
struct Spline {
  int first = 0;
  std::array<double, 4> w{}, dw{};
};
Spline catmull_rom(double x, int intervals) {
  const bool inside = x >= 0.0 && x <= intervals;
  x = std::clamp(x, 0.0, double(intervals));
  const int i = std::min(int(x), intervals - 1);
  const double s = x - i, s2 = s * s, s3 = s2 * s;
  Spline sp;
  sp.first = i;  // nodes i - 1 .. i + 2 of x, stored at i .. i + 3
  sp.w = {0.5 * (-s3 + 2.0 * s2 - s), 0.5 * (3.0 * s3 - 5.0 * s2 + 2.0), 0.5 * (-3.0 * s3 + 4.0 * s2 + s), 0.5 * (s3 - s2)};
  if (inside) sp.dw = {0.5 * (-3.0 * s2 + 4.0 * s - 1.0), 0.5 * (9.0 * s2 - 10.0 * s), 0.5 * (-9.0 * s2 + 8.0 * s + 1.0), 0.5 * (3.0 * s2 - 2.0 * s)};
  return sp;
}

}  // namespace

void VisibleMoments::for_each_visible_normal(double cos_o, double alpha_x, double alpha_y,
                                             const std::function<void(double, double)>& visit) {
  static const std::vector<std::array<double, 3>> disk = [] {
    std::vector<std::array<double, 3>> d;
    const double golden = kPi * (3.0 - std::sqrt(5.0));
    for (int k = 0; k < kPoints; ++k) d.push_back({std::sqrt((k + 0.5) / kPoints), std::cos(golden * k), std::sin(golden * k)});
    return d;
  }();
  const Vec3 o(std::sqrt(std::max(0.0, 1.0 - cos_o * cos_o)), 0.0, cos_o);
  const Ndf ndf{NdfType::ggx, alpha_x, alpha_y};
  const double lambda_o = ndf.lambda(o), g1_o = 1.0 / (1.0 + lambda_o), n = double(kPoints);
  for (const auto& [r, cos_phi, sin_phi] : disk) {
    const auto i = ggx_visible_direction_of_disk(o, alpha_x, alpha_y, r, cos_phi, sin_phi);
    if (!i) continue;
    const Vec3 h = glm::normalize(*i + o);
    visit(clamp(glm::dot(o, h), 0.0, 1.0), smith_g2(Smith::correlated, lambda_o, ndf.lambda(*i)) / g1_o / n);
  }
}

double VisibleMoments::sum(double cos_o, double alpha_x, double alpha_y, double exponent) {
  double m = 0.0;
  for_each_visible_normal(cos_o, alpha_x, alpha_y, [&](double mu, double ratio) { m += ratio * std::pow(1.0 - mu, exponent); });
  return m;
}

struct VisibleMoments::Filled {
  std::unique_ptr<std::once_flag[]> once;
};

VisibleMoments::VisibleMoments(std::vector<double> cos_o)
    : cos_o_(std::move(cos_o)), table_(cos_o_.size() * kAlphaNodes * kAlphaNodes * kRootNodes, 0.0), filled_(std::make_unique<Filled>()) {
  filled_->once = std::make_unique<std::once_flag[]>(cos_o_.size() * kAlphaNodes * kAlphaNodes);
}

VisibleMoments::~VisibleMoments() = default;

const double* VisibleMoments::cell(std::size_t view, int x, int y) const {
  const std::size_t index = (view * kAlphaNodes + std::size_t(x)) * kAlphaNodes + std::size_t(y);
  double* moments = table_.data() + index * kRootNodes;
  std::call_once(filled_->once[index], [&] {
    const double alpha_step = -kLogMinAlpha / kAlphaIntervals, root_step = std::sqrt(kMaxExponent) / kRootIntervals;
    const auto alpha = [&](int node) { return std::exp(kLogMinAlpha + (node - 1.0) * alpha_step); };
    for_each_visible_normal(cos_o_[view], alpha(x), alpha(y), [&](double mu, double ratio) {
      // m^(t_k^2) at t_k = (k - 1) step by products: m^(t_(k+1)^2) = m^(t_k^2) m^((2k - 1) step^2) for k >= 1.
      const double m = 1.0 - mu, unit = std::pow(m, root_step * root_step), unit2 = unit * unit;
      double power = 1.0, factor = unit;
      moments[1] += ratio;
      for (int k = 2; k < kRootNodes && power > 1e-200; ++k) {
        power *= factor, factor *= unit2;
        moments[k] += ratio * power;
      }
    });
    moments[0] = moments[2];  // t = -step: the same e as t = step
  });
  return moments;
}

std::shared_ptr<const VisibleMoments> VisibleMoments::at_views(const std::vector<double>& cos_o) {
  static std::mutex mutex;
  static std::map<std::vector<double>, std::shared_ptr<const VisibleMoments>> tables;
  const std::lock_guard<std::mutex> lock(mutex);
  std::shared_ptr<const VisibleMoments>& table = tables[cos_o];
  if (!table) table = std::make_shared<const VisibleMoments>(cos_o);
  return table;
}

VisibleMoments::Moment VisibleMoments::at(std::size_t view, double log_alpha_x, double log_alpha_y, double exponent) const {
  const double alpha_step = -kLogMinAlpha / kAlphaIntervals, root_step = std::sqrt(kMaxExponent) / kRootIntervals;
  const double t = std::sqrt(std::max(0.0, exponent));
  const Spline ax = catmull_rom((log_alpha_x - kLogMinAlpha) / alpha_step, kAlphaIntervals);
  const Spline ay = catmull_rom((log_alpha_y - kLogMinAlpha) / alpha_step, kAlphaIntervals);
  const Spline r = catmull_rom(t / root_step, kRootIntervals);
  Moment m;
  double d_t = 0.0;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      const double* row = cell(view, ax.first + i, ay.first + j) + r.first;
      double v = 0.0, dv = 0.0;
      for (int k = 0; k < 4; ++k) v += r.w[std::size_t(k)] * row[k], dv += r.dw[std::size_t(k)] * row[k];
      const double wx = ax.w[std::size_t(i)], wy = ay.w[std::size_t(j)];
      m.value += wx * wy * v;
      m.d_log_alpha_x += ax.dw[std::size_t(i)] * wy * v;
      m.d_log_alpha_y += wx * ay.dw[std::size_t(j)] * v;
      d_t += wx * wy * dv;
    }
  m.d_log_alpha_x /= alpha_step;
  m.d_log_alpha_y /= alpha_step;
  m.d_exponent = t > 0.0 ? d_t / root_step / (2.0 * t) : 0.0;  // de = 2 t dt
  return m;
}

}  // namespace facetfit
