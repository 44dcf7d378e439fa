// SPDX-License-Identifier: BSD-3-Clause
// InverseDynamics/PerSample/<robot> and InverseDynamics/Trajectory100/<robot>.
#include <benchmark/benchmark.h>

#include "bench/bench_fixture.hpp"
#include "core/actuators.hpp"
#include "core/trajectory_gradient.hpp"

namespace mcopt::bench {

namespace {

void perSample(benchmark::State& state, const BenchRobot& named) {
  const RobotModel robot = loadBenchRobot(named);
  const DynamicsModel model(robot, named.sole);
  DynamicsData data(model);
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  constexpr int kStates = 64;  // cycle through seeded states so branch predictors see real inputs
  std::vector<Eigen::VectorXd> q(kStates), v(kStates), a(kStates);
  for (int s = 0; s < kStates; ++s) {
    q[s] = Eigen::VectorXd::NullaryExpr(robot.jointCount(), [&] { return u(rng); });
    v[s] = Eigen::VectorXd::NullaryExpr(robot.jointCount(), [&] { return 2 * u(rng); });
    a[s] = Eigen::VectorXd::NullaryExpr(robot.jointCount(), [&] { return 5 * u(rng); });
  }
  int s = 0;
  for (auto _ : state) {
    inverseDynamics(model, data, q[s], v[s], a[s]);
    benchmark::DoNotOptimize(data.tau.data());
    benchmark::ClobberMemory();
    s = (s + 1) % kStates;
  }
  if (!data.tau.allFinite()) state.SkipWithError("non-finite torques");
  state.counters["joints"] = robot.jointCount();
  state.counters["bodies"] = robot.bodyCount();
}

void trajectory100(benchmark::State& state, const BenchRobot& named) {
  const RobotModel robot = loadBenchRobot(named);
  const DynamicsModel model(robot, named.sole);
  const MotionParametrization parametrization(robot.jointCount());
  TrajectoryEvaluator evaluator(model, defaultActuators(robot), SampledTrajectory(parametrization, 100));
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  const Eigen::VectorXd x = Eigen::VectorXd::NullaryExpr(parametrization.parameterCount(), [&] { return u(rng); });
  TrajectoryResult result;
  evaluator.evaluate(x, 1.5, result);
  for (auto _ : state) {
    evaluator.evaluate(x, 1.5, result);
    benchmark::DoNotOptimize(result.energy);
  }
  if (!std::isfinite(result.energy)) state.SkipWithError("non-finite energy");
  state.counters["samples"] = 100;
}

void derivativesPerSample(benchmark::State& state, const BenchRobot& named) {
  const RobotModel robot = loadBenchRobot(named);
  const DynamicsModel model(robot, named.sole);
  DynamicsData data(model);
  DynamicsDerivatives derivatives(model);
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::VectorXd q = Eigen::VectorXd::NullaryExpr(robot.jointCount(), [&] { return u(rng); });
  const Eigen::VectorXd v = 2 * q.reverse(), a = 5 * q;
  for (auto _ : state) {
    inverseDynamicsDerivatives(model, data, derivatives, q, v, a);
    benchmark::DoNotOptimize(derivatives.dtauDq.data());
    benchmark::ClobberMemory();
  }
  if (!derivatives.dtauDq.allFinite()) state.SkipWithError("non-finite derivatives");
  state.counters["joints"] = robot.jointCount();
}

// The report's Figure 5.1 "gradient": energy and every sampled torque w.r.t. all motion
// parameters, one contact (the reference sole), N = 100. Threads: OMP_NUM_THREADS.
void gradientOneContact100(benchmark::State& state) {
  const std::filesystem::path dir = std::filesystem::path(MCOPT_SOURCE_DIR) / "robots/hrp2";
  const RobotModel robot = loadUrdfFile(dir / "hrp2.urdf");
  const DynamicsModel model(robot, "l_sole");
  const MotionParametrization parametrization(robot.jointCount());
  TrajectoryGradientEvaluator evaluator(model, loadActuators(dir / "actuators.yaml", robot),
                                        SampledTrajectory(parametrization, 100));
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  const Eigen::VectorXd x = Eigen::VectorXd::NullaryExpr(parametrization.parameterCount(), [&] { return u(rng); });
  TrajectoryResult result;
  TrajectoryGradient gradient;
  evaluator.evaluate(x, 1.5, result, gradient);
  for (auto _ : state) {
    evaluator.evaluate(x, 1.5, result, gradient);
    benchmark::DoNotOptimize(gradient.energyGradient.data());
  }
  if (!gradient.energyGradient.allFinite()) state.SkipWithError("non-finite gradient");
  state.counters["parameters"] = parametrization.parameterCount();
}

}  // namespace

void registerDynamicsBenchmarks() {
  benchmark::RegisterBenchmark("Gradient/OneContact100/hrp2", gradientOneContact100)
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
  for (const BenchRobot& robot : benchRobots()) {
    benchmark::RegisterBenchmark(("InverseDynamics/PerSample/" + robot.name).c_str(), perSample, robot);
    benchmark::RegisterBenchmark(("InverseDynamics/Trajectory100/" + robot.name).c_str(), trajectory100, robot)
        ->Unit(benchmark::kMicrosecond)
        ->UseRealTime();
    benchmark::RegisterBenchmark(("Derivatives/PerSample/" + robot.name).c_str(), derivativesPerSample, robot)
        ->Unit(benchmark::kMicrosecond);
  }
}

}  // namespace mcopt::bench
