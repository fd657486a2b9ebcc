// Image files through OpenImageIO with facetfit's error and write rules: one-line errors naming the
// file, and every output written under a temporary name and renamed into place.
#pragma once

#include <OpenImageIO/imageio.h>

#include <memory>
#include <string>

namespace facetfit {

// Opens an image for reading. Throws Error("<path>: <OpenImageIO's first line>"), or
// "<path>: <fallback>" when OpenImageIO gives no reason.
std::unique_ptr<OIIO::ImageInput> open_image(const std::string& path, const std::string& fallback = "cannot open");

// Writes `pixels` (spec.format, interleaved as spec says) to `path` through an AtomicFile; the format
// follows the extension. Throws Error("<path>: cannot write: ...").
void write_image_atomic(const std::string& path, const OIIO::ImageSpec& spec, const void* pixels);

}  // namespace facetfit
