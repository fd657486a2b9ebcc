#include "io/image_file.h"

#include "core/error.h"
#include "io/atomic_file.h"

namespace facetfit {

std::unique_ptr<OIIO::ImageInput> open_image(const std::string& path, const std::string& fallback) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    const std::string why = OIIO::geterror();
    fail(path, why.empty() ? fallback : why.substr(0, why.find('\n')));
  }
  return in;
}

void write_image_atomic(const std::string& path, const OIIO::ImageSpec& spec, const void* pixels) {
  AtomicFile out(path);
  auto image = OIIO::ImageOutput::create(out.temp_path());
  if (!image) fail(path, "cannot write: " + OIIO::geterror());
  if (!image->open(out.temp_path(), spec) || !image->write_image(spec.format, pixels) || !image->close())
    fail(path, "cannot write: " + image->geterror());
  image.reset();
  out.commit();
}

}  // namespace facetfit
