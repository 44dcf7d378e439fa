// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Exact analytic derivatives of the rooted Newton–Euler inverse dynamics (issue 4,
// formulation.md §4): ∂Γ0/∂(q, q̇, q̈) and ∂W0/∂(q, q̇, q̈).
//
// In the world frame a change of q_j moves joint j's subtree rigidly with twist S_j, so
// every quantity X fixed to an outboard body varies as ∂X/∂q_j = S_j × X (S_j ×* X for
// forces, S_j ×* I − I S_j × for inertias). With V_i, A_i the twists and accelerations:
//   ∂V_i/∂q_j = S_j × (V_i − V_j)
//   ∂A_i/∂q_j = S_j × (A_i − A_j) + (V_i − V_j) × (S_j × V_j)
//   ∂V_i/∂q̇_j = S_j,    ∂A_i/∂q̇_j = S_j × (V_i − V_j − V_λ(j)),    ∂A_i/∂q̈_j = S_j
// for bodies i in the subtree of j (and zero elsewhere). Differentiating the body wrenches
// F_i = I_i A_i + V_i ×* I_i V_i and summing over a subtree, every term is bilinear in a
// quantity of j and one of the bodies: with the per-body matrices
//   Y_i = I_i crm(V_i) − crf(V_i) I_i,     Z_i = crf(V_i) B(h_i) − B(h_i) crm(V_i)
// (h_i = I_i V_i, B(h) x = x ×* h) and their subtree sums (ᶜ), each joint k in the subtree
// of j gets, with c_j = S_j × V_j, u_j = S_j × A_j + V_j × c_j, e_j = S_j × (V_j + V_λ(j)):
//   ∂Γ_k/∂q_j = S_j·α_k + u_j·β_k + c_j·γ_k,     ∂Γ_k/∂q̇_j = −S_j·γ_k + e_j·β_k
//   α_k = Zᶜ_kᵀ S_k + S_k ×* (Fᶜ_k − Pᶜ_k),  β_k = −Iᶜ_k S_k,  γ_k = Yᶜ_kᵀ S_k + S_k ×* Hᶜ_k
// (P = I A, H = h; the identity b·(a ×* f) = −a·(b ×* f) moves S_k to the other side), and
// the joints between j and the reference body get S_a · Gⱼ with Gⱼ the subtree sum at j:
//   G_j^q = S_j ×* Pᶜ_j − Iᶜ_j u_j + Yᶜ_j c_j + Zᶜ_j S_j − c_j ×* Hᶜ_j = ∂W0/∂q_j
//   G_j^v = −Yᶜ_j S_j + S_j ×* Hᶜ_j − Iᶜ_j e_j = ∂W0/∂q̇_j
// ∂Γ/∂q̈ is the mass matrix (CRBA). Per sample: O(bodies) work, then five dot products of
// 6-vectors per (joint, descendant) pair, read from contiguous per-joint columns — the
// organisation of Carpentier & Mansard's analytical RNEA derivatives (RSS 2018), derived here
// for the rooted world-frame recursion.
//
// No 6 × 6 matrix is formed. In 3 × 3 blocks, with V = (v, ω), h = (f, n) = I V:
//   I = [[m, −[mc]×], [[mc]×, J]]              (J: rotational inertia about the origin)
//   Y = [[0, [f]×], [−[f]×, E]],  E = v (mc)ᵀ + mc vᵀ − 2 (mc·v) 1 + J[ω]× + (J[ω]×)ᵀ   (Y = Yᵀ)
//   Z = [[0, [z₁]×], [[z₁]×, [z₂]×]],  z₁ = f × ω,  z₂ = f × v + n × ω                  (Z = −Zᵀ)
// and subtree sums add the block parameters (m, mc, J, f, E, z₁, z₂).

#include <Eigen/Core>
#include <vector>

#include "core/inverse_dynamics.hpp"
#include "core/spatial_algebra.hpp"

namespace mcopt {

/// Per-sample derivative buffers, sized once from a DynamicsModel.
struct DynamicsDerivatives {
  explicit DynamicsDerivatives(const DynamicsModel& model);

  Eigen::MatrixXd dtauDq, dtauDv, dtauDa;           ///< jointCount × jointCount, URDF joint order
  Eigen::Matrix<double, 6, Eigen::Dynamic> dwrenchDq, dwrenchDv, dwrenchDa;  ///< W0 at the world origin, 6 × jointCount

  // Workspace, by tree position.
  /// Block parameters of I, Y and Z (see above) of each body, then of its subtree.
  struct BodyTerms {
    double mass = 0.0;
    Vector3 massCom = Vector3::Zero();        ///< m c
    Matrix3 rotational = Matrix3::Zero();     ///< J about the world origin
    Matrix3 velocityBlock = Matrix3::Zero();  ///< E of Y
    Vector3 z1 = Vector3::Zero(), z2 = Vector3::Zero();
  };
  std::vector<BodyTerms> terms;
  std::vector<Vector6> motion, twist, acceleration;   ///< S_i, V_i, A_i
  std::vector<Vector6> momentum, inertiaTimesAcceleration, wrench;  ///< h_i, P_i, F_i, then their subtree sums
  /// Column k: (α_k, β_k, γ_k) of joint k's row (see above).
  Eigen::Matrix<double, 18, Eigen::Dynamic> rowFactors;
  /// Column j: (u_j, c_j, e_j), joint j's factors of ∂Γ/∂q and ∂Γ/∂q̇ below it (with S_j).
  Eigen::Matrix<double, 18, Eigen::Dynamic> columnFactors;
  /// Column j: (G_j^q, G_j^v, G_j^a), the subtree wrench's derivatives in q_j, q̇_j, q̈_j.
  Eigen::Matrix<double, 18, Eigen::Dynamic> subtreeWrench;
};

/// Runs inverseDynamics (filling `data`) and its derivatives (filling `derivatives`).
/// No allocation.
void inverseDynamicsDerivatives(const DynamicsModel& model, DynamicsData& data, DynamicsDerivatives& derivatives,
                                const ConstVectorRef& q, const ConstVectorRef& v, const ConstVectorRef& a);

/// Moves W0 derivatives from the world origin to the reference frame's origin (what
/// `mcopt dynamics` reports): rows 3–5 −= p_ref × rows 0–2. out: 6 × jointCount.
void wrenchDerivativeAtReferenceFrame(const DynamicsModel& model,
                                      const Eigen::Matrix<double, 6, Eigen::Dynamic>& atOrigin,
                                      Eigen::Matrix<double, 6, Eigen::Dynamic>& out);

}  // namespace mcopt
