// SPDX-License-Identifier: BSD-3-Clause
// The per-sample paths allocate nothing (style.md: "no allocation is enforced, not hoped
// for"). Every heap allocation is counted, not only `new`: malloc, calloc, realloc and the
// aligned allocators are interposed (glibc: an executable's definitions take precedence for
// every library, so libstdc++'s operator new and Eigen's aligned_malloc both land here), so
// a dynamic Eigen matrix resized on a per-sample path is seen. Counted around: one sample's
// dynamics, whole-motion evaluation and gradient, each contact model with 2 to 4 contacts,
// warm and cold inner solves, degenerate samples, and the outer problem's evaluation.
#include <catch2/catch.hpp>
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <new>
#include <execinfo.h>
#include <unistd.h>

#include "common/test_support.hpp"
#include "core/bspline.hpp"
#include "core/dynamics_derivatives.hpp"
#include "core/kinematics.hpp"
#include "core/robot_files.hpp"
#include "core/trajectory_gradient.hpp"
#include "inner_qp/multi_contact_dynamics.hpp"
#include "outer_nlp/motion_problem.hpp"
#include "common/random_inner_problem.hpp"
#include "sensitivity/inner_sensitivity.hpp"
#include "sensitivity/multi_contact_gradient.hpp"
#include "outer_nlp/formulation_registry.hpp"

namespace {
std::atomic<long> allocations{0};
// MCOPT_TRACE_ALLOCATIONS=1 prints a backtrace of every allocation inside a measured region
// (addr2line -f -C -e <this executable> <offset> names the frames): what found the ones fixed.
std::atomic<bool> tracing{false};
thread_local bool inside = false;
void count() {
  allocations.fetch_add(1, std::memory_order_relaxed);
  if (tracing && !inside) {
    inside = true;
    void* frames[12];
    const int n = backtrace(frames, 12);
    backtrace_symbols_fd(frames, n, 2);
    write(2, "----\n", 5);
    inside = false;
  }
}
/// Counts the allocations of what runs between its construction and `count()`.
class Measured {
 public:
  Measured() : before_(allocations.load()) { tracing = std::getenv("MCOPT_TRACE_ALLOCATIONS") != nullptr; }
  long count() {
    tracing = false;
    return allocations.load() - before_;
  }
 private:
  long before_;
};

/// Keeps a probe allocation from being optimised away.
void* volatile probeSink = nullptr;

}  // namespace

extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* pointer, std::size_t size);
void* __libc_memalign(std::size_t alignment, std::size_t size);

void* malloc(std::size_t size) noexcept {
  count();
  return __libc_malloc(size);
}
void* calloc(std::size_t n, std::size_t size) noexcept {
  count();
  return __libc_calloc(n, size);
}
void* realloc(void* pointer, std::size_t size) noexcept {
  count();
  return __libc_realloc(pointer, size);
}
void* aligned_alloc(std::size_t alignment, std::size_t size) noexcept {
  count();
  return __libc_memalign(alignment, size);
}
void* memalign(std::size_t alignment, std::size_t size) noexcept {
  count();
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t size) noexcept {
  count();
  *out = __libc_memalign(alignment, size);
  return *out != nullptr ? 0 : ENOMEM;
}
}

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

  Measured measured;
  for (int s = 0; s < samples.sampleCount(); ++s) {
    samples.evaluate(s, points, 1.5, q, v, a);
    inverseDynamics(model, data, q, v, a);
    inverseDynamicsDerivatives(model, data, derivatives, q, v, a);
    frameJacobian(model, data, model.framePosition(hand), framePose(model, data, hand).translation, jacobian);
  }
  CHECK(measured.count() == 0);
  CHECK(data.tau.allFinite());
  CHECK(derivatives.dtauDq.allFinite());
  // The counter works: a `new` is seen, and so is an Eigen resize (aligned_malloc → malloc).
  Measured probe;
  auto* p = new double[3];
  probeSink = p;
  delete[] p;
  CHECK(probe.count() == 1);
  Measured resize;
  Eigen::MatrixXd grown;
  grown.setZero(7, 9);
  probeSink = grown.data();
  CHECK(resize.count() == 1);
}

