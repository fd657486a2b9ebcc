#include "io/image_file.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfFloatAttribute.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfVecAttribute.h>
#include <dlfcn.h>

#include <algorithm>
#include <cctype>
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

// What the first part's header says of the chunks: its data window, tile size and compression.
struct ExrLayout {
  std::int32_t window[4] = {0, 0, -1, -1};
  std::uint32_t tile[2] = {1, 1};
  int compression = 0;
  bool has_window = false;
};

// An attribute of a type whose value OpenEXR reads by its own size must state that size.
void check_fixed_size(const std::string& path, const std::string& name, const std::string& type, std::int32_t size) {
  static const std::pair<const char*, int> kFixedSizes[] = {
      {"box2i", 16}, {"box2f", 16}, {"compression", 1}, {"lineOrder", 1}, {"envmap", 1}, {"deepImageState", 1},
      {"float", 4},  {"int", 4},    {"double", 8},      {"rational", 8},  {"timecode", 8}, {"keycode", 28},
      {"v2i", 8},    {"v2f", 8},    {"v2d", 16},        {"v3i", 12},      {"v3f", 12},     {"v3d", 24},
      {"m33f", 36},  {"m33d", 72},  {"m44f", 64},       {"m44d", 128},    {"tiledesc", 9}, {"chromaticities", 32}};
  for (const auto& [known, bytes] : kFixedSizes)
    if (type == known && size != bytes)
      fail(path, "OpenEXR header: attribute '" + name + "' of type " + type + " has " + std::to_string(size) + " bytes, not " +
                     std::to_string(bytes));
}

// A preview's value: OpenEXR allocates width x height x 4 bytes from its first 8.
void check_preview(const std::string& path, const std::string& name, std::int32_t size, const std::vector<char>& value) {
  std::uint32_t wh[2] = {0, 0};
  if (size >= 8) std::memcpy(wh, value.data(), 8);
  if (size < 8 || std::uint64_t(wh[0]) * wh[1] * 4u + 8u != std::uint64_t(size))
    fail(path, "OpenEXR header: preview '" + name + "' does not match its size");
}

// The data window, compression and tiles of the first part, from an attribute's first (up to 16) bytes.
void record_layout(const std::string& name, std::int32_t size, const std::vector<char>& value, ExrLayout& layout) {
  if (name == "dataWindow" && size == 16) {
    std::memcpy(layout.window, value.data(), 16);
    layout.has_window = true;
  }
  if (name == "compression" && size == 1) layout.compression = static_cast<unsigned char>(value[0]);
  if (name == "tiles" && size >= 8) std::memcpy(layout.tile, value.data(), 8);
}

// An OpenEXR file's headers, walked attribute by attribute: every attribute must fit in the file (of
// `file_size` bytes), a name in `max_name` characters.
struct ExrHeaderWalk {
  std::istream& in;
  const std::string& path;
  std::uint64_t file_size;
  std::size_t max_name;

  void read_name(std::string& out) {
    out.clear();
    for (char c; in.get(c);) {
      if (c == '\0') return;
      if (out.size() == max_name) fail(path, "OpenEXR header: a name longer than " + std::to_string(max_name) + " characters");
      out += c;
    }
    fail(path, "OpenEXR header: truncated");
  }

  // A value that OpenEXR reads entry by entry (a channel list, a string vector), of `size` bytes from
  // `at`: each entry must fit.
  void check_entries(const std::string& name, const std::string& type, std::int32_t size, std::uint64_t at) {
    std::vector<char> all(static_cast<std::size_t>(size));
    in.seekg(std::streamoff(at));
    in.read(all.data(), size);
    if (!in) fail(path, "OpenEXR header: truncated");
    if (!(type == "chlist" ? channel_list_fits(all, max_name) : string_vector_fits(all)))
      fail(path, "OpenEXR header: attribute '" + name + "' of type " + type + " does not match its size");
  }

