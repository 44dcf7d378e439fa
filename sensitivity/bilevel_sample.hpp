// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// One time sample of the bilevel formulation (formulation.md §7–§9, the report's Figure
// 4.3): the inner problem over the contacts active at this sample picks the wrenches F*,
// Γ = Γ0 − J1 F* (4.8), and — from one factorisation of the inner KKT system — the exact
// derivatives of Γ and F* with respect to the sample's state (q, q̇, q̈):
//     dΓ/dx = dΓ0/dx − (∂J1/∂x) F* − J1 dF*/dx                                   (4.8)
// The right-hand sides of the KKT system are those of multi_contact_gradient.hpp.
//
// An infeasible sample (no admissible wrench balances the robot) has the inner solver's
// elastic solution: the least-norm balance slack s = W0 − B F_ls at the least-slack phase's
// own minimiser F_ls (InnerResult::leastSlackWrenches). Its squared size
//     φ = ‖s‖² / (m g)²
// is what the outer problem holds at zero (formulation.md §7: "slack = 0"). By the envelope
// theorem (φ is the minimum of ‖W0 − B F‖² over the admissible wrenches, a set that does not
// depend on the state) its derivative is 2 sᵀ (∂W0/∂x − ∂(B F)/∂x |_{F = F_ls}) / (m g)²: exact, and
// zero wherever the sample is feasible. There the wrenches' own derivative is not defined
// (the inner KKT system is that of the shifted balance), so dF*/dx is taken as zero and the
// sample is counted: Ipopt is steered by φ, never by a silent zero.
//
// With InnerFeasibility::Margin the row is instead −m_ε, the admissibility margin of the sample's
// contacts (inner_qp/admissibility_margin.hpp) held ≤ 0: signed, C¹, and with the derivative
//     ∂(−m_ε)/∂x = −λᵀ (∂W0/∂x − ∂(B F)/∂x |_{F = F_m})
// (λ its balance multiplier, F_m its maximiser), nonzero on the boundary where φ's vanishes.
// It does not depend on the inner solution: the wrenches and Γ are those of the inner problem
// as before. Should the margin's QP not end optimal (only its iteration limit could stop it:
// it is strictly convex and always feasible), the sample's row is φ's, an exact feasibility
// row as well.
//
// Model/data: the contacts, settings and solver choice are fixed at construction; every
// buffer is sized then, and evaluate() allocates nothing once the solver has seen a problem.

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "core/actuators.hpp"
#include "core/dynamics_derivatives.hpp"
#include "inner_qp/admissibility_margin.hpp"
#include "inner_qp/multi_contact_dynamics.hpp"
#include "sensitivity/inner_sensitivity.hpp"

namespace mcopt {

class BilevelSample {
 public:
  /// contacts: the surfaces active at this sample (the reference body's among them).
  /// weight: m g [N], the scale of φ.
  BilevelSample(const DynamicsModel& model, std::vector<ContactSurface> contacts, const MultiContactSettings& settings,
                const SensitivitySettings& sensitivity, double weight);
  ~BilevelSample();
  BilevelSample(BilevelSample&&) noexcept;
  BilevelSample& operator=(BilevelSample&&) noexcept;

  int contactCount() const { return static_cast<int>(contacts_.size()); }
  const std::vector<ContactSurface>& contacts() const { return contacts_; }

  /// `data` holds the inverse dynamics of (q, v, a), and `derivatives` their derivatives
  /// when `withDerivatives` is set. Solves the inner problem (warm-started from this
  /// sample's previous result) and fills the outputs below.
  /// With `solveKkt` false the KKT system is factorised but not solved: dF*/dx is left at
  /// zero until setWrenchDerivative() (the all-samples layout solves many samples' systems
  /// together, sensitivity/multi_contact_gradient.hpp).
  void evaluate(const DynamicsModel& model, const DynamicsData& data, const DynamicsDerivatives* derivatives,
                const ActuatorSet& actuators, const Eigen::Ref<const Eigen::VectorXd>& v,
                const Eigen::Ref<const Eigen::VectorXd>& a, bool withDerivatives, bool solveKkt = true);

