// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/nlp_problem.hpp"

#include <cmath>

namespace mcopt {

void NlpProblem::lagrangianGradient(const Eigen::VectorXd& x, double objectiveFactor,
                                    const Eigen::Ref<const Eigen::VectorXd>& multipliers, Eigen::VectorXd& gradient) {
  objectiveGradient(x, gradient);
  gradient *= objectiveFactor;
  jacobianValues(x, jacobianScratch_);
  const Eigen::VectorXi& rows = jacobianRows();
  const Eigen::VectorXi& columns = jacobianColumns();
  for (Eigen::Index k = 0; k < jacobianScratch_.size(); ++k) gradient[columns[k]] += jacobianScratch_[k] * multipliers[rows[k]];
}

void NlpProblem::hessianPattern(std::vector<int>& rows, std::vector<int>& columns) const {
  const int curved = nonlinearVariableCount();
  rows.clear(), columns.clear();
  for (int r = 0; r < curved; ++r)
    for (int c = 0; c <= r; ++c) rows.push_back(r), columns.push_back(c);
}

void NlpProblem::lagrangianHessian(const Eigen::VectorXd& x, double objectiveFactor,
                                   const Eigen::Ref<const Eigen::VectorXd>& multipliers, Eigen::VectorXd& values) {
  // Column c = (∇L(x + h e_c) − ∇L(x)) / h, then symmetrised. Forward differences: half the
  // evaluations of central ones (differenceStep).
  const int curved = nonlinearVariableCount();
  Eigen::VectorXd point = x, base, plus, units;
  variableUnits(units);
  lagrangianGradient(point, objectiveFactor, multipliers, base);
  Eigen::MatrixXd columns(curved, curved);
  for (int c = 0; c < curved; ++c) {
    const double saved = point[c], h = differenceStep(saved, units[c]);
    point[c] = saved + h;
    lagrangianGradient(point, objectiveFactor, multipliers, plus);
    point[c] = saved;
    columns.col(c) = (plus - base).head(curved) / h;
  }
  values.resize(static_cast<Eigen::Index>(curved) * (curved + 1) / 2);
  for (int r = 0; r < curved; ++r)
    for (int c = 0; c <= r; ++c) values[lowerTriangleIndex(r, c)] = 0.5 * (columns(r, c) + columns(c, r));
}

}  // namespace mcopt
