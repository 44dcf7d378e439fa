#pragma once
// One interface for the inner-problem solvers (formulation.md §7, style.md §7: settings,
// result, status). Every solver fills the same InnerResult; numerical outcomes are
// statuses, bad input throws InputError.
//
// Infeasibility (no wrench satisfies the contact constraints and the balance: the robot
// would tip or slip) is reported, never hidden. The elastic solution is lexicographic:
// first the balance slack of least norm, s = W − wrenchToWorld F over the contact
// constraints; then the best objective with wrenchToWorld F + s = W. Status Infeasible
// carries that s; the outer problem can then steer it to zero.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "inner_qp/contact_problem.hpp"

namespace mcopt {

enum class InnerStatus { Optimal, Infeasible, Failed };
const char* toString(InnerStatus status);

struct InnerSettings {
  double tolerance = 1e-9;         ///< constraint and stationarity tolerance (relative to the data's scale)
  double kktTolerance = 1e-6;      ///< a stop counts as a solution only below this KKT residual
  int maxIterations = 500;
};

struct InnerResult {
  InnerStatus status = InnerStatus::Failed;
  Eigen::VectorXd wrenches;             ///< Fc, 6nc, each in its contact frame
  double objective = 0.0;               ///< Σ w Γ² + l Γ, without regularisation
  Vector6 balanceMultipliers = Vector6::Zero();
  Eigen::VectorXd inequalityMultipliers;  ///< ≥ 0, one per linear row
  Eigen::VectorXd coneMultipliers;        ///< ≥ 0, one per friction cone (report model)
  std::vector<int> activeSet;           ///< active linear rows, then rows + cone index for active cones
  int iterations = 0;
  double kktResidual = 0.0;             ///< max of stationarity, feasibility, complementarity (see kktResidual)
  double solveTimeUs = 0.0;
  Vector6 balanceSlack = Vector6::Zero();  ///< s of the elastic solution; zero when optimal
  std::string message;                  ///< the underlying solver's own words
};

class InnerSolver {
 public:
  virtual ~InnerSolver() = default;
  virtual std::string name() const = 0;
  /// `result` is overwritten; its wrenches are used as the starting point when sized right.
  virtual void solve(const ContactProblem& problem, InnerResult& result) = 0;
};

std::unique_ptr<InnerSolver> makeSlsqpSolver(const InnerSettings& settings = {});
std::unique_ptr<InnerSolver> makeIpoptSolver(const InnerSettings& settings = {});

/// KKT residual of a result for its problem (balance shifted by the slack when Infeasible):
/// the largest of ‖∇L‖∞ (stationarity, with the multipliers of the result), the constraint
/// violation, and |multiplier × constraint| (complementarity), each relative to the data's scale.
double kktResidual(const ContactProblem& problem, const InnerResult& result);

}  // namespace mcopt