  /// After evaluate(…, solveKkt = false) with an optimal inner result: the KKT matrix and the
  /// right-hand side of dF*/d(q, q̇, q̈) (InnerSensitivity::kktMatrix, rightHandSide).
  const Eigen::MatrixXd& kktMatrix() const { return sensitivity_.kktMatrix(); }
  void kktRightHandSide(Eigen::MatrixXd& rhs) const { sensitivity_.rightHandSide(stationarity_, balance_, rhs); }
  /// dF*/d(q, q̇, q̈) solved elsewhere (wrench variables × 3n), after an evaluation with
  /// derivatives; the torque derivatives follow (4.8).
  void setWrenchDerivative(const Eigen::Ref<const Eigen::MatrixXd>& dF);

  /// Starts the next solve from `other`'s result (a neighbouring sample with the same contacts).
  void warmStartFrom(const BilevelSample& other);
  bool hasResult() const { return result_.wrenches.size() > 0; }

  const InnerResult& innerResult() const { return result_; }
  const SampleProblem& problem() const { return sample_; }
  /// Γ = Γ0 − J1 F* (n), the feasibility row (φ, or −m_ε with the margin; ≤ 0 when feasible),
  /// and with derivatives n × n blocks and 1 × n rows (empty before the first evaluation with
  /// derivatives).
  const Eigen::VectorXd& torque() const { return torque_; }
  double infeasibility() const { return infeasibility_; }
  const Eigen::MatrixXd& torqueDq() const { return dTorqueDq_; }
  const Eigen::MatrixXd& torqueDv() const { return dTorqueDv_; }
  const Eigen::MatrixXd& torqueDa() const { return dTorqueDa_; }
  const Eigen::RowVectorXd& infeasibilityDq() const { return dInfeasibilityDq_; }
  const Eigen::RowVectorXd& infeasibilityDv() const { return dInfeasibilityDv_; }
  const Eigen::RowVectorXd& infeasibilityDa() const { return dInfeasibilityDa_; }
  /// dF*/d(q, q̇, q̈): wrench variables (problem().problem.contactColumn) × 3n (zero when the sample has no derivative).
  const Eigen::MatrixXd& wrenchesDstate() const { return dF_; }
  /// The last evaluation had an optimal inner result and so an exact dF*.
  bool hasWrenchDerivative() const { return hasWrenchDerivative_; }
  const SensitivityDiagnostics& diagnostics() const { return diagnostics_; }

 private:
  std::vector<ContactSurface> contacts_;
  double scale_;  ///< 1 / (m g)²
  SampleProblem sample_;
  std::unique_ptr<InnerSolver> solver_;
  InnerSensitivity sensitivity_;
  InnerResult result_;
  std::unique_ptr<AdmissibilityMargin> margin_;  ///< null: the slack row φ
  MarginResult marginResult_;
  SensitivityDiagnostics diagnostics_;
  bool hasWrenchDerivative_ = false;
  double infeasibility_ = 0.0;
  Eigen::VectorXd torque_, g_, linearDv_, linearDa_;
  void updateTorqueDerivatives();
  /// The derivatives' buffers, sized at the first evaluation that asks for them: a values-only
  /// problem (the energy balance's and `mcopt verify`'s fine grids, thousands of samples) never
  /// allocates them (about 90 kB a sample on HRP-2).
  void sizeDerivatives(int n);

  Eigen::MatrixXd dTorqueDq_, dTorqueDv_, dTorqueDa_, dF_, stationarity_, balance_, dJ1Fdq_, dTorque_, scaled_;
  Eigen::MatrixXd fixedDq_, fixedDv_, fixedDa_;  ///< ∂Γ/∂x at fixed wrenches
  Eigen::Matrix<double, 6, Eigen::Dynamic> dBFdq_, dLeastSlackBFdq_, dWorld_, dTorqueT_, dWorldT_;
  Vector6 leastSlack_ = Vector6::Zero();
  /// The row's derivative from a balance-space covector `c` at wrenches `wrenches`:
  /// factor · cᵀ (∂W0/∂x − ∂(B F)/∂x |_F) into dInfeasibilityD*.
  void balanceRowDerivative(const DynamicsModel& model, const DynamicsData& data, const DynamicsDerivatives& d,
                            const Eigen::VectorXd& wrenches, const Vector6& c, double factor);
  Eigen::RowVectorXd dInfeasibilityDq_, dInfeasibilityDv_, dInfeasibilityDa_;
};

}  // namespace mcopt
