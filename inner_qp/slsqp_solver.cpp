// SPDX-License-Identifier: BSD-3-Clause
// NLopt SLSQP on the inner problem (formulation.md §7). NLopt's header stays in this file.
// NLopt returns no multipliers: they are estimated by least squares on the active set, and
// a stop on an x/f tolerance is re-checked against the constraints by the common flow.
#include <nlopt.h>

#include <vector>

#include "inner_qp/inner_nlp.hpp"

namespace mcopt {

namespace {

using inner_detail::BalanceMode;
using inner_detail::InnerNlp;
using inner_detail::RunOutcome;

/// An InnerNlp handed to an NLopt optimiser: objective, the balance equalities and the
/// inequalities, with tolerances relative to the data's scale; counts the objective's evaluations.
class NloptProblem {
 public:
  /// Sets `opt`'s objective and constraints from `nlp` (both must outlive the optimisation).
  NloptProblem(nlopt_opt opt, const InnerNlp& nlp, const InnerSettings& settings) : nlp_(nlp) {
    const double scale = nlp.problem().dataScale();
    equalityTolerance_.assign(6, 1e-3 * settings.tolerance * scale);
    inequalityTolerance_.assign(static_cast<std::size_t>(nlp.inequalityCount()), 1e-3 * settings.tolerance * scale);
    nlopt_set_min_objective(opt, objective, this);
    if (nlp.equalityCount() > 0) nlopt_add_equality_mconstraint(opt, 6, equalities, this, equalityTolerance_.data());
    if (nlp.inequalityCount() > 0)
      nlopt_add_inequality_mconstraint(opt, static_cast<unsigned>(nlp.inequalityCount()), inequalities, this,
                                       inequalityTolerance_.data());
  }
  NloptProblem(const NloptProblem&) = delete;
  NloptProblem& operator=(const NloptProblem&) = delete;

  int evaluations() const { return evaluations_; }
  /// Largest violation of the balance and the inequalities at x (absolute).
  double violation(const Eigen::VectorXd& x) const {
    Eigen::VectorXd g(nlp_.inequalityCount());
    Vector6 e = Vector6::Zero();
    if (nlp_.inequalityCount() > 0) nlp_.inequalities(x.data(), g.data(), nullptr);
    nlp_.equalities(x.data(), e.data(), nullptr);
    return std::max(e.cwiseAbs().maxCoeff(), g.size() > 0 ? g.maxCoeff() : 0.0);
  }

 private:
  static double objective(unsigned, const double* x, double* gradient, void* data) {
    auto* self = static_cast<NloptProblem*>(data);
    ++self->evaluations_;
    if (gradient) self->nlp_.objectiveGradient(x, gradient);
    return self->nlp_.objective(x);
  }
  static void equalities(unsigned, double* value, unsigned, const double* x, double* jacobian, void* data) {
    static_cast<NloptProblem*>(data)->nlp_.equalities(x, value, jacobian);
  }
  static void inequalities(unsigned, double* value, unsigned, const double* x, double* jacobian, void* data) {
    static_cast<NloptProblem*>(data)->nlp_.inequalities(x, value, jacobian);
  }

  const InnerNlp& nlp_;
  std::vector<double> equalityTolerance_, inequalityTolerance_;
  int evaluations_ = 0;
};


RunOutcome runSlsqp(const ContactProblem& problem, BalanceMode balance, double band, const InnerSettings& settings,
                    Eigen::VectorXd& x) {
  // The smooth inner cone keeps SLSQP's subproblems regular at unloaded contacts; δ is far
  // below every tolerance of the result (1e-10 of the data's scale).
  const InnerNlp nlp(problem, balance, 1e-10 * problem.dataScale(), band);
  const auto n = static_cast<unsigned>(nlp.variableCount());
  nlopt_opt opt = nlopt_create(NLOPT_LD_SLSQP, n);
  const NloptProblem bound(opt, nlp, settings);
  const double scale = nlp.problem().dataScale();
  nlopt_set_xtol_rel(opt, 1e-14);
  nlopt_set_ftol_rel(opt, 1e-16);
  nlopt_set_maxeval(opt, settings.maxIterations);
  // SLSQP may stop on its x tolerance a hair outside the constraints; a restart from its
  // own point finishes the job (at most a few times).
  RunOutcome out;
  nlopt_result code = NLOPT_FAILURE;
  for (int attempt = 0; attempt < 4; ++attempt) {
    double value = 0.0;
    code = nlopt_optimize(opt, x.data(), &value);
    const double violation = bound.violation(x);
    if (code == NLOPT_ROUNDOFF_LIMITED) continue;  // restart from where it stalled
    if (code < 0 || !x.allFinite() || violation <= settings.tolerance * scale) break;
  }
  out.iterations = bound.evaluations();
  // ROUNDOFF_LIMITED stops at a usable point more often than not: the common flow re-checks
  // feasibility, so it counts as a stop, not a failure.
  out.converged = (code > 0 || code == NLOPT_ROUNDOFF_LIMITED) && code != NLOPT_MAXEVAL_REACHED &&
                  code != NLOPT_MAXTIME_REACHED && x.allFinite();
  out.message = std::string("nlopt: ") + nlopt_result_to_string(code);
  nlopt_destroy(opt);
  return out;
}

class SlsqpSolver final : public InnerSolver {
 public:
  explicit SlsqpSolver(const InnerSettings& settings) : settings_(settings) {}
  std::string name() const override { return "slsqp"; }
  void solve(const ContactProblem& problem, InnerResult& result) override {
    inner_detail::solveWithElasticFallback(problem, settings_, runSlsqp, result);
  }

 private:
  InnerSettings settings_;
};

}  // namespace

std::unique_ptr<InnerSolver> makeSlsqpSolver(const InnerSettings& settings) {
  return std::make_unique<SlsqpSolver>(settings);
}

}  // namespace mcopt