TEST_CASE("a one-contact motion's evaluation and exact gradient allocate nothing once sized", "[core][allocation]") {
  const RobotModel robot = loadUrdfFile(test::hrp2().urdf);
  const DynamicsModel model(robot, "r_sole");
  const ActuatorSet actuators = loadActuators(test::sourceDir() / "robots/hrp2/actuators.yaml", robot);
  const MotionParametrization parametrization(robot.jointCount());
  TrajectoryEvaluator evaluator(model, actuators, SampledTrajectory(parametrization, 100));
  TrajectoryGradientEvaluator gradientEvaluator(model, actuators, SampledTrajectory(parametrization, 100));
  std::mt19937 rng(11);
  Eigen::VectorXd x = test::randomVector(rng, parametrization.parameterCount(), 0.3);
  TrajectoryResult result, gradientResult;
  TrajectoryGradient gradient;
  evaluator.evaluate(x, 1.5, result);  // set-up: buffers sized
  gradientEvaluator.evaluate(x, 1.5, gradientResult, gradient);
  x += test::randomVector(rng, x.size(), 0.01);
  Measured measured;
  evaluator.evaluate(x, 1.4, result);
  gradientEvaluator.evaluate(x, 1.4, gradientResult, gradient);
  const long during = measured.count();
  CHECK(during == 0);
  CHECK(std::isfinite(result.energy));
}

namespace {

struct ContactCase {
  std::string model;
  int contacts;  ///< the first 2, 3 or 4 surfaces: soles, then hands
  bool warm;     ///< the active-set method warm-started from the previous sample
};

/// 2–4 contacts × each model × warm and cold (formulation.md §7). A model whose wrench is a
/// force alone (point) is the hands' own, beside wrench-cone soles.
std::vector<ContactCase> contactCases() {
  std::vector<ContactCase> cases;
  for (const std::string& model : contactModelNames()) {
    const bool handsOnly = makeContactModel(model)->wrenchSize() < 6;
    for (const int contacts : {2, 3, 4})
      for (const bool warm : {true, false})
        if (!handsOnly || contacts > 2) cases.push_back({model, contacts, warm});
  }
  return cases;
}

struct HalfSitting {
  RobotModel robot = loadUrdfFile(test::hrp2().urdf);
  DynamicsModel model{robot, "l_sole"};
  std::vector<ContactSurface> surfaces = loadContactSurfaces(test::sourceDir() / "robots/hrp2/contacts.yaml", robot);
  ActuatorSet actuators = loadActuators(test::sourceDir() / "robots/hrp2/actuators.yaml", robot);
  Eigen::VectorXd posture = loadPostures(test::sourceDir() / "robots/hrp2/postures.yaml", robot).at("half_sitting");
  MotionParametrization parametrization{robot.jointCount()};

  std::vector<ContactSurface> first(int count) const {
    // contacts.yaml: r_sole, l_sole, r_hand, l_hand; the hands carry little or nothing
    // at half-sitting (unloaded contacts: the degenerate path of the sensitivity).
    return {surfaces.begin(), surfaces.begin() + count};
  }
  MultiContactSettings settings(const ContactCase& c) const {
    MultiContactSettings s;
    s.problem.model = makeContactModel(c.model);
    if (s.problem.model->wrenchSize() < 6) {
      for (const ContactSurface& hand : first(c.contacts))
        if (hand.name.find("hand") != std::string::npos) s.problem.byContact[hand.name] = s.problem.model;
      s.problem.model = makeContactModel("wrench-cone");
    }
    s.solver.warmStart = c.warm;
    return s;
  }
};

}  // namespace

TEST_CASE("a multi-contact motion (inverse dynamics → inner active-set solve per sample) allocates nothing once warm",
          "[inner][allocation]") {
  const HalfSitting hs;
  for (const ContactCase& c : contactCases()) {
    MultiContactEvaluator evaluator(hs.model, hs.actuators, SampledTrajectory(hs.parametrization, 60), hs.first(c.contacts),
                                    hs.settings(c));
    Eigen::VectorXd x = hs.parametrization.constantMotion(hs.posture);
    MultiContactResult result;
    evaluator.evaluate(x, 1.5, result);  // set-up: buffers sized, warm starts recorded
    std::mt19937 rng(3);
    x += test::randomVector(rng, x.size(), 0.01);
    Measured measured;
    evaluator.evaluate(x, 1.5, result);
    const long during = measured.count();  // read before INFO, which allocates its message
    INFO(c.model << ", " << c.contacts << " contacts, " << (c.warm ? "warm" : "cold"));
    CHECK(during == 0);
    CHECK(result.failedSamples == 0);
  }
}

TEST_CASE("a multi-contact motion's exact gradient (per-sample dense KKT) allocates nothing once warm",
          "[sensitivity][allocation]") {
  const HalfSitting hs;
  for (const ContactCase& c : contactCases()) {
    MultiContactGradientEvaluator evaluator(hs.model, hs.actuators, SampledTrajectory(hs.parametrization, 60),
                                            hs.first(c.contacts), hs.settings(c));
    Eigen::VectorXd x = hs.parametrization.constantMotion(hs.posture);
    MultiContactResult result;
    MultiContactGradient gradient;
    evaluator.evaluate(x, 1.5, result, gradient);  // set-up
    std::mt19937 rng(5);
    x += test::randomVector(rng, x.size(), 0.01);
    Measured measured;
    evaluator.evaluate(x, 1.5, result, gradient);
    const long during = measured.count();
    INFO(c.model << ", " << c.contacts << " contacts, " << (c.warm ? "warm" : "cold"));
    CHECK(during == 0);
    CHECK(gradient.samplesWithoutDerivative == 0);
  }
}

