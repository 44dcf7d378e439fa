// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A whole motion: splines → (q, q̇, q̈) → Newton–Euler → motor power → energy at
// every sample (formulation.md §3–§6). Samples are independent and run in parallel
// (OpenMP), each thread with its own preallocated DynamicsData.

#include <Eigen/Core>
#include <vector>

#include "core/actuators.hpp"
#include "core/bspline.hpp"
#include "core/inverse_dynamics.hpp"

namespace mcopt {

/// Sampled quantities, one column per sample.
struct TrajectoryResult {
  Eigen::VectorXd time;                            ///< N sample times [s]
  Eigen::MatrixXd q, v, a;                         ///< jointCount × N
  Eigen::MatrixXd tau;                             ///< Γ0, jointCount × N, friction excluded [N m]
  Eigen::Matrix<double, 6, Eigen::Dynamic> referenceWrench;  ///< W0 at the reference frame origin, world axes
  Eigen::MatrixXd power;                           ///< electrical power P per joint, jointCount × N [W]
  double energy = 0.0;                             ///< ∫ Σ_j max(P_j, 0) dt, trapezoid rule [J]
};

/// Checks parameters (count, finiteness) and duration, then sizes `result` for the samples
/// (no allocation once sized). Throws InputError naming what is wrong.
void prepareTrajectoryResult(const SampledTrajectory& samples, int jointCount,
                             const Eigen::Ref<const Eigen::VectorXd>& parameters, double duration,
                             TrajectoryResult& result);

/// ∫ Σ_j max(P_j, 0) dt by the trapezoid rule over the sample times (formulation.md §6).
double positiveEnergy(const Eigen::MatrixXd& power, const Eigen::VectorXd& time);

class TrajectoryEvaluator {
 public:
  TrajectoryEvaluator(const DynamicsModel& model, ActuatorSet actuators, SampledTrajectory samples);

  const DynamicsModel& model() const { return model_; }
  const SampledTrajectory& samples() const { return samples_; }
  const ActuatorSet& actuators() const { return actuators_; }

  /// parameters: samples().parametrization().parameterCount() free spline parameters;
  /// duration T > 0. `result` is resized on first use only.
  void evaluate(const Eigen::Ref<const Eigen::VectorXd>& parameters, double duration, TrajectoryResult& result);

 private:
  const DynamicsModel& model_;
  ActuatorSet actuators_;
  SampledTrajectory samples_;
  Eigen::MatrixXd controlPoints_;
  std::vector<DynamicsData> threadData_;
};

}  // namespace mcopt
