// facetfit convert INPUT -o OUT.binary : any input in MERL layout.
#include <cstdio>

#include "commands.h"
#include "core/error.h"
#include "io/input.h"
#include "model/builtin.h"

namespace facetfit::cli {

void add_convert_command(CLI::App& app, Context& ctx) {
  auto input = std::make_shared<std::string>();
  auto output = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand("convert", "Write any input as a MERL .binary table");
  cmd->add_option("input", *input, "Input material (file or builtin:NAME)")->required();
  cmd->add_option("-o,--output", *output, "Output .binary file")->required();
  cmd->callback([input, output, &ctx] {
    try {
      load_table(*input).write(*output);
      std::printf("%s\n", output->c_str());
    } catch (const Error& e) {
      report_error(e.what());
      ctx.status = 1;
    }
  });
}

void add_builtins_command(CLI::App& app, Context& ctx) {
  CLI::App* cmd = app.add_subcommand("list-builtins", "List the built-in synthetic materials");
  cmd->callback([&ctx] {
    for (const auto& m : builtin_materials()) std::printf("builtin:%-24s %s\n", m.name.c_str(), m.description.c_str());
    ctx.status = 0;
  });
}

}  // namespace facetfit::cli
