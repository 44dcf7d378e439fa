// SPDX-License-Identifier: BSD-3-Clause
// Derivatives through the splines and the energy model against central differences
// (issue 4 acceptance), plus the wrench maps of formulation.md §5 and body motion.
#include <catch2/catch.hpp>

#include "common/finite_differences.hpp"
#include "common/robots.hpp"
#include "core/contact_maps.hpp"
#include "core/dynamics_derivatives.hpp"
#include "core/kinematics.hpp"
#include "core/motion_derivatives.hpp"
#include "core/robot_files.hpp"
#include "core/trajectory_gradient.hpp"

using namespace mcopt;

namespace {

/// A motor with every term of the power model at HRP-2's scale.
ActuatorParameters testMotor() {
  ActuatorParameters m;
  m.gearRatio = 160;
  m.torqueConstant = 0.026;
  m.resistance = 0.58;
  m.rotorInertia = 7e-6;
  m.viscousFriction = 2e-6;
  m.dryFriction = 0.005;
  return m;
}

}  // namespace

TEST_CASE("motor power derivatives match central differences", "[derivatives][energy]") {
  const ActuatorParameters m = testMotor();
  std::mt19937 rng(2);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::VectorXd x = test::randomVector(rng, 3, 3.0);
    const MotorPowerDerivatives d = motorPowerDerivatives(m, 100.0, 10 * x[0], x[1], x[2]);
    const double h = 1e-6;
    auto power = [&](double t, double v, double a) { return motorPower(m, 100.0, t, v, a).power; };
    const Eigen::Vector3d fd((power(10 * x[0] + h, x[1], x[2]) - power(10 * x[0] - h, x[1], x[2])) / (2 * h),
                             (power(10 * x[0], x[1] + h, x[2]) - power(10 * x[0], x[1] - h, x[2])) / (2 * h),
                             (power(10 * x[0], x[1], x[2] + h) - power(10 * x[0], x[1], x[2] - h)) / (2 * h));
    CHECK(test::scaledError(Eigen::Vector3d(d.dTorque, d.dVelocity, d.dAcceleration), fd) <= 1e-6);
  }
}

TEST_CASE("motor power Hessian matches central differences of its derivatives", "[derivatives][energy]") {
  // The exact curvature the gauss-newton Hessian chains (core/actuators.hpp), every entry,
  // at velocities inside the dry friction's steep region (ν Ω ≈ 1) and outside it.
  const ActuatorParameters m = testMotor();
  std::mt19937 rng(5);
  int compared = 0;
  for (const double sharpness : {1.0, 0.01}) {
    for (int trial = 0; trial < 20; ++trial) {
      const Eigen::VectorXd x = test::randomVector(rng, 3, 1.0);
      const Eigen::Vector3d z(10 * x[0], (trial % 2 == 0 ? 0.01 : 1.0) * x[1], x[2]);
      const Eigen::Matrix3d H = motorPowerHessian(m, sharpness, z[0], z[1], z[2]);
      auto gradient = [&](const Eigen::Vector3d& p) {
        const MotorPowerDerivatives d = motorPowerDerivatives(m, sharpness, p[0], p[1], p[2]);
        return Eigen::Vector3d(d.dTorque, d.dVelocity, d.dAcceleration);
      };
      Eigen::Matrix3d fd;
      for (int c = 0; c < 3; ++c) {
        const double h = 1e-5 * (c == 1 ? 0.01 : 1.0);
        Eigen::Vector3d plus = z, minus = z;
        plus[c] += h, minus[c] -= h;
        fd.col(c) = (gradient(plus) - gradient(minus)) / (2 * h);
      }
      CHECK((H - H.transpose()).cwiseAbs().maxCoeff() == 0.0);
      // Entry by entry, relative to the entry (they span 1e-5 to 1e5: a scale-free check).
      const double floor = 1e-9 * fd.cwiseAbs().maxCoeff();
      CHECK(((H - fd).array().abs() / (fd.array().abs() + floor)).maxCoeff() <= 1e-6);
      ++compared;
    }
  }
  CHECK(compared == 40);
}

