// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Where a motion's energy goes (docs/reference/scenario-file.md, "Energy balance"), on a fine grid of the
// motion: the joints' net mechanical work, the change of the robot's potential and kinetic
// energy, the work of the environment contacts (zero when they hold), a thrown ball's energy,
// and on the motors' side the rotors' kinetic energy, the Joule losses, the friction, and the
// energy fed back by braking that max(P, 0) does not count.
//
// Two identities hold for any motion, whatever the optimiser did:
//   mechanical   ∫ Σ Γ q̇ dt + ∫ Σ_i F_i·V_i dt = ΔE_pot + ΔE_kin (+ the ball's energy at release)
//                (Γ the joint torques with the contact wrenches, F_i a contact's wrench on the
//                robot, V_i the twist of its frame; the reference body is fixed and does no work)
//   electrical   ∫ Σ P dt = ∫ Σ Γ q̇ dt + ΔE_rotor + ∫ Σ Γ_fric Ω dt + ∫ Σ (R/K²) Γem² dt
// The first checks the splines, the dynamics and the split of the torques between the motors
// and the contacts at once (tests/outer_nlp/test_energy_balance.cpp).
//
// The grid: `instantsPerInterval` instants per interval of the problem's samples (its samples
// among them). Between the samples the wrenches are the formulation's own where it defines
// them — the reference contact alone (the balance), the inner problem at each instant (bilevel),
// the wrench splines (splines) — and, for the `variables` formulation, which defines them at the
// samples only, interpolated linearly in time between them (`wrenchesBetweenSamples` says which);
// for `splines` and `variables`, the closest admissible distribution of the same total wrench
// wherever theirs breaks a contact row (fine_grid_motion.hpp, `redistribution`).

#include <Eigen/Core>
#include <string>

#include "outer_nlp/fine_grid_motion.hpp"
#include "outer_nlp/motion_problem.hpp"

namespace mcopt {

struct EnergyBalance {
  int instants = 0;                 ///< of the fine grid
  int instantsPerInterval = 0;
  std::string wrenchesBetweenSamples;  ///< "balance", "inner problem", "splines" or "linear interpolation"
  /// `splines`, `variables`: where the fine grid took the closest admissible wrenches instead of
  /// the formulation's between the samples (fine_grid_motion.hpp).
  WrenchRedistribution redistribution;

  double jointWork = 0.0;           ///< ∫ Σ Γ q̇ dt [J]
  double contactWork = 0.0;         ///< ∫ Σ_i F_i·V_i dt: the environment contacts' work on the robot [J]
  double potentialChange = 0.0;     ///< E_pot(T) − E_pot(0), the robot without a ball [J]
  double kineticChange = 0.0;       ///< E_kin(T) − E_kin(0), the robot without a ball [J]
  double ballEnergy = 0.0;          ///< a throw: the ball's E_kin + E_pot at release minus at t = 0 [J]
  double rotorKineticChange = 0.0;  ///< Σ ½ I_m N² (q̇(T)² − q̇(0)²) [J]
  double jouleLosses = 0.0;         ///< ∫ Σ (R/K²) Γem² dt [J]
  double frictionDissipation = 0.0; ///< ∫ Σ Γ_fric Ω dt [J]
  double electricalEnergy = 0.0;    ///< ∫ Σ P dt, net [J]
  double positiveEnergy = 0.0;      ///< ∫ Σ max(P, 0) dt: the criterion's energy [J]
  double braking = 0.0;             ///< ∫ Σ min(P, 0) dt ≤ 0: fed back by the motors, taken by nobody [J]
  double jointPowerFlow = 0.0;      ///< ∫ |Σ Γ q̇| dt: the power that flows through the joints either way [J]

  /// jointWork + contactWork − (potentialChange + kineticChange + ballEnergy).
  double mechanicalResidual() const { return jointWork + contactWork - (potentialChange + kineticChange + ballEnergy); }
  /// The largest |term| of the mechanical identity, or the power that flows through the joints
  /// when larger (a motion that returns to its start has every term zero): the scale of its
  /// residual, which is the quadrature's error of integrals of that size.
  double mechanicalScale() const;
  /// electricalEnergy − (jointWork + rotorKineticChange + frictionDissipation + jouleLosses).
  double electricalResidual() const {
    return electricalEnergy - (jointWork + rotorKineticChange + frictionDissipation + jouleLosses);
  }
  /// The potential energy the motion releases (−ΔE_pot when the end is lower, else 0) [J].
  double gravityReleased() const { return potentialChange < 0.0 ? -potentialChange : 0.0; }
};

/// The energy balance of `problem`'s motion at x on a grid of `instantsPerInterval` instants per
/// interval of its samples (≥ 1; 0: energyGridInstants(scenario, 10)). Builds the same problem on
/// that grid (so, bilevel, one inner problem per instant); the problem's own state is left as
/// any evaluation leaves it. The integrals are composite Simpson sums (a trapezoid for an odd
/// interval left at the end of a run).
EnergyBalance energyBalance(MotionProblem& problem, const Eigen::VectorXd& x, int instantsPerInterval = 0);

/// The least number of instants per sample interval, at least `atLeast`, that puts every knot of
/// the splines (where q̈ has a kink), a throw's release and a window's ends (where the power
/// jumps) on an even instant of the grid, so that no Simpson pair straddles one: the integrals
/// then converge as h⁴ (the kick: 12; the throws: 16; the lean reach: 32). `atLeast` when no
/// number up to 20 × atLeast does (then a window's end between instants costs a trapezoid on
/// each side).
int energyGridInstants(const Scenario& scenario, int atLeast);

/// How a scenario's contact wrenches are known between its samples: "balance" (the reference
/// contact alone), else its formulation's (registry: "inner problem", "splines", "linear
/// interpolation") — the scenario's own, whichever problem carries its fine grid.
std::string wrenchesBetweenSamples(const Scenario& scenario);

/// The balance of given physics at the samples of `problem` (the fine grid's problem of
/// energyBalance, whose sampledPhysics they are): apart so that a test can perturb them.
EnergyBalance energyBalanceOf(const MotionProblem& problem, const SampledPhysics& physics);

}  // namespace mcopt
