// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Exact gradients of a whole motion with respect to its free spline parameters x and the
// duration T (issue 4): every sampled torque and the energy. Sample s depends on at most
// 4 parameters a joint (B-spline local support, formulation.md §3), so each sample's
// torque Jacobian is a dense jointCount × (jointCount · k) block over the k ≤ 4 local
// parameters of every joint, and nothing else is stored or touched.
//
// Chain rule: ∂Γ/∂x_{j,k} = ∂Γ/∂q_j w_k + ∂Γ/∂q̇_j w'_k / T + ∂Γ/∂q̈_j w''_k / T²,
//             ∂Γ/∂T = −(∂Γ/∂q̇ q̇ + 2 ∂Γ/∂q̈ q̈) / T.
// Energy E = Δt Σ_s c_s Σ_j max(P_js, 0) (trapezoid, Δt = T/(N−1)); its gradient takes the
// derivative of P where P > 0 (formulation.md §6; the smooth and epigraph forms of the
// outer problem build on the same per-sample derivatives).

#include <Eigen/Core>
#include <vector>

#include "core/dynamics_derivatives.hpp"
#include "core/sample_chunks.hpp"
#include "core/trajectory_evaluation.hpp"

namespace mcopt {

struct SampleTorqueJacobian {
  Eigen::VectorXi parameters;  ///< global parameter index of each block column (jointCount · k)
  Eigen::MatrixXd dtauDx;      ///< jointCount × (jointCount · k)
  Eigen::VectorXd dtauDT;      ///< jointCount
};

struct TrajectoryGradient {
  Eigen::VectorXd energyGradient;           ///< ∂E/∂x, parameterCount
  double energyDT = 0.0;                    ///< ∂E/∂T
  std::vector<SampleTorqueJacobian> torque; ///< per sample
};

/// The energy's gradient summed per chunk of samples (core/sample_chunks.hpp), then over the
/// chunks in order: the same sums in the same order for any thread count. The trajectory
/// gradient and the multi-contact gradient (sensitivity/multi_contact_gradient.hpp) use it.
class ChunkedEnergyGradient {
 public:
  struct Sum {
    Eigen::VectorXd energyGradient;  ///< ∂E/∂x of the chunk's samples
    double energyDT = 0.0;           ///< ∂E/∂T of the chunk's samples
  };
  /// Zeros every chunk's sum (sized on the first call; no allocation afterwards).
  void reset(int sampleCount, int parameterCount) {
    sums_.resize(static_cast<std::size_t>(sampleChunkCount(sampleCount)));
    for (Sum& sum : sums_) sum.energyGradient.setZero(parameterCount), sum.energyDT = 0.0;
  }
  /// The sum sample s adds to (its chunk's).
  Sum& of(int sample) { return sums_[static_cast<std::size_t>(sample / kSampleChunk)]; }
  /// Σ over the chunks, in order, into gradient and dT (set, not added to).
  void total(Eigen::VectorXd& gradient, double& dT) const {
    gradient.setZero(sums_.empty() ? 0 : sums_.front().energyGradient.size());
    dT = 0.0;
    for (const Sum& sum : sums_) gradient += sum.energyGradient, dT += sum.energyDT;
  }

 private:
  std::vector<Sum> sums_;
};

class TrajectoryGradientEvaluator {
 public:
  TrajectoryGradientEvaluator(const DynamicsModel& model, ActuatorSet actuators, SampledTrajectory samples);

  /// Fills `result` (as TrajectoryEvaluator) and `gradient`; buffers are sized on first use.
  void evaluate(const Eigen::Ref<const Eigen::VectorXd>& parameters, double duration, TrajectoryResult& result,
                TrajectoryGradient& gradient);

 private:
  struct ThreadWorkspace {
    explicit ThreadWorkspace(const DynamicsModel& model) : data(model), derivatives(model) {}
    DynamicsData data;
    DynamicsDerivatives derivatives;
    Eigen::VectorXd powerTorque, rowQ, rowV, rowA;
  };
  const DynamicsModel& model_;
  ActuatorSet actuators_;
  SampledTrajectory samples_;
  Eigen::MatrixXd controlPoints_;
  std::vector<ThreadWorkspace> workspaces_;
  ChunkedEnergyGradient chunkSums_;
};

}  // namespace mcopt
