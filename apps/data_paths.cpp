// SPDX-License-Identifier: BSD-3-Clause
#include "apps/data_paths.hpp"

#include "core/errors.hpp"
#include "study/child_process.hpp"

namespace mcopt::cli {
namespace {

/// <prefix>/share/mcopt when this executable is <prefix>/bin/mcopt and that folder holds `probe`.
std::filesystem::path installedData(const std::filesystem::path& probe) {
  std::error_code ignored;
  const std::filesystem::path executable = std::filesystem::weakly_canonical(study::currentExecutable(), ignored);
  const std::filesystem::path share = executable.parent_path().parent_path() / "share" / "mcopt";
  return std::filesystem::exists(share / probe, ignored) ? share : std::filesystem::path{};
}

std::filesystem::path dataFile(const std::filesystem::path& installed, const std::filesystem::path& inSource) {
  if (const std::filesystem::path share = installedData(installed); !share.empty()) return share / installed;
  const std::filesystem::path source = std::filesystem::path(MCOPT_SOURCE_DIR) / inSource;
  std::error_code ignored;
  if (std::filesystem::exists(source, ignored)) return source;
  throw InputError(installed.string() + ": not found beside the command (<prefix>/share/mcopt of " +
                   study::currentExecutable().string() + ") nor in the source tree it was built from (" + source.string() +
                   "): reinstall mcopt (cmake --install, or the .deb)");
}

}  // namespace

std::filesystem::path scriptFile(const std::string& name) {
  return dataFile(std::filesystem::path("scripts") / name, std::filesystem::path("scripts") / name);
}

std::filesystem::path replayViewerDirectory() {
  return dataFile("replay", std::filesystem::path("apps") / "replay");
}

}  // namespace mcopt::cli
