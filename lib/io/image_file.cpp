#include "io/image_file.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "core/error.h"
#include "io/atomic_file.h"
#include "io/input.h"

namespace facetfit {

namespace {

std::string first_line(const std::string& text) { return text.substr(0, text.find('\n')); }

// Whether a channel list, read as OpenEXR reads it (entries of a name, 16 bytes of type, linearity and
// sampling, until an empty name), ends exactly at the end of its value.
bool channel_list_fits(const std::vector<char>& v, std::size_t max_name) {
  std::size_t k = 0;
  while (k < v.size()) {
    if (v[k] == '\0') return k + 1 == v.size();
    const std::size_t end = std::size_t(std::find(v.begin() + std::ptrdiff_t(k), v.end(), '\0') - v.begin());
    if (end == v.size() || end - k > max_name) return false;
    k = end + 1 + 16;
  }
  return false;
}

// Whether a string vector's strings (each a 32-bit length and its bytes) fill its value exactly.
bool string_vector_fits(const std::vector<char>& v) {
  std::size_t k = 0;
  while (k < v.size()) {
    std::int32_t n = 0;
    if (v.size() - k < 4) return false;
    std::memcpy(&n, v.data() + k, 4);
    if (n < 0 || std::size_t(n) > v.size() - k - 4) return false;
    k += 4 + std::size_t(n);
  }
  return true;
}

// OpenEXR 3.1 allocates what a header claims before reading it: a 6 KB file whose string attribute
// claims 1.6 GB took 1.7 GB (found by fuzz_lut). The headers are walked here first, and every attribute
// must fit in the file, as must the chunk offset table the data window implies (8 bytes per chunk).
void check_exr_header(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::error_code ec;
  const std::uint64_t file_size = std::filesystem::file_size(path, ec);
  unsigned char magic[8];
  if (!in || ec || !in.read(reinterpret_cast<char*>(magic), 8)) return;  // OpenImageIO says why
  if (!(magic[0] == 0x76 && magic[1] == 0x2f && magic[2] == 0x31 && magic[3] == 0x01)) return;  // not OpenEXR
  const bool multipart = (magic[5] & 0x10) != 0, tiled = (magic[5] & 0x02) != 0;
  // OpenEXR reads at most 31 characters of a name (255 with the long-names flag) and the values of the
  // types it knows by their own size, whatever size the header states: a header that disagrees is parsed
  // differently by OpenEXR than here, so it is refused.
  const std::size_t max_name = (magic[5] & 0x04) != 0 ? 255 : 31;
  const auto read_name = [&](std::string& out) {
    out.clear();
    for (char c; in.get(c);) {
      if (c == '\0') return true;
      if (out.size() == max_name) fail(path, "OpenEXR header: a name longer than " + std::to_string(max_name) + " characters");
      out += c;
    }
    fail(path, "OpenEXR header: truncated");
  };
  static const std::pair<const char*, int> kFixedSizes[] = {
      {"box2i", 16}, {"box2f", 16}, {"compression", 1}, {"lineOrder", 1}, {"envmap", 1}, {"deepImageState", 1},
      {"float", 4},  {"int", 4},    {"double", 8},      {"rational", 8},  {"timecode", 8}, {"keycode", 28},
      {"v2i", 8},    {"v2f", 8},    {"v2d", 16},        {"v3i", 12},      {"v3f", 12},     {"v3d", 24},
      {"m33f", 36},  {"m33d", 72},  {"m44f", 64},       {"m44d", 128},    {"tiledesc", 9}, {"chromaticities", 32}};
  std::int32_t window[4] = {0, 0, -1, -1};
  std::uint32_t tile[2] = {1, 1};
  int compression = 0;
  bool has_window = false;
  for (int part = 0;; ++part) {
    std::string name, type;
    read_name(name);
    if (name.empty()) break;  // end of this header (or, in a multi-part file, of all headers)
    for (; !name.empty(); read_name(name)) {
      read_name(type);
      std::int32_t size = 0;
      if (!in.read(reinterpret_cast<char*>(&size), 4)) fail(path, "OpenEXR header: truncated");
      const std::uint64_t at = std::uint64_t(in.tellg());
      if (size < 0 || std::uint64_t(size) > file_size - at)
        fail(path, "OpenEXR header: attribute '" + name + "' claims " + std::to_string(size) + " bytes, the file has " +
                       std::to_string(file_size - at) + " left");
      for (const auto& [known, bytes] : kFixedSizes)
        if (type == known && size != bytes)
          fail(path, "OpenEXR header: attribute '" + name + "' of type " + type + " has " + std::to_string(size) + " bytes, not " +
                         std::to_string(bytes));
      std::vector<char> value(std::size_t(std::min<std::int32_t>(size, 16)));
      in.read(value.data(), std::streamsize(value.size()));
      if (type == "chlist" || type == "stringvector") {  // read by OpenEXR entry by entry: each must fit
        std::vector<char> all(static_cast<std::size_t>(size));
        in.seekg(std::streamoff(at));
        in.read(all.data(), size);
        if (!in) fail(path, "OpenEXR header: truncated");
        if (!(type == "chlist" ? channel_list_fits(all, max_name) : string_vector_fits(all)))
          fail(path, "OpenEXR header: attribute '" + name + "' of type " + type + " does not match its size");
      }
      if (type == "preview") {  // OpenEXR allocates width x height x 4 bytes from the first 8
        std::uint32_t wh[2] = {0, 0};
        if (size >= 8) std::memcpy(wh, value.data(), 8);
        if (size < 8 || std::uint64_t(wh[0]) * wh[1] * 4u + 8u != std::uint64_t(size))
          fail(path, "OpenEXR header: preview '" + name + "' does not match its size");
      }
      if (part == 0 && name == "dataWindow" && size == 16) {
        std::memcpy(window, value.data(), 16);
        has_window = true;
      }
      if (part == 0 && name == "compression" && size == 1) compression = static_cast<unsigned char>(value[0]);
      if (part == 0 && name == "tiles" && size >= 8) std::memcpy(tile, value.data(), 8);
      in.seekg(std::streamoff(at + std::uint64_t(size)));
    }
    if (!multipart) break;
  }
  if (multipart || !has_window) return;  // OpenImageIO refuses a header without a data window
  const std::int64_t width = std::int64_t(window[2]) - window[0] + 1, height = std::int64_t(window[3]) - window[1] + 1;
  if (width < 1 || height < 1) fail(path, "OpenEXR header: empty data window");
  // OpenEXR sizes its line buffers by the width as it opens the file: nothing facetfit reads is wider or
  // taller than 65536 (an 8-million-pixel-wide 416-byte file took seconds to open and close).
  if (width > 65536 || height > 65536)
    fail(path, "OpenEXR header: a " + std::to_string(width) + " x " + std::to_string(height) + " image; at most 65536 x 65536");
  // Scanlines per chunk of each compression (OpenEXR's table), or tiles of the first level.
  static constexpr int kLines[] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};
  std::uint64_t chunks;
  if (tiled) {
    if (tile[0] == 0 || tile[1] == 0) fail(path, "OpenEXR header: zero tile size");
    chunks = std::uint64_t((width + tile[0] - 1) / tile[0]) * std::uint64_t((height + tile[1] - 1) / tile[1]);
  } else {
    const int lines = compression >= 0 && compression < 10 ? kLines[compression] : 1;
    chunks = std::uint64_t((height + lines - 1) / lines);
  }
  const std::uint64_t header_end = std::uint64_t(in.tellg());
  if (chunks > (file_size - header_end) / 8)
    fail(path, "OpenEXR header: a " + std::to_string(width) + " x " + std::to_string(height) + " image needs " +
                   std::to_string(chunks) + " chunks, more than the file's " + std::to_string(file_size) + " bytes can hold");
}

}  // namespace

