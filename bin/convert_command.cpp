// facetfit convert INPUT -o OUT.binary|OUT.bin : any input in MERL layout, or sampled at UTIA's nodes.
#include <array>
#include <cstdio>
#include <filesystem>

#include "commands.h"
#include "core/error.h"
#include "io/atomic_file.h"
#include "io/input.h"
#include "io/utia.h"
#include "model/builtin.h"

namespace facetfit::cli {

void add_convert_command(CLI::App& app, Context& ctx) {
  auto input = std::make_shared<std::string>();
  auto output = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand("convert", "Write any input as a MERL .binary table or a UTIA .bin file");
  cmd->add_option("input", *input, "Input material (file or builtin:NAME)")->required();
  cmd->add_option("-o,--output", *output, "Output file: .binary (MERL) or .bin (UTIA, sampled at its nodes)")->required();
  cmd->callback([input, output, &ctx] {
    try {
      const std::string extension = std::filesystem::path(*output).extension().string();
      // Temporaries of converts killed mid-write (their processes are gone) go first, as bake and render do.
      remove_stale_temporaries(std::filesystem::absolute(*output).parent_path().string());
      if (extension == ".bin") {
        UtiaBrdf::tabulate(*load_brdf(*input)).write(*output);
      } else if (extension == ".binary") {
        const std::array<std::size_t, 3> clamped = load_table(*input).write(*output);
        if (clamped[0] + clamped[1] + clamped[2] > 0)
          std::fprintf(stderr, "facetfit: warning: %s: %zu red, %zu green and %zu blue values below zero (noise on a measurement near zero) written as 0: a MERL table holds no negative value\n",
                       output->c_str(), clamped[0], clamped[1], clamped[2]);
      } else {
        fail(*output, "unsupported output format '" + extension + "' (supported: .binary, .bin)");
      }
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
