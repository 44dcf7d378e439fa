// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/timing_check.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/dynamics_data.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"

namespace mcopt {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// A known centre of mass along the two axes: a point at rest, or a target interval.
struct Waypoint {
  std::string name;
  double time = 0.0;
  bool rest = false;
  Eigen::Vector2d lower, upper;  ///< equal for a point at rest; ±inf where the task leaves an axis free
};

}  // namespace

double pendulumTravelTime(double from, double to, double lower, double upper, double omega, PendulumLeg leg) {
  if (to == from) return 0.0;
  if (to < from) return pendulumTravelTime(-from, -to, -upper, -lower, omega, leg);
  // Moving up: towards b = upper, the zero-moment point at a = lower first.
  const double a = lower, b = upper;
  if (leg == PendulumLeg::ToRest) {
    // Reversed time from rest at `to`, moving down to `from`, the convergent component at b:
    // y − b = (to − b) cosh ωs.
    if (!(to < b)) return kInf;
    return std::acosh((b - from) / (b - to)) / omega;
  }
  if (!(to < b)) return kInf;
  double xs = from, ts = 0.0;
  if (leg == PendulumLeg::FromRest) {
    const double c = from - a;
    if (!(c > 0.0)) return kInf;  // at rest on the support's edge: it cannot move away from it and stop
    ts = std::log((b - a) / c) / omega;
    xs = a + c * std::cosh(omega * ts);
    if (to <= xs) return std::acosh((to - a) / c) / omega;
  }
  return ts + std::log((b - xs) / (b - to)) / omega;
}

std::string TimingCheck::message() const {
  std::ostringstream m;
  m.precision(3);
  m << task << " (t = " << time << " s): " << available << " s after " << from << ", ";
  if (std::isinf(needed))
    m << "the centre of mass cannot reach " << axis << " = " << toPosition << " m and stop there: it lies outside the support's extent ["
      << supportLower << ", " << supportUpper << "] m along " << axis;
  else
    m << "the centre of mass needs at least " << needed << " s to go from " << axis << " = " << fromPosition << " to "
      << toPosition << " m (a linear inverted pendulum " << height << " m high, its zero-moment and capture points in ["
      << supportLower << ", " << supportUpper << "] m along " << axis << ")";
  if (tooShort()) m << ": too short for this robot";
  return m.str();
}

std::vector<TimingCheck> checkCenterOfMassTimings(MotionProblem& problem) {
  const Scenario& scenario = problem.scenario();
  const DynamicsModel& model = problem.model();
  std::vector<TimingCheck> checks;
  const double T = scenario.duration.initial;

  std::vector<Waypoint> waypoints;
  for (const TaskSpec& task : scenario.tasks) {
    if (task.task->reads() != TaskQuantity::CenterOfMass || task.window) continue;
    Waypoint w{"task '" + task.name + "'", task.start, false, task.lower.head<2>(), task.upper.head<2>()};
    if (std::isfinite(w.lower.x()) || std::isfinite(w.upper.x()) || std::isfinite(w.lower.y()) || std::isfinite(w.upper.y()))
      waypoints.push_back(w);
  }
  if (waypoints.empty()) return checks;
  std::sort(waypoints.begin(), waypoints.end(), [](const Waypoint& a, const Waypoint& b) { return a.time < b.time; });

  // The postures' centres of mass, the support's corners at the start posture, the height.
  DynamicsData data(model);
  forwardKinematics(model, data, scenario.start);
  const Vector3 startCom = centerOfMass(model, data);
  auto corners = [&](const ContactSurface& surface, const RigidTransform& pose) {
    std::vector<Vector3> out;
    for (const double cx : {surface.xMin, surface.xMax})
      for (const double cy : {surface.yMin, surface.yMax}) out.push_back(pose.apply(Vector3(cx, cy, 0.0)));
    return out;
  };
  const std::vector<Vector3> supportCorners = corners(scenario.support, framePose(model, data, scenario.support.frame) * scenario.support.placement);
  std::vector<std::vector<Vector3>> contactCorners;
  for (const EnvironmentContact& c : scenario.contacts)
    contactCorners.push_back(corners(c.surface, c.poseGiven ? c.worldPose : framePose(model, data, c.surface.frame) * c.surface.placement));
  double ground = 0.0;
  for (const Vector3& p : supportCorners) ground += p.z() / static_cast<double>(supportCorners.size());
  const double height = startCom.z() - ground;
  if (!(height > 0.0)) return checks;
  const double omega = std::sqrt(scenario.gravity.norm() / height);

  if (scenario.fixStart) {
    const Eigen::Vector2d p = startCom.head<2>();
    waypoints.insert(waypoints.begin(), Waypoint{"the start posture at rest", 0.0, true, p, p});
  }
  if (scenario.fixEnd || (scenario.periodic && scenario.fixStart)) {
    forwardKinematics(model, data, scenario.periodic ? scenario.start : scenario.end);
    const Eigen::Vector2d p = centerOfMass(model, data).head<2>();
    waypoints.push_back(Waypoint{"the end posture at rest", T, true, p, p});
  }

  for (std::size_t k = 1; k < waypoints.size(); ++k) {
    const Waypoint& from = waypoints[k - 1];
    const Waypoint& to = waypoints[k];
    // The largest support over the leg: the reference sole and every contact active in it.
    std::vector<Vector3> points = supportCorners;
    for (std::size_t i = 0; i < scenario.contacts.size(); ++i) {
      const EnvironmentContact& c = scenario.contacts[i];
      if (!c.window || (c.start < to.time && c.end > from.time))
        points.insert(points.end(), contactCorners[i].begin(), contactCorners[i].end());
    }
    for (int axis = 0; axis < 2; ++axis) {
      double a = kInf, b = -kInf;
      for (const Vector3& p : points) a = std::min(a, p[axis]), b = std::max(b, p[axis]);
      // The nearest points of the two targets (intervals; a point at rest is one).
      double x0, x1;
      if (from.upper[axis] < to.lower[axis]) x0 = from.upper[axis], x1 = to.lower[axis];
      else if (to.upper[axis] < from.lower[axis]) x0 = from.lower[axis], x1 = to.upper[axis];
      else continue;  // overlapping, or an axis left free
      if (!std::isfinite(x0) || !std::isfinite(x1)) continue;
      TimingCheck check;
      check.task = to.name;
      check.from = from.rest ? from.name : from.name + " (t = " + [&] {
        std::ostringstream t;
        t.precision(3);
        t << from.time;
        return t.str();
      }() + " s)";
      check.axis = axis == 0 ? 'x' : 'y';
      check.time = to.time;
      check.available = to.time - from.time;
      check.fromPosition = x0, check.toPosition = x1;
      check.supportLower = a, check.supportUpper = b;
      check.height = height;
      check.needed = pendulumTravelTime(x0, x1, a, b, omega,
                                        to.rest ? PendulumLeg::ToRest : from.rest ? PendulumLeg::FromRest : PendulumLeg::Between);
      checks.push_back(check);
    }
  }
  return checks;
}

}  // namespace mcopt