std::unique_ptr<OIIO::ImageInput> open_image(const std::string& path, const std::string& fallback) {
  require_regular_file(path);  // OpenImageIO would probe a device with every format reader, forever
  check_exr_header(path);
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    const std::string why = OIIO::geterror();
    fail(path, why.empty() ? fallback : first_line(why));
  }
  return in;
}

std::array<int, 3> rgb_channels(const OIIO::ImageSpec& spec, const std::string& path, OneChannel one_channel) {
  std::array<int, 3> channel{};
  if (spec.nchannels == 1 && one_channel == OneChannel::grey) return channel;
  const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    channel[std::size_t(c)] = spec.channelindex(names[c]);
    if (channel[std::size_t(c)] < 0) {
      std::string present;
      for (const std::string& n : spec.channelnames) present += (present.empty() ? "" : ", ") + n;
      fail(path, std::string("no ") + names[c] + " channel (channels: " + present + ")");
    }
  }
  return channel;
}

std::vector<float> read_pixels(OIIO::ImageInput& in, const std::string& path) {
  const OIIO::ImageSpec& spec = in.spec();
  // read_image reads every slice of a volume and the samples of a deep image: not into this buffer.
  if (spec.deep) fail(path, "deep images are not supported");
  if (spec.depth != 1) fail(path, "volume images are not supported");
  if (spec.width < 1 || spec.height < 1 || spec.nchannels < 1) fail(path, "empty image");
  std::vector<float> all(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(spec.nchannels));
  if (!in.read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data())) fail(path, "cannot read pixels: " + first_line(in.geterror()));
  return all;
}

