// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/posture_check.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/dynamics_data.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"

namespace mcopt {

namespace {

double cross(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
}

/// Distance from p to the segment [a, b].
double segmentDistance(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p) {
  const Eigen::Vector2d d = b - a;
  const double length2 = d.squaredNorm();
  const double t = length2 > 0.0 ? std::clamp((p - a).dot(d) / length2, 0.0, 1.0) : 0.0;
  return (a + t * d - p).norm();
}

}  // namespace

double signedDistanceToHull(const std::vector<Eigen::Vector2d>& input, const Eigen::Vector2d& p) {
  if (input.empty()) return -std::numeric_limits<double>::infinity();
  // Andrew's monotone chain: the hull counter-clockwise, without collinear points.
  std::vector<Eigen::Vector2d> points = input;
  std::sort(points.begin(), points.end(),
            [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  std::vector<Eigen::Vector2d> hull(2 * points.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], points[i]) <= 0.0) --k;
    hull[k++] = points[i];
  }
  for (std::size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(hull[k - 2], hull[k - 1], points[i]) <= 0.0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k > 1 ? k - 1 : k);
  double distance = std::numeric_limits<double>::infinity();
  bool inside = hull.size() >= 3;
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2d& a = hull[i];
    const Eigen::Vector2d& b = hull[(i + 1) % hull.size()];
    distance = std::min(distance, segmentDistance(a, b, p));
    if (cross(a, b, p) < 0.0) inside = false;
  }
  return inside ? distance : -distance;
}

std::string PostureCheck::message() const {
  std::ostringstream m;
  m << which << " posture (t = " << time << " s): ";
  std::ostringstream polygon;
  for (std::size_t i = 0; i < contacts.size(); ++i) polygon << (i == 0 ? "" : ", ") << contacts[i];
  m.setf(std::ios::fixed);
  m.precision(1);
  if (supportMargin >= 0.0)
    m << "centre of mass " << 100.0 * supportMargin << " cm inside the support polygon of " << polygon.str();
  else
    m << "centre of mass " << -100.0 * supportMargin << " cm OUTSIDE the support polygon of " << polygon.str();
  m.precision(3);
  m << " (at x " << centerOfMass.x() << ", y " << centerOfMass.y() << " m)";
  for (const TorqueExcess& t : torques)
    m << "; static torque of " << t.joint << " " << t.torque << " N m beyond its limit " << t.limit << " N m";
  if (innerStatus == "infeasible") m << "; no admissible contact wrenches hold it (the inner problem is infeasible)";
  return m.str();
}

std::vector<PostureCheck> checkFixedPostures(MotionProblem& problem) {
  const Scenario& scenario = problem.scenario();
  std::vector<PostureCheck> checks;
  if (!scenario.fixStart && !scenario.fixEnd) return checks;
  // The motion that stays at rest in each fixed posture at its end of the motion.
  const Eigen::VectorXd x = problem.initialPoint(scenario.start, scenario.end);
  const SampledPhysics physics = problem.sampledPhysics(x, MotionProblem::ClosureDrift::Skipped);
  const DynamicsModel& model = problem.model();
  DynamicsData data(model);
  const int last = problem.sampleCount() - 1;
  std::vector<std::pair<int, std::string>> ends;
  if (scenario.fixStart) ends.push_back({0, scenario.periodic ? "start and end" : "start"});
  if (scenario.fixEnd && !scenario.periodic) ends.push_back({last, "end"});
  for (const auto& [sample, which] : ends) {
    PostureCheck check;
    check.which = which;
    check.time = physics.time[sample];
    forwardKinematics(model, data, physics.q.col(sample));
    check.centerOfMass = centerOfMass(model, data);
    std::vector<Eigen::Vector2d> corners;
    auto addSurface = [&](const ContactSurface& surface) {
      check.contacts.push_back(surface.name);
      const RigidTransform pose = framePose(model, data, surface.frame) * surface.placement;
      for (const double cx : {surface.xMin, surface.xMax})
        for (const double cy : {surface.yMin, surface.yMax}) corners.push_back(pose.apply(Vector3(cx, cy, 0.0)).head<2>());
    };
    addSurface(scenario.support);
    for (std::size_t i = 0; i < scenario.contacts.size(); ++i)
      if (problem.contactActive(static_cast<int>(i), sample)) addSurface(scenario.contacts[i].surface);
    check.supportMargin = signedDistanceToHull(corners, check.centerOfMass.head<2>());
    double nearest = -1.0;
    for (int j = 0; j < model.jointCount(); ++j) {
      const double limit = scenario.actuators.joints[static_cast<std::size_t>(j)].torqueLimit;
      const double torque = std::abs(physics.tau(j, sample));
      const std::string& name = scenario.robot.joints[static_cast<std::size_t>(j)].name;
      if (std::isfinite(limit) && torque > limit) check.torques.push_back({name, torque, limit});
      const double ratio = std::isfinite(limit) && limit > 0.0 ? torque / limit : 0.0;
      if (ratio > nearest) nearest = ratio, check.nearestLimit = {name, torque, limit};
      check.staticPower += physics.power(j, sample);
    }
    if (!physics.innerStatus.empty()) check.innerStatus = physics.innerStatus[static_cast<std::size_t>(sample)];
    checks.push_back(check);
  }
  return checks;
}

}  // namespace mcopt
