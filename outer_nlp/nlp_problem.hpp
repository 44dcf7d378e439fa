// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A smooth NLP with exact first derivatives and a sparse constraint Jacobian whose pattern
// is fixed once: min f(x) s.t. x_L ≤ x ≤ x_U, g_L ≤ g(x) ≤ g_U. The motion problem and the
// configuration (static posture) problem both take this form; ipopt_driver solves it.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace mcopt {

class NlpProblem {
 public:
  virtual ~NlpProblem() = default;
  virtual int variableCount() const = 0;
  virtual int constraintCount() const = 0;
  /// Row and column of every Jacobian entry, in the order of jacobianValues.
  virtual const Eigen::VectorXi& jacobianRows() const = 0;
  virtual const Eigen::VectorXi& jacobianColumns() const = 0;
  virtual void variableBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const = 0;
  virtual void constraintBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const = 0;
  /// The size of one unit of each variable for the solver (`units` resized to variableCount(),
  /// every entry positive): the solver works on x_i / unit_i, so that variables of different
  /// kinds (radians, newtons) come to it at comparable sizes; every function here still takes
  /// x in the problem's own units. Ones unless the problem says otherwise.
  virtual void variableUnits(Eigen::VectorXd& units) const { units.setOnes(variableCount()); }
  virtual double objective(const Eigen::VectorXd& x) = 0;
  virtual void objectiveGradient(const Eigen::VectorXd& x, Eigen::VectorXd& gradient) = 0;
  virtual void constraints(const Eigen::VectorXd& x, Eigen::VectorXd& values) = 0;
  virtual void jacobianValues(const Eigen::VectorXd& x, Eigen::VectorXd& values) = 0;
  /// Variables [0, n) that enter f or g nonlinearly (the rest, e.g. epigraph slacks, enter
  /// linearly): the block a finite-difference Hessian has to fill.
  virtual int nonlinearVariableCount() const { return variableCount(); }
  /// A readable name of constraint row `row`, for messages.
  virtual std::string rowName(int row) const = 0;

  /// The Lagrangian's Hessian σ ∇²f + Σ λ_i ∇²g_i over the nonlinear variables, as the dense
  /// lower triangle row by row ((0,0), (1,0), (1,1), (2,0) …; `values` resized). This
  /// generic version takes forward differences of the exact gradients, one evaluation per
  /// nonlinear variable; a problem that knows its structure overrides it.
  virtual void lagrangianHessian(const Eigen::VectorXd& x, double objectiveFactor,
                                 const Eigen::Ref<const Eigen::VectorXd>& multipliers, Eigen::VectorXd& values);
  /// The entries of lagrangianHessian's lower triangle that can be nonzero at any x and
  /// multipliers, as (row, column) pairs, column ≤ row, row by row: the sparsity the solver is
  /// told (its factorisation then skips the rest). Every entry of the dense triangle unless the
  /// problem knows which variables never meet in one term.
  virtual void hessianPattern(std::vector<int>& rows, std::vector<int>& columns) const;
  /// ∇L = σ ∇f + Jᵀ λ (all variables).
  void lagrangianGradient(const Eigen::VectorXd& x, double objectiveFactor,
                          const Eigen::Ref<const Eigen::VectorXd>& multipliers, Eigen::VectorXd& gradient);

 private:
  Eigen::VectorXd jacobianScratch_;
};

/// A forward difference's step for a variable of magnitude `value` and unit `unit`
/// (NlpProblem::variableUnits): 1e-6 of its size, at least of its unit. h = 1e-6 balances
/// truncation and round-off, and Newton's steps need no more than its ~1e-6 relative accuracy.
inline double differenceStep(double value, double unit = 1.0) { return 1e-6 * std::max(unit, std::abs(value)); }

/// Index of entry (row, column), column ≤ row, in a dense lower triangle stored row by row.
inline Eigen::Index lowerTriangleIndex(Eigen::Index row, Eigen::Index column) { return row * (row + 1) / 2 + column; }

}  // namespace mcopt
