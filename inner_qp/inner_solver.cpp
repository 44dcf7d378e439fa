#include "inner_qp/inner_solver.hpp"

#include <Eigen/QR>
#include <chrono>
#include <sstream>

#include "inner_qp/inner_nlp.hpp"

namespace mcopt {

const char* toString(InnerStatus status) {
  switch (status) {
    case InnerStatus::Optimal: return "optimal";
    case InnerStatus::Infeasible: return "infeasible";
    case InnerStatus::Failed: return "failed";
  }
  return "failed";
}

namespace inner_detail {

double dataScale(const ContactProblem& p) {
  return 1.0 + p.hessian.cwiseAbs().maxCoeff() + p.gradient.cwiseAbs().maxCoeff() +
         p.balanceTarget.cwiseAbs().maxCoeff();
}

namespace {

// Stationarity ∇f + Aᵀλ + Gᵀμ + Σ ν ∇cone, on the wrench variables.
Eigen::VectorXd stationarity(const ContactProblem& p, const InnerResult& r) {
  const Eigen::VectorXd& F = r.wrenches;
  Eigen::VectorXd g = p.hessian * F + p.gradient + p.balance.transpose() * r.balanceMultipliers;
  if (p.inequality.rows() > 0) g += p.inequality.transpose() * r.inequalityMultipliers;
  for (std::size_t k = 0; k < p.cones.size(); ++k) {
    const FrictionCone& c = p.cones[k];
    const double nu = r.coneMultipliers[static_cast<Eigen::Index>(k)];
    g[c.index] += nu * 2.0 * F[c.index];
    g[c.index + 1] += nu * 2.0 * F[c.index + 1];
    g[c.index + 2] -= nu * 2.0 * c.friction * c.friction * F[c.index + 2];
  }
  return g;
}

double coneValue(const FrictionCone& c, const Eigen::VectorXd& F) {
  return F[c.index] * F[c.index] + F[c.index + 1] * F[c.index + 1] - c.friction * c.friction * F[c.index + 2] * F[c.index + 2];
}

}  // namespace

void finishResult(const ContactProblem& p, const double* x, InnerResult& r) {
  const int n = 6 * p.contactCount;
  r.wrenches = Eigen::Map<const Eigen::VectorXd>(x, n);
  r.objective = p.objective(r.wrenches);
  const double scale = dataScale(p);
  const double activeTolerance = 1e-7 * scale;
  r.activeSet.clear();
  const Eigen::Index rows = p.inequality.rows();
  const Eigen::VectorXd linear = p.inequality * r.wrenches - p.inequalityBound;
  for (Eigen::Index i = 0; i < rows; ++i)
    if (linear[i] >= -activeTolerance * (1.0 + p.inequality.row(i).cwiseAbs().maxCoeff() * r.wrenches.cwiseAbs().maxCoeff()))
      r.activeSet.push_back(static_cast<int>(i));
  for (std::size_t k = 0; k < p.cones.size(); ++k) {
    const FrictionCone& c = p.cones[k];
    // An unloaded contact (fz at zero) has a vanishing cone gradient: keep it out (formulation.md §7).
    const double fz = r.wrenches[c.index + 2];
    if (fz > std::sqrt(activeTolerance) && coneValue(c, r.wrenches) >= -activeTolerance * (1.0 + fz * fz))
      r.activeSet.push_back(static_cast<int>(rows + static_cast<Eigen::Index>(k)));
  }
}

void estimateMultipliers(const ContactProblem& p, InnerResult& r) {
  const int n = 6 * p.contactCount;
  const Eigen::Index rows = p.inequality.rows();
  const int active = static_cast<int>(r.activeSet.size());
  Eigen::MatrixXd A(n, 6 + active);
  A.leftCols<6>() = p.balance.transpose();
  for (int a = 0; a < active; ++a) {
    const int row = r.activeSet[static_cast<std::size_t>(a)];
    if (row < rows) {
      A.col(6 + a) = p.inequality.row(row).transpose();
    } else {
      const FrictionCone& c = p.cones[static_cast<std::size_t>(row - rows)];
      A.col(6 + a).setZero();
      A(c.index, 6 + a) = 2.0 * r.wrenches[c.index];
      A(c.index + 1, 6 + a) = 2.0 * r.wrenches[c.index + 1];
      A(c.index + 2, 6 + a) = -2.0 * c.friction * c.friction * r.wrenches[c.index + 2];
    }
  }
  const Eigen::VectorXd rhs = -(p.hessian * r.wrenches + p.gradient);
  Eigen::VectorXd multipliers = A.completeOrthogonalDecomposition().solve(rhs);
  r.balanceMultipliers = multipliers.head<6>();
  r.inequalityMultipliers.setZero(rows);
  r.coneMultipliers.setZero(static_cast<Eigen::Index>(p.cones.size()));
  for (int a = 0; a < active; ++a) {
    const int row = r.activeSet[static_cast<std::size_t>(a)];
    if (row < rows)
      r.inequalityMultipliers[row] = multipliers[6 + a];
    else
      r.coneMultipliers[row - rows] = multipliers[6 + a];
  }
}

void solveWithElasticFallback(const ContactProblem& p, const InnerSettings& settings, NlpRunner run,
                              InnerResult& r) {
  const auto start = std::chrono::steady_clock::now();
  const int n = 6 * p.contactCount;
  const double scale = dataScale(p);
  Eigen::VectorXd x(n);
  if (r.wrenches.size() == n && r.wrenches.allFinite())
    x = r.wrenches;  // warm start
  else
    x = p.balance.completeOrthogonalDecomposition().solve(Eigen::VectorXd(p.balanceTarget));  // least-norm balance
  RunOutcome outcome = run(p, true, settings, x);
  std::string diagnostics;
  Vector6 slack = Vector6::Zero();
  const ContactProblem* solved = &p;
  ContactProblem shifted;
  if (!outcome.converged || !x.allFinite() || p.constraintViolation(x) > settings.tolerance * scale) {
    std::ostringstream note;
    note << "first solve: " << outcome.message << (outcome.converged ? "" : " (not converged)") << ", relative violation "
         << p.constraintViolation(x) / scale << "; ";
    diagnostics = note.str();
    // Phase 1: least balance slack, min ‖B F − W‖² = Fᵀ BᵀB F − 2 WᵀB F + ‖W‖², contact constraints only.
    ContactProblem leastSlack = p;
    leastSlack.hessian = 2.0 * p.balance.transpose() * p.balance;
    leastSlack.hessian.diagonal().array() += p.tikhonov;
    leastSlack.gradient = -2.0 * p.balance.transpose() * p.balanceTarget;
    leastSlack.constant = p.balanceTarget.squaredNorm();
    Eigen::VectorXd y = x.allFinite() ? x : Eigen::VectorXd::Zero(n);
    const RunOutcome phase1 = run(leastSlack, false, settings, y);
    slack = p.balanceTarget - p.balance * y;
    if (slack.cwiseAbs().maxCoeff() <= settings.tolerance * scale) slack.setZero();
    // Phase 2: the real objective with the balance shifted by that slack.
    shifted = p;
    shifted.balanceTarget -= slack;
    solved = &shifted;
    x = y;
    const int earlier = outcome.iterations + phase1.iterations;
    outcome = run(shifted, true, settings, x);
    outcome.iterations += earlier;
    if (!outcome.converged || !x.allFinite() || shifted.constraintViolation(x) > settings.tolerance * scale) {
      // The shifted feasible set can shrink to the cones' apex (every contact unloaded),
      // where gradient-based steps stall; the least-slack point is feasible for it.
      x = y;
      outcome.converged = phase1.converged;
      outcome.hasMultipliers = false;
      outcome.message += "; the objective step after the least-slack phase failed, its point is returned";
    }
  }
  finishResult(*solved, x.data(), r);
  r.objective = p.objective(r.wrenches);
  r.balanceSlack = slack;
  if (outcome.hasMultipliers) {
    r.balanceMultipliers = outcome.equalityMultipliers;
    const Eigen::Index rows = p.inequality.rows();
    r.inequalityMultipliers = outcome.inequalityMultipliers.head(rows).cwiseMax(0.0);
    r.coneMultipliers = outcome.inequalityMultipliers.tail(static_cast<Eigen::Index>(p.cones.size())).cwiseMax(0.0);
  } else {
    estimateMultipliers(*solved, r);
  }
  r.iterations = outcome.iterations;
  r.message = diagnostics + outcome.message;
  r.kktResidual = kktResidual(p, r);
  // A stop is a solution only where the KKT conditions hold (style.md §9: re-check, never
  // trust a stop). An infeasible sample rests on the least balance slack having been found.
  const bool stopped = outcome.converged && r.wrenches.allFinite() &&
                       solved->constraintViolation(r.wrenches) <= settings.tolerance * scale;
  if (stopped && slack.cwiseAbs().maxCoeff() > 0.0)
    r.status = InnerStatus::Infeasible;
  else if (stopped && r.kktResidual <= settings.kktTolerance)
    r.status = InnerStatus::Optimal;
  else
    r.status = InnerStatus::Failed;
  r.solveTimeUs = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace inner_detail

double kktResidual(const ContactProblem& p, const InnerResult& r) {
  using inner_detail::dataScale;
  const double scale = dataScale(p);
  const Eigen::VectorXd g = inner_detail::stationarity(p, r);
  double residual = g.cwiseAbs().maxCoeff();
  // Feasibility (with the slack in the elastic problem).
  ContactProblem shifted = p;
  shifted.balanceTarget -= r.balanceSlack;
  residual = std::max(residual, shifted.constraintViolation(r.wrenches));
  // Dual feasibility and complementarity.
  const Eigen::VectorXd linear = p.inequality * r.wrenches - p.inequalityBound;
  for (Eigen::Index i = 0; i < linear.size(); ++i) {
    residual = std::max(residual, -r.inequalityMultipliers[i]);
    residual = std::max(residual, std::abs(r.inequalityMultipliers[i] * linear[i]));
  }
  for (std::size_t k = 0; k < p.cones.size(); ++k) {
    const double nu = r.coneMultipliers[static_cast<Eigen::Index>(k)];
    residual = std::max(residual, -nu);
    residual = std::max(residual, std::abs(nu * inner_detail::coneValue(p.cones[k], r.wrenches)));
  }
  return residual / scale;
}

}  // namespace mcopt
