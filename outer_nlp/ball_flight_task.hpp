// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The two rows of a `throw` (formulation.md §10; outer_nlp/ballistic_flight.hpp), both at the
// release instant on the ball's point, functions of the ball's state k = (p, v_p):
//   landing  (L_x − target_x, L_y − target_y, τ): the landing point at the target's height
//            relative to the target, and the flight time;
//   release  (|v|, elevation of v [rad], apex height above the target [m]).
// Their exact Hessian splits along k (docs/theory/outer-problem.md, "The exact Hessian"):
// ∇² Σ λ_i f_i = J_kᵀ (Σ λ_i ∇²f_i) J_k + Σ_m w_m ∇²k_m with w = Σ λ_i ∇f_i; the flight's own
// curvature is flightCurvature, the second term a stencil of ballStateGradient with w held.

#include "outer_nlp/task.hpp"

namespace mcopt {

class BallFlightTask final : public Task {
 public:
  enum class Part { Landing, Release };
  /// The ball at `point` of `frame`'s body; `target` in the world [m]; gravity g along −z [m/s²].
  BallFlightTask(Part part, int frame, const Vector3& point, const Vector3& target, double gravity);

  std::string kind() const override { return part_ == Part::Landing ? "throw_landing" : "throw_release"; }
  TaskQuantity reads() const override { return TaskQuantity::Ball; }
  int frame() const override { return frame_; }
  std::string componentName(int i) const override;
  Part part() const { return part_; }

  void calc(const DynamicsModel& model, const DynamicsData& data, TaskWorkspace& workspace,
            Eigen::Ref<Eigen::VectorXd> value) const override;
  void calcDiff(const DynamicsModel& model, const DynamicsData& data, TaskWorkspace& workspace,
                Eigen::Ref<Eigen::VectorXd> value, Eigen::Ref<Eigen::MatrixXd> dq,
                Eigen::Ref<Eigen::MatrixXd> dv) const override;
  const BallFlightTask* ballFlight() const override { return this; }

  /// The rows weighted by their multipliers λ: the flight's curvature J_kᵀ (Σ λ_i ∇²f_i) J_k
  /// in (q, q̇) (2n × 2n) into `curvature`, and the weights w = Σ λ_i ∇f_i on k into `ballWeights`.
  void flightCurvature(const DynamicsModel& model, const DynamicsData& data, const Vector3& multipliers,
                       TaskWorkspace& workspace, Vector6& ballWeights, Eigen::Ref<Eigen::MatrixXd> curvature) const;
  /// wᵀ ∂k/∂q and wᵀ ∂k/∂q̇, n entries each (p and v_p have a position's and a linear velocity's degrees).
  void ballStateGradient(const DynamicsModel& model, const DynamicsData& data, const Vector6& ballWeights,
                         TaskWorkspace& workspace, Eigen::Ref<Eigen::VectorXd> dq, Eigen::Ref<Eigen::VectorXd> dv) const;

 private:
  struct BallState {
    Vector3 position, velocity;
  };
  BallState ballState(const DynamicsModel& model, const DynamicsData& data, bool derivatives, TaskWorkspace& w) const;

  Part part_;
  int frame_;
  Vector3 point_, target_;
  double gravity_;
};

}  // namespace mcopt
