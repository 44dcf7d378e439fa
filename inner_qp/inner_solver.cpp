// SPDX-License-Identifier: BSD-3-Clause
#include "inner_qp/inner_solver.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <chrono>
#include <optional>
#include <sstream>

#include "core/errors.hpp"
#include "core/registry.hpp"
#include "inner_qp/dual_active_set_qp.hpp"
#include "inner_qp/answer_polishing.hpp"
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

// Factories of solvers known only by name (each in its own file).
std::unique_ptr<InnerSolver> makeAugLagMmaSolver(const InnerSettings& settings);
std::unique_ptr<InnerSolver> makeAugLagLbfgsSolver(const InnerSettings& settings);

const std::vector<InnerSolverEntry>& innerSolvers() {
  static const std::vector<InnerSolverEntry> registry = {
      {"active-set", "ours: a dual active-set QP in an SQP loop over the cones, warm-started along the motion",
       makeActiveSetSolver},
      {"slsqp", "NLopt's SLSQP (sequential quadratic programming; the report's FSQP analogue)", makeSlsqpSolver},
      {"ipopt", "Ipopt's interior point, one NLP a solve (the report's baseline)", makeIpoptSolver},
      {"barrier", "ours: the central path of a fixed barrier parameter, a smooth answer for the outer problem (linear contact models)",
       makeBarrierSolver},
      {"auglag-mma", "NLopt's augmented Lagrangian over every constraint, MMA (moving asymptotes) on its subproblems",
       makeAugLagMmaSolver},
      {"auglag-lbfgs", "NLopt's augmented Lagrangian over every constraint, L-BFGS on its subproblems",
       makeAugLagLbfgsSolver},
  };
  return registry;
}

const std::vector<std::string>& innerSolverNames() {
  static const std::vector<std::string> names = registryNames(innerSolvers());
  return names;
}

bool isInnerSolverName(const std::string& name) {
  const auto& names = innerSolverNames();
  return std::find(names.begin(), names.end(), name) != names.end();
}

std::string innerSolverList() { return alternatives(innerSolverNames()); }

std::unique_ptr<InnerSolver> makeInnerSolver(const std::string& name, const InnerSettings& settings) {
  if (const InnerSolverEntry* e = findInRegistry(innerSolvers(), name)) return e->make(settings);
  throw InputError("solver: expected " + innerSolverList() + "; got '" + name + "'");
}

