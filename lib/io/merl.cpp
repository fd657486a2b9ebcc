#include "io/merl.h"

#include <fcntl.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <filesystem>
#include <memory>

#include "core/error.h"
#include "core/halfdiff.h"
#include "io/atomic_file.h"

namespace facetfit {

namespace fs = std::filesystem;

namespace {

constexpr float kMissing = std::numeric_limits<float>::quiet_NaN();

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

struct FileDescriptor {
  int fd;
  ~FileDescriptor() {
    if (fd >= 0) ::close(fd);
  }
};

// Continuous bin coordinates of a direction pair: bin i of each axis sits at coordinate i.
struct BinCoords {
  double h, d, p;
};

// Whether a stored double, scaled, is a value the table's float holds: not NaN or infinite (x - x is NaN for
// both), not past a float's range. Branch-free, for the reader's vectorized loop.
bool representable(double x, double scale) { return x - x == 0.0 && x * scale <= HalfDiffTable::kMaxValue; }

BinCoords bin_coords(const Vec3& o, const Vec3& i) {
  const HalfDiff hd = to_half_diff(o, i);
  double phi_d = hd.phi_d;
  if (phi_d < 0.0) phi_d += kPi;  // reciprocity: period pi
  if (phi_d >= kPi) phi_d -= kPi;
  return {std::sqrt(std::max(0.0, hd.theta_h) / (0.5 * kPi)) * HalfDiffTable::kThetaH,
          hd.theta_d / (0.5 * kPi) * HalfDiffTable::kThetaD, phi_d / kPi * HalfDiffTable::kPhiD};
}

// A MERL file: three 32-bit dimensions, then 3 x kBins doubles, channel by channel (HalfDiffTable::kFileBytes).
constexpr std::size_t kHeaderBytes = 3 * sizeof(std::int32_t);
constexpr std::size_t kValues = 3 * HalfDiffTable::kBins;

// The values are read in chunks of 1 MiB: chunk c holds values [first, first + n) of the file.
constexpr std::size_t kChunk = std::size_t(1) << 17;  // doubles
constexpr std::size_t kChunks = (kValues + kChunk - 1) / kChunk;
struct Chunk {
  std::size_t first, n;
};

Chunk chunk_at(std::size_t chunk) {
  const std::size_t first = chunk * kChunk;
  return {first, std::min(kChunk, kValues - first)};
}

// Reads a chunk's doubles into `buf`; false on a short read.
bool read_chunk(int fd, const Chunk& c, double* buf) {
  const auto bytes = ssize_t(c.n * sizeof(double));
  return ::pread(fd, buf, std::size_t(bytes), off_t(kHeaderBytes + c.first * sizeof(double))) == bytes;
}

// Opens `path` for reading, once it is known to be a regular file: a FIFO or a device would make open()
// wait for a writer forever, and its size would mean nothing. Returns the descriptor.
int open_regular_file(const std::string& path) {
  std::error_code ec;
  const auto status = fs::status(path, ec);
  if (!fs::exists(status)) fail(path, "cannot open: no such file");
  if (fs::is_directory(status)) fail(path, "is a folder, not a MERL .binary file");
  if (!fs::is_regular_file(status)) fail(path, "not a regular file");
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) fail(path, std::string("cannot open: ") + std::strerror(errno));
  return fd;
}

// The header's dimensions, checked before they are trusted with any allocation, and the file's size
// against them.
void check_header(const std::string& path, int fd) {
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  if (ec) fail(path, "cannot read its size: " + ec.message());
  if (size == 0) fail(path, "file is empty");
  std::int32_t dims[3] = {0, 0, 0};
  if (size < sizeof dims || ::pread(fd, dims, sizeof dims, 0) != ssize_t(sizeof dims))
    fail(path, "truncated header (" + std::to_string(size) + " bytes; a MERL file starts with three 32-bit dimensions)");
  if (dims[0] != HalfDiffTable::kThetaH || dims[1] != HalfDiffTable::kThetaD || dims[2] != HalfDiffTable::kPhiD)
    fail(path, "header claims " + std::to_string(dims[0]) + " x " + std::to_string(dims[1]) + " x " +
                   std::to_string(dims[2]) + " bins; a MERL isotropic table is 90 x 90 x 180");
  if (size != HalfDiffTable::kFileBytes)
    fail(path, "size is " + std::to_string(size) + " bytes, expected " + std::to_string(HalfDiffTable::kFileBytes) +
                   (size < HalfDiffTable::kFileBytes ? " (truncated)" : " (trailing data)"));
}

// A chunk's values into the table's floats `out` (the chunk's first): scaled by their channel's kScale,
// negative values missing. Returns how many are not representable.
int convert_chunk(const double* buf, const Chunk& chunk, float* out) {
  int nonfinite = 0;
  // A chunk may straddle two channels: convert channel by channel.
  for (std::size_t t = 0; t < chunk.n;) {
    const std::size_t c = (chunk.first + t) / HalfDiffTable::kBins;
    const std::size_t end = std::min(chunk.n, (c + 1) * HalfDiffTable::kBins - chunk.first);
    const double scale = HalfDiffTable::kScale[c];
#pragma omp simd reduction(+ : nonfinite)
    for (std::size_t k = t; k < end; ++k) {
      const double x = buf[k];
      nonfinite += representable(x, scale) ? 0 : 1;
      out[k] = x < 0.0 ? kMissing : float(x * scale);
    }
    t = end;
  }
  return nonfinite;
}

// Every chunk read with pread and converted in parallel into `table` (3 x kBins floats, channel-planar):
// the copy out of the page cache and the conversion both run on every core, and no 35 MB buffer of
// doubles is ever allocated. Returns each chunk's state: 0 a short read, 1 converted, 2 converted with a
// value that is not representable.
std::vector<unsigned char> convert_chunks(int fd, float* table) {
  tbb::enumerable_thread_specific<std::vector<double>> buffers([] { return std::vector<double>(kChunk); });
  std::vector<unsigned char> chunk_ok(kChunks, 0);
  tbb::parallel_for(std::size_t(0), kChunks, [&](std::size_t chunk) {
    std::vector<double>& buf = buffers.local();
    const Chunk c = chunk_at(chunk);
    if (!read_chunk(fd, c, buf.data())) return;
    chunk_ok[chunk] = convert_chunk(buf.data(), c, table + c.first) == 0 ? 1 : 2;
  });
  return chunk_ok;
}

// Value `at` of the file (`value`), not representable: the message names its byte offset, channel and bin.
[[noreturn]] void fail_unrepresentable(const std::string& path, std::size_t at, double value) {
  const std::size_t c = at / HalfDiffTable::kBins, bin = at % HalfDiffTable::kBins;
  const std::size_t offset = kHeaderBytes + at * sizeof(double);
  const int k = int(bin % HalfDiffTable::kPhiD), j = int(bin / HalfDiffTable::kPhiD % HalfDiffTable::kThetaD);
  const int i = int(bin / (HalfDiffTable::kPhiD * HalfDiffTable::kThetaD));
  char text[48];
  std::snprintf(text, sizeof text, "%g (out of float's range)", value);
  const std::string what = std::isnan(value) ? "NaN" : std::isinf(value) ? "Inf" : text;
  fail(path, what + " at byte offset " + std::to_string(offset) + " (" + HalfDiffTable::channel_name(int(c)) +
                 " channel, bin theta_h " + std::to_string(i) + ", theta_d " + std::to_string(j) + ", phi_d " +
                 std::to_string(k) + ")");
}

// The first problem of convert_chunks in file order: a short read, or the first value that is not
// representable (its chunk read again).
void report_first_problem(const std::string& path, int fd, const std::vector<unsigned char>& chunk_ok) {
  for (std::size_t chunk = 0; chunk < kChunks; ++chunk) {
    if (chunk_ok[chunk] == 1) continue;
    if (chunk_ok[chunk] == 0) fail(path, "read error (file changed while reading?)");
    const Chunk c = chunk_at(chunk);
    std::vector<double> buf(c.n);
    if (!read_chunk(fd, c, buf.data())) fail(path, "read error (file changed while reading?)");
    for (std::size_t t = 0; t < c.n; ++t)
      if (!representable(buf[t], HalfDiffTable::kScale[(c.first + t) / HalfDiffTable::kBins]))
        fail_unrepresentable(path, c.first + t, buf[t]);
  }
}


}  // namespace