TEST_CASE("a multi-contact motion's gradient through the barrier inner solver allocates nothing once warm",
          "[sensitivity][allocation][barrier]") {
  const HalfSitting hs;
  for (const char* modelName : {"wrench-cone", "pyramid"}) {
    for (const int contacts : {2, 3, 4}) {
      MultiContactSettings settings = hs.settings({modelName, contacts, true});
      settings.solverName = "barrier";
      MultiContactGradientEvaluator evaluator(hs.model, hs.actuators, SampledTrajectory(hs.parametrization, 60),
                                              hs.first(contacts), settings);
      Eigen::VectorXd x = hs.parametrization.constantMotion(hs.posture);
      MultiContactResult result;
      MultiContactGradient gradient;
      evaluator.evaluate(x, 1.5, result, gradient);  // set-up: the first answers come from the exact solver
      std::mt19937 rng(7);
      x += test::randomVector(rng, x.size(), 0.01);
      Measured measured;
      evaluator.evaluate(x, 1.5, result, gradient);  // warm: Newton steps from the previous central points
      const long during = measured.count();
      INFO(modelName << ", " << contacts << " contacts");
      CHECK(during == 0);
      CHECK(result.failedSamples == 0);
      CHECK(gradient.samplesWithoutDerivative == 0);
    }
  }
}

TEST_CASE("a multi-contact motion's gradient with the admissibility-margin row allocates nothing once warm",
          "[sensitivity][allocation][margin]") {
  // inner.feasibility: margin: each sample also solves its margin QP (inner_qp/admissibility_margin.hpp)
  // and differentiates it, warm from its own last working set.
  const HalfSitting hs;
  for (const char* modelName : {"wrench-cone", "pyramid"}) {
    for (const int contacts : {2, 3}) {
      MultiContactSettings settings = hs.settings({modelName, contacts, true});
      settings.feasibility = InnerFeasibility::Margin;
      MultiContactGradientEvaluator evaluator(hs.model, hs.actuators, SampledTrajectory(hs.parametrization, 60),
                                              hs.first(contacts), settings);
      Eigen::VectorXd x = hs.parametrization.constantMotion(hs.posture);
      MultiContactResult result;
      MultiContactGradient gradient;
      evaluator.evaluate(x, 1.5, result, gradient);  // set-up
      std::mt19937 rng(9);
      x += test::randomVector(rng, x.size(), 0.01);
      Measured measured;
      evaluator.evaluate(x, 1.5, result, gradient);
      const long during = measured.count();
      INFO(modelName << ", " << contacts << " contacts");
      CHECK(during == 0);
      CHECK(gradient.samplesWithoutDerivative == 0);
    }
  }
}

TEST_CASE("a multi-contact motion's exact gradient with per-sample KLU allocates nothing while the patterns hold",
          "[sensitivity][allocation]") {
  // KLU keeps each sample's analysis and numeric object (sparse_kkt_factor.hpp): at an
  // iterate whose active sets are those of the last, klu_refactor, klu_condest and klu_solve
  // work in them. (UMFPACK's numeric factorisation makes a new object every time.)
  const HalfSitting hs;
  SensitivitySettings klu;
  klu.backend = KktBackend::SparseKlu;
  for (const int contacts : {2, 3}) {
    MultiContactGradientEvaluator evaluator(hs.model, hs.actuators, SampledTrajectory(hs.parametrization, 60),
                                            hs.first(contacts), {}, klu);
    Eigen::VectorXd x = hs.parametrization.constantMotion(hs.posture);
    MultiContactResult result;
    MultiContactGradient gradient;
    evaluator.evaluate(x, 1.5, result, gradient);  // set-up: patterns analysed
    x *= 1.0 + 1e-7;  // a new iterate, the same active sets
    Measured measured;
    evaluator.evaluate(x, 1.5, result, gradient);
    const long during = measured.count();
    int reused = 0;
    for (const SensitivityDiagnostics& d : gradient.diagnostics) reused += d.analysisReused;
    INFO(contacts << " contacts: " << reused << " of 60 samples reused their analysis");
    REQUIRE(reused == 60);
    CHECK(during == 0);
  }
}

