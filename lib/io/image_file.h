// Image files through OpenImageIO with facetfit's error and write rules: one-line errors naming the
// file, and every output written under a temporary name and renamed into place.
#pragma once

#include <OpenImageIO/imageio.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace facetfit {

// Opens an image for reading. Throws Error("<path>: <OpenImageIO's first line>"), or
// "<path>: <fallback>" when OpenImageIO gives no reason.
std::unique_ptr<OIIO::ImageInput> open_image(const std::string& path, const std::string& fallback = "cannot open");

// The indices of the R, G and B channels, found by name (OpenEXR stores channels sorted by name, so
// position says nothing); with `grey`, a one-channel image is grey: its channel three times. Throws
// Error("<path>: no <C> channel (channels: ...)").
enum class OneChannel { grey, refused };
std::array<int, 3> rgb_channels(const OIIO::ImageSpec& spec, const std::string& path, OneChannel one_channel);

// Every channel of an open image's first subimage as floats, interleaved, row 0 at the top. Throws
// Error("<path>: ...") for a deep, volume or empty image and for a failed read.
std::vector<float> read_pixels(OIIO::ImageInput& in, const std::string& path);

// The R, G and B (rgb_channels) of `pixels`, read_pixels of an image with `spec`, as interleaved floats; a
// NaN or infinite value is refused, naming the pixel.
std::vector<float> rgb_of(const std::vector<float>& pixels, const OIIO::ImageSpec& spec, const std::string& path, OneChannel one_channel);
// rgb_of(read_pixels(in, path), ...).
std::vector<float> read_rgb(OIIO::ImageInput& in, const std::string& path, OneChannel one_channel);

// Writes `pixels` (spec.format, interleaved as spec says) to `path` through an AtomicFile; the format
// follows the extension. Throws Error("<path>: cannot write: ...").
void write_image_atomic(const std::string& path, const OIIO::ImageSpec& spec, const void* pixels);

}  // namespace facetfit