HalfDiffTable::HalfDiffTable() : data_(3 * kBins) { std::fill(data_.begin(), data_.end(), kMissing); }

HalfDiffTable::HalfDiffTable(Uninitialized) : data_(3 * kBins) {}

double HalfDiffTable::theta_h(double i) {
  const double u = i / kThetaH;
  return u * u * 0.5 * kPi;
}
double HalfDiffTable::theta_d(double j) { return j / kThetaD * 0.5 * kPi; }
double HalfDiffTable::phi_d(double k) { return k / kPhiD * kPi; }

HalfDiffTable HalfDiffTable::centres_to_edges() const {
  // What is averaged is f cos(theta_i) cos(theta_o), smooth and bounded, not f, which grows as
  // 1 / cos^2 toward grazing back-scattering: a plain mean of f there is off by 7% in the last theta_h
  // bin, and the power iteration carries that into alpha (+1.7% at alpha 0.4). In half/diff
  // coordinates cos(theta_i) cos(theta_o) = A^2 - B^2 cos^2(phi_d), A = cos(theta_h) cos(theta_d),
  // B = sin(theta_h) sin(theta_d) (docs/conventions.md).
  // cos and sin of every axis position, at the edges ([0]) and at the centres ([1]), computed once.
  struct Trig {
    double cos[2], sin[2];
  };
  std::vector<Trig> th(kThetaH), td(kThetaD), tp(kPhiD);
  for (int at = 0; at < 2; ++at) {
    for (int i = 0; i < kThetaH; ++i) th[i].cos[at] = std::cos(theta_h(i + 0.5 * at)), th[i].sin[at] = std::sin(theta_h(i + 0.5 * at));
    for (int j = 0; j < kThetaD; ++j) td[j].cos[at] = std::cos(theta_d(j + 0.5 * at)), td[j].sin[at] = std::sin(theta_d(j + 0.5 * at));
    for (int k = 0; k < kPhiD; ++k) tp[k].cos[at] = std::cos(phi_d(k + 0.5 * at));
  }
  const auto cosines = [&](int i, int j, int k, int at) {
    const double a = th[i].cos[at] * td[j].cos[at], b = th[i].sin[at] * td[j].sin[at], c = tp[k].cos[at];
    return a * a - b * b * c * c;
  };
  HalfDiffTable out;
  tbb::parallel_for(0, kThetaH, [&](int i) {
    // The lower edge of bin i lies halfway between the centres of bins i - 1 and i.
    const int h[2] = {std::max(i - 1, 0), i};
    for (int j = 0; j < kThetaD; ++j) {
      const int d[2] = {std::max(j - 1, 0), j};
      for (int k = 0; k < kPhiD; ++k) {
        const int p[2] = {(k + kPhiD - 1) % kPhiD, k};
        const std::size_t n = index(i, j, k);
        const double edge = cosines(i, j, k, 0);
        double weight[8];
        for (int corner = 0; corner < 8; ++corner) weight[corner] = cosines(h[corner & 1], d[(corner >> 1) & 1], p[corner >> 2], 1);
        for (int c = 0; c < 3; ++c) {
          double sum = 0.0, plain = 0.0;
          int count = 0;
          for (int corner = 0; corner < 8; ++corner) {
            const float v = channel(c)[index(h[corner & 1], d[(corner >> 1) & 1], p[corner >> 2])];
            if (!missing(v)) sum += v * weight[corner], plain += v, ++count;
          }
          if (count == 0) continue;
          // At the horizon the cosines vanish: there the plain mean.
          out.channel(c)[n] = float(edge > 1e-4 ? sum / count / edge : plain / count);
        }
      }
    }
  });
  out.lookup_ = lookup_;
  return out;
}

