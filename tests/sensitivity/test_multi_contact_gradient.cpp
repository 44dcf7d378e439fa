// SPDX-License-Identifier: BSD-3-Clause
// The multi-contact gradient (formulation.md §8, (4.8)): sampled torques, contact wrenches and
// the energy differentiated w.r.t. the spline parameters and the duration, against central
// differences of the multi-contact dynamic model itself.
#include <omp.h>

#include <catch2/catch.hpp>

#include "common/robots.hpp"
#include "core/errors.hpp"
#include "core/trajectory_gradient.hpp"
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
  // The active-set solver's exact optima with either backend, and the barrier solver's central
  // points (wrench-cone model: the barrier takes linear models) through their own KKT system.
  struct Variant {
    KktBackend backend;
    const char* solver;
  };
  for (int contactCount : {2, 3, 4}) {
    for (const Variant variant : {Variant{KktBackend::Dense, "active-set"}, Variant{KktBackend::SparseKlu, "active-set"},
                                  Variant{KktBackend::Dense, "barrier"}}) {
      const KktBackend backend = variant.backend;
      SensitivitySettings sensitivity;
      sensitivity.backend = backend;
      MultiContactSettings settings;
      settings.solverName = variant.solver;
      if (settings.solverName == "barrier") settings.problem.model = makeContactModel("wrench-cone");
      const auto contacts = hrp2.contacts(contactCount);
      MultiContactGradientEvaluator gradientEvaluator(model, hrp2.actuators, SampledTrajectory(parametrization, samples),
                                                      contacts, settings, sensitivity);
      MultiContactEvaluator valueEvaluator(model, hrp2.actuators, SampledTrajectory(parametrization, samples), contacts,
                                           settings);
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
      INFO(contactCount << " contacts, " << variant.solver << ", " << toString(backend) << ": " << gradient.degenerateSamples
                        << " degenerate samples");
      // The value side agrees with the plain evaluator.
      valueEvaluator.evaluate(x, duration, moved);
      CHECK((moved.motion.tau - result.motion.tau).cwiseAbs().maxCoeff() <= 1e-9);
      CHECK(moved.motion.energy == Approx(result.motion.energy).epsilon(1e-12));

      // Every spline parameter, and T (−1). Columns where both sides are zero (a joint whose
      // spline does not reach the sample: local support) are not counted as compared.
      int compared = 0;
      for (int parameter = -1; parameter < parametrization.parameterCount(); ++parameter) {
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
          compared += analyticTau.cwiseAbs().maxCoeff() > 1e-12 || dTau.col(s).cwiseAbs().maxCoeff() > 1e-12;
        }
        const double analyticEnergy =
            parameter < 0 ? gradient.torqueAndEnergy.energyDT : gradient.torqueAndEnergy.energyGradient[parameter];
        CHECK(analyticEnergy == Approx(dEnergy).epsilon(1e-6).margin(1e-6));
      }
      // 151 columns × 12 samples; with the cubic B-spline's local support each parameter
      // reaches about half the samples (9 control points).
      CHECK(compared >= 151 * samples / 3);
    }
  }
}

