// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Solves an NlpProblem with Ipopt (formulation.md §10): exact first derivatives, the
// declared sparse Jacobian, a limited-memory Hessian unless the options say otherwise,
// the scenario's options on top of ours, a report after every iteration (which can stop
// the solve), and an outcome that always carries the last iterate Ipopt handed back.

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "outer_nlp/nlp_problem.hpp"
#include "outer_nlp/scenario.hpp"

namespace mcopt {

/// How an outer solve ended (Ipopt's SolverReturn in our words), and `Running` for a
/// checkpoint of a solve still under way. toString gives result.json's `status`.
enum class OuterStatus {
  Running, Optimal, Acceptable, MaximumIterations, MaximumCpuTime, TinyStep, Infeasible, Interrupted,
  FeasiblePointFound, Diverging, RestorationFailed, ErrorInStepComputation, InvalidNumber, TooFewDegreesOfFreedom,
  InvalidOption, OutOfMemory, InternalError
};
/// "running", "optimal", "acceptable", "maximum_iterations", … (docs/reference/results.md, "Results").
const char* toString(OuterStatus status);

struct IpoptOutcome;

/// Where an optimisation's time went, cumulative [s]: our callbacks (values of f and g;
/// gradient and Jacobian; Hessian) and the total since Ipopt started. The rest,
/// total − functions − derivatives − hessian, is Ipopt's own work: the KKT factorisations
/// and solves (MUMPS), line search and convergence tests.
struct SolveTimings {
  double functions = 0.0, derivatives = 0.0, hessian = 0.0, total = 0.0;
  double ipopt() const { return total - functions - derivatives - hessian; }
  SolveTimings& operator+=(const SolveTimings& o) {
    functions += o.functions, derivatives += o.derivatives, hessian += o.hessian, total += o.total;
    return *this;
  }
};

struct IterationReport {
  int iteration = 0;
  double objective = 0.0;
  double violation = 0.0;      ///< Ipopt's primal infeasibility (of the scaled problem's unscaled rows)
  double dualInfeasibility = 0.0;
  double elapsedSeconds = 0.0;
  double barrier = 0.0;         ///< Ipopt's barrier parameter μ
  double regularisation = 0.0;  ///< δ added to the Hessian's diagonal for the inertia (0: none)
  double stepSize = 0.0;        ///< α of the primal step that led here
  SolveTimings timings;         ///< cumulative, up to this iteration
  /// The current iterate in the problem's variables; null in Ipopt's restoration phase,
  /// whose iterates belong to another problem.
  const Eigen::VectorXd* iterate = nullptr;
  const IpoptOutcome* progress = nullptr;  ///< evaluations counted so far; no status yet
};

struct IpoptOutcome {
  OuterStatus status = OuterStatus::InternalError;
  std::string message;         ///< Ipopt's words, e.g. "Optimal Solution Found"
  bool optimal() const { return status == OuterStatus::Optimal; }  ///< Ipopt's SUCCESS
  Eigen::VectorXd x;           ///< the iterate handed back by Ipopt (empty when it never got one)
  double objective = 0.0;
  int iterations = 0;
  int objectiveEvaluations = 0, gradientEvaluations = 0, constraintEvaluations = 0, jacobianEvaluations = 0;
  double seconds = 0.0;
  SolveTimings timings;
  std::string evaluationError; ///< the first exception a callback raised, if any
};

struct IpoptSettings {
  std::vector<SolverOption> options;   ///< applied after ours, in order
  int printLevel = 0;                  ///< Ipopt's console output (ours is the progress line)
  /// Give Ipopt the Lagrangian's Hessian from NlpProblem::lagrangianHessian (dense over the
  /// nonlinear variables) instead of its limited-memory approximation.
  bool problemHessian = false;
};

/// Returns false from `onIteration` to stop (Ipopt then reports "interrupted").
/// Throws InputError naming the scenario line when Ipopt rejects an option.
IpoptOutcome solveWithIpopt(NlpProblem& problem, const Eigen::VectorXd& start, const IpoptSettings& settings,
                            const std::function<bool(const IterationReport&)>& onIteration);

}  // namespace mcopt
