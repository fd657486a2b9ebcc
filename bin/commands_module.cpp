// The command plugin (bin/main.cpp): every command, registered on the same app as the executable's.
#include "commands.h"

namespace facetfit::cli {
namespace {

void add_image_commands(CLI::App& app, Context& ctx) {
  add_bake_command(app, ctx);
  add_info_command(app, ctx);
  add_render_command(app, ctx);
  add_diff_command(app, ctx);
  add_deltae_command(app, ctx);
  add_report_command(app, ctx);
  add_export_command(app, ctx);
}

}  // namespace
}  // namespace facetfit::cli

extern "C" __attribute__((visibility("default"))) int facetfit_commands_main(int argc, char** argv) {
  return facetfit::cli::run_app(argc, argv, &facetfit::cli::add_image_commands);
}
