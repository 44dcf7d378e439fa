// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The wrench maps of formulation.md §5 for one contact frame C on the robot, and their
// derivatives with respect to q. A contact wrench F = (f, m) is what the environment
// applies to the robot at C's origin, in C's axes.
//   wrenchToWorld  (6 × 6):  F ↦ the same wrench in world axes about the world origin (J2's block)
//   wrenchToTorque (n × 6):  F ↦ its joint-torque image, Γ = Γ0 − wrenchToTorque · F (J1's block)
// wrenchToTorque's row for joint i is S_i · wrenchToWorld on the path from the reference
// body to C's body, zero elsewhere (the reference body's own contact has a zero block).

#include <Eigen/Core>

#include "core/dynamics_data.hpp"
#include "core/spatial_algebra.hpp"

namespace mcopt {

using WrenchToTorque = Eigen::Matrix<double, Eigen::Dynamic, 6>;

/// Contact frame C: on the body at tree position `bodyPosition`, with world pose `contactPose`.
struct ContactFrame {
  int bodyPosition = 0;
  RigidTransform contactPose;
};

/// World pose of a contact frame placed at `placement` in RobotModel frame `frame`.
ContactFrame contactFrame(const DynamicsModel& model, const DynamicsData& data, int frame,
                          const RigidTransform& placement);

/// wrenchToWorld: 6 × 6, written.
void wrenchToWorld(const ContactFrame& contact, Matrix6& toWorld);
/// The same for a contact frame given by its world pose alone.
void wrenchToWorld(const RigidTransform& contactPose, Eigen::Ref<Eigen::Matrix<double, 6, 6>> toWorld);

/// wrenchToTorque: jointCount × 6, written (structural zeros off the path).
void wrenchToTorque(const DynamicsModel& model, const DynamicsData& data, const ContactFrame& contact,
                    WrenchToTorque& toTorque);

/// Derivatives of the products with a fixed contact wrench F (in C) w.r.t. q:
///   dWorld (6 × n) = ∂(wrenchToWorld F)/∂q:   column j = S_j ×* W for j on the path, W = wrenchToWorld F
///   dTorque (n × n) = ∂(wrenchToTorque F)/∂q: entry (i, j) = S_i · (S_j ×* W) for i strictly inboard of j
///                                              on the path (the other terms cancel: (a × b)·f = −b·(a ×* f))
/// These are the (∂J2/∂p) Fc and (∂J1/∂p) Fc terms of (4.8).
void wrenchMapDerivatives(const DynamicsModel& model, const DynamicsData& data, const ContactFrame& contact,
                          const Vector6& wrench, Eigen::Matrix<double, 6, Eigen::Dynamic>& dWorld,
                          Eigen::MatrixXd& dTorque);

/// Derivatives of the transposed maps w.r.t. q, for a fixed joint-space vector g (n) and a
/// fixed world-wrench multiplier λ (6) — the (∂J1/∂p)ᵀ and (∂J2/∂p)ᵀ terms of the inner
/// problem's sensitivity (formulation.md §8):
///   dTorqueTransposed (6 × n) = ∂(wrenchToTorqueᵀ g)/∂q: column k = −Xᵀ (S_k × Σ_{j on the path, j = k or inboard} g_j S_j)
///   dWorldTransposed  (6 × n) = ∂(wrenchToWorldᵀ λ)/∂q:  column k = −Xᵀ (S_k × λ)
/// for k on the path from the reference body to C's body, zero elsewhere (X = wrenchToWorld;
/// from ∂X/∂q_k = (S_k ×*) X and ∂S_j/∂q_k = S_k × S_j for k inboard of j).
void transposedWrenchMapDerivatives(const DynamicsModel& model, const DynamicsData& data, const ContactFrame& contact,
                                    const Eigen::Ref<const Eigen::VectorXd>& g, const Vector6& lambda,
                                    Eigen::Matrix<double, 6, Eigen::Dynamic>& dTorqueTransposed,
                                    Eigen::Matrix<double, 6, Eigen::Dynamic>& dWorldTransposed);

}  // namespace mcopt
