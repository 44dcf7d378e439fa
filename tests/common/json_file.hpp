// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A JSON file as nlohmann::json (results, problems, reports the CLI tests read back).
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

namespace mcopt::test {

inline nlohmann::json readJson(const std::filesystem::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in);
}

}  // namespace mcopt::test
