// SPDX-License-Identifier: BSD-3-Clause
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
  bool warmStart = true;           ///< active-set method: start from the result passed in (its active set and wrenches)
  /// SLSQP and Ipopt: polish each answer on its own active set (linear contact models; the
  /// report model's cones are left as solved). docs/theory/inner-problem.md, "Polishing".
  bool polish = false;
  /// The barrier solver: the central-path parameter μ > 0 at which it stops, in the objective's
  /// units (W). Its answer's objective lies at most (linear rows) × μ above the exact minimum,
  /// and is a smooth function of the data (docs/theory/inner-problem.md, "The barrier-smoothed
  /// inner problem"). Other solvers do not read it.
  double barrier = 1e-3;
};

struct InnerResult {
  InnerStatus status = InnerStatus::Failed;
  Eigen::VectorXd wrenches;             ///< Fc, 6nc, each in its contact frame
  double objective = 0.0;               ///< Σ w Γ² + l Γ, without regularisation
  Vector6 balanceMultipliers = Vector6::Zero();
  Eigen::VectorXd inequalityMultipliers;  ///< ≥ 0, one per linear row
  /// Per friction cone (report model) its conic multiplier y = (y_x, y_y, y_z) in the dual
  /// cone μ‖(y_x, y_y)‖ ≤ y_z, 3 entries a cone; stationarity reads
  ///   H F + c + balanceᵀ λ + Gᵀ μ − Σ_cones E_iᵀ y_i = 0,   y_iᵀ (fx, fy, fz)_i = 0.
  /// On the cone's surface y = ν (−2 fx, −2 fy, 2 μ² fz) for the quadratic form's multiplier
  /// ν; at the apex (an unloaded contact, formulation.md §7) y is any point of the dual cone,
  /// which is what certifies an unloaded contact where the quadratic form's gradient vanishes.
  Eigen::VectorXd coneMultipliers;
  std::vector<int> activeSet;           ///< active linear rows, then rows + cone index for active cones
  int iterations = 0;
  double kktResidual = 0.0;             ///< max of stationarity, feasibility, complementarity (see kktResidual)
  double solveTimeUs = 0.0;
  Vector6 balanceSlack = Vector6::Zero();  ///< s of the elastic solution; zero when optimal
  /// Infeasible: the least-slack phase's own point, the unique minimiser of
  /// ‖W − B F‖² + ε‖F‖² over the contact constraints. The envelope theorem differentiates
  /// the least slack's size at this point (phase 2's wrenches are another minimiser of ‖s‖²,
  /// at which (∂B/∂q) F differs). Meaningful only when Infeasible.
  Eigen::VectorXd leastSlackWrenches;
  bool polished = false;                ///< the answer was polished on its active set (InnerSettings::polish)
  /// 0: an exact optimum. μ > 0: the barrier solver's central-path point at μ, where every
  /// row is strictly inside (s_i > 0), each multiplier is z_i = μ / s_i and `activeSet` is empty.
  double barrier = 0.0;
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
/// The in-house method (formulation.md §7): a dual active-set QP inside an SQP loop over the
/// friction cones; allocation-free once it has seen a problem of the same size.
std::unique_ptr<InnerSolver> makeActiveSetSolver(const InnerSettings& settings = {});
/// The central path at a fixed μ (InnerSettings::barrier) of the linear contact models: a
/// smooth answer for the bilevel outer problem (barrier_solver.cpp).
std::unique_ptr<InnerSolver> makeBarrierSolver(const InnerSettings& settings = {});

/// One registered inner solver: the name scenario files, `mcopt inner --solver` and the Python
/// module know it by, one line saying what it is, and how to make it.
struct InnerSolverEntry {
  std::string name;
  std::string description;
  std::unique_ptr<InnerSolver> (*make)(const InnerSettings& settings);
};

/// Every inner solver, in the order documents list them (the registry, inner_solver.cpp: a new
/// solver is its own file and one line there).
const std::vector<InnerSolverEntry>& innerSolvers();
/// Their names, in the same order.
const std::vector<std::string>& innerSolverNames();
bool isInnerSolverName(const std::string& name);
/// The names for a message or a help text: "active-set, slsqp or ipopt".
std::string innerSolverList();

/// Solver by name; throws InputError naming the registered ones otherwise.
std::unique_ptr<InnerSolver> makeInnerSolver(const std::string& name, const InnerSettings& settings = {});

/// KKT residual of a result for its problem (balance shifted by the slack when Infeasible):
/// the largest of ‖∇L‖∞ (stationarity, with the multipliers of the result), the constraint
/// violation, and |multiplier × constraint| (complementarity; |multiplier × constraint + μ| for a
/// barrier answer), each relative to the data's scale.
/// Allocation-free.
double kktResidual(const ContactProblem& problem, const InnerResult& result);

}  // namespace mcopt
