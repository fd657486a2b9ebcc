// facetfit deltae : CIEDE2000 of Lab pairs read on stdin.
// facetfit diff A.exr B.exr : mean and max ΔE00 between two renders through the display chain, and a heatmap.
// The colour options of bake, render and report: --working-space, --display, --view, --ocio-config.

#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "color/ciede2000.h"
#include "color/ocio_config.h"
#include "color/display.h"
#include "color/image_diff.h"
#include "commands.h"
#include "core/error.h"
#include "core/memory_budget.h"
#include "io/atomic_file.h"
#include "io/image_file.h"

namespace facetfit::cli {

namespace {

void add_ocio_config_option(CLI::App* cmd, ColorSettings& s) {
  if (!cmd->get_option_no_throw("--ocio-config"))
    cmd->add_option("--ocio-config", s.ocio_config, "OpenColorIO config of the working space and the views (default: $OCIO)");
}

}  // namespace

void add_working_space_options(CLI::App* cmd, ColorSettings& s) {
  cmd->add_option("--working-space", s.working_space,
                  "Linear colour space of the LUT's colours or the render (a name of the OpenColorIO config, e.g. ACEScg)")
      ->capture_default_str();
  add_ocio_config_option(cmd, s);
}

void add_view_options(CLI::App* cmd, ColorSettings& s) {
  CLI::Option* display = cmd->add_option("--display", s.display, "Pictures through this display of the OpenColorIO config (default: sRGB of Rec.709)");
  cmd->add_option("--view", s.view, "With --display: its view (default: the display's default view)")->needs(display);
  add_ocio_config_option(cmd, s);
}

// A config named by $OCIO is read, and refused when broken, even where the command ends up not needing it.
ColorConfig ColorSettings::config() const { return ColorConfig(ocio_config); }

ColorMatrix ColorSettings::from_rec709(const ColorConfig& config) const { return config.from_rec709(working_space); }

DisplayTransform ColorSettings::pictures(const ColorConfig& config, const std::string& space, const ColorMatrix& space_from_rec709) const {
  if (display.empty()) {
    if (!view.empty()) fail("--view " + view, "needs --display");
    return DisplayTransform(glm::inverse(space_from_rec709));
  }
  return DisplayTransform(config, space, display, view);
}

namespace {

// ---- deltae ----------------------------------------------------------------------------------------------

void run_deltae(Context& ctx) {
  int& status = ctx.status;
  std::string line;
  int number = 0, failures = 0;
  while (std::getline(std::cin, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();  // files written on Windows
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    try {
      const auto v = parse_lab_pair(line, "stdin line " + std::to_string(number));
      std::printf("%.6f\n", ciede2000({v[0], v[1], v[2]}, {v[3], v[4], v[5]}));
    } catch (const Error& e) {
      report_error(e.what());
      ++failures;
    }
  }
  if (failures > 0) status = 1;
}

// ---- diff ------------------------------------------------------------------------------------------------

// An image's colour (and alpha, if it has an A channel), as float.
struct Image {
  int width = 0, height = 0;
  std::vector<float> rgb;    // interleaved, 3 per pixel
  std::vector<float> alpha;  // empty without an A channel
  bool display_referred = false;

  std::size_t pixels() const { return std::size_t(width) * std::size_t(height); }
};

std::string size_text(int width, int height) { return std::to_string(width) + " x " + std::to_string(height); }

// Every channel of the first subimage as float, with its spec. The header's size is checked against what
// is `left` of the memory budget first (a small file can claim a huge image): its pixels as read, their
// RGB copy and alpha, and the Delta E per pixel.
std::vector<float> read_all(const std::string& path, ImageSpec& spec, std::uint64_t& left) {
  ImageReader in = ImageReader::open(path);
  spec = in.spec();
  const std::uint64_t pixels = std::uint64_t(spec.width) * std::uint64_t(spec.height);
  const std::uint64_t need = pixels * (4 * (std::uint64_t(spec.channels.size()) + 4) + 8);
  check_memory(path, "its " + size_text(spec.width, spec.height) + " image (diff --max-memory)", need, left);
  left -= need;
  return in.read_pixels();
}

// Channels by name, never by position: EXR stores them sorted by name (A, B, G, R).
Image read_image(const std::string& path, std::uint64_t& left) {
  ImageSpec spec;
  const std::vector<float> all = read_all(path, spec, left);
  const int a = spec.channel_index("A");
  Image image;
  image.width = spec.width;
  image.height = spec.height;
  // 8- and 16-bit PNG, JPEG and the like hold display code values already and skip the display
  // transform. Everything else (EXR) is scene-linear.
  image.display_referred = spec.display_referred;
  // A NaN or infinite pixel has no colour difference: refused, not averaged into a score.
  image.rgb = rgb_of(all, spec, path, OneChannel::refused);
  // A render in another working space (facetfit render --working-space) goes back to lin_rec709 by the
  // inverse of the matrix it records: Delta E is measured on the sRGB display of Rec.709 colour.
  if (const std::string m = spec.get_string("facetfit:colorspace_matrix"); !m.empty()) {
    const std::optional<ColorMatrix> from_rec709 = parse_matrix(m);
    if (!from_rec709) fail(path, "facetfit:colorspace_matrix is not nine numbers of an invertible matrix");
    convert_pixels(image.rgb.data(), image.pixels(), 3, glm::inverse(*from_rec709));
  }
  if (a >= 0) {
    const std::size_t n = image.pixels(), nch = spec.channels.size();
    image.alpha.resize(n);
    for (std::size_t p = 0; p < n; ++p) image.alpha[p] = all[p * nch + std::size_t(a)];
  }
  return image;
}

// The --mask image: a pixel counts where its first channel is > 0.5.
std::vector<bool> read_mask(const std::string& path, int width, int height, std::uint64_t& left) {
  ImageSpec spec;
  const std::vector<float> all = read_all(path, spec, left);
  if (spec.width != width || spec.height != height)
    fail(path, "mask is " + size_text(spec.width, spec.height) + ", the images are " + size_text(width, height));
  std::vector<bool> mask(std::size_t(width) * std::size_t(height));
  for (std::size_t p = 0; p < mask.size(); ++p) mask[p] = all[p * spec.channels.size()] > 0.5f;
  return mask;
}

// Without --mask: where either image has alpha > 0 (a render's background has none), else everywhere.
std::vector<bool> coverage_mask(const Image& a, const Image& b) {
  if (a.alpha.empty() && b.alpha.empty()) return std::vector<bool>(a.pixels(), true);
  std::vector<bool> mask(a.pixels());
  for (std::size_t p = 0; p < mask.size(); ++p)
    mask[p] = (!a.alpha.empty() && a.alpha[p] > 0) || (!b.alpha.empty() && b.alpha[p] > 0);
  return mask;
}

struct DiffArgs {
  std::string a, b, mask, heatmap;
  bool json = false;
  std::uint64_t max_memory = 0;
};

void run_diff(const DiffArgs& args, Context& ctx) {
  int& status = ctx.status;
  if (!args.heatmap.empty() && !has_extension(args.heatmap, ".png")) {
    report_error("--heatmap " + args.heatmap + ": must end in .png");
    status = 2;
    return;
  }
  try {
    if (!args.heatmap.empty())
      for (const std::string* input : {&args.a, &args.b, &args.mask})
        if (!input->empty() && file_key(args.heatmap) == file_key(*input)) fail(args.heatmap, "--heatmap would overwrite an input of the diff");
    std::uint64_t left = args.max_memory > 0 ? args.max_memory : default_memory_budget();
    Image a = read_image(args.a, left);
    Image b = read_image(args.b, left);
    if (a.width != b.width || a.height != b.height)
      fail(args.b, "is " + size_text(b.width, b.height) + " but " + args.a + " is " + size_text(a.width, a.height));
    const std::vector<bool> mask = args.mask.empty() ? coverage_mask(a, b) : read_mask(args.mask, a.width, a.height, left);
    const int width = a.width, height = a.height;
    const bool a_display = a.display_referred, b_display = b.display_referred;
    const ImageDiff d = image_delta_e(std::move(a.rgb), a_display, std::move(b.rgb), b_display, mask, DisplayTransform());
    if (d.pixels == 0) {
      if (args.mask.empty()) fail(args.a, "no pixel has alpha > 0 in either image");
      fail(args.mask, "the mask selects no pixel");
    }
    // The heatmap before the numbers: a run that prints them has done everything asked.
    if (!args.heatmap.empty()) write_heatmap_png(args.heatmap, width, height, d.delta_e, mask);
    if (args.json)
      std::printf("%s\n", nlohmann::json{{"mean", d.mean}, {"max", d.max}, {"pixels", d.pixels}}.dump().c_str());
    else
      std::printf("mean %.6f max %.6f pixels %zu\n", d.mean, d.max, d.pixels);
  } catch (const Error& e) {
    report_error(e.what());
    status = 1;
  }
}

}  // namespace

void add_deltae_command(CLI::App& app, Context& ctx) {
  CLI::App* cmd = app.add_subcommand("deltae",
                                     "CIEDE2000 of colour pairs: reads lines 'L1 a1 b1 L2 a2 b2' on stdin, prints "
                                     "one Delta E 2000 per line (6 decimals)");
  cmd->callback([&ctx] { run_deltae(ctx); });
}

void add_diff_command(CLI::App& app, Context& ctx) {
  auto args = std::make_shared<DiffArgs>();
  CLI::App* cmd = app.add_subcommand(
      "diff", "Mean and max CIEDE2000 between two scene-linear images, through the sRGB display transform");
  cmd->add_option("a", args->a, "First image (scene-linear Rec.709, e.g. an EXR from facetfit render)")->required();
  cmd->add_option("b", args->b, "Second image, the same size")->required();
  cmd->add_option("--mask", args->mask, "Only pixels whose first channel is > 0.5 (default: alpha > 0 in either image, "
                                        "or every pixel without alpha)");
  cmd->add_option("--heatmap", args->heatmap,
                  "Write a PNG of per-pixel Delta E 2000 (viridis from 0 to 10, saturating; black outside the mask)");
  cmd->add_flag("--json", args->json, "As one JSON object {\"mean\", \"max\", \"pixels\"}");
  add_max_memory_option(cmd, args->max_memory, "the images (and mask) read");
  cmd->callback([args, &ctx] { run_diff(*args, ctx); });
}

}  // namespace facetfit::cli
