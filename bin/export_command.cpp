// facetfit export LUT... -o DIR: each LUT's production closures as a MaterialX document, DIR/NAME.mtlx, and
// with --usd a UsdShade material referencing it, DIR/NAME.usda (lib/lut/materialx.h). A batch goes on past a
// LUT it cannot read or whose name another took; the exit status is 1 if any failed.
#include <cstdio>
#include <filesystem>
#include <map>

#include "commands.h"
#include "core/error.h"
#include "io/atomic_file.h"
#include "lut/lut.h"
#include "lut/materialx.h"

namespace facetfit::cli {

void add_export_command(CLI::App& app, Context& ctx) {
  auto luts = std::make_shared<std::vector<std::string>>();
  auto out_dir = std::make_shared<std::string>();
  auto color82 = std::make_shared<bool>(false), usd = std::make_shared<bool>(false);
  CLI::App* cmd = app.add_subcommand("export", "Write each LUT's closures as a MaterialX document (pbrlib nodes), OUT/NAME.mtlx");
  cmd->add_option("luts", *luts, "LUT files (.exr, from bake)")->required();
  cmd->add_option("-o,--output", *out_dir, "Output folder (created if missing)")->required();
  cmd->add_flag("--color82", *color82,
                "Write F82-tint lobes exactly (color82), for a MaterialX implementation that honours it; by default "
                "each is the nearest generalized Schlick lobe, which every implementation renders alike (a LUT "
                "baked with --closure-fresnel schlick has no F82-tint lobe: its document is exact everywhere)");
  cmd->add_flag("--usd", *usd,
                "Also write OUT/NAME.usda: a UsdShade material referencing NAME.mtlx, with a UsdPreviewSurface fallback");
  cmd->callback([luts, out_dir, color82, usd, &ctx] {
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::create_directories(*out_dir, ec);
    if (ec) {
      report_error(*out_dir + ": cannot create the output folder: " + ec.message());
      ctx.status = 1;
      return;
    }
    remove_stale_temporaries(*out_dir);
    // A document's name is the material's name in every scene that binds it: two LUTs whose names clean to
    // the same one are refused (the second), never written over each other or renamed behind the user.
    std::map<std::string, fs::path> taken;
    for (const std::string& path : *luts) {
      try {
        const std::string name = materialx_name(fs::path(path).stem().string());
        const Lut lut = read_lut(path);  // a LUT that cannot be read takes no name
        const fs::path source = fs::weakly_canonical(path);
        const auto [first, fresh] = taken.emplace(name, source);
        if (!fresh && first->second != source)
          fail(path, "its MaterialX name " + name + " is " + first->second.string() + "'s in this export: rename one of the two");
        if (!fresh) continue;  // the same LUT given twice
        const std::string target = (fs::path(*out_dir) / (name + ".mtlx")).string();
        write_file_atomic(target, materialx_document(name, lut, *color82));
        if (!ctx.quiet()) std::printf("%s\n", target.c_str());
        if (!*usd) continue;
        const std::string usda = (fs::path(*out_dir) / (name + ".usda")).string();
        write_file_atomic(usda, usd_document(name, "./" + name + ".mtlx", lut));
        if (!ctx.quiet()) std::printf("%s\n", usda.c_str());
      } catch (const Error& e) {
        report_error(e.what());
        ctx.status = 1;
      } catch (const fs::filesystem_error& e) {
        report_error(path + ": " + e.code().message());
        ctx.status = 1;
      }
    }
  });
}

}  // namespace facetfit::cli