TEST_CASE("torque Jacobians and the energy gradient w.r.t. spline parameters and duration", "[derivatives][spline]") {
  std::mt19937 rng(31);
  for (const auto& named : test::allRobots()) {
    const RobotModel robot = test::load(named);
    const DynamicsModel model(robot, named.soles[0]);
    ActuatorSet actuators = defaultActuators(robot);
    if (named.name == "hrp2") actuators = loadActuators(test::sourceDir() / "robots/hrp2/actuators.yaml", robot);
    if (named.name != "hrp2") {
      // Make every power term count on the third-party robots too. Dry friction is kept
      // gentle (ν = 1): with ν N = 10⁴ the atan is so steep near q̇ = 0 — which every motion
      // crosses at its rest ends — that no finite-difference step resolves it.
      for (auto& a : actuators.joints) a = ActuatorParameters{100.0, 0.03, 0.3, 1e-5, 2e-6, 0.005};
      actuators.frictionSharpness = 1.0;
    }
    const MotionParametrization parametrization(robot.jointCount());
    const int samples = 12;
    TrajectoryGradientEvaluator evaluator(model, actuators, SampledTrajectory(parametrization, samples));
    TrajectoryEvaluator plain(model, actuators, SampledTrajectory(parametrization, samples));
    Eigen::VectorXd x = test::randomVector(rng, parametrization.parameterCount(), 0.4);
    double T = 1.3;
    TrajectoryResult result, plus, minus;
    TrajectoryGradient gradient;
    evaluator.evaluate(x, T, result, gradient);
    plain.evaluate(x, T, plus);
    CHECK(result.energy == Approx(plus.energy).epsilon(1e-12));

    const double h = 1e-6;
    const int n = robot.jointCount();
    // Every parameter: all sampled torques (central differences, h = 1e-6) and the energy
    // (4th-order differences, h = 1e-5: the energy sums thousands of watts, so a 1e-6 step
    // drowns its difference in round-off).
    double worstEnergy = 0.0, worstTorque = 0.0;
    const double hEnergy = 1e-5;
    TrajectoryResult far1, far2;
    int kinks = 0;
    const double roundOff = 1e-15 * result.energy / hEnergy;
    for (int p = 0; p < parametrization.parameterCount(); ++p) {
      const double saved = x[p];
      x[p] = saved + h;
      plain.evaluate(x, T, plus);
      x[p] = saved - h;
      plain.evaluate(x, T, minus);
      x[p] = saved;
      const Eigen::MatrixXd fdTau = (plus.tau - minus.tau) / (2 * h);
      for (int s = 0; s < samples; ++s) {
        const SampleTorqueJacobian& block = gradient.torque[static_cast<std::size_t>(s)];
        Eigen::VectorXd analytic = Eigen::VectorXd::Zero(n);
        for (Eigen::Index c = 0; c < block.parameters.size(); ++c)
          if (block.parameters[c] == p) analytic += block.dtauDx.col(c);
        worstTorque = std::max(worstTorque, test::scaledError(analytic, fdTau.col(s)));
      }
      x[p] = saved + hEnergy;
      plain.evaluate(x, T, plus);
      x[p] = saved - hEnergy;
      plain.evaluate(x, T, minus);
      x[p] = saved + 2 * hEnergy;
      plain.evaluate(x, T, far1);
      x[p] = saved - 2 * hEnergy;
      plain.evaluate(x, T, far2);
      x[p] = saved;
      // max(P, 0) has no derivative where some P changes sign inside the stencil: skip those.
      const auto signs = [](const TrajectoryResult& r) { return (r.power.array() > 0.0).eval(); };
      if ((signs(far1) != signs(far2)).any() || (signs(plus) != signs(minus)).any()) {
        ++kinks;
        continue;
      }
      const double fdEnergy = (-far1.energy + 8 * plus.energy - 8 * minus.energy + far2.energy) / (12 * hEnergy);
      // Error beyond the difference's own round-off floor (≈ 1e-15 E / h).
      const double excess = std::max(0.0, std::abs(gradient.energyGradient[p] - fdEnergy) - roundOff);
      worstEnergy = std::max(worstEnergy, excess / (1 + std::abs(fdEnergy)));
    }
    // Duration.
    plain.evaluate(x, T + 2 * hEnergy, far1);
    plain.evaluate(x, T - 2 * hEnergy, far2);
    plain.evaluate(x, T + hEnergy, plus);
    plain.evaluate(x, T - hEnergy, minus);
    const double fdEnergyDT = (-far1.energy + 8 * plus.energy - 8 * minus.energy + far2.energy) / (12 * hEnergy);
    plain.evaluate(x, T + h, plus);
    plain.evaluate(x, T - h, minus);
    INFO(named.name << ": energy " << result.energy << " J, worst energy error " << worstEnergy
                    << ", worst torque error " << worstTorque << ", " << kinks << " parameters at a kink");
    CHECK(kinks <= parametrization.parameterCount() / 5);
    CHECK(worstEnergy <= 1e-6);
    CHECK(worstTorque <= 1e-6);
    CHECK(std::max(0.0, std::abs(gradient.energyDT - fdEnergyDT) - roundOff) / (1 + std::abs(fdEnergyDT)) <= 1e-6);
    for (int s = 0; s < samples; ++s)
      CHECK(test::scaledError(gradient.torque[static_cast<std::size_t>(s)].dtauDT,
                              (plus.tau.col(s) - minus.tau.col(s)) / (2 * h)) <= 1e-6);
    CHECK(gradient.energyGradient.cwiseAbs().maxCoeff() > 1e-3);
  }
}

