// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The inner problem as a plain NLP, shared by the third-party adapters (private header).
// Variables x = Fc (6nc). Constraints, in order:
//   6 balance equalities   wrenchToWorld F − W = 0          (BalanceMode::Equality)
//   linear inequalities    G F − h ≤ 0
//   friction cones         fx² + fy² − μ² fz² ≤ 0          (report model), or with
//                          coneSmoothing δ > 0 the inner smooth cone √(fx² + fy² + δ²) − μ fz ≤ 0,
//                          whose fz-gradient never vanishes (constraint qualification holds at
//                          an unloaded contact) and whose every point satisfies the true cone
//   with BalanceMode::Band, after the cones: ±(wrenchToWorld F − W) − ε ≤ 0 (12 rows), the
//   elastic phase 2's balance, whose exact equality would only touch the admissible set
// Objective ½ Fᵀ H F + cᵀ F + constant of the given problem.

#include <Eigen/Core>
#include <cmath>
#include <functional>
#include <string>

#include "inner_qp/inner_solver.hpp"

namespace mcopt::inner_detail {

enum class BalanceMode { Equality, Dropped, Band };

class InnerNlp {
 public:
  InnerNlp(const ContactProblem& problem, BalanceMode balance, double coneSmoothing = 0.0, double band = 0.0)
      : p_(problem), mode_(balance), delta_(coneSmoothing), band_(band) {}

  int variableCount() const { return p_.variableCount(); }
  int equalityCount() const { return mode_ == BalanceMode::Equality ? 6 : 0; }
  int bandCount() const { return mode_ == BalanceMode::Band ? 12 : 0; }
  int inequalityCount() const { return static_cast<int>(p_.inequality.rows() + p_.cones.size()) + bandCount(); }
  const ContactProblem& problem() const { return p_; }

  double objective(const double* x) const {
    const auto F = wrenches(x);
    return 0.5 * F.dot(p_.hessian * F) + p_.gradient.dot(F) + p_.constant;
  }
  void objectiveGradient(const double* x, double* out) const {
    Eigen::Map<Eigen::VectorXd>(out, variableCount()) = p_.hessian * wrenches(x) + p_.gradient;
  }
  /// Equalities: value and dense row-major Jacobian (equalityCount × variableCount).
  void equalities(const double* x, double* value, double* jacobian) const {
    if (mode_ != BalanceMode::Equality) return;
    Eigen::Map<Vector6> out(value);
    out = p_.balance * wrenches(x) - p_.balanceTarget;
    if (jacobian)
      Eigen::Map<Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::RowMajor>>(jacobian, 6, variableCount()) = p_.balance;
  }
  /// Inequalities g ≤ 0: value and dense row-major Jacobian (inequalityCount × variableCount).
  void inequalities(const double* x, double* value, double* jacobian) const {
    const auto F = wrenches(x);
    const Eigen::Index rows = p_.inequality.rows();
    const Eigen::Index bandStart = rows + static_cast<Eigen::Index>(p_.cones.size());
    Eigen::Map<Eigen::VectorXd> v(value, inequalityCount());
    v.head(rows) = p_.inequality * F - p_.inequalityBound;
    for (std::size_t k = 0; k < p_.cones.size(); ++k) {
      const FrictionCone& c = p_.cones[k];
      const double shear2 = F[c.index] * F[c.index] + F[c.index + 1] * F[c.index + 1];
      v[rows + static_cast<Eigen::Index>(k)] =
          delta_ > 0.0 ? std::sqrt(shear2 + delta_ * delta_) - c.friction * F[c.index + 2]
                       : shear2 - c.friction * c.friction * F[c.index + 2] * F[c.index + 2];
    }
    if (bandCount() > 0) {
      // The elastic phase 2's band: −band ≤ balance F − target ≤ band, as two rows a component.
      const Vector6 residual = p_.balance * F - p_.balanceTarget;
      v.segment<6>(bandStart) = residual.array() - band_;
      v.segment<6>(bandStart + 6) = -residual.array() - band_;
    }
    if (jacobian) {
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J(jacobian, inequalityCount(),
                                                                                            variableCount());
      J.setZero();
      J.topRows(rows) = p_.inequality;
      for (std::size_t k = 0; k < p_.cones.size(); ++k) {
        const FrictionCone& c = p_.cones[k];
        const Eigen::Index r = rows + static_cast<Eigen::Index>(k);
        if (delta_ > 0.0) {
          const double norm = std::sqrt(F[c.index] * F[c.index] + F[c.index + 1] * F[c.index + 1] + delta_ * delta_);
          J(r, c.index) = F[c.index] / norm;
          J(r, c.index + 1) = F[c.index + 1] / norm;
          J(r, c.index + 2) = -c.friction;
        } else {
          J(r, c.index) = 2.0 * F[c.index];
          J(r, c.index + 1) = 2.0 * F[c.index + 1];
          J(r, c.index + 2) = -2.0 * c.friction * c.friction * F[c.index + 2];
        }
      }
      if (bandCount() > 0) {
        J.middleRows(bandStart, 6) = p_.balance;
        J.middleRows(bandStart + 6, 6) = -p_.balance;
      }
    }
  }
  /// Hessian of cone k's constraint on (fx, fy) (its fz part is linear or, for the
  /// quadratic form, −2μ² on the diagonal, returned in `fz`).
  void coneHessian(const double* x, std::size_t k, Eigen::Matrix2d& shear, double& fz) const {
    const FrictionCone& c = p_.cones[k];
    if (delta_ > 0.0) {
      const Eigen::Vector2d t(x[c.index], x[c.index + 1]);
      const double norm = std::sqrt(t.squaredNorm() + delta_ * delta_);
      shear = (Eigen::Matrix2d::Identity() - t * t.transpose() / (norm * norm)) / norm;
      fz = 0.0;
    } else {
      shear = 2.0 * Eigen::Matrix2d::Identity();
      fz = -2.0 * c.friction * c.friction;
    }
  }
  Eigen::Map<const Eigen::VectorXd> wrenches(const double* x) const { return {x, p_.variableCount()}; }

