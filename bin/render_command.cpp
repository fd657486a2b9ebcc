// facetfit render [SCENE.json] -o OUT.exr : the reference renderer.
#include <tbb/global_control.h>
#include <unistd.h>

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "commands.h"
#include "color/image_diff.h"
#include "core/error.h"
#include "io/atomic_file.h"
#include "io/image_file.h"
#include "io/input.h"
#include "lut/bake.h"
#include "render/environment.h"
#include "render/materials.h"
#include "render/renderer.h"

namespace facetfit::cli {

namespace {

namespace fs = std::filesystem;

struct RenderArgs {
  std::string scene;
  std::string output;
  std::string png;
  std::string save_sky;
  int spp = 0;
  std::uint64_t seed = 0;
  std::string material = "builtin:gold-ggx-0.15";
  std::string material_type = "measured";
  int width = 0, height = 0;
  std::uint64_t max_memory = 0;
  ColorSettings color;
};

// The image format each output flag writes, by its extension.
struct OutputFormat {
  const char* flag;
  const char* extension;
  const char* what;
};
constexpr OutputFormat kOutputFormats[] = {
    {"-o", ".exr", "a linear OpenEXR image"},
    {"--png", ".png", "a display-referred PNG image"},
    {"--save-sky", ".exr", "a lat-long OpenEXR image"},
};

// The outputs (flag, path), checked before any work, since a render can take minutes: each is of its
// flag's format, its folder takes a new file (not a folder, not missing, not read-only), and no two name
// the same file.
void check_outputs(const std::vector<std::pair<std::string, std::string>>& outputs) {
  for (std::size_t a = 0; a < outputs.size(); ++a) {
    const auto& [flag, path] = outputs[a];
    if (path.empty()) continue;
    std::error_code ec;
    if (fs::is_directory(path, ec)) fail(path, "cannot write " + flag + ": it is a folder");
    const fs::path dir = fs::absolute(path).parent_path();
    if (!fs::is_directory(dir, ec)) fail(path, "cannot write " + flag + ": folder " + dir.string() + " does not exist");
    for (const OutputFormat& format : kOutputFormats)
      if (flag == format.flag && !has_extension(path, format.extension))
        fail(path, flag + " writes " + format.what + ": give it a " + format.extension + " name");
    for (std::size_t b = 0; b < a; ++b)
      if (!outputs[b].second.empty() && file_key(outputs[b].second) == file_key(path))
        fail(path, outputs[b].first + " and " + flag + " name the same file");
    AtomicFile(path).probe();
  }
}

// No output may overwrite what the scene reads (its file, environment map, materials, textures, meshes).
void check_outputs_spare_inputs(const std::vector<std::pair<std::string, std::string>>& outputs, const SceneDesc& scene,
                                const std::string& scene_file) {
  std::vector<std::string> inputs;
  if (!scene_file.empty()) inputs.push_back(scene_file);
  if (!scene.environment.file.empty()) inputs.push_back(resolve(scene, scene.environment.file));
  for (const auto& [name, m] : scene.materials) {
    if (!m.file.empty() && !is_builtin(m.file)) inputs.push_back(resolve(scene, m.file));
    if (!m.stretch_texture.empty()) inputs.push_back(resolve(scene, m.stretch_texture));
  }
  for (const ObjectDesc& o : scene.objects)
    if (!o.file.empty()) inputs.push_back(resolve(scene, o.file));
  for (const auto& [flag, path] : outputs)
    for (const std::string& input : inputs)
      if (!path.empty() && file_key(path) == file_key(input)) fail(path, flag + " would overwrite an input of the scene");
}

// The removal of a temporary folder when it goes out of scope.
using TemporaryFolder = std::unique_ptr<fs::path, void (*)(fs::path*)>;

TemporaryFolder no_temporary_folder() {
  return TemporaryFolder(nullptr, [](fs::path* p) {
    std::error_code ec;
    fs::remove_all(*p, ec);
    delete p;
  });
}

// The scene: the given file, or the embedded default around --material. A measurement rendered as one of the
// LUT's representations is baked first, into a temporary folder (`baked_dir`, removed by its owner).
SceneDesc render_scene(const RenderArgs& args, TemporaryFolder& baked_dir) {
  if (!args.scene.empty()) return parse_scene(args.scene);
  MaterialDesc subject;
  subject.type = args.material_type;
  subject.file = args.material;
  if (find_material_type(subject.type)->reads_lut && fs::path(subject.file).extension() != ".exr") {
    baked_dir.reset(new fs::path(fs::temp_directory_path() / ("facetfit-render-" + std::to_string(::getpid()))));
    fs::create_directories(*baked_dir);
    const BakeOptions bake_options;
    const BakeOutcome baked = bake_material(subject.file, "subject", baked_dir->string(), bake_options, Fitter(bake_options.fit));
    if (baked.status == BakeOutcome::Status::failed) throw Error(baked.error);
    subject.file = (*baked_dir / "subject.exr").string();
  }
  return default_scene(subject);
}

// The built-in sky as a lat-long EXR, for other renderers.
void save_sky(const std::string& path) {
  const Environment sky = Environment::sky();
  RenderedImage img;
  img.width = sky.width();
  img.height = sky.height();
  for (std::size_t p = 0; p < sky.pixels().size() / 3; ++p)
    img.rgba.insert(img.rgba.end(), {sky.pixels()[3 * p], sky.pixels()[3 * p + 1], sky.pixels()[3 * p + 2], 1.0f});
  write_exr(path, img, {{"environment", "builtin sky"}});
}

// Samples, seed and memory from the command line; progress as a line redrawn on a terminal, with -v one line
// per pass anywhere, nothing with -q.
RenderSettings render_settings(const RenderArgs& args, const Context& ctx) {
  RenderSettings settings;
  settings.spp = args.spp;
  settings.seed = args.seed;
  settings.max_memory = args.max_memory;
  const bool tty = ::isatty(STDERR_FILENO) == 1 && !ctx.quiet(), lines = ctx.verbose();
  settings.progress = [tty, lines](int done, int total) {
    if (lines) std::fprintf(stderr, "facetfit: render: pass %d/%d\n", done, total);
    else if (tty) std::fprintf(stderr, "\rrendering: pass %d/%d%s", done, total, done == total ? "\n" : "");
  };
  return settings;
}

void run_render(const RenderArgs& args, Context& ctx) {
  int& status = ctx.status;
  try {
    const std::vector<std::pair<std::string, std::string>> outputs = {
        {"-o", args.output}, {"--png", args.png}, {"--save-sky", args.save_sky}};
    check_outputs(outputs);
    const ColorConfig config = args.color.config();
    const ColorMatrix from_rec709 = args.color.from_rec709(config);
    // Before the render, which can take minutes: the --png's display and view must exist.
    std::optional<DisplayTransform> pictures;
    if (!args.png.empty() || !args.color.display.empty() || !args.color.view.empty())
      pictures.emplace(args.color.pictures(config, args.color.working_space, from_rec709));
    TemporaryFolder baked_dir = no_temporary_folder();
    SceneDesc scene = render_scene(args, baked_dir);
    check_outputs_spare_inputs(outputs, scene, args.scene);
    if (!args.save_sky.empty()) save_sky(args.save_sky);
    scene.working_space = args.color.working_space;
    scene.from_rec709 = from_rec709;
    if (args.width > 0) scene.camera.width = args.width;
    if (args.height > 0) scene.camera.height = args.height;
    const RenderSettings settings = render_settings(args, ctx);
    if (ctx.verbose())
      std::fprintf(stderr, "facetfit: render: %dx%d, %zu objects, %zu lights, threads %zu\n", scene.camera.width, scene.camera.height,
                   scene.objects.size(), scene.lights.size(),
                   tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
    // Temporaries of renders killed before they wrote (their processes are gone) go first.
    for (const std::string& out : {args.output, args.png})
      if (!out.empty()) remove_stale_temporaries(fs::absolute(out).parent_path().string());
    const RenderedImage image = render(scene, settings);
    write_exr(args.output, image,
              {{"scene", args.scene.empty() ? "default" : args.scene}, {"spp", std::to_string(image.spp)},
               {"seconds", std::to_string(image.seconds)}});
    if (!args.png.empty()) write_display_png(args.png, image.rgba.data(), image.width, image.height, 4, *pictures);
    if (!ctx.quiet()) std::printf("%s (%dx%d, %d spp, %.3f s)\n", args.output.c_str(), image.width, image.height, image.spp, image.seconds);
  } catch (const Error& e) {
    report_error(e.what());
    status = 1;
  }
}

}  // namespace

void add_render_command(CLI::App& app, Context& ctx) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand("render", "Render a scene (or the embedded default) with the reference renderer");
  cmd->add_option("scene", args->scene, "Scene JSON (docs/scene-format.md); omitted: a sphere under the built-in sky");
  cmd->add_option("-o,--output", args->output, "Linear EXR to write")->required();
  cmd->add_option("--png", args->png, "Also write a display-referred PNG (sRGB, or --display and --view)");
  cmd->add_option("--save-sky", args->save_sky, "Also write the built-in sky as a lat-long EXR (for other renderers)");
  cmd->add_option("--spp", args->spp, "Samples per pixel (default: the scene's)")->check(CLI::Range(1, 1 << 20));
  cmd->add_option("--seed", args->seed, "Random seed (default: the scene's)")->check(uint64_text());
  cmd->add_option("--width", args->width, "Image width (default: the scene's)")->check(CLI::Range(1, 16384));
  cmd->add_option("--height", args->height, "Image height (default: the scene's)")->check(CLI::Range(1, 16384));
  add_max_memory_option(cmd, args->max_memory);
  add_working_space_options(cmd, args->color);
  add_view_options(cmd, args->color);
  cmd->add_option("--material", args->material, "Default scene only: the sphere's material file (a LUT .exr renders as lut "
                  "unless --material-type says otherwise)")->capture_default_str();
  std::vector<std::string> types;
  for (const MaterialType& t : kMaterialTypes) types.push_back(t.name);
  cmd->add_option("--material-type", args->material_type, "Default scene only: " + material_type_list() +
                  " (docs/scene-format.md; a measurement is baked first for a type that reads a LUT; analytic: a built-in's "
                  "analytic model; lambert: albedo 0.8)")
      ->check(CLI::IsMember(types))
      ->capture_default_str();
  cmd->callback([args, cmd, &ctx] {
    // They shape the default scene only: with a scene of one's own they would be silently ignored.
    if (!args->scene.empty() && (cmd->count("--material") > 0 || cmd->count("--material-type") > 0)) {
      report_error("--material and --material-type shape the default scene, not " + args->scene + " (see facetfit render --help)");
      ctx.status = 2;
      return;
    }
    // A baked LUT named without a type renders as the tabulated model (a measurement's is "measured").
    if (cmd->count("--material-type") == 0 && std::filesystem::path(args->material).extension() == ".exr") args->material_type = "lut";
    run_render(*args, ctx);
  });
}

}  // namespace facetfit::cli
