// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A scenario's YAML tree to be written away from its file (a study's case, a scenario saved
// from Python): its side files (kScenarioSideFileFields) are relative to the scenario file, so
// they are made absolute, and the tree loads from anywhere.

#include <yaml-cpp/yaml.h>

#include <filesystem>

namespace mcopt::study {

/// A copy of `root` with every relative side-file path resolved against `scenarioFile`'s folder.
YAML::Node withAbsoluteSideFiles(const YAML::Node& root, const std::filesystem::path& scenarioFile);

}  // namespace mcopt::study