namespace inner_detail {

namespace {

double coneValue(const FrictionCone& c, const Eigen::VectorXd& F) {
  return F[c.index] * F[c.index] + F[c.index + 1] * F[c.index + 1] - c.friction * c.friction * F[c.index + 2] * F[c.index + 2];
}

/// Component j of the stationarity residual H F + c + Bᵀλ + Gᵀμ − Σ E_iᵀ y_i, without temporaries.
double stationarity(const ContactProblem& p, const InnerResult& r, Eigen::Index j) {
  double g = p.hessian.col(j).dot(r.wrenches) + p.gradient[j] + p.balance.col(j).dot(r.balanceMultipliers);
  if (p.inequality.rows() > 0) g += p.inequality.col(j).dot(r.inequalityMultipliers);
  for (std::size_t k = 0; k < p.cones.size(); ++k) {
    const Eigen::Index offset = j - p.cones[k].index;
    if (offset >= 0 && offset < 3) g -= r.coneMultipliers[3 * static_cast<Eigen::Index>(k) + offset];
  }
  return g;
}

}  // namespace

void finishResult(const ContactProblem& p, const double* x, InnerResult& r) {
  const int n = p.variableCount();
  r.wrenches = Eigen::Map<const Eigen::VectorXd>(x, n);
  r.objective = p.objective(r.wrenches);
  const double scale = p.dataScale();
  const double activeTolerance = 1e-7 * scale;
  r.activeSet.clear();
  const Eigen::Index rows = p.inequality.rows();
  for (Eigen::Index i = 0; i < rows; ++i)
    if (p.inequality.row(i).dot(r.wrenches) - p.inequalityBound[i] >=
        -activeTolerance * (1.0 + p.inequality.row(i).cwiseAbs().maxCoeff() * r.wrenches.cwiseAbs().maxCoeff()))
      r.activeSet.push_back(static_cast<int>(i));
  for (std::size_t k = 0; k < p.cones.size(); ++k) {
    const FrictionCone& c = p.cones[k];
    // On the surface, or at the apex (an unloaded contact): the conic multiplier covers both.
    const double fz = r.wrenches[c.index + 2];
    if (coneValue(c, r.wrenches) >= -activeTolerance * (1.0 + fz * fz))
      r.activeSet.push_back(static_cast<int>(rows + static_cast<Eigen::Index>(k)));
  }
}

void estimateMultipliers(const ContactProblem& p, InnerResult& r) {
  // Columns: the balance rows, the active linear rows, and per active cone either its
  // surface normal (u, −μ) (coefficient ν ≥ 0, y = ν (−u, μ)) or, at the apex, the three
  // unit vectors on (fx, fy, fz) (coefficients −y: the dual-cone membership of y is then
  // checked by the KKT residual, not assumed).
  const int n = p.variableCount();
  const Eigen::Index rows = p.inequality.rows();
  const double apex = 1e-7 * p.dataScale();
  std::vector<std::pair<int, int>> columns;  // (active-set entry, component: -1 surface, 0..2 apex axis)
  for (std::size_t a = 0; a < r.activeSet.size(); ++a) {
    const int row = r.activeSet[a];
    if (row < rows) {
      columns.push_back({static_cast<int>(a), -1});
      continue;
    }
    const FrictionCone& c = p.cones[static_cast<std::size_t>(row - rows)];
    if (std::hypot(r.wrenches[c.index], r.wrenches[c.index + 1]) > apex)
      columns.push_back({static_cast<int>(a), -1});
    else
      for (int axis = 0; axis < 3; ++axis) columns.push_back({static_cast<int>(a), axis});
  }
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, 6 + static_cast<Eigen::Index>(columns.size()));
  A.leftCols<6>() = p.balance.transpose();
  for (std::size_t k = 0; k < columns.size(); ++k) {
    const auto [entry, axis] = columns[k];
    const int row = r.activeSet[static_cast<std::size_t>(entry)];
    const Eigen::Index col = 6 + static_cast<Eigen::Index>(k);
    if (row < rows) {
      A.col(col) = p.inequality.row(row).transpose();
      continue;
    }
    const FrictionCone& c = p.cones[static_cast<std::size_t>(row - rows)];
    if (axis >= 0) {
      A(c.index + axis, col) = 1.0;
    } else {
      const double shear = std::hypot(r.wrenches[c.index], r.wrenches[c.index + 1]);
      A(c.index, col) = r.wrenches[c.index] / shear;
      A(c.index + 1, col) = r.wrenches[c.index + 1] / shear;
      A(c.index + 2, col) = -c.friction;
    }
  }
  // Sign-constrained least squares, min ‖A m − rhs‖² + ε‖m‖² with the rows' and the cone
  // surfaces' multipliers ≥ 0: a least-squares estimate that ignored the signs would fail the
  // KKT check on points that satisfy it (the dual active-set QP does the work).
  const Eigen::VectorXd rhs = -(p.hessian * r.wrenches + p.gradient);
  const auto unknowns = static_cast<int>(A.cols());
  DualActiveSetQp leastSquares;
  leastSquares.resize(unknowns, 0, unknowns);
  leastSquares.hessian = A.transpose() * A;
  leastSquares.hessian.diagonal().array() += 1e-14 * (1.0 + leastSquares.hessian.diagonal().maxCoeff());
  leastSquares.gradient = -A.transpose() * rhs;
  for (std::size_t k = 0; k < columns.size(); ++k)
    if (columns[k].second < 0) {
      leastSquares.inequality(leastSquares.inequalityCount, 6 + static_cast<Eigen::Index>(k)) = -1.0;
      ++leastSquares.inequalityCount;
    }
  Eigen::VectorXd multipliers;
  if (leastSquares.solve({}, 10 * unknowns + 10, 1e-14) == DualActiveSetQp::Status::Optimal)
    multipliers = leastSquares.x;
  else
    multipliers = A.completeOrthogonalDecomposition().solve(rhs);
  r.balanceMultipliers = multipliers.head<6>();
  r.inequalityMultipliers.setZero(rows);
  r.coneMultipliers.setZero(3 * static_cast<Eigen::Index>(p.cones.size()));
  for (std::size_t k = 0; k < columns.size(); ++k) {
    const auto [entry, axis] = columns[k];
    const int row = r.activeSet[static_cast<std::size_t>(entry)];
    const double value = multipliers[6 + static_cast<Eigen::Index>(k)];
    if (row < rows) {
      r.inequalityMultipliers[row] = value;
      continue;
    }
    const Eigen::Index cone = row - rows;
    const FrictionCone& c = p.cones[static_cast<std::size_t>(cone)];
    if (axis >= 0) {
      r.coneMultipliers[3 * cone + axis] = -value;
    } else {
      const double shear = std::hypot(r.wrenches[c.index], r.wrenches[c.index + 1]);
      r.coneMultipliers[3 * cone] = -value * r.wrenches[c.index] / shear;
      r.coneMultipliers[3 * cone + 1] = -value * r.wrenches[c.index + 1] / shear;
      r.coneMultipliers[3 * cone + 2] = value * c.friction;
    }
  }
}

