// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A bundled scenario changed for a test: its side files named absolutely (so that the copy
// may live anywhere), then `edit` applied, written into the test's folder.
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <functional>
#include <string>

#include "common/temp_dir.hpp"

namespace mcopt::test {

inline std::filesystem::path scenarioVariant(const std::filesystem::path& source, const TempDir& dir,
                                             const std::function<void(YAML::Node&)>& edit, const std::string& name) {
  YAML::Node root = YAML::LoadFile(source.string());
  for (const char* key : {"robot", "actuators", "contact_surfaces", "postures"})
    root[key] = (source.parent_path() / root[key].as<std::string>()).lexically_normal().string();
  edit(root);
  YAML::Emitter out;
  out << root;
  return dir.write(name, std::string(out.c_str()) + "\n");
}

}  // namespace mcopt::test
