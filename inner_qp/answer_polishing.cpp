// SPDX-License-Identifier: BSD-3-Clause
#include "inner_qp/answer_polishing.hpp"

#include <Eigen/QR>
#include <vector>

#include "inner_qp/dual_active_set_qp.hpp"

namespace mcopt::inner_detail {

namespace {

/// Solution polishing (Stellato et al., "OSQP", Math. Prog. Comp. 2020, §5.2, for our QP):
/// the NLP solvers stop at a KKT residual near their tolerance, and a least balance slack
/// below √(that residual) of the scale cannot be told from zero (solveWithElasticFallback).
/// With linear rows only, the solution on an active set is one linear system:
///   [H  Eᵀ] [F]   [−c]
///   [E  0 ] [λ] = [ e],   E: the balance rows (unless dropped) and the active rows.
/// Dependent active rows (an unloaded contact at the wrench cone's apex) leave it singular but
/// consistent; the least-norm solution is one of its solutions. Returns F.
Eigen::VectorXd solveOnActiveRows(const ContactProblem& p, BalanceMode balance, const std::vector<int>& rows) {
  const int n = p.variableCount();
  const int balanceRows = balance == BalanceMode::Dropped ? 0 : 6;
  const auto m = static_cast<Eigen::Index>(balanceRows + rows.size());
  Eigen::MatrixXd kkt = Eigen::MatrixXd::Zero(n + m, n + m);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n + m);
  kkt.topLeftCorner(n, n) = p.hessian;
  rhs.head(n) = -p.gradient;
  if (balanceRows > 0) {
    kkt.block(n, 0, 6, n) = p.balance;
    rhs.segment<6>(n) = p.balanceTarget;  // the band's centre in the elastic phase 2
  }
  for (std::size_t a = 0; a < rows.size(); ++a) {
    const Eigen::Index at = n + balanceRows + static_cast<Eigen::Index>(a);
    kkt.row(at).head(n) = p.inequality.row(rows[a]);
    rhs[at] = p.inequalityBound[rows[a]];
  }
  kkt.topRightCorner(n, m) = kkt.bottomLeftCorner(m, n).transpose();
  return kkt.completeOrthogonalDecomposition().solve(rhs).head(n);
}

/// The elastic phase 2's problem with its band −band ≤ B F − target ≤ band as twelve linear
/// rows after the contact rows (BalanceMode::Band), for a solve with the balance dropped.
ContactProblem withBandRows(const ContactProblem& p, double band) {
  ContactProblem banded = p;
  const Eigen::Index rows = p.inequality.rows();
  const int n = p.variableCount();
  banded.inequality.resize(rows + 12, n);
  banded.inequalityBound.resize(rows + 12);
  banded.inequality.topRows(rows) = p.inequality;
  banded.inequalityBound.head(rows) = p.inequalityBound;
  banded.inequality.middleRows(rows, 6) = p.balance;
  banded.inequality.bottomRows(6) = -p.balance;
  banded.inequalityBound.segment<6>(rows) = p.balanceTarget.array() + band;
  banded.inequalityBound.tail<6>() = -p.balanceTarget.array() + band;
  banded.balance.setZero();
  banded.balanceTarget.setZero();
  return banded;
}

/// Crossover, as interior-point LP solvers end on a basis: the QP solved exactly by our dual
/// active-set method (the active-set solver's core), started from the rows the answer's
/// multipliers hold; its point and exact multipliers, in the form RunOutcome carries them, or
/// nothing when it does not end optimal. A primal add-one-drop-one loop from the same rows
/// cycled on the weight shift's degenerate band vertices, as such loops do.
/// Needed where an answer is accurate in its objective but not in its point: the least-slack
/// phase's Hessian 2BᵀB + εI has rank 6 but for ε, so an NLP solver's least-slack point lies
/// anywhere along the near-flat directions, the rows tight there are not the minimiser's, and
/// the solution on them leaves the admissible set; its least slack is then right to the square
/// root of its objective's accuracy only, and phase 2 (the objective at that balance) moved by
/// 50 to 109 N of wrench for 1e-5 N of slack on the weight shift (docs/theory/inner-problem.md,
/// "Polishing").
std::optional<RunOutcome> crossover(const ContactProblem& p, BalanceMode balance, const InnerSettings& settings,
                                    const std::vector<int>& rows, Eigen::VectorXd& x) {
  const int n = p.variableCount();
  const int balanceRows = balance == BalanceMode::Dropped ? 0 : 6;
  const auto inequalities = static_cast<int>(p.inequality.rows());
  DualActiveSetQp qp;
  qp.resize(n, balanceRows, inequalities);
  qp.hessian = p.hessian;
  qp.gradient = p.gradient;
  if (balanceRows > 0) {
    qp.equality = p.balance;
    qp.equalityTarget = p.balanceTarget;
  }
  qp.inequality = p.inequality;
  qp.inequalityBound = p.inequalityBound;
  qp.inequalityCount = inequalities;
  constexpr double kViolationTolerance = 1e-13;  // the active-set solver's
  if (qp.solve(rows, settings.maxIterations, kViolationTolerance) != DualActiveSetQp::Status::Optimal || !qp.x.allFinite())
    return std::nullopt;
  RunOutcome outcome;
  outcome.converged = true;
  outcome.hasMultipliers = true;
  if (balanceRows > 0) outcome.equalityMultipliers = qp.equalityMultipliers;
  outcome.inequalityMultipliers = qp.inequalityMultipliers.head(inequalities).cwiseMax(0.0);
  outcome.iterations = qp.iterations;
  x = qp.x;
  return outcome;
}

}  // namespace

