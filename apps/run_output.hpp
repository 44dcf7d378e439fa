// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// What a scenario's run leaves (docs/reference/results.md, "Results"): result.json, trajectory.csv,
// power_fine.csv, states.json (the sampled states as a `mcopt dynamics` input) and
// contact_wrenches.json, each written atomically so that an interrupted run never leaves a
// half-written file. `mcopt run` writes them; the Python module returns result.json's
// content (and writes the files when asked).

#include <filesystem>
#include <optional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "outer_nlp/energy_balance.hpp"
#include "outer_nlp/motion_problem.hpp"
#include "outer_nlp/scenario_run.hpp"

namespace mcopt::cli {

/// The files of one run, in memory.
struct RunFiles {
  nlohmann::ordered_json result, states, contactWrenches;
  std::string trajectoryCsv, powerFineCsv;
  double energy = 0.0;        ///< exact ∫ Σ max(P, 0) dt at the samples
  double maxViolation = 0.0;  ///< the largest violation of any row
  std::optional<ReleaseState> release;  ///< a throw's ball at its release (result.json `release`)
  std::optional<EnergyBalance> balance;  ///< result.json `energy_balance` (none in a checkpoint)
  std::vector<std::string> warnings;     ///< result.json `warnings`: the record's and the energy balance's
};

/// The warning of a motion that draws more energy from gravity than its criterion counts
/// (empty when it does not).
std::string gravityWarning(const EnergyBalance& balance, double energy);

/// Where the energy of a motion goes, as result.json's `energy_balance` (docs/reference/results.md,
/// "Energy balance").
nlohmann::ordered_json energyBalanceJson(const EnergyBalance& balance);

/// Evaluates the motion of `record.x` (regular and fine samples) and serialises it; with
/// `withEnergyBalance`, its energy balance on a grid of 10 instants an interval too (a
/// checkpoint goes without: it is written while Ipopt runs).
RunFiles makeRunFiles(MotionProblem& problem, const RunRecord& record, bool withEnergyBalance = true);

/// Writes the files into `directory` (created if needed), result.json last.
void writeRunFiles(const std::filesystem::path& directory, const RunFiles& files);

/// A checkpoint of a run still going (status `running`): result.json alone, after removing
/// the side files an earlier run may have left, so that what a killed run leaves is one
/// iterate — never side files of one iteration beside a result.json of another (each file
/// is atomic, a set of files is not). result.json holds the whole motion; the side files
/// come with the run's final result.
void writeCheckpointFile(const std::filesystem::path& directory, const RunFiles& files);

/// makeRunFiles then writeRunFiles. Returns the exact energy and the largest violation.
/// Makes and writes the files; returns them for the run's summary.
RunFiles writeRunOutput(const std::filesystem::path& directory, MotionProblem& problem, const RunRecord& record);

}  // namespace mcopt::cli