#ifdef MCOPT_SHARED_DIR
TEST_CASE("multi-contact gradients on the ../shared robots match central differences", "[sensitivity][gradient][shared]") {
  // Both soles in contact (a rectangle about each sole frame), generic motors, a motion moving
  // every joint a little. Samples that are not optimal or degenerate (one-sided derivatives)
  // are reported, not compared; the energy is compared when every sample has a derivative.
  // Every parameter is compared.
  std::mt19937 rng(409);
  for (const auto& named : test::sharedRobots()) {
    const RobotModel robot = test::load(named);
    const DynamicsModel model(robot, named.soles[0]);
    ActuatorSet actuators = defaultActuators(robot);
    for (ActuatorParameters& m : actuators.joints)
      m.gearRatio = 100.0, m.torqueConstant = 0.1, m.resistance = 1.0, m.rotorInertia = 1e-5, m.viscousFriction = 1e-4,
      m.dryFriction = 0.0;
    std::vector<ContactSurface> contacts;
    for (const std::string& sole : named.soles) {
      ContactSurface s;
      s.name = sole;
      s.frame = robot.frameIndex(sole);
      s.xMin = -0.08, s.xMax = 0.1, s.yMin = -0.05, s.yMax = 0.05, s.friction = 0.8;
      contacts.push_back(s);
    }
    const MotionParametrization parametrization(robot.jointCount());
    const int samples = 8;
    MultiContactGradientEvaluator gradientEvaluator(model, actuators, SampledTrajectory(parametrization, samples), contacts);
    MultiContactEvaluator valueEvaluator(model, actuators, SampledTrajectory(parametrization, samples), contacts);
    const Eigen::VectorXd x = test::randomVector(rng, parametrization.parameterCount(), 0.05);
    MultiContactResult result;
    MultiContactGradient gradient;
    gradientEvaluator.evaluate(x, 1.2, result, gradient);
    int compared = 0, energyCompared = 0;
    const bool everySampleDifferentiable = gradient.samplesWithoutDerivative == 0 && gradient.degenerateSamples == 0;
    for (int parameter = 0; parameter < parametrization.parameterCount(); ++parameter) {
      auto difference = [&](double h, MultiContactResult& plus, MultiContactResult& minus) {
        Eigen::VectorXd y = x;
        y[parameter] += h;
        valueEvaluator.evaluate(y, 1.2, plus);
        y[parameter] = x[parameter] - h;
        valueEvaluator.evaluate(y, 1.2, minus);
      };
      MultiContactResult plus, minus, plus2, minus2;
      difference(1e-5, plus, minus);
      difference(2e-5, plus2, minus2);
      const Eigen::MatrixXd dTau = (4.0 * (plus.motion.tau - minus.motion.tau) / 2e-5 -
                                    (plus2.motion.tau - minus2.motion.tau) / 4e-5) / 3.0;
      bool allOptimal = true;
      for (const auto* run : {&plus, &minus, &plus2, &minus2}) allOptimal = allOptimal && run->infeasibleSamples == 0 && run->failedSamples == 0;
      if (everySampleDifferentiable && allOptimal) {
        // The energy is compared when every sample has a derivative (formulation.md §8).
        const double dEnergy = (4.0 * (plus.motion.energy - minus.motion.energy) / 2e-5 -
                                (plus2.motion.energy - minus2.motion.energy) / 4e-5) / 3.0;
        INFO(named.name << ", parameter " << parameter << ": energy");
        CHECK(gradient.torqueAndEnergy.energyGradient[parameter] == Approx(dEnergy).epsilon(1e-5).margin(1e-6));
        ++energyCompared;
      }
      for (int s = 0; s < samples; ++s) {
        const auto k = static_cast<std::size_t>(s);
        const bool usable = result.status[k] == InnerStatus::Optimal && !gradient.diagnostics[k].degenerate() &&
                            plus.status[k] == InnerStatus::Optimal && minus.status[k] == InnerStatus::Optimal &&
                            plus2.status[k] == InnerStatus::Optimal && minus2.status[k] == InnerStatus::Optimal;
        if (!usable) continue;
        const SampleTorqueJacobian& torque = gradient.torqueAndEnergy.torque[k];
        Eigen::VectorXd analytic = Eigen::VectorXd::Zero(robot.jointCount());
        for (Eigen::Index c = 0; c < torque.parameters.size(); ++c)
          if (torque.parameters[c] == parameter) analytic = torque.dtauDx.col(c);
        INFO(named.name << ", parameter " << parameter << ", sample " << s << ": " << gradient.diagnostics[k].describe());
        CHECK((analytic - dTau.col(s)).cwiseAbs().maxCoeff() <= 1e-6 * (1.0 + dTau.col(s).cwiseAbs().maxCoeff()));
        // Structural zeros (the parameter's spline does not reach the sample) are not counted.
        compared += analytic.cwiseAbs().maxCoeff() > 1e-12 || dTau.col(s).cwiseAbs().maxCoeff() > 1e-12;
      }
    }
    WARN(named.name << ": " << compared << " non-zero sample torque columns compared over all "
                    << parametrization.parameterCount() << " parameters, energy on " << energyCompared << "; "
                    << result.infeasibleSamples << " infeasible, " << gradient.degenerateSamples << " degenerate samples");
    // At least a quarter of parameter × sample pairs (local support reaches about half).
    CHECK(compared >= parametrization.parameterCount() * samples / 4);
    if (everySampleDifferentiable) CHECK(energyCompared >= parametrization.parameterCount() / 2);
  }
}
#endif

