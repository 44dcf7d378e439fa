// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The inner problem handed to NLopt, shared by the NLopt adapters (private header; NLopt's own
// header stays in the adapters' .cpp files and nlopt_problem.cpp). NLopt returns no
// multipliers: the common flow estimates them on the active set and re-checks every stop
// against the constraints and the KKT conditions.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "inner_qp/inner_nlp.hpp"

struct nlopt_opt_s;

namespace mcopt::inner_detail {

/// How NLopt sees the inner problem: x = wrenchUnit · y for its variables y, the objective
/// divided by objectiveUnit and the constraints (all homogeneous of degree one in the wrenches
/// but for their bounds) by wrenchUnit. 1 and 1: the problem as it is.
struct NloptScaling {
  double wrenchUnit = 1.0;
  double objectiveUnit = 1.0;
};

/// An InnerNlp set on an NLopt optimiser: objective, the balance equalities and the
/// inequalities, with tolerances relative to the data's scale; counts the objective's
/// evaluations. `nlp` must outlive the optimisation.
class NloptProblem {
 public:
  NloptProblem(nlopt_opt_s* opt, const InnerNlp& nlp, const InnerSettings& settings, NloptScaling scaling = {});
  NloptProblem(const NloptProblem&) = delete;
  NloptProblem& operator=(const NloptProblem&) = delete;

  int evaluations() const { return evaluations_; }
  /// Largest violation of the balance and the inequalities at x (absolute).
  double violation(const Eigen::VectorXd& x) const;

 private:
  static double objective(unsigned, const double* x, double* gradient, void* data);
  static void equalities(unsigned, double* value, unsigned, const double* x, double* jacobian, void* data);
  static void inequalities(unsigned, double* value, unsigned, const double* x, double* jacobian, void* data);
  /// The wrenches at NLopt's point y (y itself when unscaled).
  const double* wrenches(const double* y);

  const InnerNlp& nlp_;
  NloptScaling scaling_;
  bool scaled_ = false;
  Eigen::VectorXd x_;  ///< the wrenches of the scaled point (sized once)
  std::vector<double> equalityTolerance_, inequalityTolerance_;
  int evaluations_ = 0;
};

/// Whether an NLopt return code is a stop at a point the common flow may check: a positive
/// code other than a budget, or NLOPT_ROUNDOFF_LIMITED (usable more often than not).
bool nloptStopped(int code);
/// "nlopt: <name of the code>".
std::string nloptMessage(int code);

/// Which of NLopt's gradient-based algorithms runs the inner problem, and its stops.
/// `algorithm` takes the whole problem; when it is NLopt's augmented Lagrangian, `local` (≥ 0)
/// solves its subproblems.
struct NloptMethod {
  int algorithm = 0;  ///< an nlopt_algorithm
  int local = -1;     ///< an nlopt_algorithm for the subproblems, or none
  /// Scale the problem for NLopt (NloptScaling): wrenches in units of the balance target's
  /// largest component, the objective in units of its value at the start. The augmented
  /// Lagrangian's penalties and the first-order subproblem solvers need it; SLSQP runs on the
  /// problem as it is.
  bool scaled = false;
  double xtolRel = 1e-14, ftolRel = 1e-16;            ///< the run's relative stops
  double localXtolRel = 1e-14, localFtolRel = 1e-16;  ///< the subproblems' relative stops
  /// The evaluation budget: this many objective evaluations per InnerSettings::maxIterations
  /// (first-order methods take many cheap evaluations where SQP takes few).
  int evaluationsPerIteration = 1;
};

/// One run of `method` on the InnerNlp of `problem` (the inner smooth cone with δ = 1e-10 of
/// the data's scale, which keeps the subproblems regular at unloaded contacts), from x;
/// restarted from its own point when NLopt stops on round-off or a hair outside the
/// constraints (at most four runs).
RunOutcome runNlopt(const NloptMethod& method, const ContactProblem& problem, BalanceMode balance, double band,
                    const InnerSettings& settings, Eigen::VectorXd& x);

/// An inner solver that is `method` behind the common elastic flow (solveWithElasticFallback).
std::unique_ptr<InnerSolver> makeNloptSolver(std::string name, NloptMethod method, const InnerSettings& settings);

}  // namespace mcopt::inner_detail
