// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The admissibility margin of one sample's contacts (docs/theory/outer-problem.md,
// "Inner feasibility"): how far inside its contact models' linear rows the most comfortable
// balancing wrench lies, negative when no admissible wrench balances the robot. With the
// wrenches scaled to F̃ (forces by m g, moments by m g ℓ) and each row G_i F ≤ b_i divided by
// the norm of its scaled normal, the margin is the value
//     m_ε(W) = max  t − ε/2 (‖F̃‖² + t²)   s.t.   B F = W,   G_i F + ‖G_i S‖ t ≤ b_i,
// a strictly convex QP (Goldfarb–Idnani, dual_active_set_qp.hpp), always feasible (t is free
// and the reference contact's six wrench components span the balance). Its properties:
//   - m_ε ≥ 0 implies an admissible wrench (m_ε ≤ the LP margin max t): the row m_ε ≥ 0 is
//     conservative by about ε/2 ‖F̃‖², 2.5e-3 m g for two soles sharing the weight at ε = 1e-2;
//   - m_ε is C¹ in the data, and its gradient is the balance multiplier (envelope theorem):
//         ∂m_ε/∂W = λ,   ∂m_ε/∂(B F)|_F = −λ   at the maximiser F_m,
//     nonzero where m_ε = 0. That is what the inner problem's least balance slack lacks: φ =
//     ‖s‖² is identically zero on the admissible side, so its gradient vanishes on the boundary
//     and an outer optimum that lies there has no constraint qualification.
// Linear contact models only (pyramid, wrench-cone): a second-order cone has no row to shift.
// Allocation-free after construction.

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "core/spatial.hpp"
#include "inner_qp/contact_problem.hpp"

namespace mcopt {

namespace inner_detail {
class DualActiveSetQp;
}

struct MarginSettings {
  double weight = 1.0;            ///< m g [N]: forces are measured in it
  double length = 0.1;            ///< ℓ [m]: moments are measured in m g ℓ
  /// ε (dimensionless, on the scaled variables): the margin's Hessian in W is of order 1/ε, its
  /// bias ε/2 ‖F̃‖². At 1e-3 the throws' restoration phases failed on its near-kinks, at 1e-2
  /// they passed (docs/developers/lab-notes/admissibility-margin.md).
  double regularisation = 1e-2;
  int maxIterations = 500;        ///< working-set changes
};

struct MarginResult {
  bool solved = false;            ///< the QP ended optimal (false: iteration limit or breakdown)
  double margin = 0.0;            ///< m_ε, a fraction of m g; negative: no admissible wrench
  Eigen::VectorXd wrenches;       ///< the maximiser F_m (the problem's variables, unscaled)
  Vector6 balanceGradient = Vector6::Zero();  ///< λ = ∂m_ε/∂W, per N and per N m, world axes
  std::vector<int> activeSet;     ///< the last working set: the next solve's warm start
  int iterations = 0;
};

class AdmissibilityMargin {
 public:
  /// Sized for the contact set of `layout`; throws InputError when a contact has a
  /// second-order cone or fewer than six wrench variables, or a setting is not positive.
  AdmissibilityMargin(const ContactProblem& layout, MarginSettings settings);
  ~AdmissibilityMargin();
  AdmissibilityMargin(AdmissibilityMargin&&) noexcept;
  AdmissibilityMargin& operator=(AdmissibilityMargin&&) noexcept;

  /// The margin of `problem`: the layout's contact set, whose rows were scaled at construction
  /// (sizes are checked; the balance and W are read here). Warm-started from the
  /// active set in `result`.
  void solve(const ContactProblem& problem, MarginResult& result);

  const MarginSettings& settings() const { return settings_; }

 private:
  MarginSettings settings_;
  int variables_ = 0, rows_ = 0;
  Eigen::VectorXd scale_;  ///< S: m g for a force component, m g ℓ for a moment's
  std::unique_ptr<inner_detail::DualActiveSetQp> qp_;  ///< the QP in (F̃, t), sized once
};

}  // namespace mcopt
