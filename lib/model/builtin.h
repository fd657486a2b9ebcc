// The built-in synthetic material set: analytic models whose parameters are known exactly. The demo,
// the tests and the default report run on it; any command takes one as the input `builtin:NAME`.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/brdf.h"

namespace facetfit {

struct BuiltinMaterial {
  std::string name;
  std::string description;
  std::shared_ptr<const Brdf> brdf;
};

std::vector<BuiltinMaterial> builtin_materials();
std::optional<BuiltinMaterial> find_builtin(const std::string& name);

}  // namespace facetfit
