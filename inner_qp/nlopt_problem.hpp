// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The inner problem handed to NLopt, shared by the NLopt adapters (private header, not
// installed; NLopt's own header and types stay in the .cpp files). NLopt returns no
// multipliers: the common flow estimates them on the active set and re-checks every stop
// against the constraints and the KKT conditions.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "inner_qp/inner_nlp.hpp"

namespace mcopt::inner_detail {

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

/// NLopt's augmented Lagrangian (NLOPT_AUGLAG) over every constraint — the balance, the rows
/// and the cones — with `local` (an algorithm taking no constraints) on its unconstrained
/// subproblems: scaled, stops at 1e-12 relative change in x for the run and the subproblems,
/// 20 evaluations per InnerSettings::maxIterations. Measured against the alternatives in the
/// developers' lab note on NLopt's inner solvers.
NloptMethod augmentedLagrangian(int local);

/// One run of `method` on the InnerNlp of `problem` (the inner smooth cone with δ = 1e-10 of
/// the data's scale, which keeps the subproblems regular at unloaded contacts), from x;
/// restarted from its own point when NLopt stops on round-off or a hair outside the
/// constraints (at most four runs).
RunOutcome runNlopt(const NloptMethod& method, const ContactProblem& problem, BalanceMode balance, double band,
                    const InnerSettings& settings, Eigen::VectorXd& x);

/// An inner solver that is `method` behind the common elastic flow (solveWithElasticFallback).
std::unique_ptr<InnerSolver> makeNloptSolver(std::string name, NloptMethod method, const InnerSettings& settings);

}  // namespace mcopt::inner_detail