  // The attribute `name` of header `part`, after its name: its type, size and value, left behind.
  void read_attribute(const std::string& name, int part, ExrLayout& layout) {
    std::string type;
    read_name(type);
    std::int32_t size = 0;
    if (!in.read(reinterpret_cast<char*>(&size), 4)) fail(path, "OpenEXR header: truncated");
    const std::uint64_t at = std::uint64_t(in.tellg());
    if (size < 0 || std::uint64_t(size) > file_size - at)
      fail(path, "OpenEXR header: attribute '" + name + "' claims " + std::to_string(size) + " bytes, the file has " +
                     std::to_string(file_size - at) + " left");
    check_fixed_size(path, name, type, size);
    std::vector<char> value(std::size_t(std::min<std::int32_t>(size, 16)));
    in.read(value.data(), std::streamsize(value.size()));
    if (type == "chlist" || type == "stringvector") check_entries(name, type, size, at);
    if (type == "preview") check_preview(path, name, size, value);
    if (part == 0) record_layout(name, size, value, layout);
    in.seekg(std::streamoff(at + std::uint64_t(size)));
  }

  // Every header (one, or each part's of a multi-part file), to the end of the last.
  ExrLayout read_headers(bool multipart) {
    ExrLayout layout;
    for (int part = 0;; ++part) {
      std::string name;
      read_name(name);
      if (name.empty()) break;  // end of this header (or, in a multi-part file, of all headers)
      for (; !name.empty(); read_name(name)) read_attribute(name, part, layout);
      if (!multipart) break;
    }
    return layout;
  }
};

// The data window's width and height, which OpenEXR sizes its line buffers by.
std::pair<std::int64_t, std::int64_t> data_window_size(const std::string& path, const ExrLayout& layout) {
  const std::int32_t* window = layout.window;
  const std::int64_t width = std::int64_t(window[2]) - window[0] + 1, height = std::int64_t(window[3]) - window[1] + 1;
  if (width < 1 || height < 1) fail(path, "OpenEXR header: empty data window");
  // OpenEXR sizes its line buffers by the width as it opens the file: nothing facetfit reads is wider or
  // taller than 65536 (an 8-million-pixel-wide 416-byte file took seconds to open and close).
  if (width > 65536 || height > 65536)
    fail(path, "OpenEXR header: a " + std::to_string(width) + " x " + std::to_string(height) + " image; at most 65536 x 65536");
  return {width, height};
}

// The chunks of a width x height image: its scanline blocks, or the tiles of the first level.
std::uint64_t chunk_count(const std::string& path, const ExrLayout& layout, bool tiled, std::int64_t width, std::int64_t height) {
  // Scanlines per chunk of each compression (OpenEXR's table).
  static constexpr int kLines[] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};
  if (tiled) {
    const std::uint32_t* tile = layout.tile;
    if (tile[0] == 0 || tile[1] == 0) fail(path, "OpenEXR header: zero tile size");
    return std::uint64_t((width + tile[0] - 1) / tile[0]) * std::uint64_t((height + tile[1] - 1) / tile[1]);
  }
  const int compression = layout.compression;
  const int lines = compression >= 0 && compression < 10 ? kLines[compression] : 1;
  return std::uint64_t((height + lines - 1) / lines);
}

// A scanline file's chunks follow its offset table, every offset inside the file. A data window changed
// after writing implies a table of another length, and OpenEXR then decodes chunks of other sizes
// without an error: a 512 x 256 map whose window said 65536 x 1 read as one line of garbage.
void check_chunk_offsets(std::istream& in, const std::string& path, std::uint64_t file_size, std::uint64_t header_end,
                         std::uint64_t chunks) {
  const std::uint64_t table_end = header_end + 8 * chunks;
  std::uint64_t first = file_size;
  for (std::uint64_t c = 0; c < chunks; ++c) {
    std::uint64_t offset = 0;
    if (!in.read(reinterpret_cast<char*>(&offset), 8)) fail(path, "OpenEXR: truncated chunk offset table");
    if (offset < table_end || offset >= file_size)
      fail(path, "OpenEXR: chunk " + std::to_string(c) + "'s offset " + std::to_string(offset) +
                     " is outside the file's chunks (an incomplete file, or a data window that does not match its data)");
    first = std::min(first, offset);
  }
  if (first != table_end)
    fail(path, "OpenEXR: the chunks start at byte " + std::to_string(first) + ", not right after the " + std::to_string(chunks) +
                   "-entry offset table the data window implies (byte " + std::to_string(table_end) +
                   "): the data window does not match the data");
}

