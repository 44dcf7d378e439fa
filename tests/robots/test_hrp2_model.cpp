// SPDX-License-Identifier: BSD-3-Clause
// Our HRP-2 model against the published facts (issue 3 acceptance): 30 joints, 58 kg,
// 1.54 m at the zero posture, and half-sitting statics on either sole.
#include <catch2/catch.hpp>

#include "common/test_support.hpp"
#include "core/actuators.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"
#include "core/robot_files.hpp"

using namespace mcopt;

namespace {

const std::filesystem::path kDir = test::sourceDir() / "robots/hrp2";

/// Is p inside the convex polygon (counter-clockwise hull of `points`)?
bool insideConvexHull(std::vector<Eigen::Vector2d> points, const Eigen::Vector2d& p, double& margin) {
  std::sort(points.begin(), points.end(), [](const auto& a, const auto& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
  };
  std::vector<Eigen::Vector2d> hull;
  for (int pass = 0; pass < 2; ++pass) {  // Andrew's monotone chain
    const std::size_t start = hull.size();
    for (const auto& q : points) {
      while (hull.size() >= start + 2 && cross(hull[hull.size() - 2], hull.back(), q) <= 0) hull.pop_back();
      hull.push_back(q);
    }
    hull.pop_back();
    std::reverse(points.begin(), points.end());
  }
  margin = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2d& a = hull[i];
    const Eigen::Vector2d& b = hull[(i + 1) % hull.size()];
    margin = std::min(margin, cross(a, b, p) / (b - a).norm());
  }
  return margin > 0.0;
}

}  // namespace

TEST_CASE("HRP-2: 30 actuated joints in OpenHRP names, 58 kg, 1.54 m tall", "[hrp2]") {
  const RobotModel robot = loadUrdfFile(kDir / "hrp2.urdf");
  CHECK(robot.warnings.empty());
  REQUIRE(robot.jointCount() == 30);
  for (const char* name : {"RLEG_JOINT0", "LLEG_JOINT5", "CHEST_JOINT1", "HEAD_JOINT1", "RARM_JOINT6", "LARM_JOINT6"})
    CHECK(robot.findJoint(name) >= 0);
  CHECK(std::abs(robot.totalMass() - 58.0) <= 0.5);

  const DynamicsModel model(robot, "l_sole");
  DynamicsData data(model);
  forwardKinematics(model, data, Eigen::VectorXd::Zero(30));
  const double height = framePose(model, data, robot.frameIndex("head_top")).translation.z() -
                        framePose(model, data, robot.frameIndex("l_sole")).translation.z();
  CHECK(std::abs(height - 1.54) <= 0.02);
  // Both soles on the ground at the zero posture.
  CHECK(std::abs(framePose(model, data, robot.frameIndex("r_sole")).translation.z()) <= 1e-12);
}

TEST_CASE("HRP-2 half-sitting: static torques within limits, com inside the support polygon", "[hrp2]") {
  const RobotModel robot = loadUrdfFile(kDir / "hrp2.urdf");
  const ActuatorSet actuators = loadActuators(kDir / "actuators.yaml", robot);
  const auto postures = loadPostures(kDir / "postures.yaml", robot);
  const auto surfaces = loadContactSurfaces(kDir / "contacts.yaml", robot);
  const Eigen::VectorXd q = postures.at("half_sitting");
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(robot.jointCount());
  for (const char* sole : {"l_sole", "r_sole"}) {
    INFO("rooted at " << sole);
    const DynamicsModel model(robot, sole);
    DynamicsData data(model);
    inverseDynamics(model, data, q, zero, zero);
    // Rooted at one sole, that leg carries the whole weight: the hardest static case.
    for (int j = 0; j < robot.jointCount(); ++j) {
      INFO(robot.joints[j].name << " " << data.tau[j] << " N m, limit " << actuators.joints[j].torqueLimit);
      CHECK(std::abs(data.tau[j]) <= actuators.joints[j].torqueLimit);
    }
    // Both soles flat on the ground.
    for (const char* foot : {"l_sole", "r_sole"}) {
      const RigidTransform pose = framePose(model, data, robot.frameIndex(foot));
      CHECK(std::abs(pose.translation.z()) <= 1e-9);
      CHECK(pose.rotation.col(2).isApprox(Vector3::UnitZ(), 1e-9));
    }
    std::vector<Eigen::Vector2d> corners;
    for (const ContactSurface& s : surfaces) {
      if (s.name != "l_sole" && s.name != "r_sole") continue;
      const RigidTransform frame = framePose(model, data, s.frame) * s.placement;
      for (double x : {s.xMin, s.xMax})
        for (double y : {s.yMin, s.yMax}) corners.push_back(frame.apply(Vector3(x, y, 0.0)).head<2>());
    }
    double margin = 0.0;
    const Vector3 com = centerOfMass(model, data);
    CHECK(insideConvexHull(corners, com.head<2>(), margin));
    INFO("com " << com.transpose() << ", margin " << margin);
    CHECK(margin > 0.02);
  }
}
