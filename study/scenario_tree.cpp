// SPDX-License-Identifier: BSD-3-Clause
#include "study/scenario_tree.hpp"

#include "outer_nlp/scenario.hpp"

namespace mcopt::study {

YAML::Node withAbsoluteSideFiles(const YAML::Node& root, const std::filesystem::path& scenarioFile) {
  YAML::Node tree = YAML::Clone(root);
  for (const char* key : kScenarioSideFileFields) {
    if (!tree[key] || !tree[key].IsScalar()) continue;
    const std::filesystem::path path = tree[key].Scalar();
    if (path.is_relative())
      tree[key] = std::filesystem::absolute(scenarioFile.parent_path() / path).lexically_normal().string();
  }
  return tree;
}

}  // namespace mcopt::study