// OpenEXR 3.1 allocates what a header claims before reading it: a 6 KB file whose string attribute
// claims 1.6 GB took 1.7 GB (found by fuzz_lut). The headers are walked here first, and every attribute
// must fit in the file, as must the chunk offset table the data window implies (8 bytes per chunk).
// Returns whether the file is an OpenEXR file (by its magic number).
bool check_exr_header(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::error_code ec;
  const std::uint64_t file_size = std::filesystem::file_size(path, ec);
  unsigned char magic[8];
  if (!in || ec || !in.read(reinterpret_cast<char*>(magic), 8)) return false;  // OpenImageIO says why
  if (!(magic[0] == 0x76 && magic[1] == 0x2f && magic[2] == 0x31 && magic[3] == 0x01)) return false;  // not OpenEXR
  const bool multipart = (magic[5] & 0x10) != 0, tiled = (magic[5] & 0x02) != 0;
  // OpenEXR reads at most 31 characters of a name (255 with the long-names flag) and the values of the
  // types it knows by their own size, whatever size the header states: a header that disagrees is parsed
  // differently by OpenEXR than here, so it is refused.
  const std::size_t max_name = (magic[5] & 0x04) != 0 ? 255 : 31;
  ExrHeaderWalk walk{in, path, file_size, max_name};
  const ExrLayout layout = walk.read_headers(multipart);
  if (multipart || !layout.has_window) return true;  // OpenEXR refuses a header without a data window
  const auto [width, height] = data_window_size(path, layout);
  const std::uint64_t chunks = chunk_count(path, layout, tiled, width, height);
  const std::uint64_t header_end = std::uint64_t(in.tellg());
  if (chunks > (file_size - header_end) / 8)
    fail(path, "OpenEXR header: a " + std::to_string(width) + " x " + std::to_string(height) + " image needs " +
                   std::to_string(chunks) + " chunks, more than the file's " + std::to_string(file_size) + " bytes can hold");
  if (!tiled && (magic[5] & 0x08) == 0) check_chunk_offsets(in, path, file_size, header_end, chunks);
  return true;
}

// ---- OpenEXR ----------------------------------------------------------------------------------------------

// The spec of an open OpenEXR file: R, G, B, A first (as OpenImageIO orders them), then the others in the
// file's (sorted) order; the int, float, string and v3f attributes.
ImageSpec exr_spec(const Imf::Header& header) {
  ImageSpec spec;
  const Imath::Box2i window = header.dataWindow();
  spec.width = window.max.x - window.min.x + 1;
  spec.height = window.max.y - window.min.y + 1;
  for (const char* name : {"R", "G", "B", "A"})
    if (header.channels().findChannel(name)) spec.channels.push_back(name);
  for (auto c = header.channels().begin(); c != header.channels().end(); ++c)
    if (spec.channel_index(c.name()) < 0) spec.channels.push_back(c.name());
  for (auto a = header.begin(); a != header.end(); ++a) {
    if (const auto* i = dynamic_cast<const Imf::IntAttribute*>(&a.attribute())) spec.set(a.name(), i->value());
    else if (const auto* f = dynamic_cast<const Imf::FloatAttribute*>(&a.attribute())) spec.set(a.name(), f->value());
    else if (const auto* t = dynamic_cast<const Imf::StringAttribute*>(&a.attribute())) spec.set(a.name(), t->value());
    else if (const auto* v = dynamic_cast<const Imf::V3fAttribute*>(&a.attribute()))
      spec.set(a.name(), std::array<float, 3>{v->value().x, v->value().y, v->value().z});
  }
  return spec;
}

// One float slice per channel of `spec`, interleaved in `pixels`, placed by the data window (OpenEXR
// converts half and uint channels as it reads).
Imf::FrameBuffer exr_frame_buffer(const ImageSpec& spec, const Imath::Box2i& window, const float* pixels) {
  const std::size_t stride = sizeof(float) * spec.channels.size();
  Imf::FrameBuffer frame;
  for (std::size_t c = 0; c < spec.channels.size(); ++c)
    frame.insert(spec.channels[c], Imf::Slice::Make(Imf::FLOAT, pixels + c, window, stride, stride * std::size_t(spec.width)));
  return frame;
}

// Where formats other than OpenEXR are read and written: facetfit-oiio.so, found beside the object this
// code is linked into (the command's plugin, a Python extension), in ../lib/facetfit from it (an
// installed executable), or in the build tree. Loaded once per process, on first use, and kept.
struct LoadedCodec {
  const ImageCodec* codec = nullptr;
  std::string error;
};

