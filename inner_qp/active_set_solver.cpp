// SPDX-License-Identifier: BSD-3-Clause
// The in-house inner solver (formulation.md §7): an SQP loop over the friction cones with
// a dual active-set QP (dual_active_set_qp.hpp) inside, warm-started from the previous
// sample's result, allocation-free once it has seen a problem of the same size.
//
// The cone ‖(fx, fy)‖ ≤ μ fz is taken in its convex form c = ‖f_t‖ − μ fz ≤ 0. Each QP
// holds, per cone, tangent planes uᵀ f_t ≤ μ fz (u a unit vector): eight fixed ones (an
// octagon circumscribing the cone), the linearisation at the current iterate (the SQP
// constraint) and up to three earlier linearisations. Every tangent plane is valid for the
// cone, so each QP is a relaxation of the inner problem:
//   - a QP with no feasible point proves the sample infeasible (then the elastic phases);
//   - at an unloaded contact (the cone's apex, where c has no gradient) the planes pin
//     f_t = 0 with f_z = 0 and their multipliers add up to a point of the dual cone — the
//     apex certificate, with no special case.
// The Hessian of the Lagrangian adds ν ∇²c = ν (1 − u uᵀ) / ‖f_t‖ on each active cone's
// shear block (ν = y_z / μ from the cone's multiplier), which makes the steps Newton steps:
// near the solution the cone violation squares from one iteration to the next.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numbers>

#include "inner_qp/dual_active_set_qp.hpp"
#include "inner_qp/inner_nlp.hpp"

namespace mcopt {

namespace {

using inner_detail::DualActiveSetQp;

constexpr int kFixedPlanes = 8;
constexpr int kLinearisation = kFixedPlanes;  // slot of the current linearisation
constexpr int kHistory = 3;
constexpr int kSlots = kFixedPlanes + 1 + kHistory;
constexpr int kMaxSqpIterations = 60;
// Linearisations closer than this angle to the current one are not kept in the history:
// near-duplicate planes only make the working set ill-conditioned.
constexpr double kHistoryAngle = 0.02;
// A shear below this fraction of the force scale is the cone's apex (an unloaded contact):
// no linearisation there and no curvature, which grows as 1/‖f_t‖; the fixed planes hold it.
constexpr double kApex = 1e-9;

struct ConePlanes {
  std::array<Eigen::Vector2d, kSlots> direction;
  std::array<bool, kSlots> used{};
  int nextHistory = 0;

  void reset() {
    for (int s = 0; s < kFixedPlanes; ++s) {
      const double angle = 2.0 * std::numbers::pi * s / kFixedPlanes;
      direction[s] = Eigen::Vector2d(std::cos(angle), std::sin(angle));
      used[s] = true;
    }
    for (int s = kFixedPlanes; s < kSlots; ++s) used[s] = false;
    nextHistory = 0;
  }
  /// The linearisation moves to u; the previous one goes to the history when it differs enough.
  void linearise(const Eigen::Vector2d& u) {
    if (used[kLinearisation] && std::acos(std::clamp(direction[kLinearisation].dot(u), -1.0, 1.0)) > kHistoryAngle) {
      const int slot = kLinearisation + 1 + nextHistory;
      direction[slot] = direction[kLinearisation];
      used[slot] = true;
      nextHistory = (nextHistory + 1) % kHistory;
    }
    direction[kLinearisation] = u;
    used[kLinearisation] = true;
  }
};

enum class SqpOutcome { Converged, IterationLimit, Infeasible, Failed };

class ActiveSetSolver final : public InnerSolver {
 public:
  explicit ActiveSetSolver(const InnerSettings& settings) : settings_(settings) {}
  std::string name() const override { return "active-set"; }
  void solve(const ContactProblem& problem, InnerResult& result) override;

 private:
  void resize(const ContactProblem& p);
  /// One SQP run on `qp` (whose gradient and equalities the caller has written), from the
  /// point x_ with cone multipliers coneNu_ and QP working set workingSet_. The cone data
  /// come from p; the Hessian without the cones' curvature is `baseHessian`; `extraRows`
  /// rows the caller wrote after the cones' planes join the inequalities.
  SqpOutcome runSqp(const ContactProblem& p, DualActiveSetQp& qp, const Eigen::MatrixXd& baseHessian, int extraRows,
                    int& iterations, std::string& why);
  void writeResult(const ContactProblem& p, const DualActiveSetQp& qp, bool balanceBand, InnerResult& r) const;