/// The result's multipliers: the solver's own, converted to the conic form, or estimated.
void takeMultipliers(const ContactProblem& p, const RunOutcome& outcome, InnerResult& r) {
  if (outcome.hasMultipliers) {
    const Eigen::Index rows = p.inequality.rows();
    const auto bandStart = rows + static_cast<Eigen::Index>(p.cones.size());
    if (outcome.inequalityMultipliers.size() == bandStart + 12)  // band rows: λ = μ₊ − μ₋
      r.balanceMultipliers = outcome.inequalityMultipliers.segment<6>(bandStart) -
                             outcome.inequalityMultipliers.segment<6>(bandStart + 6);
    else
      r.balanceMultipliers = outcome.equalityMultipliers;
    r.inequalityMultipliers = outcome.inequalityMultipliers.head(rows).cwiseMax(0.0);
    // The cone form's ν to the conic multiplier: quadratic form y = ν (−2 fx, −2 fy, 2 μ² fz);
    // smooth form √(fx² + fy² + δ²) − μ fz: y = ν (−fx / N, −fy / N, μ), N = √(fx² + fy² + δ²).
    r.coneMultipliers.resize(3 * static_cast<Eigen::Index>(p.cones.size()));
    const double delta = outcome.coneSmoothing;
    for (std::size_t k = 0; k < p.cones.size(); ++k) {
      const FrictionCone& c = p.cones[k];
      const auto i = static_cast<Eigen::Index>(k);
      const double nu = std::max(outcome.inequalityMultipliers[rows + i], 0.0);
      const double fx = r.wrenches[c.index], fy = r.wrenches[c.index + 1], fz = r.wrenches[c.index + 2];
      if (delta > 0.0) {
        const double norm = std::sqrt(fx * fx + fy * fy + delta * delta);
        r.coneMultipliers.segment<3>(3 * i) << -nu * fx / norm, -nu * fy / norm, nu * c.friction;
      } else {
        r.coneMultipliers.segment<3>(3 * i) << -2.0 * nu * fx, -2.0 * nu * fy, 2.0 * nu * c.friction * c.friction * fz;
      }
    }
  } else {
    estimateMultipliers(p, r);
  }
}

