// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Runs the built `mcopt` executable and captures its output and exit code.
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <unistd.h>

namespace mcopt::test {

struct CommandResult {
  int exitCode = -1;
  std::string output;  ///< standard output
  std::string errors;  ///< standard error
  std::string all() const { return output + errors; }
};

/// environment: assignments placed before the command, e.g. "OMP_NUM_THREADS=2".
inline CommandResult runMcopt(const std::string& arguments, const std::string& environment = "") {
  std::string errorFile = (std::filesystem::temp_directory_path() / "mcopt-stderr-XXXXXX").string();
  const int fd = ::mkstemp(errorFile.data());
  if (fd >= 0) ::close(fd);
  const std::string command = (environment.empty() ? "" : environment + " ") + std::string(MCOPT_EXECUTABLE) + " " +
                              arguments + " 2>'" + errorFile + "'";
  CommandResult result;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr) result.output += buffer.data();
  const int status = ::pclose(pipe);
  result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream errors(errorFile);
  result.errors.assign(std::istreambuf_iterator<char>(errors), std::istreambuf_iterator<char>());
  std::filesystem::remove(errorFile);
  return result;
}

inline std::string quoted(const std::filesystem::path& path) { return "'" + path.string() + "'"; }

}  // namespace mcopt::test
