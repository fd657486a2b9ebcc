// The measurement every fit reads: an isotropic BRDF tabulated over Rusinkiewicz's half and difference
// angles in the layout of MERL's tables (Matusik et al. 2003), 90 x 90 x 180 bins over (theta_h, theta_d,
// phi_d), whatever the source: a MERL file is read into it as it is, other formats tabulate themselves into
// it (io/input.h table_of) with what their fits read of them besides the bins (the source_* members).
//
// Bin positions (docs/conventions.md): theta_h bin i sits at theta_h = (i / 90)^2 pi/2, theta_d bin j
// at j/90 pi/2, phi_d bin k at k/180 pi, the inverse of the index maps of MERL's reference reader
// (which truncates). Values are held in 1/sr, already multiplied by MERL's channel scales. A missing
// measurement is NaN (missing()): no computation reads it as zero. Negative values are measurements
// (RGL's noise around zero, tabulated as it is); MERL files mark missing bins with negative numbers, so
// the reader makes those missing, and the writer writes missing bins as -1 and negative measurements as 0.
// A channel is missing on its own: a lookup keeps the channels it has.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "core/brdf.h"
#include "io/backscatter_lattice.h"
#include "io/half_diff_lattice.h"

namespace facetfit {

class HalfDiffTable final : public Brdf {
 public:
  static constexpr int kThetaH = 90;
  static constexpr int kThetaD = 90;
  static constexpr int kPhiD = 180;
  static constexpr std::size_t kBins = std::size_t(kThetaH) * kThetaD * kPhiD;
  static constexpr std::size_t kFileBytes = 3 * sizeof(int) + 3 * kBins * sizeof(double);
  // MERL's reference reader multiplies the stored doubles by these.
  static constexpr double kScale[3] = {1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0};
  // The largest value, scaled, a table holds: its float (beyond it, a value read as infinite).
  static constexpr double kMaxValue = double(std::numeric_limits<float>::max());

  // How eval() reads between bins. The fit never calls eval(): it reads the bins themselves.
  enum class Lookup {
    nearest,  // the bin containing the point, as MERL's reference reader does
    linear,   // trilinear in (sqrt(theta_h), theta_d, phi_d) bin coordinates, periodic in phi_d
  };

  // Which point of its bin a value stands for. MERL's format does not fix it: its reference reader
  // truncates (a value covers [i, i+1) in bin coordinates), and writers tabulate either at the lower
  // edge or at the centre. In memory a table is always at the lower edges (theta_h(i), theta_d(j),
  // phi_d(k) below); a file written at centres is resampled on reading (docs/conventions.md).
  enum class BinPoint { start, center };

  HalfDiffTable();  // every bin missing

  // Throws Error("<path>: <problem>") for anything that is not a complete, finite MERL table.
  static HalfDiffTable read(const std::string& path, BinPoint at = BinPoint::start);
  // Tabulates any BRDF at the bins' lower edges (`center`: at their centres, as a table for a file of
  // that convention); pairs below the horizon become missing bins.
  static HalfDiffTable tabulate(const Brdf& brdf, BinPoint at = BinPoint::start);
  // The table of values at the bins' centres moved to their lower edges: each value the mean of the
  // valid centre values around it (2 per axis; theta axes clamp at 0, phi_d wraps with period pi).
  HalfDiffTable centres_to_edges() const;
  // Writes MERL layout through a temporary file; missing bins are written as -1. MERL's readers take every
  // negative number for a missing bin, so a negative measurement (noise around zero, as an RGL file's) is
  // written as 0: returns how many were, per channel (the caller says so).
  std::array<std::size_t, 3> write(const std::string& path) const;

  std::optional<Rgb> eval(const Vec3& o, const Vec3& i) const override;
  Lookup lookup() const { return lookup_; }
  void set_lookup(Lookup lookup) { lookup_ = lookup; }

  // Positions in bin coordinates (i + 0.5: a bin's centre).
  static double theta_h(double i);
  static double theta_d(double j);
  static double phi_d(double k);
  static std::size_t index(int i, int j, int k) { return std::size_t(k) + kPhiD * (std::size_t(j) + kThetaD * std::size_t(i)); }

