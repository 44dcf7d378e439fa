// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A motion problem's initial point (a run's: through the postures reaching the contacts with
// a window, outer_nlp/scenario_run.hpp) with its spline parameters (± size) and force variables
// (± 20 size, newtons) perturbed at random: a generic point for the outer problems' tests.
#include <Eigen/Core>
#include <random>

#include "outer_nlp/motion_problem.hpp"
#include "outer_nlp/scenario_run.hpp"
#include "common/nlp_jacobian.hpp"

namespace mcopt::test {

inline Eigen::VectorXd perturbedMotion(MotionProblem& problem, double size, unsigned seed) {
  Eigen::VectorXd x = initialPointThroughContacts(problem, problem.scenario().start, problem.scenario().end);
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> u(-size, size);
  for (int i = 0; i < problem.parametrization().parameterCount(); ++i) x[i] += u(random);
  for (int i = 0; i < problem.forceVariableCount(); ++i) x[problem.forceVariableStart() + i] += 20.0 * u(random);
  return x;
}

/// x moved, least norm (Gauss–Newton on the rows alone), until every window end's rows hold to
/// 1e-12: a motion that meets its closures where its splines hand over to them — continuous,
/// as every motion Ipopt accepts (the energy balance's identities hold for such motions only).
inline Eigen::VectorXd withWindowEndsMet(MotionProblem& problem, Eigen::VectorXd x) {
  std::vector<int> rows;
  for (int r = 0; r < problem.constraintCount(); ++r)
    if (problem.rowKind(r) == "closure") rows.push_back(r);
  if (rows.empty()) return x;
  Eigen::VectorXd lower, upper, g;
  problem.constraintBounds(lower, upper);
  for (int iteration = 0; iteration < 30; ++iteration) {
    problem.constraints(x, g);
    const Eigen::MatrixXd J = denseJacobian(problem, x);
    Eigen::VectorXd residual(static_cast<Eigen::Index>(rows.size()));
    Eigen::MatrixXd A(static_cast<Eigen::Index>(rows.size()), x.size());
    for (std::size_t k = 0; k < rows.size(); ++k) {
      residual[static_cast<Eigen::Index>(k)] = g[rows[k]] - lower[rows[k]];  // equalities: lower = upper
      A.row(static_cast<Eigen::Index>(k)) = J.row(rows[k]);
    }
    if (residual.lpNorm<Eigen::Infinity>() < 1e-12) return x;
    x -= A.transpose() * (A * A.transpose()).ldlt().solve(residual);
  }
  throw std::runtime_error("withWindowEndsMet: the window ends' rows did not converge");
}

}  // namespace mcopt::test
