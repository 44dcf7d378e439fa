#pragma once
// An NlpProblem's sparse Jacobian as a dense matrix, and its declared pattern, for the
// derivative tests of the outer problems.
#include <Eigen/Core>

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

}  // namespace mcopt::test
