// The multi-contact gradient (formulation.md §8, (4.8)): sampled torques, contact wrenches and
// the energy differentiated w.r.t. the spline parameters and the duration, against central
// differences of the multi-contact dynamic model itself.
#include <catch2/catch.hpp>

#include "common/robots.hpp"
#include "sensitivity/multi_contact_gradient.hpp"

using namespace mcopt;

namespace {

struct Setup {
  RobotModel robot = loadUrdfFile(test::hrp2().urdf);
  ActuatorSet actuators = loadActuators(test::sourceDir() / "robots/hrp2/actuators.yaml", robot);
  std::vector<ContactSurface> surfaces = loadContactSurfaces(test::sourceDir() / "robots/hrp2/contacts.yaml", robot);
  Eigen::VectorXd halfSitting = loadPostures(test::sourceDir() / "robots/hrp2/postures.yaml", robot).at("half_sitting");
  std::vector<ContactSurface> contacts(int count) const {
    std::vector<ContactSurface> chosen;
    for (const char* name : {"l_sole", "r_sole", "r_hand", "l_hand"})
      for (const ContactSurface& s : surfaces)
        if (s.name == name && static_cast<int>(chosen.size()) < count) chosen.push_back(s);
    return chosen;
  }
};

}  // namespace

TEST_CASE("multi-contact torque, wrench and energy gradients match central differences", "[sensitivity][gradient]") {
  Setup hrp2;
  // The dry friction's smooth sign, atan(ν N q̇) with ν N ≈ 2e4, turns over within 5e-5 rad/s
  // of q̇ = 0 — where the still legs sit — and no difference step resolves that; the chain
  // under test does not care, so the sign is made gentle here (ν = 1 s/rad).
  hrp2.actuators.frictionSharpness = 1.0;
  const DynamicsModel model(hrp2.robot, "l_sole");
  const MotionParametrization parametrization(hrp2.robot.jointCount());
  const int samples = 12;
  std::mt19937 rng(401);
  for (int contactCount : {2, 3}) {
    for (KktBackend backend : {KktBackend::Dense, KktBackend::SparseKlu}) {
      SensitivitySettings sensitivity;
      sensitivity.backend = backend;
      const auto contacts = hrp2.contacts(contactCount);
      MultiContactGradientEvaluator gradientEvaluator(model, hrp2.actuators, SampledTrajectory(parametrization, samples),
                                                      contacts, {}, sensitivity);
      MultiContactEvaluator valueEvaluator(model, hrp2.actuators, SampledTrajectory(parametrization, samples), contacts);
      // Half-sitting, the legs still (both soles flat where they stand), the upper body moving.
      Eigen::VectorXd x = parametrization.constantMotion(hrp2.halfSitting);
      const Eigen::VectorXd motion = test::randomVector(rng, parametrization.parameterCount(), 0.2);
      for (int j = 0; j < hrp2.robot.jointCount(); ++j)
        if (hrp2.robot.joints[j].name.rfind("LEG", 1) != 1)
          x.segment(j * parametrization.parametersPerJoint(), parametrization.parametersPerJoint()) +=
              motion.segment(j * parametrization.parametersPerJoint(), parametrization.parametersPerJoint());
      double duration = 1.5;
      MultiContactResult result, moved;
      MultiContactGradient gradient;
      gradientEvaluator.evaluate(x, duration, result, gradient);
      REQUIRE(result.failedSamples == 0);
      REQUIRE(result.infeasibleSamples == 0);
      INFO(contactCount << " contacts, " << toString(backend) << ": " << gradient.degenerateSamples << " degenerate samples");
      // The value side agrees with the plain evaluator.
      valueEvaluator.evaluate(x, duration, moved);
      CHECK((moved.motion.tau - result.motion.tau).cwiseAbs().maxCoeff() <= 1e-9);
      CHECK(moved.motion.energy == Approx(result.motion.energy).epsilon(1e-12));

      // A few parameters of different joints and spline positions, and T.
      const int perJoint = parametrization.parametersPerJoint();
      for (int parameter : {0 * perJoint + 1, 3 * perJoint + 2, 12 * perJoint + 4, 14 * perJoint + 1, 17 * perJoint + 0,
                            28 * perJoint + 3, -1}) {
        INFO("parameter " << parameter << " (−1: T)");
        // Richardson-extrapolated central differences (error O(h⁴)): moving a leg joint under a
        // double support tilts a sole, and the optimal wrenches then change fast (the plain
        // difference still moves by 1e-3 between h = 1e-6 and 1e-7).
        auto evaluateMoved = [&](double delta, MultiContactResult& out) {
          Eigen::VectorXd y = x;
          double T = duration;
          if (parameter < 0)
            T += delta;
          else
            y[parameter] += delta;
          valueEvaluator.evaluate(y, T, out);
        };
        auto centralDifference = [&](double h, Eigen::MatrixXd& dTauOut, Eigen::MatrixXd& dWrenchOut, double& dEnergyOut) {
          MultiContactResult plus, minus;
          evaluateMoved(h, plus);
          evaluateMoved(-h, minus);
          dTauOut = (plus.motion.tau - minus.motion.tau) / (2 * h);
          dWrenchOut = (plus.wrenches - minus.wrenches) / (2 * h);
          dEnergyOut = (plus.motion.energy - minus.motion.energy) / (2 * h);
        };
        Eigen::MatrixXd dTauCoarse, dWrenchCoarse, dTau, dWrench;
        double dEnergyCoarse = 0.0, dEnergy = 0.0;
        centralDifference(2e-5, dTauCoarse, dWrenchCoarse, dEnergyCoarse);
        centralDifference(1e-5, dTau, dWrench, dEnergy);
        dTau = (4.0 * dTau - dTauCoarse) / 3.0;
        dWrench = (4.0 * dWrench - dWrenchCoarse) / 3.0;
        dEnergy = (4.0 * dEnergy - dEnergyCoarse) / 3.0;
        for (int s = 0; s < samples; ++s) {
          const SampleTorqueJacobian& torque = gradient.torqueAndEnergy.torque[static_cast<std::size_t>(s)];
          const SampleWrenchJacobian& wrench = gradient.wrenches[static_cast<std::size_t>(s)];
          Eigen::VectorXd analyticTau = Eigen::VectorXd::Zero(hrp2.robot.jointCount());
          Eigen::VectorXd analyticWrench = Eigen::VectorXd::Zero(6 * contactCount);
          if (parameter < 0) {
            analyticTau = torque.dtauDT;
            analyticWrench = wrench.dFdT;
          } else {
            for (Eigen::Index c = 0; c < torque.parameters.size(); ++c)
              if (torque.parameters[c] == parameter) analyticTau = torque.dtauDx.col(c);
            for (Eigen::Index c = 0; c < wrench.parameters.size(); ++c)
              if (wrench.parameters[c] == parameter) analyticWrench = wrench.dFdx.col(c);
          }
          INFO("sample " << s);
          const double tauScale = 1.0 + dTau.col(s).cwiseAbs().maxCoeff();
          const double wrenchScale = 1.0 + dWrench.col(s).cwiseAbs().maxCoeff();
          CHECK((analyticTau - dTau.col(s)).cwiseAbs().maxCoeff() <= 1e-6 * tauScale);
          CHECK((analyticWrench - dWrench.col(s)).cwiseAbs().maxCoeff() <= 1e-6 * wrenchScale);
        }
        const double analyticEnergy =
            parameter < 0 ? gradient.torqueAndEnergy.energyDT : gradient.torqueAndEnergy.energyGradient[parameter];
        CHECK(analyticEnergy == Approx(dEnergy).epsilon(1e-6).margin(1e-6));
      }
    }
  }
}
