// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Sensitivity of an inner solution (formulation.md §8; the report's (4.25)–(4.47)): at the
// optimal wrenches F with strictly active set A, the KKT conditions
//     ∇_F L = H F + c + Bᵀ λ + Σ_A μ_r a_r + Σ_cones ν_k ∇c_k = 0,    B F = W,   a_r F = b_r,   c_k(F) = 0
// hold identically in any parameter p of the data, so
//     [ H + Σ ν_k ∇²c_k   Aᵀ ] [ dF/dp ]       [ ∂(∇_F L)/∂p ]
//     [ A                 0  ] [ dμ/dp ]  = −  [ ∂(A F − b)/∂p ]
// with A stacking the balance rows, the strictly active linear rows and the active cones'
// gradients (convex form c = ‖f_t‖ − μ fz, ν = y_z / μ of the conic multiplier). One
// factorisation serves every parameter column.
//
// Unloaded contacts (formulation.md §7): a contact whose fz sits at zero with a positive
// multiplier stays unloaded under small perturbations, and its centre-of-pressure rows then
// pin m_x = m_y = 0 (its yaw rows, as the wrench-cone model has, m_z = 0): its wrench components
// are held by unit rows and its own rows and cone leave the system.
//
// Degenerate points — an active constraint with (near) zero multiplier, or a near-singular
// KKT matrix — have one-sided derivatives only: they are counted in the diagnostics, the
// weakly active constraints are left out (the derivative of the strictly active side), never
// silently.

#include <Eigen/Core>
#include <memory>
#include <string>

#include "inner_qp/inner_solver.hpp"

namespace mcopt {

enum class KktBackend {
  Dense,       ///< Eigen partial-pivoting LU of the per-sample KKT matrix
  SparseKlu,   ///< SuiteSparse KLU, analysis kept per pattern (sparse_kkt_factor.hpp)
  SparseUmfpack,  ///< SuiteSparse UMFPACK, analysis kept per pattern (sparse_kkt_factor.hpp)
};
const char* toString(KktBackend backend);
/// "dense", "klu" or "umfpack"; throws InputError otherwise.
KktBackend parseKktBackend(const std::string& name);

/// Whole motions (MultiContactGradientEvaluator): one KKT system per sample, or all samples'
/// systems as one block-diagonal sparse matrix factorised once (sparse backends only).
enum class KktLayout { PerSample, AllSamples };

struct SensitivitySettings {
  KktBackend backend = KktBackend::Dense;
  KktLayout layout = KktLayout::PerSample;
  /// A constraint whose multiplier is at most this fraction of the data's scale is weakly
  /// active: left out of the system and counted as degenerate.
  double strictMultiplier = 1e-9;
  /// A contact whose fz and shear are both below this fraction of the force scale, with its
  /// fz_min row or its cone's apex active, is unloaded (an interior-point result stops near
  /// the apex, the active-set method on it).
  double unloadedForce = 1e-6;
};

struct SensitivityDiagnostics {
  int activeRows = 0;        ///< strictly active linear rows in the system
  int activeCones = 0;       ///< cones active on their surface
  int unloadedContacts = 0;  ///< contacts held at zero wrench
  int weaklyActive = 0;      ///< active constraints with (near) zero multiplier, left out
  /// Of the KKT matrix, estimated by the backend's own factorisation: dense, Hager–Higham on
  /// the LU; klu, klu_condest (the same estimator); umfpack, its rough min|U_ii| / max|U_ii|.
  double reciprocalCondition = 1.0;
  /// min|U_ii| / max|U_ii| of the backend's factorisation. Hager–Higham bounds ‖K⁻¹‖ from
  /// below and can miss an exact dependency that the pivots show (an NLP inner solver's
  /// active set of dependent rows: estimate 3e-4, pivot ratio 2e-17, and the LU's solve NaN).
  double pivotRatio = 1.0;
  int size = 0;              ///< KKT dimension
  /// The backend that solved: the chosen one, or dense least-norm for a near-singular system.
  KktBackend backend = KktBackend::Dense;
  bool analysisReused = false;  ///< sparse backends: the pattern's symbolic analysis was reused
  bool nearSingular() const { return reciprocalCondition < 1e-13 || pivotRatio < 1e-13; }
  bool degenerate() const { return weaklyActive > 0 || nearSingular(); }
  std::string describe() const;
};

class InnerSensitivity {
 public:
  explicit InnerSensitivity(SensitivitySettings settings = {});
  ~InnerSensitivity();
  InnerSensitivity(InnerSensitivity&&) noexcept;
  InnerSensitivity& operator=(InnerSensitivity&&) noexcept;

  /// Assembles and factorises the KKT system at an optimal inner result of `problem`.
  /// Throws InputError if the result is not optimal (an infeasible sample's elastic solution
  /// has no such derivative; the outer problem sees its slack instead) or sizes disagree.
  const SensitivityDiagnostics& factorize(const ContactProblem& problem, const InnerResult& result);
  const SensitivityDiagnostics& diagnostics() const;

  /// m parameter directions at once. dStationarity: (wrench variables, 6nc for six-component contacts) × m, ∂(∇_F L)/∂p at fixed F and
  /// multipliers; dBalance: 6 × m, ∂(B F − W)/∂p at fixed F. Writes dWrenches (variables × m) and,
  /// when given, dBalanceMultipliers (6 × m). The contact rows do not depend on p (they live
  /// in the contact frames).
  void solve(const Eigen::Ref<const Eigen::MatrixXd>& dStationarity, const Eigen::Ref<const Eigen::MatrixXd>& dBalance,
             Eigen::MatrixXd& dWrenches, Eigen::MatrixXd* dBalanceMultipliers = nullptr) const;

  /// The data sensitivities of `mcopt inner --sensitivity`: dF/dτ0 (variables × n) and dF/dW
  /// (variables × 6), from ∂c/∂τ0 = −2 J1ᵀ diag(w) (the problem's weightedWrenchToTorque) and
  /// ∂(B F − W)/∂W = −1.
  void dataSensitivities(const ContactProblem& problem, Eigen::MatrixXd& dWrenchesDtau0,
                         Eigen::MatrixXd& dWrenchesDbalance) const;

  /// For factorising many samples' systems together: the assembled KKT matrix (size × size)
  /// and the right-hand side −[dStationarity; dBalance; 0] of solve().
  const Eigen::MatrixXd& kktMatrix() const;
  void rightHandSide(const Eigen::Ref<const Eigen::MatrixXd>& dStationarity,
                     const Eigen::Ref<const Eigen::MatrixXd>& dBalance, Eigen::MatrixXd& rhs) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mcopt
