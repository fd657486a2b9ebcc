// The module facetfit-oiio.so: every image format but OpenEXR, through OpenImageIO (io/image_file.h says
// why it is a module). It holds no facetfit code: errors go back as text.
#include <OpenImageIO/imageio.h>

#include <cerrno>
#include <cstring>
#include <memory>

#include "io/image_file.h"

namespace {

using facetfit::ImageCodec;
using facetfit::ImageSpec;

void* open_image(const std::string& path, ImageSpec& spec, std::string& error) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    error = OIIO::geterror();
    return nullptr;
  }
  const OIIO::ImageSpec& s = in->spec();
  // read_image reads every slice of a volume and the samples of a deep image: not into one buffer.
  if (s.deep || s.depth != 1) {
    error = s.deep ? "deep images are not supported" : "volume images are not supported";
    return nullptr;
  }
  spec = ImageSpec(s.width, s.height, s.channelnames);
  spec.display_referred = s.get_string_attribute("oiio:ColorSpace") == "sRGB";
  for (const OIIO::ParamValue& p : s.extra_attribs) {
    const OIIO::TypeDesc t = p.type();
    if (t == OIIO::TypeInt) spec.set(p.name().string(), p.get_int());
    else if (t == OIIO::TypeFloat) spec.set(p.name().string(), p.get_float());
    else if (t == OIIO::TypeString) spec.set(p.name().string(), p.get_string());
    else if (t.basetype == OIIO::TypeDesc::FLOAT && t.basevalues() == 3) {
      const float* v = static_cast<const float*>(p.data());
      spec.set(p.name().string(), std::array<float, 3>{v[0], v[1], v[2]});
    }
  }
  return in.release();
}

bool read_image(void* handle, float* pixels, std::string& error) {
  auto* in = static_cast<OIIO::ImageInput*>(handle);
  if (in->read_image(0, 0, 0, in->spec().nchannels, OIIO::TypeDesc::FLOAT, pixels)) return true;
  error = in->geterror();
  return false;
}

void close_image(void* handle) { std::unique_ptr<OIIO::ImageInput>(static_cast<OIIO::ImageInput*>(handle)); }

bool write_image(const std::string& path, const ImageSpec& spec, const void* pixels, std::string& error) {
  const OIIO::TypeDesc format = spec.format == ImageSpec::Format::uint8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT;
  OIIO::ImageSpec s(spec.width, spec.height, int(spec.channels.size()), format);
  s.channelnames = spec.channels;
  s.alpha_channel = spec.channel_index("A");
  s.attribute("oiio:ColorSpace", spec.display_referred ? "sRGB" : "Linear");
  for (const auto& [name, value] : spec.attributes) {
    if (const int* i = std::get_if<int>(&value)) s.attribute(name, *i);
    else if (const float* f = std::get_if<float>(&value)) s.attribute(name, *f);
    else if (const std::string* t = std::get_if<std::string>(&value)) s.attribute(name, *t);
    else if (const auto* v = std::get_if<std::array<float, 3>>(&value)) s.attribute(name, OIIO::TypeColor, v->data());
  }
  auto out = OIIO::ImageOutput::create(path);
  if (!out) {
    error = OIIO::geterror();
    return false;
  }
  errno = 0;
  if (!out->open(path, s)) {
    // OpenImageIO names the temporary and not the reason; the system's reason says more.
    const int code = errno;
    error = code != 0 ? std::string(std::strerror(code)) : out->geterror();
    return false;
  }
  if (out->write_image(format, pixels) && out->close()) return true;
  error = out->geterror();
  return false;
}

constexpr ImageCodec kCodec{ImageCodec::kVersion, open_image, read_image, close_image, write_image};

}  // namespace

extern "C" __attribute__((visibility("default"))) const ImageCodec* facetfit_image_codec() { return &kCodec; }