TEST_CASE("wrench maps: J1 is the contact frame Jacobian transposed, derivatives match differences",
          "[derivatives][contacts]") {
  std::mt19937 rng(41);
  const auto hrp2 = test::hrp2();
  const RobotModel robot = test::load(hrp2);
  const auto surfaces = loadContactSurfaces(test::sourceDir() / "robots/hrp2/contacts.yaml", robot);
  const DynamicsModel model(robot, "l_sole");
  DynamicsData data(model);
  const int n = robot.jointCount();
  Eigen::VectorXd q, v, a;
  for (const ContactSurface& surface : surfaces) {
    test::randomState(rng, robot, q, v, a);
    forwardKinematics(model, data, q);
    const ContactFrame contact = contactFrame(model, data, surface.frame, surface.placement);
    Matrix6 toWorld;
    WrenchToTorque toTorque;
    wrenchToWorld(contact, toWorld);
    wrenchToTorque(model, data, contact, toTorque);
    // Independent route: τ = J_Cᵀ (f_world, m_world about C's origin).
    FrameJacobian jacobian;
    frameJacobian(model, data, contact.bodyPosition, contact.contactPose.translation, jacobian);
    const Vector6 wrench = test::randomVector(rng, 6, 50.0);
    Vector6 atContact;
    atContact << contact.contactPose.rotation * wrench.head<3>(), contact.contactPose.rotation * wrench.tail<3>();
    INFO(surface.name);
    CHECK(test::scaledError(toTorque * wrench, jacobian.transpose() * atContact) <= 1e-12);
    CHECK(test::scaledError(toWorld * wrench, wrenchAtOrigin(atContact, contact.contactPose.translation)) <= 1e-12);
    if (surface.name == "l_sole") CHECK(toTorque.cwiseAbs().maxCoeff() == 0.0);  // the reference body's own contact

    Eigen::Matrix<double, 6, Eigen::Dynamic> dWorld;
    Eigen::MatrixXd dTorque;
    wrenchMapDerivatives(model, data, contact, wrench, dWorld, dTorque);
    // Both products with the fixed wrench, stacked: rows 0…n−1 torques, n…n+5 world wrench.
    const Eigen::MatrixXd fd = test::centralDifferences(q, 1e-6, [&] {
      forwardKinematics(model, data, q);
      const ContactFrame moved = contactFrame(model, data, surface.frame, surface.placement);
      Matrix6 w;
      WrenchToTorque t;
      wrenchToWorld(moved, w);
      wrenchToTorque(model, data, moved, t);
      Eigen::VectorXd stacked(n + 6);
      stacked << t * wrench, w * wrench;
      return stacked;
    });
    const Eigen::MatrixXd fdTorque = fd.topRows(n);
    const Eigen::MatrixXd fdWorld = fd.bottomRows(6);
    CHECK(test::scaledError(dTorque, fdTorque) <= 1e-6);
    CHECK(test::scaledError(dWorld, fdWorld) <= 1e-6);

    // The transposed maps with a fixed joint vector g and world multiplier λ (the inner
    // problem's sensitivity needs both).
    const Eigen::VectorXd g = test::randomVector(rng, n, 10.0);
    const Vector6 lambda = test::randomVector(rng, 6, 3.0);
    Eigen::Matrix<double, 6, Eigen::Dynamic> dTorqueT, dWorldT;
    transposedWrenchMapDerivatives(model, data, contact, g, lambda, dTorqueT, dWorldT);
    const Eigen::MatrixXd fdTransposed = test::centralDifferences(q, 1e-6, [&] {
      forwardKinematics(model, data, q);
      const ContactFrame moved = contactFrame(model, data, surface.frame, surface.placement);
      Matrix6 w;
      WrenchToTorque t;
      wrenchToWorld(moved, w);
      wrenchToTorque(model, data, moved, t);
      Eigen::VectorXd stacked(12);
      stacked << t.transpose() * g, w.transpose() * lambda;
      return stacked;
    });
    forwardKinematics(model, data, q);
    CHECK(test::scaledError(dTorqueT, fdTransposed.topRows(6)) <= 1e-6);
    CHECK(test::scaledError(dWorldT, fdTransposed.bottomRows(6)) <= 1e-6);
  }
}

