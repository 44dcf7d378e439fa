// The per-sample path allocates nothing (style.md: "no allocation is enforced, not
// hoped for"): global operator new is counted around one full sample evaluation, and
// around a whole multi-contact motion once its buffers and warm starts exist.
#include <catch2/catch.hpp>
#include <atomic>
#include <cstdlib>
#include <new>

#include "common/test_support.hpp"
#include "core/bspline.hpp"
#include "core/dynamics_derivatives.hpp"
#include "core/kinematics.hpp"
#include "core/robot_files.hpp"
#include "inner_qp/multi_contact_dynamics.hpp"
#include "outer_nlp/motion_problem.hpp"
#include "sensitivity/multi_contact_gradient.hpp"

namespace {
std::atomic<long> allocations{0};
}

namespace {
void* countedAllocation(std::size_t size) {
  ++allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
}  // namespace

void* operator new(std::size_t size) { return countedAllocation(size); }
void* operator new[](std::size_t size) { return countedAllocation(size); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

using namespace mcopt;

TEST_CASE("one sample (spline → inverse dynamics and its derivatives → Jacobian) allocates nothing", "[dynamics][allocation]") {
  const RobotModel robot = loadUrdfFile(test::hrp2().urdf);
  const DynamicsModel model(robot, "l_sole");
  DynamicsData data(model);
  DynamicsDerivatives derivatives(model);
  const MotionParametrization parametrization(robot.jointCount());
  const SampledTrajectory samples(parametrization, 100);
  std::mt19937 rng(1);
  Eigen::MatrixXd points;
  parametrization.controlPoints(test::randomVector(rng, parametrization.parameterCount(), 0.5), points);
  Eigen::VectorXd q(robot.jointCount()), v(robot.jointCount()), a(robot.jointCount());
  FrameJacobian jacobian(6, robot.jointCount());
  const int hand = robot.frameIndex("r_palm");

  const long before = allocations.load();
  for (int s = 0; s < samples.sampleCount(); ++s) {
    samples.evaluate(s, points, 1.5, q, v, a);
    inverseDynamics(model, data, q, v, a);
    inverseDynamicsDerivatives(model, data, derivatives, q, v, a);
    frameJacobian(model, data, model.framePosition(hand), framePose(model, data, hand).translation, jacobian);
  }
  CHECK(allocations.load() - before == 0);
  CHECK(data.tau.allFinite());
  CHECK(derivatives.dtauDq.allFinite());
  // The counter works: an allocation is seen.
  const long probe = allocations.load();
  auto* p = new double[3];
  delete[] p;
  CHECK(allocations.load() - probe == 1);
}

TEST_CASE("a multi-contact motion (inverse dynamics → inner active-set solve per sample) allocates nothing once warm",
          "[inner][allocation]") {
  const RobotModel robot = loadUrdfFile(test::hrp2().urdf);
  const DynamicsModel model(robot, "l_sole");
  const auto surfaces = loadContactSurfaces(test::sourceDir() / "robots/hrp2/contacts.yaml", robot);
  const Eigen::VectorXd halfSitting = loadPostures(test::sourceDir() / "robots/hrp2/postures.yaml", robot).at("half_sitting");
  const MotionParametrization parametrization(robot.jointCount());
  MultiContactEvaluator evaluator(model, loadActuators(test::sourceDir() / "robots/hrp2/actuators.yaml", robot),
                                  SampledTrajectory(parametrization, 100), {surfaces[0], surfaces[1], surfaces[2]});
  Eigen::VectorXd x = parametrization.constantMotion(halfSitting);
  MultiContactResult result;
  evaluator.evaluate(x, 1.5, result);  // set-up: buffers sized, warm starts recorded
  std::mt19937 rng(3);
  x += test::randomVector(rng, x.size(), 0.01);
  const long before = allocations.load();
  evaluator.evaluate(x, 1.5, result);
  const long during = allocations.load() - before;
  CHECK(during == 0);
  CHECK(result.failedSamples == 0);
}

TEST_CASE("a multi-contact motion's exact gradient (per-sample dense KKT) allocates nothing once warm",
          "[sensitivity][allocation]") {
  const RobotModel robot = loadUrdfFile(test::hrp2().urdf);
  const DynamicsModel model(robot, "l_sole");
  const auto surfaces = loadContactSurfaces(test::sourceDir() / "robots/hrp2/contacts.yaml", robot);
  const Eigen::VectorXd halfSitting = loadPostures(test::sourceDir() / "robots/hrp2/postures.yaml", robot).at("half_sitting");
  const MotionParametrization parametrization(robot.jointCount());
  MultiContactGradientEvaluator evaluator(model, loadActuators(test::sourceDir() / "robots/hrp2/actuators.yaml", robot),
                                          SampledTrajectory(parametrization, 100), {surfaces[0], surfaces[1], surfaces[2]});
  Eigen::VectorXd x = parametrization.constantMotion(halfSitting);
  MultiContactResult result;
  MultiContactGradient gradient;
  evaluator.evaluate(x, 1.5, result, gradient);  // set-up
  std::mt19937 rng(5);
  x += test::randomVector(rng, x.size(), 0.01);
  const long before = allocations.load();
  evaluator.evaluate(x, 1.5, result, gradient);
  CHECK(allocations.load() - before == 0);
  CHECK(gradient.samplesWithoutDerivative == 0);
}

TEST_CASE("the outer problem's evaluation allocates nothing once warm: one contact and each multi-contact formulation",
          "[outer][allocation]") {
  // What Ipopt calls per iterate: objective, gradient, constraints, Jacobian values, Hessian.
  for (const char* file : {"hrp2_kick.yaml", "hrp2_weight_shift.yaml"})
    for (const ContactForces forces : {ContactForces::Bilevel, ContactForces::Splines, ContactForces::Variables}) {
      Scenario scenario = loadScenario(test::sourceDir() / "scenarios" / file);
      scenario.samples = 20;
      scenario.contactForces = forces;
      MotionProblem problem(scenario);
      Eigen::VectorXd x = problem.initialPoint(scenario.start, scenario.end), gradient, constraints, jacobian, hessian;
      const Eigen::VectorXd multipliers = Eigen::VectorXd::Constant(problem.constraintCount(), 0.5);
      double objective = 0.0;
      auto evaluateAll = [&] {
        objective = problem.objective(x);
        problem.objectiveGradient(x, gradient);
        problem.constraints(x, constraints);
        problem.jacobianValues(x, jacobian);
        problem.lagrangianHessian(x, 1.0, multipliers, hessian);  // the sample-differences Hessian
      };
      evaluateAll();  // set-up: buffers sized, inner solvers warm
      std::mt19937 rng(9);
      x.head(problem.parametrization().parameterCount()) +=
          test::randomVector(rng, problem.parametrization().parameterCount(), 0.005);
      const long before = allocations.load();
      evaluateAll();
      const long during = allocations.load() - before;  // read before INFO, which allocates its message
      INFO(file << ", " << toString(forces));
      CHECK(during == 0);
      CHECK(std::isfinite(objective));
    }
}