std::optional<Polishing> polishOnActiveSet(const ContactProblem& p, BalanceMode balance, double band,
                                           const InnerSettings& settings, RunOutcome& outcome, Eigen::VectorXd& x) {
  if (!p.cones.empty() || !x.allFinite()) return std::nullopt;
  // In the band every point is judged on the band's rows, as the solver and the active-set
  // method solve it: the optimum may lean on the band's edge, where the balance held at the
  // band's centre (the simple candidates) is another point, 6e-3 N away on the weight shift.
  std::optional<ContactProblem> banded;
  if (balance == BalanceMode::Band) banded = withBandRows(p, band);
  const ContactProblem& judged = banded ? *banded : p;
  InnerResult before;
  finishResult(judged, x.data(), before);
  takeMultipliers(judged, outcome, before);
  const double residualBefore = kktResidual(judged, before);
  const double largest = before.inequalityMultipliers.size() > 0 ? before.inequalityMultipliers.maxCoeff() : 0.0;
  std::vector<int> held;
  for (const int row : before.activeSet)
    if (before.inequalityMultipliers[row] > 1e-6 * (1.0 + largest)) held.push_back(row);
  const double rowSlack = settings.tolerance * p.dataScale();
  Eigen::VectorXd best;
  double bestResidual = residualBefore;
  std::optional<RunOutcome> bestCrossed;  // the crossover's outcome, when it is the best
  const auto consider = [&](const Eigen::VectorXd& polished, const std::optional<RunOutcome>& crossed) {
    if (!polished.allFinite()) return;
    if (p.inequality.rows() > 0 && (p.inequality * polished - p.inequalityBound).maxCoeff() > rowSlack) return;
    if (balance != BalanceMode::Dropped && (p.balance * polished - p.balanceTarget).cwiseAbs().maxCoeff() > band + rowSlack)
      return;
    InnerResult after;
    finishResult(judged, polished.data(), after);
    if (crossed)
      takeMultipliers(judged, *crossed, after);
    else
      estimateMultipliers(judged, after);
    const double residualAfter = kktResidual(judged, after);
    if (!(residualAfter < bestResidual)) return;
    best = polished;
    bestResidual = residualAfter;
    bestCrossed = crossed;
  };
  // The crossover first: where it ends, its point is the QP's own, which the residual cannot
  // always tell (with near-active rows, estimated multipliers make points 2 J of objective
  // apart look alike). The simple candidates, if it fails, hold the balance as equalities (at
  // the band's centre) and the contact rows as found.
  Eigen::VectorXd crossed;
  if (const std::optional<RunOutcome> crossing =
          crossover(judged, banded ? BalanceMode::Dropped : balance, settings, held, crossed))
    consider(crossed, crossing);
  if (best.size() == 0) {
    const auto contactRows = [&](std::vector<int> rows) {
      std::erase_if(rows, [&](int row) { return row >= p.inequality.rows(); });
      return rows;
    };
    consider(solveOnActiveRows(p, balance, contactRows(held)), std::nullopt);
    if (held.size() != before.activeSet.size())
      consider(solveOnActiveRows(p, balance, contactRows(before.activeSet)), std::nullopt);
  }
  if (best.size() == 0) return Polishing{false, residualBefore};
  x = best;
  if (bestCrossed) {
    outcome.hasMultipliers = true;
    outcome.equalityMultipliers = bestCrossed->equalityMultipliers;
    outcome.inequalityMultipliers = bestCrossed->inequalityMultipliers;
    outcome.message += "; polished by crossover from its active set";
  } else {
    outcome.hasMultipliers = false;  // estimated at the polished point
    outcome.message += "; polished on its active set";
  }
  return Polishing{true, bestResidual};
}

}  // namespace mcopt::inner_detail
