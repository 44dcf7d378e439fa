// SPDX-License-Identifier: BSD-3-Clause
// `mcopt verify RESULT_DIR`: a result's motion certified between its samples (issue 42,
// docs/reference/verify.md). Reloads the scenario and the result's spline parameters, duration
// and contact-force variables — never its sampled arrays — and checks every constraint on a
// fine grid (outer_nlp/motion_verification.hpp). Prints one table, writes verify.json
// atomically; exits 0 when everything holds, 1 when something does not, 2 on bad input.
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "apps/commands.hpp"
#include "apps/verification_output.hpp"
#include "core/atomic_file.hpp"
#include "core/errors.hpp"

namespace mcopt::cli {

namespace {

struct VerifyOptions {
  std::string result, scenario, out;
  int fine = 10;
  double energyTolerance = VerificationSettings{}.energyTolerance;
  bool json = false;
};

std::string number(double value) {
  if (std::isnan(value)) return "NaN";
  std::ostringstream text;
  text << std::setprecision(3) << value;
  return text.str();
}

int runVerify(const VerifyOptions& o) {
  if (o.fine < 1) throw InputError("--fine: " + std::to_string(o.fine) + ": expected an integer ≥ 1 (instants per sample interval)");
  VerificationSettings settings;
  settings.instantsPerInterval = o.fine;
  if (!(o.energyTolerance >= 0.0))
    throw InputError("--energy-tolerance: expected a relative tolerance ≥ 0, e.g. 0.01 for 1 %");
  settings.energyTolerance = o.energyTolerance;
  const ResultVerification r = verifyResult(o.result, o.scenario, settings);
  const MotionVerification& v = r.verification;
  const std::filesystem::path out = o.out.empty() ? r.result.file.parent_path() / "verify.json" : std::filesystem::path(o.out);
  const auto json = verificationJson(r);
  writeFileAtomically(out, json.dump(1) + "\n");
  if (o.json) {
    std::cout << json.dump(1) << "\n";
    return v.passed() ? 0 : 1;
  }
  std::cout << "mcopt verify " << r.result.file.string() << "\n"
            << "  scenario " << r.scenario.string();
  if (r.result.contactNames.size() > 1)
    std::cout << " (contact forces: " << r.result.contactForces
              << (r.result.innerSolver.empty() ? "" : ", inner solver " + r.result.innerSolver) << ")";
  std::cout << "\n"
            << "  the motion of its parameters (" << v.duration << " s) at " << v.instants << " instants: " << v.instantsPerInterval
            << " per interval of its " << v.scenarioSamples << " samples, every task instant and window end";
  if (v.wrenchesBetweenSamples != "balance") std::cout << "; wrenches between samples: " << v.wrenchesBetweenSamples;
  std::cout << "\n  constraint tolerance " << number(v.constraintTolerance) << "\n\n";
  std::cout << "  " << std::left << std::setw(26) << "check" << std::right << std::setw(11) << "worst" << std::setw(11) << "tolerance"
            << "  " << std::left << std::setw(6) << "" << std::setw(26) << "at [s]" << "where\n";
  for (const VerificationCheck& c : v.checks) {
    std::string when;
    if (!std::isnan(c.time)) when = number(c.time) + (c.betweenSamples ? " (between samples)" : " (a sample)");
    std::cout << "  " << std::left << std::setw(26) << c.kind << std::right << std::setw(11) << number(c.worst) << std::setw(11)
              << number(c.tolerance) << "  " << std::left << std::setw(6) << (c.passed() ? "pass" : "FAIL") << std::setw(26)
              << (when.empty() ? "-" : when) << (c.where.empty() ? "-" : c.where);
    if (!c.passed() && !c.failingTimes.empty()) std::cout << " (broken at " << c.failingTimes.size() << " instants)";
    std::cout << "\n";
  }
  std::cout << "\n  energy " << std::setprecision(6) << v.sampledEnergy << " J at the samples, " << v.fineEnergy
            << " J on the fine grid; mechanical identity residual " << std::setprecision(3) << v.balance.mechanicalResidual()
            << " J of " << v.balance.mechanicalScale() << " J\n";
  if (const WrenchRedistribution& moved = v.balance.redistribution; moved.applies && (moved.instants > 0 || moved.unreachable > 0)) {
    std::cout << "  wrenches redistributed between samples at " << moved.instants << " of " << v.instants
              << " instants: the closest admissible with the same total wrench";
    if (moved.instants > 0)
      std::cout << ", largest change " << number(moved.largestChange) << " (" << moved.contact << ", " << number(moved.time) << " s)";
    if (moved.unreachable > 0) std::cout << "; " << moved.unreachable << " instants with no admissible distribution";
    std::cout << "\n";
  }
  if (v.innerProblems > 0)
    std::cout << "  inner problems: " << v.innerProblems << " solved, " << v.innerInfeasible << " infeasible, " << v.innerFailed << " failed\n";
  std::cout << "  written " << out.string() << " (" << std::setprecision(2) << r.seconds << " s)\n";
  if (v.passed()) {
    std::cout << "verified: every check holds between the samples\n";
    return 0;
  }
  std::string failed;
  for (const std::string& name : v.failures()) failed += (failed.empty() ? "" : ", ") + name;
  std::cout << "NOT verified: " << failed << "\n";
  return 1;
}

}  // namespace

Runner addVerify(CLI::App& command) {
  auto o = std::make_shared<VerifyOptions>();
  command.add_option("result", o->result, "a result folder of mcopt run (or its result.json)")->required();
  command.add_option("--fine", o->fine, "instants per interval of the scenario's samples (default 10)");
  command.add_option("--energy-tolerance", o->energyTolerance,
                     "largest relative difference between the energy at the samples and on the fine grid (default 0.01)");
  command.add_option("--scenario", o->scenario,
                     "check the motion against this scenario file instead of the result's own (the same robot and contacts)");
  command.add_flag("--json", o->json, "print verify.json instead of the table");
  command.add_option("--out", o->out, "where to write verify.json (default: beside result.json)");
  return [o] { return runVerify(*o); };
}

}  // namespace mcopt::cli
