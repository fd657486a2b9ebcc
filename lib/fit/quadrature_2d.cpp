#include "fit/quadrature_2d.h"

#include <fftw3.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <complex>
#include <mutex>

#include "core/error.h"

namespace facetfit {

namespace {

// FFTW's planner keeps global tables and is not thread-safe; executing a plan is.
std::mutex& planner_mutex() {
  static std::mutex m;
  return m;
}

struct FftwBuffer {
  explicit FftwBuffer(std::size_t bytes) : data(fftw_malloc(bytes)) {
    if (!data) throw Error("fftw: out of memory");
  }
  ~FftwBuffer() { fftw_free(data); }
  FftwBuffer(const FftwBuffer&) = delete;
  FftwBuffer& operator=(const FftwBuffer&) = delete;
  double* real() const { return static_cast<double*>(data); }
  fftw_complex* complex() const { return static_cast<fftw_complex*>(data); }
  void* data;
};

// Integral of max(0, a cos(t) + b) dt from 0 to x >= 0, a, b >= 0, given sin(x): the integrand vanishes
// past phi_max, whose sine is sin_max.
double clipped_antiderivative(double a, double b, double phi_max, double sin_max, double x, double sin_x) {
  return x < phi_max ? a * sin_x + b * x : a * sin_max + b * phi_max;
}

// The azimuthal bins' integrals of max(0, k.h) (cp) and of k.h (cl), k.h = a cos(delta phi) + b, over bins
// d = 0..M/2 with upper edges `edge` (and their sines); the bin centred on pi counts twice (the kernel is even).
void bin_integrals(double a, double b, const std::vector<double>& edge, const std::vector<double>& edge_sin, int m,
                   std::vector<double>& cp, std::vector<double>& cl) {
  const double phi_max = a <= b ? kPi : std::acos(-b / a);
  const double sin_max = a <= b ? 0.0 : std::sqrt(std::max(0.0, 1.0 - (b / a) * (b / a)));
  double g_lo = 0.0, lin_lo = 0.0;  // both antiderivatives at the lower edge of bin d
  for (std::size_t d = 0; d < edge.size(); ++d) {
    const double g = clipped_antiderivative(a, b, phi_max, sin_max, edge[d], edge_sin[d]);
    const double l = a * edge_sin[d] + b * edge[d];
    if (d == 0) g_lo = -g, lin_lo = -l;
    const double twice = 2 * int(d) == m ? 2.0 : 1.0;
    cp[d] = twice * (g - g_lo);
    cl[d] = twice * (l - lin_lo);
    g_lo = g, lin_lo = l;
  }
}

// Integral of |cos(t)| dt from -pi/2 to x: 2 per half period, 1 - cos within one.
double abs_cos_antiderivative(double x) {
  const double y = x + 0.5 * kPi, n = std::floor(y / kPi);
  return 2.0 * n + 1.0 - std::cos(y - n * kPi);
}

}  // namespace

// One FFT of every theta row at once, forward (real to half spectrum) and back.
struct Quadrature2D::Plans {
  fftw_plan forward = nullptr, backward = nullptr;
  ~Plans() {
    std::lock_guard<std::mutex> lock(planner_mutex());
    if (forward) fftw_destroy_plan(forward);
    if (backward) fftw_destroy_plan(backward);
  }
};

// FFTW's plans of the n transforms of length m (f frequencies each), forward and back; planning is not
// thread-safe.
std::unique_ptr<Quadrature2D::Plans> Quadrature2D::plan_transforms(int n, int m, int f) {
  std::lock_guard<std::mutex> lock(planner_mutex());
  auto plans = std::make_unique<Plans>();
  FftwBuffer real(sizeof(double) * std::size_t(n) * m), spectrum(sizeof(fftw_complex) * std::size_t(n) * f);
  plans->forward = fftw_plan_many_dft_r2c(1, &m, n, real.real(), nullptr, 1, m, spectrum.complex(), nullptr, 1, f, FFTW_ESTIMATE);
  plans->backward = fftw_plan_many_dft_c2r(1, &m, n, spectrum.complex(), nullptr, 1, f, real.real(), nullptr, 1, m, FFTW_ESTIMATE);
  if (!plans->forward || !plans->backward) throw Error("fftw: cannot plan a transform of " + std::to_string(m));
  return plans;
}

double Quadrature2D::phi(int m) const { return 2.0 * kPi * m / phi_count_; }

Quadrature2D::Quadrature2D(int resolution, int phi_count) : base_(resolution), phi_count_(phi_count) {
  if (phi_count < 4 || phi_count > 4096 || phi_count % 2 != 0)
    fail("phi count " + std::to_string(phi_count), "must be even, between 4 and 4096");
  const int n = size(), m = phi_count, f = frequencies();
  const double bin = 2.0 * kPi / m;
  const std::vector<Quadrature::Node>& nodes = base_.nodes();

  plans_ = plan_transforms(n, m, f);

  // K_kj(delta) for delta = 0..M/2 (even in delta), from the theta nodes' azimuthal bin integrals of the
  // kernel, spread onto the grid nodes like the isotropic weights; then each K_kj's spectrum.
  positive_.assign(std::size_t(n) * n * f, 0.0);
  absolute_.assign(std::size_t(n) * n * f, 0.0);
  // Bin d (d = 0..M/2) spans [-x_0, x_0] for d = 0, else [x_{d-1}, x_d], x_d = min((d + 1/2) bin, pi);
  // the one centred on pi is cut at pi and counted twice (the kernel is even).
  std::vector<double> edge(std::size_t(m / 2) + 1), edge_sin(edge.size());
  for (std::size_t e = 0; e < edge.size(); ++e) {
    edge[e] = std::min((double(e) + 0.5) * bin, kPi);
    edge_sin[e] = std::sin(edge[e]);
  }
  tbb::parallel_for(0, n, [&](int k) {
    const double sk = std::sin(grid().theta(k)), ck = std::cos(grid().theta(k));
    std::vector<double> pos(std::size_t(n) * m, 0.0), lin(std::size_t(n) * m, 0.0), cp(edge.size()), cl(edge.size());
    for (const Quadrature::Node& node : nodes) {
      const double s = std::sin(node.theta), c = std::cos(node.theta);
      bin_integrals(sk * s, ck * c, edge, edge_sin, m, cp, cl);  // k.h = a cos(delta phi) + b
      const ThetaGrid::Stencil st = grid().stencil(node.interval, node.t);
      for (int q = 0; q < 4; ++q) {
        const double w = st.weight[q] * s * node.weight;
        if (w == 0.0) continue;
        double* prow = pos.data() + std::size_t(st.index[q]) * m;
        double* lrow = lin.data() + std::size_t(st.index[q]) * m;
        for (int d = 0; d <= m / 2; ++d) prow[d] += w * cp[std::size_t(d)], lrow[d] += w * cl[std::size_t(d)];
      }
    }
    FftwBuffer real(sizeof(double) * std::size_t(n) * m), spectrum(sizeof(fftw_complex) * std::size_t(n) * f);
    for (int which = 0; which < 2; ++which) {
      double* in = real.real();
      for (int j = 0; j < n; ++j)
        for (int d = 0; d < m; ++d) {
          const int e = d <= m / 2 ? d : m - d;
          const double p = pos[std::size_t(j) * m + e], l = lin[std::size_t(j) * m + e];
          in[std::size_t(j) * m + d] = which == 0 ? p : 2.0 * p - l;  // |x| = 2 max(0, x) - x
        }
      fftw_execute_dft_r2c(plans_->forward, in, spectrum.complex());
      double* out = (which == 0 ? positive_ : absolute_).data() + std::size_t(k) * n * f;
      for (std::size_t t = 0; t < std::size_t(n) * f; ++t) out[t] = spectrum.complex()[t][0];  // even: real
    }
  });
}

Quadrature2D::~Quadrature2D() = default;

void Quadrature2D::apply(bool absolute, const std::vector<double>& D, std::vector<double>& sigma) const {
  const int n = size(), m = phi_count_, f = frequencies();
  FftwBuffer real(sizeof(double) * std::size_t(n) * m), spectrum(sizeof(fftw_complex) * std::size_t(n) * f),
      product(sizeof(fftw_complex) * std::size_t(n) * f);
  std::copy(D.begin(), D.end(), real.real());
  fftw_execute_dft_r2c(plans_->forward, real.real(), spectrum.complex());
  const auto* d_hat = reinterpret_cast<const std::complex<double>*>(spectrum.complex());
  auto* s_hat = reinterpret_cast<std::complex<double>*>(product.complex());
  for (int k = 0; k < n; ++k) {
    std::complex<double>* out = s_hat + std::size_t(k) * f;
    std::fill(out, out + f, std::complex<double>(0.0));
    for (int j = 0; j < n; ++j) {
      const double* kernel = absolute ? absolute_spectrum(k, j) : positive_spectrum(k, j);
      const std::complex<double>* in = d_hat + std::size_t(j) * f;
#pragma omp simd
      for (int q = 0; q < f; ++q) out[q] += kernel[q] * in[q];
    }
  }
  fftw_execute_dft_c2r(plans_->backward, product.complex(), real.real());
  sigma.resize(std::size_t(n) * m);
  for (std::size_t t = 0; t < sigma.size(); ++t) sigma[t] = real.real()[t] / m;  // FFTW's transforms are unnormalized
}

namespace {

// sum_jm theta_weight(j) azimuth_weight(m) D(j, m) / phi_integral: the isotropic moment's weights hold the
// azimuthal factor's integral over the circle (phi_integral), here replaced by its integral over bin m, from
// its antiderivative.
template <class Antiderivative>
double slope_moment(const std::vector<double>& theta_weight, double phi_integral, const std::vector<double>& D, int m, double psi,
                    const Antiderivative& integral) {
  const double bin = 2.0 * kPi / m;
  std::vector<double> azimuth(std::size_t(m), 0.0);
  for (int q = 0; q < m; ++q)
    azimuth[std::size_t(q)] = (integral((q + 0.5) * bin - psi) - integral((q - 0.5) * bin - psi)) / phi_integral;
  double s = 0.0;
  for (std::size_t j = 0; j < theta_weight.size(); ++j)
    for (int q = 0; q < m; ++q) s += theta_weight[j] * azimuth[std::size_t(q)] * D[j * std::size_t(m) + std::size_t(q)];
  return s;
}

}  // namespace

double Quadrature2D::abs_slope_moment(const std::vector<double>& D, double psi) const {
  return slope_moment(base_.abs_slope_moment(), 4.0, D, phi_count_, psi, abs_cos_antiderivative);  // |cos| over the circle: 4
}

double Quadrature2D::sq_slope_moment(const std::vector<double>& D, double psi) const {
  return slope_moment(base_.sq_slope_moment(), kPi, D, phi_count_, psi, [](double x) { return 0.5 * x + 0.25 * std::sin(2.0 * x); });
}

std::size_t Quadrature2D::bytes() const {
  return sizeof(double) * (positive_.size() + absolute_.size()) +
         sizeof(double) * std::size_t(size()) * std::size_t(size()) * 2;  // the isotropic base's rows
}

}  // namespace facetfit
