// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A result verified between its samples (`mcopt verify`, docs/reference/verify.md): the result
// read back (result_motion.hpp), its motion checked on a fine grid (outer_nlp/motion_verification.hpp),
// and the outcome as verify.json. The command line and the Python module share it.

#include <filesystem>
#include <nlohmann/json.hpp>

#include "apps/result_motion.hpp"
#include "outer_nlp/motion_verification.hpp"

namespace mcopt::cli {

struct ResultVerification {
  ResultMotion result;
  std::filesystem::path scenario;  ///< the scenario file the motion was checked against
  MotionVerification verification;
  double seconds = 0.0;            ///< loading and checking
};

/// Reads the result (InputError for bad input, naming the file and field) and verifies its motion.
ResultVerification verifyResult(const std::filesystem::path& resultFolder, const std::filesystem::path& scenarioFile,
                                const VerificationSettings& settings);

/// verify.json's content.
nlohmann::ordered_json verificationJson(const ResultVerification& v);

}  // namespace mcopt::cli
