// Image files with facetfit's error and write rules: one-line errors naming the file, and every output
// written under a temporary name and renamed into place.
//
// OpenEXR, the format of LUTs, renders and environment maps, is read and written here through OpenEXR
// itself. Every other format goes through OpenImageIO in the module facetfit-oiio.so, loaded the first
// time such a file is met: OpenImageIO brings some 260 shared libraries, 0.3 s at start-up, more than
// a whole `facetfit info` (docs/benchmarks.md, "Start-up").
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace facetfit {

// A header value: the types facetfit writes (OpenEXR int, float, string and v3f attributes).
using ImageAttribute = std::variant<int, float, std::string, std::array<float, 3>>;

// What an image file says about itself, and how an image is to be written.
struct ImageSpec {
  int width = 0, height = 0;
  std::vector<std::string> channels;  // names; pixels are interleaved in this order
  // Of the pixels handed to write_image_atomic (read_pixels always gives floats).
  enum class Format { float32, uint8 } format = Format::float32;
  // Code values of a display (8- and 16-bit PNG, JPEG: what OpenImageIO calls "sRGB"), not scene-linear.
  bool display_referred = false;
  // Scene-linear colour (a render): an OpenEXR file then carries the space's standard `chromaticities`
  // attribute and its name (oiio:ColorSpace), for compositors and image tools. Empty name: neither.
  std::string linear_space;
  std::array<float, 8> linear_chromaticities{};  // red, green, blue, white (x, y): core/rgb_space.h
  std::map<std::string, ImageAttribute> attributes;

  ImageSpec() = default;
  ImageSpec(int w, int h, std::vector<std::string> names, Format f = Format::float32)
      : width(w), height(h), channels(std::move(names)), format(f) {}

  int channel_index(const std::string& name) const {  // -1 when absent
    const auto at = std::find(channels.begin(), channels.end(), name);
    return at == channels.end() ? -1 : int(at - channels.begin());
  }
  // Typed attributes: `fallback` when absent or of another type.
  int get_int(const std::string& name, int fallback = 0) const { return get<int>(name).value_or(fallback); }
  float get_float(const std::string& name, float fallback = 0.0f) const { return get<float>(name).value_or(fallback); }
  std::string get_string(const std::string& name) const { return get<std::string>(name).value_or(std::string()); }
  std::optional<std::array<float, 3>> get_vec3(const std::string& name) const { return get<std::array<float, 3>>(name); }
  void set(const std::string& name, ImageAttribute value) { attributes[name] = std::move(value); }

 private:
  template <class T>
  std::optional<T> get(const std::string& name) const {
    const auto at = attributes.find(name);
    const T* v = at == attributes.end() ? nullptr : std::get_if<T>(&at->second);
    return v ? std::optional<T>(*v) : std::nullopt;
  }
};

// Whether `path` ends in `extension` (".exr"), in any case, after a name.
bool has_extension(const std::string& path, const std::string& extension);

// An image file opened for reading: its spec at once, its pixels on demand (a caller checks the size
// against its memory budget in between).
class ImageReader {
 public:
  // Throws Error("<path>: <the first line of the reason>"), or "<path>: <fallback>" when there is none.
  static ImageReader open(const std::string& path, const std::string& fallback = "cannot open");
  ImageReader(ImageReader&&) noexcept;
  ImageReader& operator=(ImageReader&&) noexcept;
  ~ImageReader();

  const ImageSpec& spec() const { return spec_; }
  const std::string& path() const { return path_; }
  // Every channel of the first part (subimage) as float, interleaved, row 0 at the top. Throws
  // Error("<path>: ...") for a failed read.
  std::vector<float> read_pixels();

  struct Backend;  // OpenEXR's reader or OpenImageIO's (image_file.cpp)

 private:
  ImageReader(std::string path, ImageSpec spec, std::unique_ptr<Backend> backend);
  std::string path_;
  ImageSpec spec_;
  std::unique_ptr<Backend> backend_;
};

// The indices of the R, G and B channels, found by name (OpenEXR stores channels sorted by name, so
// position says nothing); with `grey`, a one-channel image is grey: its channel three times. Throws
// Error("<path>: no <C> channel (channels: ...)").
enum class OneChannel { grey, refused };
std::array<int, 3> rgb_channels(const ImageSpec& spec, const std::string& path, OneChannel one_channel);

// The R, G and B (rgb_channels) of `pixels`, read_pixels of an image with `spec`, as interleaved floats; a
// NaN or infinite value is refused, naming the pixel.
std::vector<float> rgb_of(const std::vector<float>& pixels, const ImageSpec& spec, const std::string& path, OneChannel one_channel);
// rgb_of(in.read_pixels(), ...).
std::vector<float> read_rgb(ImageReader& in, OneChannel one_channel);

// Writes `pixels` (spec.format, interleaved as spec.channels) to `path` through an AtomicFile, read back
// whole before it takes the name; the format follows the extension (.exr: float, ZIP compression, the
// attributes in the header). `check`, if given, then reads the temporary as its own reader would and
// throws Error where it refuses it. Throws Error("<path>: cannot write: ...").
void write_image_atomic(const std::string& path, const ImageSpec& spec, const void* pixels,
                        const std::function<void(const std::string& temp_path)>& check = {});

// The interface of the module facetfit-oiio.so (io/oiio_codec.cpp): formats other than OpenEXR through
// OpenImageIO. Errors come back as text, not exceptions, across the module's boundary.
struct ImageCodec {
  static constexpr int kVersion = 1;
  int version;
  // A handle of the opened file and its spec, or null with `error` set.
  void* (*open)(const std::string& path, ImageSpec& spec, std::string& error);
  bool (*read)(void* handle, float* pixels, std::string& error);  // spec's size of floats
  void (*close)(void* handle);
  bool (*write)(const std::string& path, const ImageSpec& spec, const void* pixels, std::string& error);
};

}  // namespace facetfit