TEST_CASE("body twist and acceleration derivatives match central differences", "[derivatives][kinematics]") {
  std::mt19937 rng(43);
  for (const auto& named : test::allRobots()) {
    const RobotModel robot = test::load(named);
    const DynamicsModel model(robot, named.soles[0]);
    DynamicsData data(model);
    const int n = robot.jointCount();
    const int body = model.framePosition(robot.frameIndex(named.soles[1]));
    Eigen::VectorXd q, v, a;
    test::randomState(rng, robot, q, v, a);
    inverseDynamics(model, data, q, v, a);
    MotionDerivative dVq, dVv, dAq, dAv, dAa;
    bodyMotionDerivatives(model, data, body, dVq, dVv, dAq, dAv, dAa);
    auto motion = [&] {
      inverseDynamics(model, data, q, v, a);
      Eigen::VectorXd out(12);
      out << data.linearVelocity[body], data.angularVelocity[body], data.linearAcceleration[body],
          data.angularAcceleration[body];
      return out;
    };
    for (Eigen::VectorXd* input : {&q, &v, &a}) {
      const Eigen::MatrixXd fd = test::centralDifferences(*input, 1e-6, motion);
      Eigen::Matrix<double, 12, Eigen::Dynamic> analytic(12, n);
      if (input == &q) analytic << dVq, dAq;
      else if (input == &v) analytic << dVv, dAv;
      else analytic << Eigen::MatrixXd::Zero(6, n), dAa;
      INFO(named.name << (input == &q ? " q" : input == &v ? " v" : " a"));
      CHECK(test::scaledError(analytic, fd) <= 1e-6);
    }
  }
}

