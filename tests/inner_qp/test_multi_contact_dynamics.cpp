// SPDX-License-Identifier: BSD-3-Clause
// The multi-contact dynamic model (splines → Newton–Euler → inner solve per sample) checked
// by physics that needs no reference: one contact reduces to the one-contact evaluator; the
// chosen wrenches balance the robot; the joint torques do not depend on which foot is the
// reference body (formulation.md §4–§5).
#include <catch2/catch.hpp>

#include "common/robots.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"
#include "inner_qp/multi_contact_dynamics.hpp"

using namespace mcopt;

namespace {

struct Hrp2Setup {
  RobotModel robot = loadUrdfFile(test::hrp2().urdf);
  ActuatorSet actuators = loadActuators(test::sourceDir() / "robots/hrp2/actuators.yaml", robot);
  std::vector<ContactSurface> surfaces = loadContactSurfaces(test::sourceDir() / "robots/hrp2/contacts.yaml", robot);
  Eigen::VectorXd halfSitting = loadPostures(test::sourceDir() / "robots/hrp2/postures.yaml", robot).at("half_sitting");

  std::vector<ContactSurface> contacts(std::initializer_list<const char*> names) const {
    std::vector<ContactSurface> chosen;
    for (const char* name : names)
      for (const ContactSurface& s : surfaces)
        if (s.name == name) chosen.push_back(s);
    return chosen;
  }
  /// Half-sitting with the head and left arm moving (legs, chest and right arm still, so
  /// the feet and the right hand stay where they are).
  Eigen::VectorXd motion(const MotionParametrization& parametrization, std::mt19937& rng) const {
    Eigen::VectorXd x = parametrization.constantMotion(halfSitting);
    std::uniform_real_distribution<double> u(-0.3, 0.3);
    for (int j = 0; j < robot.jointCount(); ++j) {
      const std::string& name = robot.joints[j].name;
      if (name.rfind("HEAD", 0) != 0 && name.rfind("LARM", 0) != 0) continue;
      for (int k = 0; k < parametrization.parametersPerJoint(); ++k) x[j * parametrization.parametersPerJoint() + k] += u(rng);
    }
    return x;
  }
};

}  // namespace

TEST_CASE("with the reference sole alone, the multi-contact model is the one-contact model", "[inner][multicontact]") {
  const Hrp2Setup hrp2;
  const DynamicsModel model(hrp2.robot, "l_sole");
  const MotionParametrization parametrization(hrp2.robot.jointCount());
  std::mt19937 rng(5);
  const Eigen::VectorXd x = hrp2.motion(parametrization, rng);
  MultiContactEvaluator multi(model, hrp2.actuators, SampledTrajectory(parametrization, 50), hrp2.contacts({"l_sole"}));
  TrajectoryEvaluator single(model, hrp2.actuators, SampledTrajectory(parametrization, 50));
  MultiContactResult a;
  TrajectoryResult b;
  multi.evaluate(x, 1.5, a);
  single.evaluate(x, 1.5, b);
  for (int s = 0; s < 50; ++s) {
    INFO("sample " << s);
    // On one foot the arm's swing may push the centre of pressure out of the sole: such a
    // sample is infeasible (an answer, with its slack), never failed.
    REQUIRE(a.status[static_cast<std::size_t>(s)] != InnerStatus::Failed);
    if (a.status[static_cast<std::size_t>(s)] == InnerStatus::Infeasible) CHECK(a.balanceSlack.col(s).norm() > 0.0);
    // The reference sole's own contact moves no joint: Γ = Γ0 whatever its wrench.
    CHECK((a.motion.tau.col(s) - b.tau.col(s)).cwiseAbs().maxCoeff() <= 1e-9 * (1 + b.tau.col(s).cwiseAbs().maxCoeff()));
  }
  CHECK(a.motion.energy == Approx(b.energy).epsilon(1e-9));
}

TEST_CASE("feet and a hand: balanced wrenches, KKT-certified, torques independent of the reference foot",
          "[inner][multicontact][physics]") {
  const Hrp2Setup hrp2;
  const DynamicsModel fromLeft(hrp2.robot, "l_sole");
  const MotionParametrization parametrization(hrp2.robot.jointCount());
  std::mt19937 rng(7);
  const Eigen::VectorXd x = hrp2.motion(parametrization, rng);
  const auto contacts = hrp2.contacts({"l_sole", "r_sole", "r_hand"});
  MultiContactEvaluator evaluator(fromLeft, hrp2.actuators, SampledTrajectory(parametrization, 40), contacts);
  MultiContactResult r;
  evaluator.evaluate(x, 1.5, r);
  DynamicsData left(fromLeft);
  // The legs do not move: the right-rooted model holds the right sole where the left-rooted
  // one puts it.
  inverseDynamics(fromLeft, left, r.motion.q.col(0), r.motion.v.col(0), r.motion.a.col(0));
  const DynamicsModel fromRight(hrp2.robot, "r_sole", framePose(fromLeft, left, hrp2.robot.frameIndex("r_sole")));
  DynamicsData right(fromRight);
  WrenchToTorque block(hrp2.robot.jointCount(), 6);
  for (int s = 0; s < 40; ++s) {
    INFO("sample " << s);
    REQUIRE(r.status[static_cast<std::size_t>(s)] == InnerStatus::Optimal);
    CHECK(r.kktResidual[s] <= 1e-9);
    const auto q = r.motion.q.col(s), v = r.motion.v.col(s), a = r.motion.a.col(s);
    // Balance: the wrenches moved to the world origin add up to what the reference sole needed.
    inverseDynamics(fromLeft, left, q, v, a);
    Vector6 total = Vector6::Zero();
    for (std::size_t i = 0; i < contacts.size(); ++i) {
      const ContactFrame frame = contactFrame(fromLeft, left, contacts[i].frame, contacts[i].placement);
      Matrix6 toWorld;
      wrenchToWorld(frame, toWorld);
      total += toWorld * r.wrenches.col(s).segment<6>(6 * static_cast<Eigen::Index>(i));
    }
    CHECK((total - left.referenceWrench).cwiseAbs().maxCoeff() <= 1e-8 * (1 + left.referenceWrench.cwiseAbs().maxCoeff()));
    // Rooted at the right sole instead, with the same wrenches on the same surfaces (the left
    // sole's now an ordinary contact): Γ = Γ0' − J1' F must be the same torques.
    inverseDynamics(fromRight, right, q, v, a);
    Eigen::VectorXd tau = right.tau;
    for (std::size_t i = 0; i < contacts.size(); ++i) {
      const ContactFrame frame = contactFrame(fromRight, right, contacts[i].frame, contacts[i].placement);
      wrenchToTorque(fromRight, right, frame, block);
      tau -= block * r.wrenches.col(s).segment<6>(6 * static_cast<Eigen::Index>(i));
    }
    CHECK((tau - r.motion.tau.col(s)).cwiseAbs().maxCoeff() <= 1e-8 * (1 + tau.cwiseAbs().maxCoeff()));
  }
  CHECK(r.infeasibleSamples == 0);
  CHECK(r.failedSamples == 0);
}
