// facetfit: turn measured BRDFs into microfacet components.
//
// The commands that only read measurements and fit (fit, convert, list-builtins) run in this executable, which
// links the core library alone, and so does --version. Every other command (bake, info, render, diff,
// deltae, report) and the help listing them all run in the plugin facetfit-commands.so, loaded on demand: it brings OpenEXR, OpenColorIO
// and Embree (OpenImageIO only in facetfit-oiio.so, for images other than EXR: io/image_file.h).
#include <dlfcn.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "commands.h"

namespace {

// The subcommand named on the command line (after the global --threads N, -q and -v), or "".
// The plugin beside the executable (the build tree) or in ../lib/facetfit (an installed tree).
std::vector<std::filesystem::path> plugin_candidates() {
  std::error_code error;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error) return {"facetfit-commands.so"};
  const std::filesystem::path dir = exe.parent_path();
  return {dir / "facetfit-commands.so", dir.parent_path() / "lib" / "facetfit" / "facetfit-commands.so"};
}

}  // namespace

int main(int argc, char** argv) {
  using namespace facetfit::cli;
  const std::string command = command_word(argc, argv);
  if (command == "--version" || is_core_command(command)) return run_app(argc, argv, nullptr);
  std::string errors;
  for (const std::filesystem::path& path : plugin_candidates()) {
    if (!std::filesystem::exists(path)) continue;
    // Bound now: a missing symbol is one clear error here, not a crash mid-command. Lazy binding saved
    // nothing measurable (0.291 against 0.283 s in make bench: the time is the libraries' data relocations).
    void* plugin = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!plugin) {
      errors = ::dlerror();
      break;
    }
    using Main = int (*)(int, char**);
    if (const auto run = reinterpret_cast<Main>(::dlsym(plugin, "facetfit_commands_main"))) return run(argc, argv);
    errors = path.string() + ": no facetfit_commands_main";
    break;
  }
  report_error("cannot load the command plugin facetfit-commands.so" + (errors.empty() ? std::string(" (not found beside the executable or in ../lib/facetfit)") : ": " + errors));
  return 1;
}
