// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Whether a scenario leaves the centre of mass time enough to reach its targets (docs/reference/
// scenario-file.md, "Timings too short for the robot"), checked before the optimisation: a
// centre-of-mass task due sooner than the robot can physically get there makes every motion of
// the problem infeasible, and Ipopt says so only after hundreds of iterations.
//
// The bound is the linear inverted pendulum's (height h the centre of mass above the soles at the
// start posture, ω = √(g/h)), along x and along y apart: ẍ = ω² (x − p) with the zero-moment point
// p inside the support's extent [a, b] along that axis, and the capture point ξ = x + ẋ/ω inside
// it too — a centre of mass whose capture point leaves the support cannot be brought back to rest,
// and every scenario ends at rest. The fastest way to move x towards b is then to hold p at a
// until ξ reaches b, then p = ξ = b: x(t) is the largest any admissible motion reaches at every
// instant (ẋ = ω (ξ − x) grows with ξ). From rest at x₀ (ξ₀ = x₀), while ξ < b,
//   x(t) = a + (x₀ − a) cosh ωt,   ξ(t) = a + (x₀ − a) e^{ωt};
// then x(t) = b + (x_s − b) e^{−ω(t − t_s)}. Between two tasks the pendulum may already carry
// speed: the bound starts from the best state (ξ = b at the nearest point of the earlier target);
// to the end at rest, in reversed time the capture point is the convergent component, held at
// the far edge: x(T − s) = b + (x_end − b) cosh ωs, moving down. A necessary condition:
// a scenario that passes may still be too fast for the whole body; one that fails cannot be done.

#include <string>
#include <vector>

#include "outer_nlp/motion_problem.hpp"

namespace mcopt {

struct TimingCheck {
  std::string task;         ///< the centre-of-mass task's name ("the end posture" for the last leg)
  std::string from;         ///< "the start posture at rest", "task 'NAME' (t = 0.6 s)", …
  char axis = 'y';
  double time = 0.0;        ///< the task's instant [s]
  double available = 0.0;   ///< the scenario's time for the leg [s]
  double needed = 0.0;      ///< the pendulum's least time (infinity: the target cannot be reached and stopped)
  double fromPosition = 0.0, toPosition = 0.0;  ///< along the axis [m]
  double supportLower = 0.0, supportUpper = 0.0;  ///< the support's extent [a, b] along the axis [m]
  double height = 0.0;      ///< h [m]
  bool tooShort() const { return needed > available; }
  /// "task 'NAME' (t = 1.2 s): 0.6 s after task 'A' (t = 0.6 s), the centre of mass needs at least …".
  std::string message() const;
};

/// One check per leg and axis where a bound applies: from the start posture (when fixed) to
/// the first centre-of-mass task, between consecutive ones, and from the last to the end posture
/// (when fixed). Instants of tasks of kind center_of_mass with a bound on x or y.
std::vector<TimingCheck> checkCenterOfMassTimings(MotionProblem& problem);

/// How a leg of the pendulum starts and ends.
enum class PendulumLeg {
  FromRest,  ///< at rest at `from`; at `to` with any admissible speed
  Between,   ///< from `from` with the best admissible speed (ξ at the support's far edge), to `to`
  ToRest,    ///< from `from` with any admissible speed, to rest at `to`
};

/// The least time for the pendulum (ω) to bring its centre of mass from `from` to `to` with the
/// zero-moment and capture points in [lower, upper]; infinity where no admissible motion does.
/// ToRest is FromRest in reversed time, where the capture point becomes the convergent component
/// and no longer caps the travel: a centre of mass beyond the support coming back fast can stop.
double pendulumTravelTime(double from, double to, double lower, double upper, double omega, PendulumLeg leg);

}  // namespace mcopt
