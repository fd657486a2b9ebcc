#include "io/image_file.h"

#include <vector>

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
  // Some writers (PNG) report no error when the disk fills and leave a truncated file: read it back
  // whole before it takes the target's name.
  auto check = OIIO::ImageInput::open(out.temp_path());
  std::vector<unsigned char> back(check ? check->spec().image_bytes() : 0);
  if (!check || !check->read_image(0, 0, 0, check->spec().nchannels, check->spec().format, back.data())) {
    const std::string why = check ? check->geterror() : OIIO::geterror();
    fail(path, "cannot write: the written file does not read back whole (disk full?)" +
                   (why.empty() ? std::string() : ": " + why.substr(0, why.find('\n'))));
  }
  check->close();
  out.commit();
}

}  // namespace facetfit
