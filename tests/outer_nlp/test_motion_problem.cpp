// SPDX-License-Identifier: BSD-3-Clause
// The outer problem's exact derivatives (formulation.md §10) against central differences:
// objective gradient and every declared Jacobian entry, for both energy forms, fixed and
// free duration, on the bundled kick; the declared pattern holds every non-zero; the
// configuration problem likewise.
#include <catch2/catch.hpp>

#include <limits>
#include <random>

#include "core/spatial.hpp"

#include "common/finite_differences.hpp"
#include "common/nlp_jacobian.hpp"
#include "common/every_task_kind.hpp"
#include "common/test_support.hpp"
#include "outer_nlp/configuration_problem.hpp"
#include "outer_nlp/motion_problem.hpp"

namespace mcopt {

namespace {

/// The exact gradient and Jacobian within `tolerance` of central differences, and nothing off
/// the declared pattern.
void checkDerivatives(NlpProblem& problem, const Eigen::VectorXd& x, double h, double tolerance) {
  const test::DerivativeErrors e = test::derivativeErrors(problem, x, h);
  INFO("gradient error " << e.gradient << ", Jacobian error " << e.jacobian << ", largest difference off the pattern "
                         << e.offPattern);
  CHECK(e.gradient < tolerance);
  CHECK(e.jacobian < tolerance);
  CHECK(e.offPattern < tolerance);
}

Eigen::VectorXd perturbed(const Eigen::VectorXd& x, int count, double size, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> u(-size, size);
  Eigen::VectorXd y = x;
  for (int i = 0; i < count; ++i) y[i] += u(random);
  return y;
}

}  // namespace

TEST_CASE("outer problem: exact gradient and sparse Jacobian agree with central differences", "[outer]") {
  Scenario scenario = loadScenario(test::sourceDir() / "scenarios/hrp2_kick.yaml");
  // The smooth maximum of the kick's first stage; the bundled kick's epigraph form is the last
  // section's. The bundled kick is periodic (end: {same_as: start}); a section takes the free
  // ends. Its exact Hessian refuses a free duration with the epigraph form: the Hessian option
  // does not enter these first derivatives.
  scenario.solve.hessian = HessianOption::SampleDifferences;
  scenario.energyForm = EnergyForm::SmoothMaximum;
  scenario.smoothing = 0.01;
#ifdef MCOPT_UNDER_SANITIZERS
  scenario.samples = 30;  // every kind of row; differences of 150 variables are slow under ASan
#else
  scenario.samples = 100;  // the scenario's own sampling
#endif
  scenario.outputSamples = 20;

  SECTION("smooth maximum, fixed duration") {
    MotionProblem problem(scenario);
    const Eigen::VectorXd x0 = problem.initialPoint(scenario.start, scenario.end);
    checkDerivatives(problem, perturbed(x0, problem.parametrization().parameterCount(), 0.2, 1), 1e-6, 1e-6);
  }
  SECTION("smooth maximum and acceleration regularisation, free duration") {
    scenario.accelerationWeight = 1e-3;
    scenario.duration.lower = 1.0, scenario.duration.upper = 2.5;
    MotionProblem problem(scenario);
    Eigen::VectorXd x0 = problem.initialPoint(scenario.start, scenario.end);
    x0 = perturbed(x0, problem.parametrization().parameterCount(), 0.2, 4);
    x0[problem.parametrization().parameterCount()] = 1.3;
    checkDerivatives(problem, x0, 1e-6, 1e-6);
  }
  SECTION("smooth maximum, free ends (the report's convention)") {
    Scenario free = loadScenario(test::sourceDir() / "scenarios/hrp2_kick_free_ends.yaml");
    free.energyForm = EnergyForm::SmoothMaximum, free.smoothing = 0.01;
    free.samples = scenario.samples, free.outputSamples = 20;
    REQUIRE(!free.periodic);
    MotionProblem problem(free);
    CHECK(problem.parametrization().parametersPerJoint() == free.controlPoints - 4);
    const Eigen::VectorXd x0 = problem.initialPoint(free.start, free.end);
    checkDerivatives(problem, perturbed(x0, problem.parametrization().parameterCount(), 0.2, 1), 1e-6, 1e-6);
  }
  SECTION("smooth maximum, at rest") {
    MotionProblem problem(scenario);
    const Eigen::VectorXd x0 = problem.initialPoint(scenario.start, scenario.end);
    checkDerivatives(problem, x0, 1e-6, 1e-6);
  }
  SECTION("epigraph, free duration") {
    scenario.energyForm = EnergyForm::Epigraph;
    scenario.accelerationWeight = 1e-3;
    scenario.duration.lower = 1.0, scenario.duration.upper = 2.5;
    MotionProblem problem(scenario);
    REQUIRE(problem.durationIsFree());
    Eigen::VectorXd x0 = problem.initialPoint(scenario.start, scenario.end);
    x0 = perturbed(x0, problem.parametrization().parameterCount(), 0.2, 2);
    x0[problem.parametrization().parameterCount()] = 1.9;
    checkDerivatives(problem, x0, 1e-6, 1e-6);
  }
}

TEST_CASE("outer problem: every task kind has exact derivatives", "[outer]") {
  Scenario scenario = loadScenario(test::sourceDir() / "scenarios/hrp2_kick.yaml");
  scenario.solve.hessian = HessianOption::SampleDifferences;  // the exact one refuses the epigraph with a free T
  scenario.samples = 20;
  scenario.duration.lower = 1.0, scenario.duration.upper = 2.5;  // free T: the instants scale with it
  scenario.tasks = test::everyTaskKind(scenario);
  MotionProblem problem(scenario);
  Eigen::VectorXd x0 = problem.initialPoint(scenario.start, scenario.end);
  x0 = perturbed(x0, problem.parametrization().parameterCount(), 0.3, 5);
  x0[problem.parametrization().parameterCount()] = 1.7;
  int taskRows = 0;
  for (int r = 0; r < problem.constraintCount(); ++r) taskRows += problem.rowKind(r) == "task";
  CHECK(taskRows > 5 * 2);
  checkDerivatives(problem, x0, 1e-6, 1e-6);
}

TEST_CASE("configuration problem: static power and rows agree with central differences", "[outer]") {
  const Scenario scenario = loadScenario(test::sourceDir() / "scenarios/hrp2_kick.yaml");
  MotionProblem motion(scenario);
  for (const double instant : {0.0, scenario.duration.initial}) {
    ConfigurationProblem problem(scenario, motion.model(), motion.support(), instant);
    CHECK(problem.constraintCount() == 6 + 2);  // support rows; foot height and side (the window)
    checkDerivatives(problem, perturbed(scenario.start, scenario.robot.jointCount(), 0.2, 3), 1e-6, 1e-6);
  }
}

}  // namespace mcopt
