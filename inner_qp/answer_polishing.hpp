// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Polishing the third-party solvers' answers (docs/theory/inner-problem.md, "Polishing"; private
// header): each answer of SLSQP or Ipopt on a linear contact model solved again exactly, by
// crossover through our dual active-set QP from the rows the solver's multipliers hold, or on
// those rows, so that the elastic flow (inner_nlp.hpp) gets the QP's own point and a
// certificate it can trust.

#include <Eigen/Core>
#include <optional>

#include "inner_qp/inner_nlp.hpp"

namespace mcopt::inner_detail {

/// What polishing did to one answer.
struct Polishing {
  bool replaced = false;  ///< the answer was replaced by the polished point
  /// The KKT residual the returned point is certified to: the polished point's, or, when the
  /// answer stands, the answer's own (no candidate did better: a warm start at an exact
  /// solution of a nearby problem often ends there).
  double residual = 0.0;
};

/// The solver's answer polished: by crossover from the rows its multipliers hold (OSQP's
/// choice: a row the solver finds at its bound with a multiplier below 1e-6 of the largest is
/// not held; an interior-point solver leaves ~1e-8 on rows that are only nearly active), with
/// the crossover's own multipliers; failing that, on the held rows, then on every row at its
/// bound (multipliers estimated there, signs enforced). The point replaces the answer when it
/// keeps every row and its KKT residual is smaller than the answer's. Empty where polishing
/// does not apply (the report model's cones, a non-finite answer).
std::optional<Polishing> polishOnActiveSet(const ContactProblem& p, BalanceMode balance, double band,
                                           const InnerSettings& settings, RunOutcome& outcome, Eigen::VectorXd& x);

}  // namespace mcopt::inner_detail
