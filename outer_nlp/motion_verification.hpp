// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A motion certified between its samples (`mcopt verify`, docs/reference/verify.md): the
// motion of a point x of a scenario's problem — its spline parameters, its duration and its
// contact-force variables, never sampled arrays — evaluated again on a fine grid of
// `instantsPerInterval` instants per interval of the scenario's samples (the samples among
// them; every task instant and both sides of every window's end as the problem has them), and
// every constraint of the scenario checked there:
//   - every constraint row of the problem on that grid (torque limits, the active contacts'
//     unilaterality, friction, centre of pressure and yaw rows with the wrenches the formulation
//     gives there, bilevel inner feasibility, the tasks and the closure at window ends, the
//     closing joints' limits), at the scenario's constraint tolerance (Ipopt's constr_viol_tol);
//   - every joint's angle and velocity against its limits, closing joints included;
//   - each environment contact's closure drift over its window;
//   - the bilevel inner problems that have no answer at an instant (the robot would tip or slip);
//   - the energy on the fine grid against the sampled one the optimiser saw, and the mechanical
//     energy identity (energy_balance.hpp) on the fine grid.
// Between the samples the wrenches are the formulation's own: the inner problem solved at each
// instant (bilevel), the wrench splines (splines), interpolated linearly between the samples
// (variables, which defines them at the samples only).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "outer_nlp/energy_balance.hpp"
#include "outer_nlp/fine_grid_motion.hpp"
#include "outer_nlp/motion_problem.hpp"

namespace mcopt {

struct VerificationSettings {
  int instantsPerInterval = 10;  ///< ≥ 1: instants per interval of the scenario's samples
  /// The constraint tolerance; negative: the scenario's Ipopt `constr_viol_tol` (Ipopt's
  /// default 1e-4 when the scenario sets none), what `optimal` held the rows to at the samples.
  double constraintTolerance = -1.0;
  double closureTolerance = 1e-6;  ///< [m] and [rad]: the drift of a held contact from its world pose
  double energyTolerance = 0.01;   ///< |E_fine − E_sampled| / E_sampled
  double balanceTolerance = 1e-3;  ///< |mechanical residual| / its scale (EnergyBalance::mechanicalScale)
};

/// One kind of check over the fine grid: its worst value and where it is.
struct VerificationCheck {
  std::string kind;    ///< "torque_limit", "contact_friction", "closure_drift", "energy", …
  std::string unit;    ///< of `worst` and `tolerance`
  /// The largest violation (≥ 0; 0 where everything holds) or, for the identities and the
  /// energy, the largest relative or absolute error.
  double worst = 0.0;
  double tolerance = 0.0;
  std::string where;   ///< the joint, contact or task of the worst value ("" when none)
  double time = std::numeric_limits<double>::quiet_NaN();  ///< [s] of the worst value (NaN: not at an instant)
  bool betweenSamples = false;  ///< the worst value's instant is none of the scenario's samples
  int rowsChecked = 0;          ///< values compared (rows, joints × instants, …)
  /// The instants at which it is broken, at most once each [s] (replay and plot mark them).
  std::vector<double> failingTimes;
  bool passed() const { return worst <= tolerance; }
};

struct MotionVerification {
  int instantsPerInterval = 0, instants = 0, scenarioSamples = 0;
  double duration = 0.0;  ///< T [s]
  std::string wrenchesBetweenSamples;  ///< as EnergyBalance: "balance", "inner problem", "splines", "linear interpolation"
  double constraintTolerance = 0.0;
  std::vector<VerificationCheck> checks;
  double sampledEnergy = 0.0, fineEnergy = 0.0;  ///< [J]: trapezoid at the scenario's samples, Simpson on the fine grid
  EnergyBalance balance;                         ///< on the fine grid
  int innerProblems = 0, innerInfeasible = 0, innerFailed = 0;  ///< bilevel, at the fine instants
  bool passed() const;
  /// The failing checks' names, in order.
  std::vector<std::string> failures() const;
};

/// Verifies the motion of `problem` at x (see above). The problem is evaluated once at x (its
/// sampled energy); the fine grid is a problem of its own.
MotionVerification verifyMotion(MotionProblem& problem, const Eigen::VectorXd& x, const VerificationSettings& settings = {});

}  // namespace mcopt
