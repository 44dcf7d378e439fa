// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A motion on a fine grid of instants (energy_balance.hpp, motion_verification.hpp): the same
// scenario on `instantsPerInterval` instants per interval of its samples, its point carrying
// the same motion and the same contact wrenches, and its physics.
//
// The single-level formulations (`splines`, `variables`) hold the contact rows at their samples
// only. Between them the environment contacts' wrenches are the formulation's own (the force
// splines, or the samples' wrenches interpolated linearly) and the reference contact's is what
// the dynamics leaves (the total wrench minus theirs): a remainder that is a smooth function of
// the motion, whose curvature between two samples where a row is active can take it outside
// its contact model by newtons (the weight shift's unloading sole, 60 samples: 2.8 N of
// friction). Which contact takes that remainder is the rooting's choice, not physics. So
// wherever the formulation's wrenches break a contact row between the samples, the fine grid
// takes instead the admissible distribution of the same total wrench closest to them
// (least squares in N and N m over every contact active there, a small QP) — what a
// controller holding the motion would do — and says where, and by how much, it moved them
// (`WrenchRedistribution`). At the samples nothing moves: the optimum holds every row there.
// An instant whose total wrench no admissible distribution carries keeps the formulation's
// wrenches, so that the check that reads them fails there.

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <string>

#include "outer_nlp/motion_problem.hpp"

namespace mcopt {

/// Where the fine grid moved a single-level formulation's wrenches between its samples.
struct WrenchRedistribution {
  bool applies = false;    ///< a single-level formulation with environment contacts
  int instants = 0;        ///< instants whose wrenches were redistributed
  int unreachable = 0;     ///< instants with a broken row that no admissible distribution mends
  double largestChange = 0.0;  ///< the largest change of one wrench component [N or N m]
  double time = std::numeric_limits<double>::quiet_NaN();  ///< where [s]
  std::string contact;     ///< whose component
};

/// The scenario on a grid of `instantsPerInterval` instants per interval of its samples, with no
/// continuation and every torque-limit row (FineGridMotion's).
Scenario fineGridScenario(const Scenario& scenario, int instantsPerInterval);

/// The constraint tolerance a scenario's run holds its rows to: its solver option
/// constr_viol_tol, else Ipopt's default 1e-4.
double scenarioConstraintTolerance(const Scenario& scenario);

class FineGridMotion {
 public:
  /// `problem`'s motion at x on `instantsPerInterval` ≥ 1 instants per sample interval
  /// (fineGridScenario); `rowTolerance`: a contact row broken by more is redistributed (the
  /// scenario's constr_viol_tol: what `optimal` held the rows to at the samples).
  FineGridMotion(MotionProblem& problem, const Eigen::VectorXd& x, int instantsPerInterval, double rowTolerance);

  MotionProblem& problem() { return *problem_; }
  const MotionProblem& problem() const { return *problem_; }
  const Eigen::VectorXd& point() const { return point_; }
  const SampledPhysics& physics() const { return physics_; }
  const WrenchRedistribution& redistribution() const { return redistribution_; }

 private:
  std::unique_ptr<Scenario> scenario_;  // MotionProblem keeps a reference to its scenario
  std::unique_ptr<MotionProblem> problem_;
  Eigen::VectorXd point_;
  SampledPhysics physics_;
  WrenchRedistribution redistribution_;
};

}  // namespace mcopt
