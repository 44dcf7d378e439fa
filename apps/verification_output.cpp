// SPDX-License-Identifier: BSD-3-Clause
#include "apps/verification_output.hpp"

#include <chrono>
#include <cmath>

#include "apps/json_io.hpp"
#include "apps/run_output.hpp"

namespace mcopt::cli {

namespace {

using Json = nlohmann::ordered_json;

Json numberOrNull(double value) { return std::isfinite(value) ? Json(value) : Json(nullptr); }

}  // namespace

ResultVerification verifyResult(const std::filesystem::path& resultFolder, const std::filesystem::path& scenarioFile,
                                const VerificationSettings& settings) {
  const auto begin = std::chrono::steady_clock::now();
  ResultVerification v;
  v.result = readResultMotion(resultFolder, true);
  v.scenario = scenarioFile.empty() ? v.result.scenario : scenarioFile;
  const Scenario scenario = scenarioOfResult(v.result, scenarioFile);
  MotionProblem problem(scenario);
  const Eigen::VectorXd x = pointOfResult(problem, v.result);
  v.verification = verifyMotion(problem, x, settings);
  v.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  return v;
}

Json verificationJson(const ResultVerification& r) {
  const MotionVerification& v = r.verification;
  Json j;
  j["format"] = 1;
  j["result"] = std::filesystem::absolute(r.result.file).lexically_normal().string();
  j["scenario"] = std::filesystem::absolute(r.scenario).lexically_normal().string();
  j["passed"] = v.passed();
  j["failed_checks"] = v.failures();
  j["duration"] = v.duration;
  j["samples"] = v.scenarioSamples;
  j["instants_per_interval"] = v.instantsPerInterval;
  j["instants"] = v.instants;
  j["wrenches_between_samples"] = v.wrenchesBetweenSamples;
  j["constraint_tolerance"] = v.constraintTolerance;
  Json checks = Json::array();
  for (const VerificationCheck& c : v.checks)
    checks.push_back({{"kind", c.kind},
                      {"passed", c.passed()},
                      {"worst", numberOrNull(c.worst)},
                      {"tolerance", c.tolerance},
                      {"unit", c.unit},
                      {"where", c.where},
                      {"time", numberOrNull(c.time)},
                      {"between_samples", c.betweenSamples},
                      {"values_checked", c.rowsChecked},
                      {"failing_times", c.failingTimes}});
  j["checks"] = checks;
  j["energy"] = {{"sampled_J", v.sampledEnergy}, {"fine_J", v.fineEnergy}};
  j["energy_balance"] = energyBalanceJson(v.balance);
  if (v.innerProblems > 0)
    j["inner"] = {{"problems", v.innerProblems}, {"infeasible", v.innerInfeasible}, {"failed", v.innerFailed}};
  j["seconds"] = r.seconds;
  return j;
}

}  // namespace mcopt::cli