void solveWithElasticFallback(const ContactProblem& p, const InnerSettings& settings, const NlpRunner& solverRun,
                              InnerResult& r) {
  // Every run of the solver polished when asked (the first solve, the least-slack phase, the
  // objective phase, the re-solve).
  std::optional<Polishing> lastPolished;  // the last run's polishing; empty: not polished
  const NlpRunner run = [&](const ContactProblem& problem, BalanceMode balance, double band, const InnerSettings& s,
                            Eigen::VectorXd& x) {
    RunOutcome outcome = solverRun(problem, balance, band, s, x);
    lastPolished.reset();
    if (s.polish && outcome.converged) lastPolished = polishOnActiveSet(problem, balance, band, s, outcome, x);
    return outcome;
  };
  const auto start = std::chrono::steady_clock::now();
  const int n = p.variableCount();
  const double scale = p.dataScale();
  Eigen::VectorXd x(n);
  if (r.wrenches.size() == n && r.wrenches.allFinite())
    x = r.wrenches;  // warm start
  else
    x = p.balance.completeOrthogonalDecomposition().solve(Eigen::VectorXd(p.balanceTarget));  // least-norm balance
  RunOutcome outcome = run(p, BalanceMode::Equality, 0.0, settings, x);
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
    leastSlack.balance.setZero();  // no balance constraint in phase 1 (its columns vanish from the KKT check)
    leastSlack.balanceTarget.setZero();
    leastSlack.tikhonov = 0.0;
    Eigen::VectorXd y = x.allFinite() ? x : Eigen::VectorXd::Zero(n);
    RunOutcome phase1 = run(leastSlack, BalanceMode::Dropped, 0.0, settings, y);
    const std::optional<Polishing> leastSlackPolished = lastPolished;
    r.leastSlackWrenches = y;
    // The least slack is an answer too: certified by its own KKT conditions, or not trusted.
    InnerResult leastSlackResult;
    finishResult(leastSlack, y.data(), leastSlackResult);
    takeMultipliers(leastSlack, phase1, leastSlackResult);
    const double leastSlackKkt = kktResidual(leastSlack, leastSlackResult);
    if (!phase1.converged || !y.allFinite() || !(leastSlackKkt <= settings.kktTolerance)) {
      std::ostringstream why;
      why << "least-slack phase: " << phase1.message << ", not certified (KKT residual " << leastSlackKkt << "); ";
      diagnostics += why.str();
      phase1.converged = false;
    }
    // Phase 2: the real objective with the balance shifted by that slack, held to a band of
    // ±tolerance (the shifted balance only touches the admissible set: an equality there
    // leaves no interior and no constraint qualification).
    shifted = p;
    shifted.balanceTarget = p.balance * y;
    solved = &shifted;
    x = y;
    const int earlier = outcome.iterations + phase1.iterations;
    outcome = run(shifted, BalanceMode::Band, settings.tolerance * scale, settings, x);
    outcome.iterations += earlier;
    // Phase 2 must stay within the band around phase 1's balance (checked against that
    // target, before the slack is taken from the returned point itself).
    const bool phase2Held = outcome.converged && x.allFinite() &&
                            shifted.constraintViolation(x) <= 2.0 * settings.tolerance * scale;
    shifted.balanceTarget = p.balance * x;
    slack = p.balanceTarget - shifted.balanceTarget;
    if (!phase2Held) {
      // The shifted feasible set can shrink to the cones' apex (every contact unloaded),
      // where gradient-based steps stall; the least-slack point is feasible for it.
      x = y;
      shifted.balanceTarget = p.balance * y;
      slack = p.balanceTarget - shifted.balanceTarget;
      outcome.converged = phase1.converged;
      outcome.hasMultipliers = false;
      outcome.message += "; the objective step after the least-slack phase failed, its point is returned";
      lastPolished = leastSlackPolished;
    }
    if (slack.cwiseAbs().maxCoeff() <= settings.tolerance * scale) slack.setZero();
    if (!phase1.converged) outcome.converged = false;
    // A certificate accurate to kktTolerance (relative) cannot tell a slack below
    // √kktTolerance of the data's scale from zero: the sample is treated as feasible and
    // solved again, from the elastic point, as the original problem; its own KKT check
    // then decides (it is never called infeasible on such a slack). A polished least-slack
    // point (or an answer that polishing could not better) is certified to its own, smaller
    // residual, and tells slacks down to √ of that.
    const double certificate = leastSlackPolished && phase1.converged ? leastSlackPolished->residual : settings.kktTolerance;
    if (slack.cwiseAbs().maxCoeff() <= std::sqrt(certificate) * scale) {
      diagnostics += "least slack negligible, solved again from the elastic point; ";
      const int before = outcome.iterations;
      outcome = run(p, BalanceMode::Equality, 0.0, settings, x);
      outcome.iterations += before;
      solved = &p;
      slack.setZero();
    }
  }
  finishResult(*solved, x.data(), r);
  r.objective = p.objective(r.wrenches);
  r.balanceSlack = slack;
  takeMultipliers(*solved, outcome, r);
  r.iterations = outcome.iterations;
  r.polished = lastPolished && lastPolished->replaced;  // of the run whose point is returned
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
  const double scale = p.dataScale();
  const Eigen::VectorXd& F = r.wrenches;
  double residual = 0.0;
  for (Eigen::Index j = 0; j < F.size(); ++j) residual = std::max(residual, std::abs(inner_detail::stationarity(p, r, j)));
  // Feasibility, with the slack in the elastic problem.
  for (int k = 0; k < 6; ++k)
    residual = std::max(residual, std::abs(p.balance.row(k).dot(F) - (p.balanceTarget[k] - r.balanceSlack[k])));
  // Linear rows: feasibility, dual feasibility and complementarity.
  for (Eigen::Index i = 0; i < p.inequality.rows(); ++i) {
    const double value = p.inequality.row(i).dot(F) - p.inequalityBound[i];
    const double mu = r.inequalityMultipliers[i];
    residual = std::max({residual, value, -mu, std::abs(mu * value + r.barrier)});
  }
  // Cones: F_i in the cone, y_i in the dual cone, y_iᵀ F_i = 0.
  for (std::size_t k = 0; k < p.cones.size(); ++k) {
    const FrictionCone& c = p.cones[k];
    const auto y = r.coneMultipliers.segment<3>(3 * static_cast<Eigen::Index>(k));
    const double primal = std::hypot(F[c.index], F[c.index + 1]) - c.friction * F[c.index + 2];
    const double dual = c.friction * std::hypot(y[0], y[1]) - y[2];
    const double complementarity = y[0] * F[c.index] + y[1] * F[c.index + 1] + y[2] * F[c.index + 2];
    residual = std::max({residual, primal, dual, std::abs(complementarity)});
  }
  return residual / scale;
}

}  // namespace mcopt