 private:
  const ContactProblem& p_;
  BalanceMode mode_;
  double delta_, band_;
};

/// Wrenches, objective and active set of a solution x of `problem`.
void finishResult(const ContactProblem& problem, const double* x, InnerResult& result);

/// Multipliers by least squares on the active set (for solvers that do not return them).
void estimateMultipliers(const ContactProblem& problem, InnerResult& result);

/// What one run of a third-party solver on an InnerNlp gives back.
struct RunOutcome {
  bool converged = false;
  int iterations = 0;
  std::string message;
  bool hasMultipliers = false;
  Vector6 equalityMultipliers = Vector6::Zero();
  Eigen::VectorXd inequalityMultipliers;  ///< linear rows, cones, then the band's 12 rows, ≥ 0
  double coneSmoothing = 0.0;             ///< δ of the cone form the multipliers belong to (0: quadratic)
};

/// The result's multipliers: the solver's own (RunOutcome), converted to the conic form, or estimated.
void takeMultipliers(const ContactProblem& problem, const RunOutcome& outcome, InnerResult& result);

/// x: starting point in, solution out (InnerNlp::variableCount()). Solver-specific choices
/// (the cone form) are made by the runner from the problem it is given.
using NlpRunner = std::function<RunOutcome(const ContactProblem& problem, BalanceMode balance, double band,
                                            const InnerSettings& settings, Eigen::VectorXd& x)>;

/// The common flow (formulation.md §7): solve; if that fails or leaves the balance violated,
/// find the balance slack of least norm (min ‖wrenchToWorld F − W‖² under the contact
/// constraints), solve again with the balance shifted by it, and report Infeasible with that
/// slack when it is not zero. Fills the whole result.
void solveWithElasticFallback(const ContactProblem& problem, const InnerSettings& settings, const NlpRunner& solverRun,
                              InnerResult& result);

}  // namespace mcopt::inner_detail
