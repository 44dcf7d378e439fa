// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Whether the robot can hold the scenario's fixed postures at rest (docs/reference/scenario-file.md, "Fixed
// postures the robot cannot hold"), checked before the optimisation: a fixed start or end
// posture whose centre of mass lies outside the support polygon of the contacts active at that
// instant, or whose static torques exceed a joint's limit, makes every motion of the problem
// infeasible, and Ipopt would only say so after its restoration phase fails.
//
// The support polygon is the convex hull of the active contact rectangles' corners seen from
// above (the static criterion for contacts on horizontal surfaces, the bundled ones); the static
// torques are the problem's own at its first (last) sample of the motion that stays at the
// posture, Γ = Γ0 − J1 F with the formulation's wrenches (one contact: Γ0).

#include <string>
#include <vector>

#include "core/spatial.hpp"
#include "outer_nlp/motion_problem.hpp"

namespace mcopt {

struct PostureCheck {
  std::string which;                 ///< "start", "end", or "start and end" (periodic)
  double time = 0.0;                 ///< [s]
  std::vector<std::string> contacts; ///< active at that instant
  Vector3 centerOfMass = Vector3::Zero();
  /// Signed distance of the centre of mass, seen from above, to the support polygon's edge [m]:
  /// positive inside, negative outside.
  double supportMargin = 0.0;
  struct TorqueExcess {
    std::string joint;
    double torque = 0.0, limit = 0.0;  ///< static |Γ| and its limit [N m]
  };
  std::vector<TorqueExcess> torques;  ///< joints whose static torque exceeds its limit
  TorqueExcess nearestLimit;          ///< the joint with the largest static |Γ| / limit
  double staticPower = 0.0;           ///< Σ P over the joints at rest [W]
  std::string innerStatus;            ///< bilevel: the inner problem at that sample ("infeasible": no admissible wrench holds it)

  bool holdable() const { return supportMargin >= 0.0 && torques.empty() && innerStatus != "infeasible"; }
  /// One line: "start posture (t = 0 s): centre of mass 3.2 cm outside the support polygon of l_sole; …".
  std::string message() const;
};

/// The scenario's fixed postures (`fixed: true`), each checked at rest; none when no end is fixed.
std::vector<PostureCheck> checkFixedPostures(MotionProblem& problem);

/// Signed distance of point p to the convex hull of `points` (2-D): positive inside, negative
/// outside (a hull of one or two points has no inside: the distance is negative or zero).
double signedDistanceToHull(const std::vector<Eigen::Vector2d>& points, const Eigen::Vector2d& p);

}  // namespace mcopt