TEST_CASE("the all-samples block-diagonal factorisation gives the per-sample gradients", "[sensitivity][gradient]") {
  const Setup hrp2;
  const DynamicsModel model(hrp2.robot, "l_sole");
  const MotionParametrization parametrization(hrp2.robot.jointCount());
  std::mt19937 rng(419);
  const Eigen::VectorXd x = parametrization.constantMotion(hrp2.halfSitting) +
                            0.01 * test::randomVector(rng, parametrization.parameterCount(), 1.0);
  MultiContactResult result;
  MultiContactGradient reference;
  MultiContactGradientEvaluator(model, hrp2.actuators, SampledTrajectory(parametrization, 20), hrp2.contacts(3))
      .evaluate(x, 1.4, result, reference);
  REQUIRE(result.failedSamples == 0);
  for (KktBackend backend : {KktBackend::SparseKlu, KktBackend::SparseUmfpack}) {
    SensitivitySettings settings;
    settings.backend = backend;
    settings.layout = KktLayout::AllSamples;
    MultiContactGradient gradient;
    MultiContactGradientEvaluator(model, hrp2.actuators, SampledTrajectory(parametrization, 20), hrp2.contacts(3), {},
                                  settings)
        .evaluate(x, 1.4, result, gradient);
    INFO(toString(backend));
    const Eigen::VectorXd& e0 = reference.torqueAndEnergy.energyGradient;
    CHECK((gradient.torqueAndEnergy.energyGradient - e0).cwiseAbs().maxCoeff() <= 1e-9 * (1.0 + e0.cwiseAbs().maxCoeff()));
    for (std::size_t s = 0; s < 20; ++s) {
      const Eigen::MatrixXd& a = reference.wrenches[s].dFdx;
      CHECK((gradient.wrenches[s].dFdx - a).cwiseAbs().maxCoeff() <= 1e-9 * (1.0 + a.cwiseAbs().maxCoeff()));
    }
  }
  SensitivitySettings dense;
  dense.layout = KktLayout::AllSamples;
  CHECK_THROWS_AS(MultiContactGradientEvaluator(model, hrp2.actuators, SampledTrajectory(parametrization, 20),
                                                hrp2.contacts(3), {}, dense),
                  InputError);
}

TEST_CASE("per-sample KLU and UMFPACK keep each pattern's analysis along the iterates and agree with dense to 1e-9",
          "[sensitivity][gradient]") {
  // What an outer optimisation does: the same samples at nearby iterates, the active sets
  // mostly unchanged, so each sample's symbolic analysis is reused and only the numeric
  // factorisation (KLU: on the kept pivot order while its pivot growth holds) is redone.
  Setup hrp2;
  const DynamicsModel model(hrp2.robot, "l_sole");
  const MotionParametrization parametrization(hrp2.robot.jointCount());
  std::mt19937 rng(421);
  const Eigen::VectorXd start = parametrization.constantMotion(hrp2.halfSitting) +
                                0.01 * test::randomVector(rng, parametrization.parameterCount(), 1.0);
  const Eigen::VectorXd step = 0.002 * test::randomVector(rng, parametrization.parameterCount(), 1.0);
  for (KktBackend backend : {KktBackend::SparseKlu, KktBackend::SparseUmfpack}) {
    SensitivitySettings settings;
    settings.backend = backend;
    MultiContactGradientEvaluator denseEvaluator(model, hrp2.actuators, SampledTrajectory(parametrization, 20), hrp2.contacts(3));
    MultiContactGradientEvaluator sparseEvaluator(model, hrp2.actuators, SampledTrajectory(parametrization, 20),
                                                  hrp2.contacts(3), {}, settings);
    int reused = 0, solvedByBackend = 0;
    for (int iterate = 0; iterate < 4; ++iterate) {
      const Eigen::VectorXd x = start + iterate * step;
      MultiContactResult denseResult, sparseResult;
      MultiContactGradient reference, gradient;
      denseEvaluator.evaluate(x, 1.4, denseResult, reference);
      sparseEvaluator.evaluate(x, 1.4, sparseResult, gradient);
      REQUIRE(sparseResult.failedSamples == 0);
      INFO(toString(backend) << ", iterate " << iterate);
      const Eigen::VectorXd& e0 = reference.torqueAndEnergy.energyGradient;
      CHECK((gradient.torqueAndEnergy.energyGradient - e0).cwiseAbs().maxCoeff() <= 1e-9 * (1.0 + e0.cwiseAbs().maxCoeff()));
      for (std::size_t s = 0; s < 20; ++s) {
        const Eigen::MatrixXd& a = reference.wrenches[s].dFdx;
        CHECK((gradient.wrenches[s].dFdx - a).cwiseAbs().maxCoeff() <= 1e-9 * (1.0 + a.cwiseAbs().maxCoeff()));
        if (iterate > 0) reused += gradient.diagnostics[s].analysisReused;
        solvedByBackend += gradient.diagnostics[s].backend == backend;
      }
    }
    INFO(toString(backend) << ": " << reused << " of 60 later factorisations reused their analysis");
    CHECK(reused >= 45);  // the active sets hold at most samples from one small step to the next
    CHECK(solvedByBackend >= 70);  // of 80: near-singular samples alone go to the dense least-norm solve
  }
}

