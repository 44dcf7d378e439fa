// SPDX-License-Identifier: BSD-3-Clause
// The barrier inner solver (docs/theory/inner-problem.md, "The barrier-smoothed inner
// problem"): the point of the central path at a fixed barrier parameter μ > 0,
//     min ½ Fᵀ H F + cᵀ F − μ Σ_i log s_i   subject to   B F = W,  G F + s = b,
// found by a primal-dual interior-point method that stops *at* μ instead of driving it to
// zero. Its solution F*_μ is a smooth (C∞) function of the data wherever the interior of the
// admissible set is not empty, so the outer problem's criterion has no kink where the exact
// optimum's active set switches; the price is a bounded inner suboptimality: the duality gap
// at the central point is Σ s_i z_i = rows × μ (in the objective's units, W), which bounds
// how far the objective lies above the exact minimum.
//
// Linear contact models only (pyramid, wrench cone, point): the report model's second-order
// cones would need their own barrier, and the solver says so. An infeasible sample (no
// admissible wrench balances the robot) has no central path: its elastic answer comes from
// the active-set solver, unchanged (inner_solver.hpp), and so does a sample whose balance rows
// are dependent (the Newton system is singular), which the message states.
//
// Each Newton step solves the condensed system
//     [ H + Gᵀ S⁻¹ Z G   Bᵀ ] [ dF ]   [ −r_d + Gᵀ S⁻¹ (r_c − Z r_p) ]
//     [ B                 0  ] [ dλ ] = [ −r_b                        ]
// with r_d = H F + c + Bᵀλ + Gᵀz, r_b = B F − W, r_p = G F + s − b, r_c = s∘z − σ; then
// ds = −r_p − G dF and dz = S⁻¹(−r_c − Z ds). The same matrix at the solution is the
// sensitivity system of sensitivity/inner_sensitivity.hpp for a barrier answer.
// Warm start: the previous answer (this sample's, or its neighbour's) is a strictly interior
// point of the same rows (they live in the contact frames), so a few Newton steps re-centre it.
#include <Eigen/LU>
#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/errors.hpp"
#include "inner_qp/inner_solver.hpp"

namespace mcopt {

namespace {

constexpr double kFractionToBoundary = 0.995;
constexpr double kCentring = 0.2;  ///< σ: the complementarity target as a fraction of the current mean, down to μ

class BarrierSolver final : public InnerSolver {
 public:
  explicit BarrierSolver(const InnerSettings& settings) : settings_(settings), exact_(makeActiveSetSolver(settings)) {
    if (!(settings.barrier > 0.0) || !std::isfinite(settings.barrier))
      throw InputError("inner solver barrier: the barrier parameter must be a positive number; got " +
                       std::to_string(settings.barrier));
  }
  std::string name() const override { return "barrier"; }
  void solve(const ContactProblem& problem, InnerResult& result) override;

 private:
  enum class Outcome { Converged, NotConverged, Singular };
  void resize(const ContactProblem& p);
  /// Newton iterations from (F_, lambda_, s_, z_); Converged when the residuals reach the
  /// tolerance at complementarity μ.
  Outcome iterate(const ContactProblem& p, int& iterations);
  /// A start from an exact optimum: its wrenches, with every slack lifted off zero.
  void startFrom(const ContactProblem& p, const InnerResult& exact);
  double residualNorm(const ContactProblem& p) const;

