// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// What a path names, without throwing: std::filesystem::exists and is_regular_file throw
// filesystem_error on a name the system refuses (too long: found by fuzzing,
// tests/fuzz/regressions/scenario/), where readers must answer with an InputError.
#include <filesystem>
#include <system_error>

namespace mcopt {

inline bool pathExists(const std::filesystem::path& p) {
  std::error_code error;
  return std::filesystem::exists(p, error);
}
inline bool isRegularFile(const std::filesystem::path& p) {
  std::error_code error;
  return std::filesystem::is_regular_file(p, error);
}

}  // namespace mcopt
