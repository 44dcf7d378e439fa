// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// `mcopt verify RESULT --json` on a result folder: its exit code and verify.json's content.

#include <nlohmann/json.hpp>
#include <string>

#include "common/run_command.hpp"

namespace mcopt::test {

struct Verified {
  int exitCode = -1;
  nlohmann::json report;  ///< null when nothing was printed
  std::string all;        ///< what it printed (for messages)
};

inline Verified verifyResult(const std::filesystem::path& result, const std::string& arguments = "") {
  const CommandResult r = runMcopt("verify " + quoted(result) + " --json " + arguments);
  Verified v{r.exitCode, nullptr, r.all()};
  if (!r.output.empty()) v.report = nlohmann::json::parse(r.output);
  return v;
}

/// verify.json's check of that kind.
inline const nlohmann::json& checkOf(const nlohmann::json& report, const std::string& kind) {
  for (const nlohmann::json& c : report.at("checks"))
    if (c.at("kind") == kind) return c;
  throw std::runtime_error("verify.json has no check " + kind);
}

}  // namespace mcopt::test
