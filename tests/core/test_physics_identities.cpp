// SPDX-License-Identifier: BSD-3-Clause
// Physics checks that need no reference (docs/developers/index.md "gold" checks), on every robot:
// power balance, invariance under a change of reference body, gravity torques equal to
// Jacobian-transposed weights, and W0 as the total external wrench in statics.
#include <catch2/catch.hpp>

#include "common/robots.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"

using namespace mcopt;

namespace {

/// Kinetic and potential energy of the whole robot from the body poses and twists.
double mechanicalEnergy(const DynamicsModel& model, const DynamicsData& d) {
  double energy = 0.0;
  for (int i = 0; i < model.bodyCount(); ++i) {
    const BodyInertia& inertia = model.inertias()[i];
    const Vector3 comVelocity = d.linearVelocity[i] + d.angularVelocity[i].cross(d.comPosition[i]);
    const Vector3 wLocal = d.rotation[i].transpose() * d.angularVelocity[i];
    energy += 0.5 * inertia.mass * comVelocity.squaredNorm() + 0.5 * wLocal.dot(inertia.inertiaAboutCom * wLocal);
    energy -= inertia.mass * model.gravity().dot(d.comPosition[i]);
  }
  return energy;
}

}  // namespace

TEST_CASE("power balance: sum of joint powers equals d(kinetic + potential)/dt", "[dynamics][physics]") {
  std::mt19937 rng(7);
  for (const auto& named : test::allRobots()) {
    const RobotModel robot = test::load(named);
    const DynamicsModel model(robot, named.soles[0]);
    DynamicsData data(model);
    for (int trial = 0; trial < 5; ++trial) {
      Eigen::VectorXd q0, v0, a0;
      test::randomState(rng, robot, q0, v0, a0);
      // Along q(t) = q0 + v0 t + a0 t²/2 the energy rate at t = 0 by a 5-point stencil.
      auto energyAt = [&](double t) {
        const Eigen::VectorXd q = q0 + v0 * t + 0.5 * a0 * t * t, v = v0 + a0 * t;
        inverseDynamics(model, data, q, v, a0);
        return mechanicalEnergy(model, data);
      };
      const double h = 1e-3;
      const double rate = (-energyAt(2 * h) + 8 * energyAt(h) - 8 * energyAt(-h) + energyAt(-2 * h)) / (12 * h);
      inverseDynamics(model, data, q0, v0, a0);
      const double jointPower = data.tau.dot(v0);
      const double scale = (data.tau.cwiseProduct(v0)).cwiseAbs().sum() + 1.0;
      INFO(named.name << " trial " << trial << ": joint power " << jointPower << ", energy rate " << rate);
      CHECK(std::abs(jointPower - rate) <= 1e-9 * scale);
    }
  }
}

TEST_CASE("torques are unchanged when the reference body changes with the load moved consistently",
          "[dynamics][physics]") {
  // Root the same motion at sole A, then at sole B (moving as it moves in the A-rooted
  // motion). In the A-rooted tree, let the environment apply at B the wrench W_B that the
  // B-rooted computation puts there: A is then unloaded and the torques must be those of
  // the B-rooted computation, τ_B = τ_A − J_Bᵀ W_B (formulation.md §5, Γ = Γ0 − J1 Fc).
  std::mt19937 rng(11);
  for (const auto& named : test::allRobots()) {
    const RobotModel robot = test::load(named);
    const DynamicsModel atA(robot, named.soles[0]);
    DynamicsData a(atA);
    Eigen::VectorXd q, v, acc;
    FrameJacobian jacobianB;
    for (int trial = 0; trial < 5; ++trial) {
      test::randomState(rng, robot, q, v, acc);
      inverseDynamics(atA, a, q, v, acc);
      const int frameB = robot.frameIndex(named.soles[1]);
      const int positionB = atA.framePosition(frameB);
      const DynamicsModel atB(robot, named.soles[1], framePose(atA, a, frameB), atA.gravity());
      DynamicsData b(atB);
      b.rootTwist << a.linearVelocity[positionB], a.angularVelocity[positionB];
      b.rootAcceleration << a.linearAcceleration[positionB] + atA.gravity(), a.angularAcceleration[positionB];
      inverseDynamics(atB, b, q, v, acc);
      // Wrench at the world origin against the spatial Jacobian at the world origin.
      frameJacobian(atA, a, positionB, Vector3::Zero(), jacobianB);
      const Eigen::VectorXd moved = a.tau - jacobianB.transpose() * b.referenceWrench;
      INFO(named.name << " trial " << trial);
      CHECK(test::scaledError(b.tau, moved) <= 1e-9);
      // Both roots carry the whole external wrench of the same motion.
      CHECK(test::scaledError(b.referenceWrench, a.referenceWrench) <= 1e-9);
      // And the torques really differ: the check is not vacuous.
      CHECK(test::scaledError(b.tau, a.tau) > 1e-3);
    }
  }
}

TEST_CASE("gravity torques equal Jacobian-transposed weights", "[dynamics][physics]") {
  std::mt19937 rng(13);
  for (const auto& named : test::allRobots()) {
    const RobotModel robot = test::load(named);
    const DynamicsModel model(robot, named.soles[1]);
    DynamicsData data(model);
    Eigen::VectorXd q, v, a;
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(robot.jointCount());
    Eigen::Matrix3Xd comJacobian;
    for (int trial = 0; trial < 5; ++trial) {
      test::randomState(rng, robot, q, v, a);
      inverseDynamics(model, data, q, zero, zero);
      centerOfMassJacobian(model, data, comJacobian);
      const double mass = robot.totalMass();
      // Holding still: τ = J_comᵀ (−M g); W0 carries the weight at the com.
      const Eigen::VectorXd expected = -mass * comJacobian.transpose() * model.gravity();
      INFO(named.name << " trial " << trial);
      CHECK(test::scaledError(data.tau, expected) <= 1e-9);
      Vector6 weight;
      weight << -mass * model.gravity(), centerOfMass(model, data).cross(-mass * model.gravity());
      CHECK(test::scaledError(data.referenceWrench, weight) <= 1e-9);
    }
  }
}

TEST_CASE("a massless chain and a single link give zero torques", "[dynamics]") {
  const RobotModel robot = loadUrdfString(R"(<robot name="r">
    <link name="base"><inertial><mass value="2"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
    <link name="a"/><link name="b"/>
    <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
    <joint name="j2" type="prismatic"><parent link="a"/><child link="b"/><origin xyz="0 0 0.3"/><axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  </robot>)", "inline");
  const DynamicsModel model(robot, "base");
  DynamicsData data(model);
  inverseDynamics(model, data, Eigen::Vector2d(0.3, 0.1), Eigen::Vector2d(1.0, -2.0), Eigen::Vector2d(3.0, 4.0));
  CHECK(data.tau.cwiseAbs().maxCoeff() == 0.0);
  CHECK(data.referenceWrench[2] == Approx(2 * 9.81));
}
