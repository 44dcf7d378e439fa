// SPDX-License-Identifier: BSD-3-Clause
#include "core/trajectory_gradient.hpp"

#include <omp.h>

#include "core/no_malloc_scope.hpp"

#include "core/errors.hpp"

namespace mcopt {

TrajectoryGradientEvaluator::TrajectoryGradientEvaluator(const DynamicsModel& model, ActuatorSet actuators,
                                                         SampledTrajectory samples)
    : model_(model), actuators_(std::move(actuators)), samples_(std::move(samples)) {
  if (static_cast<int>(actuators_.joints.size()) != model.jointCount() ||
      samples_.parametrization().jointCount() != model.jointCount())
    throw InputError("actuators, trajectory and robot disagree on the number of joints");
  workspaces_.assign(static_cast<std::size_t>(omp_get_max_threads()), ThreadWorkspace(model));
  const int n = model.jointCount(), p = samples_.parametrization().parameterCount();
  for (ThreadWorkspace& w : workspaces_)
    for (Eigen::VectorXd* v : {&w.powerTorque, &w.rowQ, &w.rowV, &w.rowA}) v->setZero(n);
  chunkSums_.reset(samples_.sampleCount(), p);
}

void TrajectoryGradientEvaluator::evaluate(const Eigen::Ref<const Eigen::VectorXd>& parameters, double duration,
                                           TrajectoryResult& r, TrajectoryGradient& g) {
  const auto& parametrization = samples_.parametrization();
  const int n = model_.jointCount(), count = samples_.sampleCount(), m = parametrization.parametersPerJoint();
  prepareTrajectoryResult(samples_, n, parameters, duration, r);
  g.torque.resize(static_cast<std::size_t>(count));
  parametrization.controlPoints(parameters, controlPoints_);
  chunkSums_.reset(count, parametrization.parameterCount());
  const double dt = duration / (count - 1);

  // Each sample's Jacobian block is sized by its first evaluation: checked once they all are.
  bool sized = true;
  for (const SampleTorqueJacobian& block : g.torque) sized = sized && block.dtauDx.size() > 0;
  const NoMallocScope perSample("trajectory gradient", sized);
#pragma omp parallel
  forEachSampleInChunks(count, [&](int s, int) {
    ThreadWorkspace& w = workspaces_[static_cast<std::size_t>(omp_get_thread_num())];
    ChunkedEnergyGradient::Sum& sum = chunkSums_.of(s);
    r.time[s] = samples_.time(s, duration);
    samples_.evaluate(s, controlPoints_, duration, r.q.col(s), r.v.col(s), r.a.col(s));
    inverseDynamicsDerivatives(model_, w.data, w.derivatives, r.q.col(s), r.v.col(s), r.a.col(s));
    r.tau.col(s) = w.data.tau;
    r.referenceWrench.col(s) = referenceWrenchAtReferenceFrame(model_, w.data);
    const DynamicsDerivatives& d = w.derivatives;

    // Torque Jacobian block over the local parameters, and w.r.t. T.
    const LocalParameterWeights& weights = samples_.weights(s);
    const int k = weights.count;
    SampleTorqueJacobian& block = g.torque[static_cast<std::size_t>(s)];
    samples_.chainRule(s, duration, d.dtauDq, d.dtauDv, d.dtauDa, block.dtauDx, block.parameters);
    SampledTrajectory::durationDerivative(duration, d.dtauDv, d.dtauDa, r.v.col(s), r.a.col(s), block.dtauDT);

    // Energy: trapezoid weight c_s Δt on Σ_j max(P, 0).
    const double weight = (s == 0 || s == count - 1) ? 0.5 * dt : dt;
    w.rowV.setZero();
    w.rowA.setZero();
    double sampleEnergy = 0.0, directDT = 0.0;
    for (int j = 0; j < n; ++j) {
      const MotorPowerDerivatives p = motorPowerDerivatives(actuators_.joints[j], actuators_.frictionSharpness,
                                                            w.data.tau[j], r.v(j, s), r.a(j, s));
      r.power(j, s) = p.power;
      const bool active = p.power > 0.0;
      sampleEnergy += active ? p.power : 0.0;
      w.powerTorque[j] = active ? weight * p.dTorque : 0.0;
      w.rowV[j] = active ? weight * p.dVelocity : 0.0;
      w.rowA[j] = active ? weight * p.dAcceleration : 0.0;
      directDT -= w.rowV[j] * r.v(j, s) + 2.0 * w.rowA[j] * r.a(j, s);
    }
    // Rows ∂E_s/∂(q, q̇, q̈) = gᵀ ∂Γ/∂(·) + direct terms.
    w.rowQ.noalias() = d.dtauDq.transpose() * w.powerTorque;
    w.rowV.noalias() += d.dtauDv.transpose() * w.powerTorque;
    w.rowA.noalias() += d.dtauDa.transpose() * w.powerTorque;
    for (int j = 0; j < n; ++j)
      for (int l = 0; l < k; ++l)
        sum.energyGradient[j * m + weights.parameter[l]] += w.rowQ[j] * weights.value[l] +
                                                         w.rowV[j] * weights.d1[l] / duration +
                                                         w.rowA[j] * weights.d2[l] / (duration * duration);
    // ∂/∂T: the weight Δt ∝ T, and q̇, q̈ scale as 1/T, 1/T² (through Γ too).
    sum.energyDT += sampleEnergy * weight / duration + directDT / duration + w.powerTorque.dot(block.dtauDT);
  });
  r.energy = positiveEnergy(r.power, r.time);
  chunkSums_.total(g.energyGradient, g.energyDT);
}

}  // namespace mcopt
