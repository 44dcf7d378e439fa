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
// for bodies i in the subtree of j (and zero elsewhere). Body wrenches F_i = I_i A_i +
// V_i ×* I_i V_i are differentiated directly, accumulated over j's subtree, and
// Γ_i = S_i · F^c_i gives ∂Γ; W0 = F^c_root. One sample costs O(joints × depth).

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
  std::vector<Matrix6> inertia;           ///< world spatial inertia of each body
  std::vector<Matrix6> compositeInertia;  ///< summed over the subtree
  std::vector<Vector6> motion, twist, acceleration, momentum, inertiaTimesAcceleration, compositeWrench, accumulated;
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
