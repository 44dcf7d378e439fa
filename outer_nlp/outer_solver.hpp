// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The outer solver (formulation.md §10): an NlpProblem (nlp_problem.hpp) solved from a start
// with settings, a report after every iteration (which can stop the solve), and an outcome
// that always carries the last iterate the solver handed back. The settings say what the
// motion solve needs of any solver (an iteration limit, tolerances, a start to keep, the
// problem's own Hessian) in its terms; a solver's own options (the scenario's `solver:`
// mapping) pass through as they are. Ipopt (ipopt_driver.cpp) is the one registered; another
// solver is one file with a class deriving from OuterSolver and its factory, and one line in
// outerSolvers() (outer_solver.cpp).

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "outer_nlp/nlp_problem.hpp"
#include "outer_nlp/scenario.hpp"

namespace mcopt {

/// How an outer solve ended (the statuses Ipopt can report, in our words), and `Running` for
/// a checkpoint of a solve still under way. toString gives result.json's `status`.
enum class OuterStatus {
  Running, Optimal, Acceptable, MaximumIterations, MaximumCpuTime, TinyStep, Infeasible, Interrupted,
  FeasiblePointFound, Diverging, RestorationFailed, ErrorInStepComputation, InvalidNumber, TooFewDegreesOfFreedom,
  InvalidOption, OutOfMemory, InternalError,
  /// A continuation stage stopped by us because its criterion stopped moving (StageStallWatch,
  /// motion_solve.hpp); the next stage starts from its iterate. Never a run's final status.
  Stalled
};
/// "running", "optimal", "acceptable", "maximum_iterations", … (docs/reference/results.md, "Results").
const char* toString(OuterStatus status);

struct OuterOutcome;

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
  const OuterOutcome* progress = nullptr;  ///< evaluations counted so far; no status yet
};

struct OuterOutcome {
  OuterStatus status = OuterStatus::InternalError;
  std::string message;         ///< Ipopt's words, e.g. "Optimal Solution Found"
  bool optimal() const { return status == OuterStatus::Optimal; }  ///< the solver's own success
  Eigen::VectorXd x;           ///< the iterate handed back by Ipopt (empty when it never got one)
  double objective = 0.0;
  int iterations = 0;
  int objectiveEvaluations = 0, gradientEvaluations = 0, constraintEvaluations = 0, jacobianEvaluations = 0;
  double seconds = 0.0;
  SolveTimings timings;
  std::string evaluationError; ///< the first exception a callback raised, if any
};

struct OuterSolverSettings {
  std::string solver = "ipopt";        ///< a registered outer solver (outerSolverNames())
  /// The solver's own options (the scenario's `solver:` mapping), applied after the settings
  /// below but the iteration limit, in order.
  std::vector<SolverOption> options;
  int printLevel = 0;                  ///< the solver's console output (ours is the progress line)
  /// Use the Lagrangian's Hessian from NlpProblem::lagrangianHessian (dense over the nonlinear
  /// variables) instead of the solver's quasi-Newton approximation.
  bool problemHessian = false;
  std::optional<int> maxIterations;    ///< applied after `options`: it overrides theirs
  std::optional<double> tolerance;             ///< optimality (Ipopt's tol)
  std::optional<double> constraintTolerance;   ///< the rows' and bounds' violation
  /// A start to keep (another solve's iterate, a given motion): the solver does not push it off
  /// its bounds, and an interior-point solver starts at this barrier parameter (formulation.md
  /// §10; docs/theory/outer-problem.md, "Continuation"). `origin` names why, for messages.
  struct WarmStart {
    double barrier = 1e-4;
    std::string origin;
  };
  std::optional<WarmStart> warmStart;
};

/// Returns false to stop the solve (status `interrupted`).
using IterationCallback = std::function<bool(const IterationReport&)>;

class OuterSolver {
 public:
  virtual ~OuterSolver() = default;
  virtual std::string_view name() const = 0;
  /// Throws InputError naming the scenario line when the solver rejects one of its options.
  virtual OuterOutcome solve(NlpProblem& problem, const Eigen::VectorXd& start, const OuterSolverSettings& settings,
                             const IterationCallback& onIteration) const = 0;
};

/// The registered outer solvers' names, and one by name (InputError listing them otherwise).
std::vector<std::string> outerSolverNames();
std::unique_ptr<OuterSolver> makeOuterSolver(std::string_view name);

/// makeOuterSolver(settings.solver)->solve(…).
OuterOutcome solveOuter(NlpProblem& problem, const Eigen::VectorXd& start, const OuterSolverSettings& settings,
                        const IterationCallback& onIteration);

}  // namespace mcopt