  // Channel c (0 red, 1 green, 2 blue) as kBins contiguous values in index() order.
  const float* channel(int c) const { return data_.data() + std::size_t(c) * kBins; }
  float* channel(int c) { return data_.data() + std::size_t(c) * kBins; }
  float value(int c, int i, int j, int k) const { return channel(c)[index(i, j, k)]; }
  static bool missing(float v) { return std::isnan(v); }
  static const char* channel_name(int c) { return c == 0 ? "red" : (c == 1 ? "green" : "blue"); }
  void set(int i, int j, int k, const Rgb& v);
  void set_missing(int i, int j, int k);

  // Back-scattering measured by the source at nodes of its own (io/backscatter_lattice.h: a UTIA file),
  // which the fits take instead of the table's theta_d = 0 bins, resampled between those nodes. Empty
  // for every other source. It describes the source, not the bins: set() and channel() leave it as it
  // is, a table resampled or written as MERL (centres_to_edges, write) does not carry it.
  const BackscatterLattice& source_backscatter() const { return source_backscatter_; }
  void set_source_backscatter(BackscatterLattice lattice) { source_backscatter_ = std::move(lattice); }
  // An anisotropic source at nodes over the half vector's azimuth too (io/half_diff_lattice.h): what its
  // anisotropic fits are measured against. Empty for every other source; carried like source_backscatter.
  const HalfDiffLattice& source_half_diff() const { return source_half_diff_; }
  void set_source_half_diff(HalfDiffLattice lattice) { source_half_diff_ = std::move(lattice); }
  // A source that holds two one-sided estimates of each pair (an RGL file): the table holds their
  // reciprocal blend, the fits' distances read both (fit/measurement.h). Null for every other source;
  // carried like source_backscatter.
  const std::shared_ptr<const OneSidedMeasurement>& source_one_sided() const { return source_one_sided_; }
  void set_source_one_sided(std::shared_ptr<const OneSidedMeasurement> source) { source_one_sided_ = std::move(source); }
  // The pairs a source was measured at, where they are few and far between (a UTIA file: 15 degrees
  // apart): the fits' distances read them instead of the table (fit/measurement.h). Null for every
  // other source; carried like source_backscatter (so a table edited after it is set still fits the
  // samples: set it last, or clear it).
  const std::shared_ptr<const std::vector<MeasuredSample>>& source_samples() const { return source_samples_; }
  void set_source_samples(std::shared_ptr<const std::vector<MeasuredSample>> samples) { source_samples_ = std::move(samples); }
  // The same for an anisotropic source's every pair (a UTIA file's, over both azimuths): its anisotropic
  // fits read them instead of source_half_diff, a resampling between them. Null for every other source.
  const std::shared_ptr<const std::vector<MeasuredSample>>& source_anisotropic_samples() const { return source_anisotropic_samples_; }
  void set_source_anisotropic_samples(std::shared_ptr<const std::vector<MeasuredSample>> samples) {
    source_anisotropic_samples_ = std::move(samples);
  }

 private:
  std::optional<Rgb> eval_nearest(double x_h, double x_d, double x_p) const;
  std::optional<Rgb> eval_linear(double x_h, double x_d, double x_p) const;

  // Leaves new elements uninitialized: the reader overwrites every one, and filling 17 MB first costs
  // as much as the conversion itself.
  template <class T>
  struct UninitializedAllocator : std::allocator<T> {
    template <class U>
    struct rebind {
      using other = UninitializedAllocator<U>;
    };
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
      if constexpr (sizeof...(Args) == 0) {
        ::new (static_cast<void*>(p)) U;
      } else {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
      }
    }
  };
  struct Uninitialized {};
  explicit HalfDiffTable(Uninitialized);

  std::vector<float, UninitializedAllocator<float>> data_;  // 3 * kBins, channel-planar as in the file
  BackscatterLattice source_backscatter_;
  HalfDiffLattice source_half_diff_;
  std::shared_ptr<const OneSidedMeasurement> source_one_sided_;
  std::shared_ptr<const std::vector<MeasuredSample>> source_samples_, source_anisotropic_samples_;
  Lookup lookup_ = Lookup::linear;
};

// A source whose reader tabulates it (an RGL or a UTIA file): into the table, with what its fits read of it
// besides the bins (the table's source_* members). table_of() (io/input.h) asks it.
class SelfTabulating {
 public:
  virtual ~SelfTabulating() = default;
  virtual HalfDiffTable table() const = 0;
};

}  // namespace facetfit