  InnerSettings settings_;
  DualActiveSetQp qp_, leastSlack_, shiftedBalance_;
  Eigen::MatrixXd leastSlackHessian_;
  Eigen::VectorXd leastSlackPoint_;  ///< phase 1's point (InnerResult::leastSlackWrenches)
  std::vector<ConePlanes> planes_;
  Eigen::VectorXd x_, previousX_, coneNu_;
  std::vector<int> workingSet_;
  int variables_ = -1, rows_ = -1, cones_ = -1;
};

void ActiveSetSolver::resize(const ContactProblem& p) {
  const int n = p.variableCount();
  const int rows = static_cast<int>(p.inequality.rows());
  const int cones = static_cast<int>(p.cones.size());
  if (n == variables_ && rows == rows_ && cones == cones_) return;
  variables_ = n, rows_ = rows, cones_ = cones;
  qp_.resize(n, 6, rows + kSlots * cones);
  leastSlack_.resize(n, 0, rows + kSlots * cones);
  shiftedBalance_.resize(n, 0, rows + kSlots * cones + 12);
  leastSlackHessian_.setZero(n, n);
  leastSlackPoint_.setZero(n);
  planes_.assign(static_cast<std::size_t>(cones), ConePlanes{});
  x_.setZero(n);
  previousX_.setZero(n);
  coneNu_.setZero(cones);
  workingSet_.reserve(static_cast<std::size_t>(rows + kSlots * cones));
}

SqpOutcome ActiveSetSolver::runSqp(const ContactProblem& p, DualActiveSetQp& qp, const Eigen::MatrixXd& baseHessian,
                                   int extraRows, int& iterations, std::string& why) {
  const int rows = rows_;
  qp.inequality.topRows(rows) = p.inequality;
  qp.inequalityBound.head(rows) = p.inequalityBound;
  qp.inequalityCount = rows + kSlots * cones_ + extraRows;
  const double violationTolerance = 1e-13;
  const double dataScale = p.dataScale();
  for (int sqp = 0; sqp < kMaxSqpIterations; ++sqp) {
    const double forceScale = 1.0 + x_.cwiseAbs().maxCoeff();
    qp.hessian = baseHessian;
    for (int k = 0; k < cones_; ++k) {
      const FrictionCone& cone = p.cones[static_cast<std::size_t>(k)];
      ConePlanes& planes = planes_[static_cast<std::size_t>(k)];
      const Eigen::Vector2d shear = x_.segment<2>(cone.index);
      const double norm = shear.norm();
      if (norm > kApex * forceScale) {
        const Eigen::Vector2d u = shear / norm;
        planes.linearise(u);
        if (coneNu_[k] > 0.0)  // ν ∇²c on the shear block
          qp.hessian.block<2, 2>(cone.index, cone.index) +=
              (coneNu_[k] / norm) * (Eigen::Matrix2d::Identity() - u * u.transpose());
      }
      for (int s = 0; s < kSlots; ++s) {
        const int row = rows + kSlots * k + s;
        qp.inequality.row(row).setZero();
        if (planes.used[s]) {
          qp.inequality(row, cone.index) = planes.direction[s].x();
          qp.inequality(row, cone.index + 1) = planes.direction[s].y();
          qp.inequality(row, cone.index + 2) = -cone.friction;
          qp.inequalityBound[row] = 0.0;
        } else {
          qp.inequality(row, cone.index + 2) = -1.0;  // fz ≥ −1e300: never binding, keeps the row scale
          qp.inequalityBound[row] = 1e300;
        }
      }
    }
    const DualActiveSetQp::Status status = qp.solve(workingSet_, settings_.maxIterations, violationTolerance);
    iterations += qp.iterations;
    if (status == DualActiveSetQp::Status::Infeasible) return SqpOutcome::Infeasible;
    if (status != DualActiveSetQp::Status::Optimal) {
      why = status == DualActiveSetQp::Status::IterationLimit ? "QP iteration limit" : "Hessian not positive definite";
      return SqpOutcome::Failed;
    }
    workingSet_ = qp.activeSet;
    previousX_ = x_;
    x_ = qp.x;
    // The cones' multipliers ν = y_z / μ, y = Σ_planes μ_plane (−u, μ), and what the QP's
    // model still misses: the cone violation and the curvature term's stationarity error.
    double coneViolation = 0.0, curvatureError = 0.0;
    for (int k = 0; k < cones_; ++k) {
      const FrictionCone& cone = p.cones[static_cast<std::size_t>(k)];
      double yz = 0.0;
      for (int s = 0; s < kSlots; ++s) yz += qp.inequalityMultipliers[rows + kSlots * k + s] * cone.friction;
      const double oldNu = coneNu_[k];
      coneNu_[k] = yz / cone.friction;
      const double fz = x_[cone.index + 2];
      coneViolation = std::max(coneViolation, (x_.segment<2>(cone.index).norm() - cone.friction * fz) / (1.0 + std::abs(fz)));
      // (H_k − H)(x_{k+1} − x_k): the curvature's part of the stationarity residual.
      const Eigen::Vector2d oldShear = previousX_.segment<2>(cone.index);
      const double oldNorm = oldShear.norm();
      if (oldNu > 0.0 && oldNorm > kApex * forceScale) {
        const Eigen::Vector2d u = oldShear / oldNorm;
        const Eigen::Vector2d move = x_.segment<2>(cone.index) - oldShear;
        curvatureError = std::max(curvatureError, oldNu / oldNorm * (move - u * u.dot(move)).norm());
      }
    }
    if (coneViolation <= 1e-13 && curvatureError <= 1e-12 * dataScale) return SqpOutcome::Converged;
  }
  why = "SQP iteration limit (the KKT residual decides)";
  return SqpOutcome::IterationLimit;
}

void ActiveSetSolver::writeResult(const ContactProblem& p, const DualActiveSetQp& qp, bool balanceBand,
                                  InnerResult& r) const {
  const int rows = rows_;
  r.wrenches = x_;
  r.objective = p.objective(r.wrenches);
  if (balanceBand) {  // rows B F ≤ target + ε, then −B F ≤ −target + ε: λ = μ₊ − μ₋
    const int band = rows + kSlots * cones_;
    for (int k = 0; k < 6; ++k)
      r.balanceMultipliers[k] = qp.inequalityMultipliers[band + k] - qp.inequalityMultipliers[band + 6 + k];
  } else {
    r.balanceMultipliers = Vector6(qp.equalityMultipliers);
  }
  r.inequalityMultipliers = qp.inequalityMultipliers.head(rows);
  r.coneMultipliers.setZero(3 * cones_);
  r.activeSet.clear();
  r.activeSet.reserve(static_cast<std::size_t>(rows + cones_));  // allocates on the first solve only
  for (int row : qp.activeSet)
    if (row < rows) r.activeSet.push_back(row);
  std::sort(r.activeSet.begin(), r.activeSet.end());
  for (int k = 0; k < cones_; ++k) {
    const FrictionCone& cone = p.cones[static_cast<std::size_t>(k)];
    const ConePlanes& planes = planes_[static_cast<std::size_t>(k)];
    auto y = r.coneMultipliers.segment<3>(3 * k);
    for (int s = 0; s < kSlots; ++s) {
      const double mu = qp.inequalityMultipliers[rows + kSlots * k + s];
      if (mu <= 0.0 || !planes.used[s]) continue;
      y[0] -= mu * planes.direction[s].x();
      y[1] -= mu * planes.direction[s].y();
      y[2] += mu * cone.friction;
    }
    if (y[2] > 0.0) r.activeSet.push_back(rows + k);
  }
}

void ActiveSetSolver::solve(const ContactProblem& p, InnerResult& r) {
  const auto start = std::chrono::steady_clock::now();
  resize(p);
  const int n = variables_;
  const double scale = p.dataScale();
  // Warm start (formulation.md §7): the previous sample's wrenches give the linearisation
  // points and the curvature, its active set the QP's first working set.
  const bool warm = settings_.warmStart && r.wrenches.size() == n && r.wrenches.allFinite() &&
                    r.coneMultipliers.size() == 3 * cones_ && r.inequalityMultipliers.size() == rows_;
  for (ConePlanes& planes : planes_) planes.reset();
  workingSet_.clear();
  if (warm) {
    x_ = r.wrenches;
    for (int k = 0; k < cones_; ++k) coneNu_[k] = std::max(r.coneMultipliers[3 * k + 2], 0.0) / p.cones[static_cast<std::size_t>(k)].friction;
    for (int row : r.activeSet) {
      if (row < rows_)
        workingSet_.push_back(row);
      else if (row - rows_ < cones_)
        workingSet_.push_back(rows_ + kSlots * (row - rows_) + kLinearisation);
    }
  } else {
    x_.setZero();
    coneNu_.setZero();
  }

  int iterations = 0;
  std::string why;
  qp_.hessian = p.hessian;
  qp_.gradient = p.gradient;
  qp_.equality = p.balance;
  qp_.equalityTarget = p.balanceTarget;
  r.balanceSlack.setZero();
  SqpOutcome outcome = runSqp(p, qp_, p.hessian, 0, iterations, why);
  const DualActiveSetQp* solved = &qp_;
  r.message.clear();
  if (outcome == SqpOutcome::Infeasible) {
    // Elastic phases (inner_solver.hpp). Every QP is a relaxation of the inner problem, so
    // an infeasible QP proves the sample infeasible. Phase 1: the least balance slack under
    // the contact constraints, min ‖B F − W‖² + ε ‖F‖².
    leastSlackHessian_.noalias() = 2.0 * p.balance.transpose() * p.balance;
    leastSlackHessian_.diagonal().array() += std::max(p.tikhonov, 1e-12 * scale);
    leastSlack_.gradient.noalias() = -2.0 * p.balance.transpose() * p.balanceTarget;
    for (ConePlanes& planes : planes_) planes.reset();
    workingSet_.clear();
    coneNu_.setZero();
    const SqpOutcome phase1 = runSqp(p, leastSlack_, leastSlackHessian_, 0, iterations, why);
    if (phase1 != SqpOutcome::Converged && phase1 != SqpOutcome::IterationLimit) {
      outcome = SqpOutcome::Failed;
      if (why.empty()) why = "the least-slack phase found no point";
    } else {
      // Phase 2: the objective with the balance shifted by that slack. The shifted balance
      // only touches the admissible set (a face of it), so an equality there is degenerate
      // to roundoff; it is held to a band of ±1e-9 of the data's scale instead, and the slack
      // reported is the returned point's own, W − B F.
      leastSlackPoint_ = x_;
      const Vector6 target = p.balance * x_;
      const double band = settings_.tolerance * scale;
      const int first = rows_ + kSlots * cones_;
      shiftedBalance_.hessian = p.hessian;
      shiftedBalance_.gradient = p.gradient;
      shiftedBalance_.inequality.middleRows(first, 6) = p.balance;
      shiftedBalance_.inequality.middleRows(first + 6, 6) = -p.balance;
      shiftedBalance_.inequalityBound.segment<6>(first) = target.array() + band;
      shiftedBalance_.inequalityBound.segment<6>(first + 6) = -target.array() + band;
      outcome = runSqp(p, shiftedBalance_, p.hessian, 12, iterations, why);
      solved = &shiftedBalance_;
      if (outcome == SqpOutcome::Infeasible) why = "the shifted balance is infeasible (should not happen: report it)";
    }
  }
  writeResult(p, *solved, solved == &shiftedBalance_, r);
  if (solved == &shiftedBalance_) {
    r.balanceSlack = p.balanceTarget - p.balance * r.wrenches;
    if (r.balanceSlack.cwiseAbs().maxCoeff() <= settings_.tolerance * scale) r.balanceSlack.setZero();
  }
  r.iterations = iterations;
  r.kktResidual = kktResidual(p, r);
  const bool converged =
      (outcome == SqpOutcome::Converged || outcome == SqpOutcome::IterationLimit) && r.wrenches.allFinite();
  if (converged && r.balanceSlack.cwiseAbs().maxCoeff() > 0.0) {
    r.status = InnerStatus::Infeasible;
    r.leastSlackWrenches = leastSlackPoint_;
  }
  else if (converged && r.kktResidual <= settings_.kktTolerance)
    r.status = InnerStatus::Optimal;
  else
    r.status = InnerStatus::Failed;
  if (!why.empty()) r.message = "active-set: " + why;
  r.solveTimeUs = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

std::unique_ptr<InnerSolver> makeActiveSetSolver(const InnerSettings& settings) {
  return std::make_unique<ActiveSetSolver>(settings);
}

}  // namespace mcopt