LoadedCodec load_codec() {
  namespace fs = std::filesystem;
  std::vector<fs::path> candidates;
  Dl_info self{};
  if (::dladdr(reinterpret_cast<void*>(&load_codec), &self) != 0 && self.dli_fname) {
    std::error_code ec;
    const fs::path here = fs::canonical(self.dli_fname, ec).parent_path();
    if (!ec) candidates.insert(candidates.end(), {here / "facetfit-oiio.so", here.parent_path() / "lib" / "facetfit" / "facetfit-oiio.so"});
  }
#ifdef FACETFIT_MODULE_DIRS
  for (const char* dir : {FACETFIT_MODULE_DIRS}) candidates.push_back(fs::path(dir) / "facetfit-oiio.so");
#endif
  std::string looked;
  for (const fs::path& path : candidates) {
    looked += (looked.empty() ? "" : ", ") + path.parent_path().string();
    if (!fs::exists(path)) continue;
    void* module = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!module) return {nullptr, "cannot load " + path.string() + ": " + first_line(::dlerror())};
    using Entry = const ImageCodec* (*)();
    const auto entry = reinterpret_cast<Entry>(::dlsym(module, "facetfit_image_codec"));
    const ImageCodec* codec = entry ? entry() : nullptr;
    if (!codec || codec->version != ImageCodec::kVersion) return {nullptr, path.string() + " is not this facetfit's image module"};
    return {codec, ""};
  }
  return {nullptr, "images other than OpenEXR need the module facetfit-oiio.so (OpenImageIO), not found in " + looked};
}

const ImageCodec& other_formats(const std::string& path) {
  static const LoadedCodec loaded = load_codec();  // a module, like the libraries it brings, is loaded once
  if (!loaded.codec) fail(path, loaded.error);
  return *loaded.codec;
}

void write_exr_file(const std::string& path, const std::string& target, const ImageSpec& spec, const void* pixels) {
  if (spec.format != ImageSpec::Format::float32) fail(target, "cannot write: OpenEXR files are written from float pixels");
  Imf::Header header(spec.width, spec.height);
  header.compression() = Imf::ZIP_COMPRESSION;
  for (const std::string& name : spec.channels) header.channels().insert(name, Imf::Channel(Imf::FLOAT));
  for (const auto& [name, value] : spec.attributes) {
    if (const int* i = std::get_if<int>(&value)) header.insert(name, Imf::IntAttribute(*i));
    else if (const float* f = std::get_if<float>(&value)) header.insert(name, Imf::FloatAttribute(*f));
    else if (const std::string* t = std::get_if<std::string>(&value)) header.insert(name, Imf::StringAttribute(*t));
    else if (const auto* v = std::get_if<std::array<float, 3>>(&value)) header.insert(name, Imf::V3fAttribute(Imath::V3f((*v)[0], (*v)[1], (*v)[2])));
  }
  if (!spec.linear_space.empty()) {
    const auto& c = spec.linear_chromaticities;
    Imf::addChromaticities(header, Imf::Chromaticities({c[0], c[1]}, {c[2], c[3]}, {c[4], c[5]}, {c[6], c[7]}));
    header.insert("oiio:ColorSpace", Imf::StringAttribute(spec.linear_space));
  }
  Imf::OutputFile out(path.c_str(), header);
  out.setFrameBuffer(exr_frame_buffer(spec, header.dataWindow(), static_cast<const float*>(pixels)));
  out.writePixels(spec.height);
}

}  // namespace

struct ImageReader::Backend {
  std::unique_ptr<Imf::InputFile> exr;
  const ImageCodec* codec = nullptr;
  void* handle = nullptr;  // codec's
  ~Backend() {
    if (handle) codec->close(handle);
  }
};

ImageReader::ImageReader(std::string path, ImageSpec spec, std::unique_ptr<Backend> backend)
    : path_(std::move(path)), spec_(std::move(spec)), backend_(std::move(backend)) {}
ImageReader::ImageReader(ImageReader&&) noexcept = default;
ImageReader& ImageReader::operator=(ImageReader&&) noexcept = default;
ImageReader::~ImageReader() = default;

