// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A field of a scenario named by a path (docs/reference/studies.md, "Field paths"): keys joined by dots,
// list elements by [index] or by [name] — the element whose `name` field is that name:
// `samples`, `inner.solver`, `tasks[kick].target[0]`, `contacts[1].window[0]`.

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <string>
#include <vector>

namespace mcopt::study {

struct FieldPathStep {
  enum class Kind { Key, Index, Name };
  Kind kind = Kind::Key;
  std::string key;  ///< a mapping key, or the element's name
  std::size_t index = 0;
};

struct FieldPath {
  std::string text;
  std::vector<FieldPathStep> steps;
};

/// Throws std::invalid_argument saying what is wrong with the path.
FieldPath parseFieldPath(const std::string& text);

/// Sets the field of `root` (a scenario's YAML tree, changed in place) to a copy of `value`.
/// A missing mapping key is created (an optional field the base scenario leaves out); a list
/// index out of range, a name no element has, or a step into a scalar throws
/// std::invalid_argument naming the step. Whether the field exists in a scenario is decided by
/// the scenario's own validation (loadScenario), not here.
void setField(YAML::Node root, const FieldPath& path, const YAML::Node& value);

/// The field of `root` at `path` (a copy). A missing key, an index out of range, a name no
/// element has or a step into a scalar throws std::invalid_argument naming the step.
YAML::Node getField(const YAML::Node& root, const FieldPath& path);

}  // namespace mcopt::study
