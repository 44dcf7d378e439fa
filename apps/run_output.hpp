#pragma once
// What `mcopt run` writes (docs/scenarios.md, "Results"): result.json, trajectory.csv,
// power_fine.csv and states.json (the sampled states as a `mcopt dynamics` input), each
// written atomically so that an interrupted run never leaves a half-written file.

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "outer_nlp/ipopt_driver.hpp"
#include "outer_nlp/motion_problem.hpp"
#include "outer_nlp/motion_solve.hpp"

namespace mcopt::cli {

/// One static posture found by configuration optimisation (report §3.5).
struct PostureOutcome {
  bool optimised = false;
  OuterStatus status = OuterStatus::InternalError;
  double staticPowerBefore = 0.0, staticPowerAfter = 0.0;  ///< [W]
  int iterations = 0;
  double seconds = 0.0;
};

/// One Ipopt iteration as the progress line shows it, with the bilevel inner problems of the
/// last evaluation before it (result.json `history`).
struct IterationRecord {
  int stage = 0;  ///< continuation stage (0 without continuation)
  int iteration = 0;
  double objective = 0.0, violation = 0.0, dualInfeasibility = 0.0, elapsedSeconds = 0.0;
  double stepSize = 0.0, regularisation = 0.0, barrier = 0.0;  ///< Ipopt's α_pr, δ_w and μ
  SolveTimings timings;  ///< cumulative up to this iteration
  MotionProblem::InnerStatistics inner;
};

struct RunRecord {
  OuterStatus status = OuterStatus::InternalError;
  std::string message, reason;  ///< reason: why a run that is not optimal ended
  Eigen::VectorXd x;                    ///< the outer problem's variables
  PostureOutcome start, end;
  IpoptOutcome solver;
  std::vector<IterationRecord> history;
  std::vector<StageOutcome> stages;  ///< one per continuation stage, the scenario's own problem last
  double configurationSeconds = 0.0, optimisationSeconds = 0.0, totalSeconds = 0.0;
};

/// Evaluates the motion of `record.x` (regular and fine samples) and writes the files.
/// Returns the exact energy ∫ Σ max(P, 0) dt and the largest violation (for the summary).
std::pair<double, double> writeRunOutput(const std::filesystem::path& directory, MotionProblem& problem,
                                         const RunRecord& record);

}  // namespace mcopt::cli