void HalfDiffTable::set(int i, int j, int k, const Rgb& v) {
  const std::size_t n = index(i, j, k);
  for (int c = 0; c < 3; ++c) channel(c)[n] = float(v[c]);
}

void HalfDiffTable::set_missing(int i, int j, int k) {
  const std::size_t n = index(i, j, k);
  for (int c = 0; c < 3; ++c) channel(c)[n] = kMissing;
}

HalfDiffTable HalfDiffTable::read(const std::string& path, BinPoint at) {
  const FileDescriptor file{open_regular_file(path)};
  check_header(path, file.fd);
  HalfDiffTable table{Uninitialized{}};
  report_first_problem(path, file.fd, convert_chunks(file.fd, table.data_.data()));
  return at == BinPoint::center ? table.centres_to_edges() : table;
}

HalfDiffTable HalfDiffTable::tabulate(const Brdf& brdf, BinPoint at) {
  HalfDiffTable table;
  const double offset = at == BinPoint::center ? 0.5 : 0.0;
  std::array<CosSin, kThetaH> h;
  std::array<CosSin, kThetaD> d;
  std::array<CosSin, kPhiD> p;
  for (int i = 0; i < kThetaH; ++i) h[std::size_t(i)] = CosSin(theta_h(i + offset));
  for (int j = 0; j < kThetaD; ++j) d[std::size_t(j)] = CosSin(theta_d(j + offset));
  for (int k = 0; k < kPhiD; ++k) p[std::size_t(k)] = CosSin(phi_d(k + offset));
  tbb::parallel_for(0, kThetaH, [&](int i) {
    for (int j = 0; j < kThetaD; ++j) {
      for (int k = 0; k < kPhiD; ++k) {
        const auto [wo, wi] = from_half_diff(h[std::size_t(i)], d[std::size_t(j)], p[std::size_t(k)]);
        if (wi.z <= 0.0 || wo.z <= 0.0) continue;  // stays missing: no measurement below the horizon
        const auto f = brdf.eval(wo, wi);
        if (!f || !std::isfinite(f->r) || !std::isfinite(f->g) || !std::isfinite(f->b)) continue;
        table.set(i, j, k, *f);  // negative measurements stay (RGL noise around zero)
      }
    }
  });
  return table;
}