TEST_CASE("frame Jacobians are the derivatives of frame poses", "[derivatives][kinematics]") {
  std::mt19937 rng(47);
  for (const auto& named : test::allRobots()) {
    const RobotModel robot = test::load(named);
    const DynamicsModel model(robot, named.soles[0]);
    DynamicsData data(model);
    const int frame = robot.frameIndex(named.soles[1]);
    Eigen::VectorXd q, v, a;
    test::randomState(rng, robot, q, v, a);
    forwardKinematics(model, data, q);
    const RigidTransform pose = framePose(model, data, frame);
    FrameJacobian jacobian;
    frameJacobian(model, data, model.framePosition(frame), pose.translation, jacobian);
    const double h = 1e-6;
    FrameJacobian fd(6, robot.jointCount());
    for (int k = 0; k < robot.jointCount(); ++k) {
      RigidTransform side[2];
      for (int s = 0; s < 2; ++s) {
        Eigen::VectorXd qs = q;
        qs[k] += s == 0 ? h : -h;
        forwardKinematics(model, data, qs);
        side[s] = framePose(model, data, frame);
      }
      fd.col(k).head<3>() = (side[0].translation - side[1].translation) / (2 * h);
      // Angular velocity from the rotation difference: R₊ R₋ᵀ ≈ 1 + 2h [ω]×.
      const Matrix3 delta = side[0].rotation * side[1].rotation.transpose();
      fd.col(k).tail<3>() = Vector3(delta(2, 1) - delta(1, 2), delta(0, 2) - delta(2, 0), delta(1, 0) - delta(0, 1)) / (4 * h);
    }
    INFO(named.name);
    CHECK(test::scaledError(jacobian, fd) <= 1e-6);
  }
}

TEST_CASE("the reference wrench through the splines: chain rule against differences", "[derivatives][spline]") {
  std::mt19937 rng(53);
  const auto named = test::hrp2();
  const RobotModel robot = test::load(named);
  const DynamicsModel model(robot, "l_sole");
  DynamicsData data(model);
  DynamicsDerivatives derivatives(model);
  const MotionParametrization parametrization(robot.jointCount());
  const SampledTrajectory samples(parametrization, 9);
  TrajectoryEvaluator plain(model, defaultActuators(robot), samples);
  Eigen::VectorXd x = test::randomVector(rng, parametrization.parameterCount(), 0.4);
  const double T = 0.9, h = 1e-6;
  Eigen::MatrixXd points;
  parametrization.controlPoints(x, points);
  Eigen::VectorXd q(30), v(30), a(30);
  std::vector<Eigen::MatrixXd> blocks;
  std::vector<Eigen::VectorXi> columns;
  for (int s = 0; s < samples.sampleCount(); ++s) {
    samples.evaluate(s, points, T, q, v, a);
    inverseDynamicsDerivatives(model, data, derivatives, q, v, a);
    Eigen::Matrix<double, 6, Eigen::Dynamic> dq, dv, da;
    wrenchDerivativeAtReferenceFrame(model, derivatives.dwrenchDq, dq);
    wrenchDerivativeAtReferenceFrame(model, derivatives.dwrenchDv, dv);
    wrenchDerivativeAtReferenceFrame(model, derivatives.dwrenchDa, da);
    blocks.emplace_back();
    columns.emplace_back();
    samples.chainRule(s, T, dq, dv, da, blocks.back(), columns.back());
  }
  TrajectoryResult plus, minus;
  for (int p = 0; p < parametrization.parameterCount(); ++p) {
    const double saved = x[p];
    x[p] = saved + h;
    plain.evaluate(x, T, plus);
    x[p] = saved - h;
    plain.evaluate(x, T, minus);
    x[p] = saved;
    for (int s = 0; s < samples.sampleCount(); ++s) {
      Vector6 analytic = Vector6::Zero();
      for (Eigen::Index c = 0; c < columns[s].size(); ++c)
        if (columns[s][c] == p) analytic += blocks[s].col(c);
      const Vector6 fd = (plus.referenceWrench.col(s) - minus.referenceWrench.col(s)) / (2 * h);
      INFO("parameter " << p << " sample " << s);
      CHECK(test::scaledError(analytic, fd) <= 1e-6);
    }
  }
}
