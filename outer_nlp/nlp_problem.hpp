#pragma once
// A smooth NLP with exact first derivatives and a sparse constraint Jacobian whose pattern
// is fixed once: min f(x) s.t. x_L ≤ x ≤ x_U, g_L ≤ g(x) ≤ g_U. The motion problem and the
// configuration (static posture) problem both take this form; ipopt_driver solves it.

#include <Eigen/Core>
#include <string>

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
  virtual double objective(const Eigen::VectorXd& x) = 0;
  virtual void objectiveGradient(const Eigen::VectorXd& x, Eigen::VectorXd& gradient) = 0;
  virtual void constraints(const Eigen::VectorXd& x, Eigen::VectorXd& values) = 0;
  virtual void jacobianValues(const Eigen::VectorXd& x, Eigen::VectorXd& values) = 0;
  /// Variables [0, n) that enter f or g nonlinearly (the rest, e.g. epigraph slacks, enter
  /// linearly): the block a finite-difference Hessian has to fill.
  virtual int nonlinearVariableCount() const { return variableCount(); }
  /// A readable name of constraint row `row`, for messages.
  virtual std::string rowName(int row) const = 0;
};

}  // namespace mcopt