std::array<std::size_t, 3> HalfDiffTable::write(const std::string& path) const {
  AtomicFile out(path);
  File file(std::fopen(out.temp_path().c_str(), "wb"));
  if (!file) fail(path, std::string("cannot write: ") + std::strerror(errno));
  const std::int32_t dims[3] = {kThetaH, kThetaD, kPhiD};
  bool ok = std::fwrite(dims, sizeof(std::int32_t), 3, file.get()) == 3;
  std::vector<double> buf(kPhiD * kThetaD);
  std::array<std::size_t, 3> clamped{};
  for (int c = 0; c < 3 && ok; ++c) {
    const float* in = channel(c);
    for (std::size_t done = 0; done < kBins && ok; done += buf.size()) {
      for (std::size_t t = 0; t < buf.size(); ++t) {
        const float v = in[done + t];
        clamped[std::size_t(c)] += v < 0.0f;
        buf[t] = missing(v) ? -1.0 : std::max(0.0, double(v) / kScale[c]);  // negative: read back as missing
      }
      ok = std::fwrite(buf.data(), sizeof(double), buf.size(), file.get()) == buf.size();
    }
  }
  if (std::fclose(file.release()) != 0 || !ok) fail(path, "cannot write: short write (disk full?)");
  out.commit();
  return clamped;
}

std::optional<Rgb> HalfDiffTable::eval(const Vec3& o, const Vec3& i) const {
  // No cosine divides here: a pair whose product of cosines underflows is still looked up (as the lanes do).
  if (!above_horizon(o) || !above_horizon(i)) return Rgb(0.0);
  const BinCoords x = bin_coords(o, i);
  if (!(std::isfinite(x.h) && std::isfinite(x.d) && std::isfinite(x.p))) return Rgb(0.0);  // far from unit length: no angle
  return lookup_ == Lookup::nearest ? eval_nearest(x.h, x.d, x.p) : eval_linear(x.h, x.d, x.p);
}

std::optional<Rgb> HalfDiffTable::eval_nearest(double x_h, double x_d, double x_p) const {
  const int i = std::min(int(x_h), kThetaH - 1);
  const int j = std::min(int(x_d), kThetaD - 1);
  const int k = std::min(int(x_p), kPhiD - 1);
  const std::size_t n = index(i, j, k);
  // A missing channel is 0 beside the others; all three missing, the bin is.
  Rgb v(0.0);
  int found = 0;
  for (int c = 0; c < 3; ++c)
    if (!missing(channel(c)[n])) v[c] = channel(c)[n], ++found;
  if (found == 0) return std::nullopt;
  return v;
}

std::optional<Rgb> HalfDiffTable::eval_linear(double x_h, double x_d, double x_p) const {
  // Weights of the two neighbours along one axis; theta axes clamp at their last bin.
  struct Axis {
    int i0, i1;
    double t;
  };
  const auto clamped = [](double x, int res) {
    const int i0 = std::min(int(x), res - 1);
    return i0 >= res - 1 ? Axis{res - 1, res - 1, 0.0} : Axis{i0, i0 + 1, x - i0};
  };
  const Axis ah = clamped(x_h, kThetaH), ad = clamped(x_d, kThetaD);
  const int p0 = std::min(int(x_p), kPhiD - 1);
  const Axis ap{p0, (p0 + 1) % kPhiD, x_p - p0};

  // Missing neighbours drop out and the remaining weights are renormalized, per channel.
  Rgb sum(0.0), weight(0.0);
  for (int corner = 0; corner < 8; ++corner) {
    const double w = ((corner & 1) ? ah.t : 1.0 - ah.t) * ((corner & 2) ? ad.t : 1.0 - ad.t) *
                     ((corner & 4) ? ap.t : 1.0 - ap.t);
    if (w <= 0.0) continue;
    const std::size_t n = index((corner & 1) ? ah.i1 : ah.i0, (corner & 2) ? ad.i1 : ad.i0, (corner & 4) ? ap.i1 : ap.i0);
    for (int c = 0; c < 3; ++c) {
      const float v = channel(c)[n];
      if (missing(v)) continue;
      sum[c] += w * v;
      weight[c] += w;
    }
  }
  // A channel with no measured neighbour is 0 beside the others (a dark channel whose noise was below zero,
  // MERL's missing); all three without one, the pair is not measured.
  if (weight.r <= 0.0 && weight.g <= 0.0 && weight.b <= 0.0) return std::nullopt;
  Rgb v(0.0);
  for (int c = 0; c < 3; ++c)
    if (weight[c] > 0.0) v[c] = sum[c] / weight[c];
  return v;
}

}  // namespace facetfit
