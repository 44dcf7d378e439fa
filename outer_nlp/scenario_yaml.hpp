#pragma once
// A scenario already parsed as YAML (a study's case after its fields are changed,
// docs/studies.md; the Python module's Scenario). outer_nlp links yaml-cpp privately: this is
// its one header with yaml-cpp types, and a target including it links yaml-cpp itself
// (tests/header_boundaries.cmake).

#include <yaml-cpp/yaml.h>

#include <filesystem>

#include "outer_nlp/scenario.hpp"

namespace mcopt {

/// loadScenario(file) for `root`, read from `file` and maybe changed since: `file` names it in
/// messages, and its folder is where relative side-file paths start.
Scenario loadScenario(const YAML::Node& root, const std::filesystem::path& file);

}  // namespace mcopt
