// The facetfit subcommands. Each registers itself on the app and reports its exit status through
// `status` (0 success, 1 some input failed, 2 usage).
#pragma once

#include <CLI/CLI.hpp>

namespace facetfit::cli {

void add_fit_command(CLI::App& app, int& status);
void add_convert_command(CLI::App& app, int& status);
void add_builtins_command(CLI::App& app, int& status);
void add_bake_command(CLI::App& app, int& status);
void add_info_command(CLI::App& app, int& status);

// "facetfit: error: <message>" on stderr, one line.
void report_error(const std::string& message);

}  // namespace facetfit::cli