TEST_CASE("the multi-contact evaluators and the trajectory gradient give the same bits with 1 and 2 threads",
          "[sensitivity][gradient][determinism]") {
  // One rule for every loop over the samples (core/sample_chunks.hpp): fixed chunks decide the
  // warm starts and the order of the energy gradient's sums, not the thread count. 21 samples:
  // three chunks, the last one short. Two evaluations each: the first warm-starts from the
  // predecessors, the second from each sample's own answer at a moved motion.
  Setup hrp2;
  const DynamicsModel model(hrp2.robot, "l_sole");
  const MotionParametrization parametrization(hrp2.robot.jointCount());
  std::mt19937 rng(431);
  const Eigen::VectorXd x0 = parametrization.constantMotion(hrp2.halfSitting) +
                             0.01 * test::randomVector(rng, parametrization.parameterCount(), 1.0);
  const Eigen::VectorXd x1 = x0 + 0.003 * test::randomVector(rng, parametrization.parameterCount(), 1.0);
  struct Outcome {
    Eigen::MatrixXd tau, wrenches, gradientTau, oneContactTau;
    Eigen::VectorXd energyGradient, oneContactGradient;
    double energy = 0.0, energyDT = 0.0, oneContactDT = 0.0;
  };
  const int before = omp_get_max_threads();
  auto run = [&](int threads) {
    omp_set_num_threads(threads);
    Outcome o;
    MultiContactEvaluator values(model, hrp2.actuators, SampledTrajectory(parametrization, 21), hrp2.contacts(3));
    MultiContactGradientEvaluator gradients(model, hrp2.actuators, SampledTrajectory(parametrization, 21), hrp2.contacts(3));
    TrajectoryGradientEvaluator oneContact(model, hrp2.actuators, SampledTrajectory(parametrization, 21));
    MultiContactResult r, g;
    MultiContactGradient gradient;
    TrajectoryResult one;
    TrajectoryGradient oneGradient;
    for (const Eigen::VectorXd* x : {&x0, &x1}) {
      values.evaluate(*x, 1.4, r);
      gradients.evaluate(*x, 1.4, g, gradient);
      oneContact.evaluate(*x, 1.4, one, oneGradient);
    }
    o.tau = r.motion.tau, o.wrenches = r.wrenches, o.energy = r.motion.energy;
    o.gradientTau = g.motion.tau, o.energyGradient = gradient.torqueAndEnergy.energyGradient;
    o.energyDT = gradient.torqueAndEnergy.energyDT;
    o.oneContactTau = one.tau, o.oneContactGradient = oneGradient.energyGradient, o.oneContactDT = oneGradient.energyDT;
    return o;
  };
  const Outcome one = run(1), two = run(2);
  omp_set_num_threads(before);
  CHECK(one.tau == two.tau);
  CHECK(one.wrenches == two.wrenches);
  CHECK(one.energy == two.energy);
  CHECK(one.gradientTau == two.gradientTau);
  CHECK(one.energyGradient == two.energyGradient);
  CHECK(one.energyDT == two.energyDT);
  CHECK(one.oneContactTau == two.oneContactTau);
  CHECK(one.oneContactGradient == two.oneContactGradient);
  CHECK(one.oneContactDT == two.oneContactDT);
}