  InnerSettings settings_;
  std::unique_ptr<InnerSolver> exact_;
  InnerResult exactResult_;
  int variables_ = -1, rows_ = -1;
  Eigen::VectorXd F_, s_, z_, dF_, ds_, dz_, rd_, rp_, rc_, rhs_, step_, scaledRp_, ratio_;
  Vector6 lambda_ = Vector6::Zero(), rb_ = Vector6::Zero();
  Eigen::MatrixXd weightedG_, system_;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
};

void BarrierSolver::resize(const ContactProblem& p) {
  const int n = p.variableCount(), rows = static_cast<int>(p.inequality.rows());
  if (n == variables_ && rows == rows_) return;
  variables_ = n, rows_ = rows;
  for (Eigen::VectorXd* v : {&F_, &dF_, &rd_}) v->setZero(n);
  for (Eigen::VectorXd* v : {&s_, &z_, &ds_, &dz_, &rp_, &rc_, &scaledRp_, &ratio_}) v->setZero(rows);
  rhs_.setZero(n + 6), step_.setZero(n + 6);
  weightedG_.setZero(rows, n);
  system_.setZero(n + 6, n + 6);
  lu_ = Eigen::PartialPivLU<Eigen::MatrixXd>(n + 6);
}

double BarrierSolver::residualNorm(const ContactProblem& p) const {
  // Stationarity, balance and rows relative to the data's scale (kktResidual's measure);
  // centrality relative to μ.
  const double scale = p.dataScale();
  double r = std::max({rd_.cwiseAbs().maxCoeff(), rb_.cwiseAbs().maxCoeff(), rows_ > 0 ? rp_.cwiseAbs().maxCoeff() : 0.0}) / scale;
  if (rows_ > 0) r = std::max(r, ((s_.array() * z_.array()) - settings_.barrier).abs().maxCoeff() / settings_.barrier * 1e-3);
  return r;
}

void BarrierSolver::startFrom(const ContactProblem& p, const InnerResult& exact) {
  const double mu = settings_.barrier;
  F_ = exact.wrenches;
  lambda_ = exact.balanceMultipliers;
  s_.noalias() = p.inequalityBound - p.inequality * F_;
  for (int i = 0; i < rows_; ++i) {
    // Off the boundary by the distance at which the exact multiplier would meet μ, at least
    // √μ (in the row's units) so that a weakly active row starts inside too.
    const double multiplier = exact.inequalityMultipliers.size() == rows_ ? std::max(exact.inequalityMultipliers[i], 0.0) : 0.0;
    s_[i] = std::max({s_[i], std::sqrt(mu), multiplier > 0.0 ? mu / multiplier : 0.0});
    z_[i] = std::max(multiplier, mu / s_[i]);
  }
}

BarrierSolver::Outcome BarrierSolver::iterate(const ContactProblem& p, int& iterations) {
  const double mu = settings_.barrier;
  const int n = variables_;
  const double tolerance = settings_.tolerance;
  double best = std::numeric_limits<double>::infinity();
  int stalled = 0;
  for (int it = 0; it < settings_.maxIterations; ++it) {
    rd_ = p.gradient;
    rd_.noalias() += p.hessian * F_;
    rd_.noalias() += p.balance.transpose() * lambda_;
    if (rows_ > 0) rd_.noalias() += p.inequality.transpose() * z_;
    rb_.noalias() = p.balance * F_;
    rb_ -= p.balanceTarget;
    rp_ = s_ - p.inequalityBound;
    rp_.noalias() += p.inequality * F_;
    const double residual = residualNorm(p);
    // Converged where the residuals stop falling (rounding) once within the tolerance; or at
    // a residual far below it.
    if (residual <= tolerance) {
      if (residual <= 1e-6 * tolerance || residual > 0.5 * best || stalled >= 2) return Outcome::Converged;
    }
    if (residual < 0.5 * best)
      stalled = 0;
    else
      ++stalled;
    best = std::min(best, residual);
    ++iterations;
    const double mean = rows_ > 0 ? s_.dot(z_) / rows_ : mu;
    const double target = std::max(mu, kCentring * mean);
    rc_ = (s_.array() * z_.array() - target).matrix();
    // The condensed Newton system (header).
    ratio_ = (z_.array() / s_.array()).matrix();
    weightedG_.noalias() = ratio_.asDiagonal() * p.inequality;
    system_.setZero();
    system_.topLeftCorner(n, n) = p.hessian;
    system_.topLeftCorner(n, n).noalias() += p.inequality.transpose() * weightedG_;
    system_.block(n, 0, 6, n) = p.balance;
    system_.block(0, n, n, 6) = p.balance.transpose();
    scaledRp_ = ((rc_.array() - z_.array() * rp_.array()) / s_.array()).matrix();
    rhs_.head(n) = -rd_;
    rhs_.head(n).noalias() += p.inequality.transpose() * scaledRp_;
    rhs_.tail<6>() = -rb_;
    lu_.compute(system_);
    step_.noalias() = lu_.solve(rhs_);
    if (!step_.allFinite()) return Outcome::Singular;
    const auto pivots = lu_.matrixLU().diagonal().cwiseAbs();
    if (pivots.minCoeff() <= 1e-14 * pivots.maxCoeff()) return Outcome::Singular;
    dF_ = step_.head(n);
    ds_ = -rp_;
    ds_.noalias() -= p.inequality * dF_;
    dz_ = ((-rc_.array() - z_.array() * ds_.array()) / s_.array()).matrix();
    // Fraction to the boundary, one step length for primal and dual.
    double alpha = 1.0;
    for (int i = 0; i < rows_; ++i) {
      if (ds_[i] < 0.0) alpha = std::min(alpha, -kFractionToBoundary * s_[i] / ds_[i]);
      if (dz_[i] < 0.0) alpha = std::min(alpha, -kFractionToBoundary * z_[i] / dz_[i]);
    }
    F_ += alpha * dF_;
    lambda_ += alpha * step_.tail<6>();
    s_ += alpha * ds_;
    z_ += alpha * dz_;
  }
  return Outcome::NotConverged;
}

void BarrierSolver::solve(const ContactProblem& p, InnerResult& r) {
  const auto start = std::chrono::steady_clock::now();
  if (!p.cones.empty())
    throw InputError("inner solver barrier: the contact model has second-order friction cones (the report model), "
                     "which the barrier solver does not smooth; use contact_model pyramid or wrench-cone");
  resize(p);
  const int n = variables_;
  int iterations = 0;
  std::string message;
  // Warm start from a previous barrier answer of the same μ and rows: strictly inside.
  bool warm = settings_.warmStart && r.barrier == settings_.barrier && r.wrenches.size() == n && r.wrenches.allFinite() &&
              r.inequalityMultipliers.size() == rows_;
  if (warm) {
    F_ = r.wrenches;
    s_.noalias() = p.inequalityBound - p.inequality * F_;
    z_ = r.inequalityMultipliers;
    warm = (rows_ == 0 || (s_.minCoeff() > 0.0 && z_.minCoeff() > 0.0));
    lambda_ = r.balanceMultipliers;
  }
  Outcome outcome = Outcome::NotConverged;
  if (warm) outcome = iterate(p, iterations);
  if (outcome != Outcome::Converged) {
    // Cold (or a warm start that did not converge): the exact optimum first, which also
    // tells an infeasible sample; then the central path from it.
    exactResult_.wrenches = r.wrenches;
    exactResult_.activeSet = r.activeSet;
    exactResult_.inequalityMultipliers = r.inequalityMultipliers;
    exactResult_.coneMultipliers = r.coneMultipliers;
    if (r.barrier > 0.0) exactResult_.activeSet.clear();
    exact_->solve(p, exactResult_);
    iterations += exactResult_.iterations;
    if (exactResult_.status != InnerStatus::Optimal) {
      const double elapsed = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
      r = exactResult_;
      r.barrier = 0.0;
      r.iterations = iterations;
      r.solveTimeUs = elapsed;
      r.message = "barrier: no central path (the active-set solver's answer); " + r.message;
      return;
    }
    startFrom(p, exactResult_);
    outcome = iterate(p, iterations);
    if (outcome != Outcome::Converged) {
      r = exactResult_;
      r.barrier = 0.0;
      r.iterations = iterations;
      if (outcome == Outcome::Singular) {
        r.message = "barrier: the Newton system is singular (dependent balance rows); the active-set solver's exact answer";
      } else {
        r.status = InnerStatus::Failed;
        r.message = "barrier: the central path at mu = " + std::to_string(settings_.barrier) + " was not reached in " +
                    std::to_string(settings_.maxIterations) + " Newton steps";
      }
      r.solveTimeUs = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
      return;
    }
  }
  r.wrenches = F_;
  r.objective = p.objective(F_);
  r.balanceMultipliers = lambda_;
  r.inequalityMultipliers = z_;
  r.coneMultipliers.resize(0);
  r.activeSet.clear();
  r.balanceSlack.setZero();
  r.leastSlackWrenches.resize(0);
  r.barrier = settings_.barrier;
  r.polished = false;
  r.iterations = iterations;
  r.kktResidual = kktResidual(p, r);
  r.status = r.kktResidual <= settings_.kktTolerance ? InnerStatus::Optimal : InnerStatus::Failed;
  r.message = message;
  r.solveTimeUs = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

std::unique_ptr<InnerSolver> makeBarrierSolver(const InnerSettings& settings) {
  return std::make_unique<BarrierSolver>(settings);
}

}  // namespace mcopt
