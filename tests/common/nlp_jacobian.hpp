// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// An NlpProblem's sparse Jacobian as a dense matrix, its declared pattern, and its exact
// derivatives' errors against central differences, for the derivative tests of the outer problems.
#include <Eigen/Core>
#include <algorithm>
#include <limits>
#include <vector>

#include "common/finite_differences.hpp"
#include "outer_nlp/nlp_problem.hpp"

namespace mcopt::test {

inline Eigen::MatrixXd denseJacobian(NlpProblem& problem, const Eigen::VectorXd& x) {
  Eigen::VectorXd values;
  problem.jacobianValues(x, values);
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(problem.constraintCount(), problem.variableCount());
  for (Eigen::Index k = 0; k < values.size(); ++k) dense(problem.jacobianRows()[k], problem.jacobianColumns()[k]) += values[k];
  return dense;
}

/// 1 where an entry is declared, 0 elsewhere.
inline Eigen::MatrixXd declaredPattern(const NlpProblem& problem) {
  Eigen::MatrixXd pattern = Eigen::MatrixXd::Zero(problem.constraintCount(), problem.variableCount());
  for (Eigen::Index k = 0; k < problem.jacobianRows().size(); ++k)
    pattern(problem.jacobianRows()[k], problem.jacobianColumns()[k]) = 1.0;
  return pattern;
}

struct DerivativeErrors {
  double gradient = 0.0, jacobian = 0.0, offPattern = 0.0;
};

/// Relative errors |exact − differences| / (1 + |differences|) of the objective's gradient
/// and of the Jacobian against central differences with step h, and the largest difference
/// off the declared pattern.
/// With `extrapolate`, the differences at h and h/2 Richardson-extrapolated, (4 D(h/2) − D(h))/3:
/// O(h⁴), for outputs strongly curved where a small h would read their rounding noise.
inline DerivativeErrors derivativeErrors(NlpProblem& problem, Eigen::VectorXd x, double h, bool extrapolate = false) {
  Eigen::VectorXd gradient;
  problem.objectiveGradient(x, gradient);
  const Eigen::MatrixXd jacobian = denseJacobian(problem, x);
  const Eigen::MatrixXd pattern = declaredPattern(problem);
  auto values = [&] {
    Eigen::VectorXd out(1 + problem.constraintCount());
    out[0] = problem.objective(x);
    Eigen::VectorXd g;
    problem.constraints(x, g);
    out.tail(problem.constraintCount()) = g;
    return out;
  };
  const Eigen::MatrixXd fd = extrapolate ? Eigen::MatrixXd((4.0 * centralDifferences(x, 0.5 * h, values) - centralDifferences(x, h, values)) / 3.0)
                                         : centralDifferences(x, h, values);
  DerivativeErrors e;
  const Eigen::VectorXd gradientFd = fd.row(0).transpose();
  e.gradient = ((gradient - gradientFd).array().abs() / (1.0 + gradientFd.array().abs())).maxCoeff();
  const Eigen::MatrixXd jacobianFd = fd.bottomRows(problem.constraintCount());
  e.jacobian = ((jacobian - jacobianFd).array().abs() / (1.0 + jacobianFd.array().abs())).maxCoeff();
  e.offPattern = (jacobianFd.array() * (1.0 - pattern.array())).abs().maxCoeff();
  return e;
}

/// Some rows' Jacobian against central differences (step h): the worst relative error
/// |exact − differences| / (1 + |differences|), the largest difference entry and the smallest
/// exact row's largest entry.
struct RowDerivativeCheck {
  double worst = 0.0, largest = 0.0, smallestRow = std::numeric_limits<double>::infinity();
};
inline RowDerivativeCheck rowDerivatives(NlpProblem& problem, Eigen::VectorXd& x, const std::vector<int>& rows, double h = 1e-6) {
  const Eigen::MatrixXd jacobian = denseJacobian(problem, x);
  const Eigen::MatrixXd fd = centralDifferences(x, h, [&] {
    Eigen::VectorXd values;
    problem.constraints(x, values);
    Eigen::VectorXd out(static_cast<Eigen::Index>(rows.size()));
    for (std::size_t k = 0; k < rows.size(); ++k) out[static_cast<Eigen::Index>(k)] = values[rows[k]];
    return out;
  });
  RowDerivativeCheck c;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const Eigen::RowVectorXd exact = jacobian.row(rows[k]), differences = fd.row(static_cast<Eigen::Index>(k));
    c.worst = std::max(c.worst, ((exact - differences).array().abs() / (1.0 + differences.array().abs())).maxCoeff());
    c.largest = std::max(c.largest, differences.cwiseAbs().maxCoeff());
    c.smallestRow = std::min(c.smallestRow, exact.cwiseAbs().maxCoeff());
  }
  return c;
}

}  // namespace mcopt::test