ImageReader ImageReader::open(const std::string& path, const std::string& fallback) {
  require_regular_file(path);  // a reader would probe a device with every format reader, forever
  auto backend = std::make_unique<Backend>();
  ImageSpec spec;
  if (check_exr_header(path)) {
    try {
      backend->exr = std::make_unique<Imf::InputFile>(path.c_str());
      const Imf::Header& header = backend->exr->header();
      if (header.hasType() && Imf::isDeepData(header.type())) fail(path, "deep images are not supported");
      spec = exr_spec(header);
    } catch (const Error&) {
      throw;
    } catch (const std::exception& e) {
      const std::string why = first_line(e.what());
      fail(path, why.empty() ? fallback : why);
    }
  } else {
    backend->codec = &other_formats(path);
    std::string error;
    backend->handle = backend->codec->open(path, spec, error);
    if (!backend->handle) fail(path, error.empty() ? fallback : first_line(error));
  }
  if (spec.width < 1 || spec.height < 1 || spec.channels.empty()) fail(path, "empty image");
  return ImageReader(path, std::move(spec), std::move(backend));
}

bool has_extension(const std::string& path, const std::string& extension) {
  if (path.size() <= extension.size()) return false;
  return std::equal(extension.begin(), extension.end(), path.end() - std::ptrdiff_t(extension.size()),
                    [](char e, char p) { return e == char(std::tolower(static_cast<unsigned char>(p))); });
}

std::vector<float> ImageReader::read_pixels() {
  std::vector<float> all(std::size_t(spec_.width) * std::size_t(spec_.height) * spec_.channels.size());
  if (backend_->exr) {
    try {
      const Imath::Box2i window = backend_->exr->header().dataWindow();
      backend_->exr->setFrameBuffer(exr_frame_buffer(spec_, window, all.data()));
      backend_->exr->readPixels(window.min.y, window.max.y);
    } catch (const std::exception& e) {
      fail(path_, "cannot read pixels: " + first_line(e.what()));
    }
  } else {
    std::string error;
    if (!backend_->codec->read(backend_->handle, all.data(), error)) fail(path_, "cannot read pixels: " + first_line(error));
  }
  return all;
}

std::array<int, 3> rgb_channels(const ImageSpec& spec, const std::string& path, OneChannel one_channel) {
  std::array<int, 3> channel{};
  if (spec.channels.size() == 1 && one_channel == OneChannel::grey) return channel;
  const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    channel[std::size_t(c)] = spec.channel_index(names[c]);
    if (channel[std::size_t(c)] < 0) {
      std::string present;
      for (const std::string& n : spec.channels) present += (present.empty() ? "" : ", ") + n;
      fail(path, std::string("no ") + names[c] + " channel (channels: " + present + ")");
    }
  }
  return channel;
}

std::vector<float> rgb_of(const std::vector<float>& all, const ImageSpec& spec, const std::string& path, OneChannel one_channel) {
  const std::array<int, 3> channel = rgb_channels(spec, path, one_channel);
  const std::size_t pixels = std::size_t(spec.width) * std::size_t(spec.height), n = spec.channels.size();
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

std::vector<float> read_rgb(ImageReader& in, OneChannel one_channel) {
  return rgb_of(in.read_pixels(), in.spec(), in.path(), one_channel);
}

void write_image_atomic(const std::string& path, const ImageSpec& spec, const void* pixels,
                        const std::function<void(const std::string& temp_path)>& check) {
  AtomicFile out(path);
  if (has_extension(path, ".exr")) {
    errno = 0;
    try {
      write_exr_file(out.temp_path(), path, spec, pixels);
    } catch (const Error&) {
      throw;
    } catch (const std::exception& e) {
      // OpenEXR names the temporary; the system's reason, where there is one, says more.
      const int error = errno;
      fail(path, "cannot write: " + (error != 0 ? std::string(std::strerror(error)) : first_line(e.what())));
    }
  } else {
    std::string error;
    if (!other_formats(path).write(out.temp_path(), spec, pixels, error)) fail(path, "cannot write: " + first_line(error));
  }
  // Some writers (PNG) report no error when the disk fills and leave a truncated file: read it back
  // whole before it takes the target's name.
  const auto reason = [&](const Error& e) {  // the reader's message without the temporary's name
    const std::string why = e.what(), own = out.temp_path() + ": ";
    return why.rfind(own, 0) == 0 ? why.substr(own.size()) : why;
  };
  try {
    ImageReader::open(out.temp_path()).read_pixels();
  } catch (const Error& e) {
    fail(path, "cannot write: the written file does not read back whole (disk full?): " + reason(e));
  }
  try {
    if (check) check(out.temp_path());
  } catch (const Error& e) {
    fail(path, "cannot write: its reader refuses what was written: " + reason(e));
  }
  out.commit();
}

}  // namespace facetfit
