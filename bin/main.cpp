// facetfit: turn measured BRDFs into microfacet components.
#include <cstdio>

#include "commands.h"
#include "core/error.h"

namespace facetfit::cli {

void report_error(const std::string& message) { std::fprintf(stderr, "facetfit: error: %s\n", message.c_str()); }

}  // namespace facetfit::cli

int main(int argc, char** argv) {
  using namespace facetfit::cli;
  CLI::App app{"facetfit: measured BRDFs to microfacet components (Dupuy et al. 2015, power iterations)", "facetfit"};
  app.require_subcommand(1);
  app.set_version_flag("--version", FACETFIT_VERSION);
  int status = 0;
  add_fit_command(app, status);
  add_bake_command(app, status);
  add_info_command(app, status);
  add_convert_command(app, status);
  add_builtins_command(app, status);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const facetfit::Error& e) {
    report_error(e.what());
    return 1;
  } catch (const std::exception& e) {
    report_error(std::string("internal: ") + e.what());
    return 1;
  }
  return status;
}
