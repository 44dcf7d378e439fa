// Inner/<solver>/<contact-model>/<contacts>: one inner solve, cycling through the 100
// samples of an HRP-2 motion in order (each warm-started from the previous sample, as in
// use; "active-set-cold" without). BilevelDynamics/<n>Contacts100/hrp2: the report's
// Figure 5.2 "dynamic model", a whole motion (splines → Newton–Euler → inner solve at every
// sample → torques, power, energy), N = 100. Threads: OMP_NUM_THREADS (the figure is
// for one: OMP_NUM_THREADS=1).
#include <benchmark/benchmark.h>

#include "bench/bench_fixture.hpp"
#include "core/robot_files.hpp"
#include "inner_qp/multi_contact_dynamics.hpp"

namespace mcopt::bench {

namespace {

const std::filesystem::path kHrp2 = std::filesystem::path(MCOPT_SOURCE_DIR) / "robots/hrp2";

/// HRP-2 in half-sitting on both soles, the right hand (and, for four contacts, the left
/// hand) against the environment where the posture puts them; the head swings and every
/// joint moves a little, so consecutive samples differ as in a real motion.
struct Hrp2Motion {
  RobotModel robot = loadUrdfFile(kHrp2 / "hrp2.urdf");
  DynamicsModel model{robot, "l_sole"};
  MotionParametrization parametrization{robot.jointCount()};
  Eigen::VectorXd parameters;

  Hrp2Motion() {
    const Eigen::VectorXd halfSitting = loadPostures(kHrp2 / "postures.yaml", robot).at("half_sitting");
    parameters = parametrization.constantMotion(halfSitting);
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> small(-0.02, 0.02), large(-0.3, 0.3);
    for (int j = 0; j < robot.jointCount(); ++j)
      for (int k = 0; k < parametrization.parametersPerJoint(); ++k)
        parameters[j * parametrization.parametersPerJoint() + k] +=
            robot.joints[j].name.rfind("HEAD", 0) == 0 ? large(rng) : small(rng);
  }
  std::vector<ContactSurface> contacts(int count) const {
    const auto all = loadContactSurfaces(kHrp2 / "contacts.yaml", robot);  // r_sole, l_sole, r_hand, l_hand
    std::vector<ContactSurface> chosen;
    for (const char* name : {"l_sole", "r_sole", "r_hand", "l_hand"})
      for (const ContactSurface& s : all)
        if (s.name == name && static_cast<int>(chosen.size()) < count) chosen.push_back(s);
    return chosen;
  }
};

void addInnerCounters(benchmark::State& state, const MultiContactResult& r) {
  const auto samples = static_cast<double>(r.status.size());
  state.counters["iterations/sample"] = r.iterations.cast<double>().sum() / samples;
  state.counters["infeasible"] = r.infeasibleSamples;
  state.counters["failed"] = r.failedSamples;
}

void innerSolve(benchmark::State& state, const std::string& solver, ContactModel model, int contacts) {
  const Hrp2Motion motion;
  MultiContactSettings settings;
  settings.problem.model = model;
  MultiContactEvaluator evaluator(motion.model, loadActuators(kHrp2 / "actuators.yaml", motion.robot),
                                  SampledTrajectory(motion.parametrization, 100), motion.contacts(contacts), settings);
  MultiContactResult reference;
  std::vector<ContactProblem> problems;
  evaluator.evaluate(motion.parameters, 1.5, reference, problems);
  const bool cold = solver == "active-set-cold";
  InnerSettings solverSettings;
  solverSettings.warmStart = !cold;
  auto inner = makeInnerSolver(cold ? "active-set" : solver, solverSettings);
  InnerResult result;
  long iterations = 0, solves = 0, failed = 0;
  std::size_t s = 0;
  for (auto _ : state) {
    if (s == 0 && solver != "active-set") result = InnerResult{};  // each pass starts cold for the NLP solvers
    inner->solve(problems[s], result);
    iterations += result.iterations;
    failed += result.status == InnerStatus::Failed;
    ++solves;
    s = (s + 1) % problems.size();
  }
  state.counters["iterations/solve"] = static_cast<double>(iterations) / static_cast<double>(solves);
  state.counters["failed/solve"] = static_cast<double>(failed) / static_cast<double>(solves);
  state.counters["variables"] = 6 * contacts;
}

void bilevelDynamics(benchmark::State& state, int contacts) {
  const Hrp2Motion motion;
  MultiContactEvaluator evaluator(motion.model, loadActuators(kHrp2 / "actuators.yaml", motion.robot),
                                  SampledTrajectory(motion.parametrization, 100), motion.contacts(contacts));
  MultiContactResult result;
  evaluator.evaluate(motion.parameters, 1.5, result);
  for (auto _ : state) {
    evaluator.evaluate(motion.parameters, 1.5, result);
    benchmark::DoNotOptimize(result.motion.energy);
  }
  if (!std::isfinite(result.motion.energy)) state.SkipWithError("non-finite energy");
  addInnerCounters(state, result);
  state.counters["inner_us/motion"] = result.innerTimeUs;
}

}  // namespace

void registerInnerBenchmarks() {
  const std::vector<std::pair<const char*, ContactModel>> models = {
      {"report", ContactModel::Report}, {"pyramid", ContactModel::Pyramid}, {"wrench-cone", ContactModel::WrenchCone}};
  for (const char* solver : {"active-set", "active-set-cold", "slsqp", "ipopt"})
    for (const auto& [modelName, model] : models)
      for (int contacts : {2, 3, 4})
        benchmark::RegisterBenchmark(
            ("Inner/" + std::string(solver) + "/" + modelName + "/" + std::to_string(contacts)).c_str(), innerSolve,
            std::string(solver), model, contacts)
            ->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark("BilevelDynamics/TwoContacts100/hrp2", bilevelDynamics, 2)
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
  benchmark::RegisterBenchmark("BilevelDynamics/ThreeContacts100/hrp2", bilevelDynamics, 3)
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
}

}  // namespace mcopt::bench