TEST_CASE("the sensitivity of degenerate samples allocates nothing once warm: weakly active rows, near-singular systems",
          "[sensitivity][allocation]") {
  // formulation.md §8: a weakly active row is left out (one-sided derivatives); a
  // near-singular system (here: the Tikhonov term alone curving the balance's null space)
  // takes the rank-revealing least-norm solve. Both after a first solve of the same shape.
  std::mt19937 rng(337);
  auto activeSet = makeActiveSetSolver();
  int weak = 0, singular = 0;
  for (int trial = 0; trial < 40 && (weak < 3 || singular < 3); ++trial) {
    // 6 joints for 24 wrench components: H's rank is at most 6.
    const test::RandomProblem r = test::randomProblem(rng, 4, 6);
    const ContactProblem p = test::assemble(r, "report");
    InnerResult solved;
    activeSet->solve(p, solved);
    if (solved.status != InnerStatus::Optimal) continue;
    for (const bool weaklyActive : {true, false}) {
      ContactProblem q = p;
      InnerResult solution = solved;
      if (weaklyActive) {  // one loaded contact's active row touching the optimum with a zero multiplier
        const auto perContact = static_cast<int>(p.inequality.rows()) / p.contactCount;
        int row = -1;
        for (int a : solution.activeSet)
          if (a < p.inequality.rows() && solution.inequalityMultipliers[a] > 0.0 &&
              solution.wrenches[6 * (a / perContact) + 2] > 1.0)
            row = a;
        if (row < 0) continue;
        solution.inequalityMultipliers[row] = 0.0;
      } else {
        // Without its Tikhonov term, H (rank ≤ 6) leaves most of the balance's and the
        // active rows' null space uncurved: a singular KKT system.
        q.hessian.diagonal().array() -= p.tikhonov;
      }
      InnerSensitivity sensitivity;
      const Eigen::MatrixXd dStationarity = Eigen::MatrixXd::Ones(6 * p.contactCount, 3);
      const Eigen::MatrixXd dBalance = Eigen::MatrixXd::Ones(6, 3);
      Eigen::MatrixXd dWrenches(6 * p.contactCount, 3);
      (void)sensitivity.factorize(q, solution);  // set-up: this shape's buffers
      sensitivity.solve(dStationarity, dBalance, dWrenches);
      Measured measured;
      const SensitivityDiagnostics& d = sensitivity.factorize(q, solution);
      sensitivity.solve(dStationarity, dBalance, dWrenches);
      const long during = measured.count();
      INFO("trial " << trial << ": " << d.describe());
      if (weaklyActive) {
        REQUIRE(d.weaklyActive > 0);
        ++weak;
      } else {
        if (!d.nearSingular()) continue;
        ++singular;
      }
      CHECK(during == 0);
      CHECK(dWrenches.allFinite());
    }
  }
  CHECK(weak >= 3);
  CHECK(singular >= 3);
}

TEST_CASE("the outer problem's evaluation allocates nothing once warm: one contact, each multi-contact formulation, a throw",
          "[outer][allocation]") {
  // What Ipopt calls per iterate: objective, gradient, constraints, Jacobian values, Hessian.
  // Each per-sample Hessian option: the differences, the Gauss–Newton model and the exact
  // Hessian (where it applies). The throw:
  // its rows and the ball's two models (21 samples keep its release on a sample).
  for (const char* file : {"hrp2_kick.yaml", "hrp2_weight_shift.yaml", "hrp2_throw.yaml"})
    for (const std::string& forces : contactForcesNames())
    for (const HessianOption option : {HessianOption::SampleDifferences, HessianOption::GaussNewton, HessianOption::Exact}) {
      Scenario scenario = loadScenario(test::sourceDir() / "scenarios" / file);
      scenario.samples = scenario.ball ? 21 : 20;
      scenario.contactForces = forces;
      scenario.solve.hessian = option;
      if (option == HessianOption::Exact && !exactHessianRefusal(scenario).empty()) continue;  // a throw, bilevel with contacts
      MotionProblem problem(scenario);
      Eigen::VectorXd x = problem.initialPoint(scenario.start, scenario.end), gradient, constraints, jacobian, hessian;
      const Eigen::VectorXd multipliers = Eigen::VectorXd::Constant(problem.constraintCount(), 0.5);
      double objective = 0.0;
      auto evaluateAll = [&] {
        objective = problem.objective(x);
        problem.objectiveGradient(x, gradient);
        problem.constraints(x, constraints);
        problem.jacobianValues(x, jacobian);
        problem.lagrangianHessian(x, 1.0, multipliers, hessian);
      };
      evaluateAll();  // set-up: buffers sized, inner solvers warm
      std::mt19937 rng(9);
      x.head(problem.parametrization().parameterCount()) +=
          test::randomVector(rng, problem.parametrization().parameterCount(), 0.005);
      Measured measured;
      evaluateAll();
      const long during = measured.count();  // read before INFO, which allocates its message
      INFO(file << ", " << forces << ", " << toString(option));
      CHECK(during == 0);
      CHECK(std::isfinite(objective));
    }
}