std::vector<float> rgb_of(const std::vector<float>& all, const OIIO::ImageSpec& spec, const std::string& path, OneChannel one_channel) {
  const std::array<int, 3> channel = rgb_channels(spec, path, one_channel);
  const std::size_t pixels = std::size_t(spec.width) * std::size_t(spec.height), n = std::size_t(spec.nchannels);
  std::vector<float> rgb(pixels * 3);
  for (std::size_t p = 0; p < pixels; ++p)
    for (std::size_t c = 0; c < 3; ++c) {
      const float v = all[p * n + std::size_t(channel[c])];
      if (!std::isfinite(v))
        fail(path, std::string("non-finite ") + "RGB"[c] + " value at pixel (" + std::to_string(p % std::size_t(spec.width)) + ", " +
                       std::to_string(p / std::size_t(spec.width)) + ")");
      rgb[p * 3 + c] = v;
    }
  return rgb;
}

std::vector<float> read_rgb(OIIO::ImageInput& in, const std::string& path, OneChannel one_channel) {
  return rgb_of(read_pixels(in, path), in.spec(), path, one_channel);
}

void write_image_atomic(const std::string& path, const OIIO::ImageSpec& spec, const void* pixels) {
  AtomicFile out(path);
  auto image = OIIO::ImageOutput::create(out.temp_path());
  if (!image) fail(path, "cannot write: " + OIIO::geterror());
  errno = 0;
  if (!image->open(out.temp_path(), spec)) {
    // OpenImageIO names the temporary and not the reason; the system's reason says more.
    const int error = errno;
    fail(path, "cannot write: " + (error != 0 ? std::string(std::strerror(error)) : first_line(image->geterror())));
  }
  if (!image->write_image(spec.format, pixels) || !image->close()) fail(path, "cannot write: " + first_line(image->geterror()));
  image.reset();
  // Some writers (PNG) report no error when the disk fills and leave a truncated file: read it back
  // whole before it takes the target's name.
  auto check = OIIO::ImageInput::open(out.temp_path());
  std::vector<unsigned char> back(check ? check->spec().image_bytes() : 0);
  if (!check || !check->read_image(0, 0, 0, check->spec().nchannels, check->spec().format, back.data())) {
    const std::string why = check ? check->geterror() : OIIO::geterror();
    fail(path, "cannot write: the written file does not read back whole (disk full?)" +
                   (why.empty() ? std::string() : ": " + first_line(why)));
  }
  check->close();
  out.commit();
}

}  // namespace facetfit
