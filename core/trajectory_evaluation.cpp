// SPDX-License-Identifier: BSD-3-Clause
#include "core/trajectory_evaluation.hpp"

#include <omp.h>

#include "core/no_malloc_scope.hpp"

#include "core/errors.hpp"

namespace mcopt {

double positiveEnergy(const Eigen::MatrixXd& power, const Eigen::VectorXd& time) {
  double energy = 0.0;
  for (Eigen::Index s = 0; s + 1 < power.cols(); ++s) {
    const double left = power.col(s).cwiseMax(0.0).sum();
    const double right = power.col(s + 1).cwiseMax(0.0).sum();
    energy += 0.5 * (left + right) * (time[s + 1] - time[s]);
  }
  return energy;
}

void prepareTrajectoryResult(const SampledTrajectory& samples, int n, const Eigen::Ref<const Eigen::VectorXd>& parameters,
                             double duration, TrajectoryResult& r) {
  const auto& parametrization = samples.parametrization();
  if (parameters.size() != parametrization.parameterCount())
    throw InputError("expected " + std::to_string(parametrization.parameterCount()) + " spline parameters, got " +
                     std::to_string(parameters.size()));
  if (!(duration > 0.0) || !std::isfinite(duration))
    throw InputError("duration must be positive and finite, got " + std::to_string(duration));
  if (!parameters.allFinite()) throw InputError("spline parameters contain NaN or infinity");
  const int count = samples.sampleCount();
  r.time.resize(count);
  for (Eigen::MatrixXd* m : {&r.q, &r.v, &r.a, &r.tau, &r.power}) m->resize(n, count);
  r.referenceWrench.resize(6, count);
}

TrajectoryEvaluator::TrajectoryEvaluator(const DynamicsModel& model, ActuatorSet actuators, SampledTrajectory samples)
    : model_(model), actuators_(std::move(actuators)), samples_(std::move(samples)) {
  if (static_cast<int>(actuators_.joints.size()) != model.jointCount())
    throw InputError("actuator set has " + std::to_string(actuators_.joints.size()) + " joints, the robot " +
                     std::to_string(model.jointCount()));
  if (samples_.parametrization().jointCount() != model.jointCount())
    throw InputError("trajectory has " + std::to_string(samples_.parametrization().jointCount()) +
                     " joints, the robot " + std::to_string(model.jointCount()));
  threadData_.assign(static_cast<std::size_t>(omp_get_max_threads()), DynamicsData(model));
}

void TrajectoryEvaluator::evaluate(const Eigen::Ref<const Eigen::VectorXd>& parameters, double duration,
                                   TrajectoryResult& r) {
  const int n = model_.jointCount(), count = samples_.sampleCount();
  prepareTrajectoryResult(samples_, n, parameters, duration, r);
  samples_.parametrization().controlPoints(parameters, controlPoints_);

  const NoMallocScope perSample("trajectory evaluation");  // `r` is sized above; the samples allocate nothing
#pragma omp parallel for schedule(static)
  for (int s = 0; s < count; ++s) {
    DynamicsData& data = threadData_[static_cast<std::size_t>(omp_get_thread_num())];
    r.time[s] = samples_.time(s, duration);
    samples_.evaluate(s, controlPoints_, duration, r.q.col(s), r.v.col(s), r.a.col(s));
    inverseDynamics(model_, data, r.q.col(s), r.v.col(s), r.a.col(s));
    r.tau.col(s) = data.tau;
    r.referenceWrench.col(s) = referenceWrenchAtReferenceFrame(model_, data);
    for (int j = 0; j < n; ++j)
      r.power(j, s) =
          motorPower(actuators_.joints[j], actuators_.frictionSharpness, data.tau[j], r.v(j, s), r.a(j, s)).power;
  }
  r.energy = positiveEnergy(r.power, r.time);
}

}  // namespace mcopt
