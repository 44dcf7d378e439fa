// SPDX-License-Identifier: BSD-3-Clause
#include "inner_qp/nlopt_problem.hpp"

#include <nlopt.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace mcopt::inner_detail {

// The adapter's own types and helpers: internal to this file.
namespace {

/// How NLopt sees the inner problem: x = wrenchUnit · y for its variables y, the objective
/// divided by objectiveUnit and the constraints (all homogeneous of degree one in the wrenches
/// but for their bounds) by wrenchUnit. 1 and 1: the problem as it is.
struct NloptScaling {
  double wrenchUnit = 1.0;
  double objectiveUnit = 1.0;
};

/// An InnerNlp set on an NLopt optimiser: objective, the balance equalities and the
/// inequalities, with tolerances relative to the data's scale; counts the objective's
/// evaluations. `nlp` must outlive the optimisation.
class NloptProblem {
 public:
  NloptProblem(nlopt_opt opt, const InnerNlp& nlp, const InnerSettings& settings, NloptScaling scaling = {});
  NloptProblem(const NloptProblem&) = delete;
  NloptProblem& operator=(const NloptProblem&) = delete;

  int evaluations() const { return evaluations_; }
  /// Largest violation of the balance and the inequalities at x (absolute).
  double violation(const Eigen::VectorXd& x) const;

 private:
  static double objective(unsigned, const double* x, double* gradient, void* data);
  static void equalities(unsigned, double* value, unsigned, const double* x, double* jacobian, void* data);
  static void inequalities(unsigned, double* value, unsigned, const double* x, double* jacobian, void* data);
  /// The wrenches at NLopt's point y (y itself when unscaled).
  const double* wrenches(const double* y);

  const InnerNlp& nlp_;
  NloptScaling scaling_;
  bool scaled_ = false;
  Eigen::VectorXd x_;  ///< the wrenches of the scaled point (sized once)
  std::vector<double> equalityTolerance_, inequalityTolerance_;
  int evaluations_ = 0;
};

/// Whether an NLopt return code is a stop at a point the common flow may check: a positive
/// code other than a budget, or NLOPT_ROUNDOFF_LIMITED (usable more often than not).
bool nloptStopped(int code);
/// "nlopt: <name of the code>".
std::string nloptMessage(int code);


NloptProblem::NloptProblem(nlopt_opt opt, const InnerNlp& nlp, const InnerSettings& settings, NloptScaling scaling)
    : nlp_(nlp), scaling_(scaling), scaled_(scaling.wrenchUnit != 1.0 || scaling.objectiveUnit != 1.0) {
  const double tolerance = 1e-3 * settings.tolerance * nlp.problem().dataScale() / scaling.wrenchUnit;
  equalityTolerance_.assign(6, tolerance);
  inequalityTolerance_.assign(static_cast<std::size_t>(nlp.inequalityCount()), tolerance);
  if (scaled_) x_.resize(nlp.variableCount());
  nlopt_set_min_objective(opt, objective, this);
  if (nlp.equalityCount() > 0) nlopt_add_equality_mconstraint(opt, 6, equalities, this, equalityTolerance_.data());
  if (nlp.inequalityCount() > 0)
    nlopt_add_inequality_mconstraint(opt, static_cast<unsigned>(nlp.inequalityCount()), inequalities, this,
                                     inequalityTolerance_.data());
}

double NloptProblem::violation(const Eigen::VectorXd& x) const {
  Eigen::VectorXd g(nlp_.inequalityCount());
  Vector6 e = Vector6::Zero();
  if (nlp_.inequalityCount() > 0) nlp_.inequalities(x.data(), g.data(), nullptr);
  nlp_.equalities(x.data(), e.data(), nullptr);
  return std::max(e.cwiseAbs().maxCoeff(), g.size() > 0 ? g.maxCoeff() : 0.0);
}

const double* NloptProblem::wrenches(const double* y) {
  if (!scaled_) return y;
  x_ = scaling_.wrenchUnit * Eigen::Map<const Eigen::VectorXd>(y, x_.size());
  return x_.data();
}

double NloptProblem::objective(unsigned, const double* y, double* gradient, void* data) {
  auto* self = static_cast<NloptProblem*>(data);
  ++self->evaluations_;
  const double* x = self->wrenches(y);
  if (!self->scaled_) {
    if (gradient) self->nlp_.objectiveGradient(x, gradient);
    return self->nlp_.objective(x);
  }
  const NloptScaling& s = self->scaling_;
  if (gradient) {
    self->nlp_.objectiveGradient(x, gradient);
    Eigen::Map<Eigen::VectorXd>(gradient, self->x_.size()) *= s.wrenchUnit / s.objectiveUnit;
  }
  return self->nlp_.objective(x) / s.objectiveUnit;
}

// The constraints are degree one in the wrenches: divided by the unit, their Jacobian in y is
// their Jacobian in x.
void NloptProblem::equalities(unsigned m, double* value, unsigned, const double* y, double* jacobian, void* data) {
  auto* self = static_cast<NloptProblem*>(data);
  self->nlp_.equalities(self->wrenches(y), value, jacobian);
  if (self->scaled_) Eigen::Map<Eigen::VectorXd>(value, m) /= self->scaling_.wrenchUnit;
}

void NloptProblem::inequalities(unsigned m, double* value, unsigned, const double* y, double* jacobian, void* data) {
  auto* self = static_cast<NloptProblem*>(data);
  self->nlp_.inequalities(self->wrenches(y), value, jacobian);
  if (self->scaled_) Eigen::Map<Eigen::VectorXd>(value, m) /= self->scaling_.wrenchUnit;
}

bool nloptStopped(int code) {
  return (code > 0 || code == NLOPT_ROUNDOFF_LIMITED) && code != NLOPT_MAXEVAL_REACHED && code != NLOPT_MAXTIME_REACHED;
}

std::string nloptMessage(int code) {
  return std::string("nlopt: ") + nlopt_result_to_string(static_cast<nlopt_result>(code));
}

}  // namespace

NloptMethod augmentedLagrangian(int local) {
  NloptMethod method;
  method.algorithm = NLOPT_AUGLAG;
  method.local = local;
  method.scaled = true;
  method.xtolRel = 1e-12;
  method.ftolRel = 1e-15;
  method.localXtolRel = 1e-12;
  method.localFtolRel = 1e-14;
  method.evaluationsPerIteration = 20;
  return method;
}

RunOutcome runNlopt(const NloptMethod& method, const ContactProblem& problem, BalanceMode balance, double band,
                    const InnerSettings& settings, Eigen::VectorXd& x) {
  const InnerNlp nlp(problem, balance, 1e-10 * problem.dataScale(), band);
  const auto n = static_cast<unsigned>(nlp.variableCount());
  nlopt_opt opt = nlopt_create(static_cast<nlopt_algorithm>(method.algorithm), n);
  const int evaluations = method.evaluationsPerIteration * settings.maxIterations;
  if (method.local >= 0) {
    nlopt_opt local = nlopt_create(static_cast<nlopt_algorithm>(method.local), n);
    nlopt_set_xtol_rel(local, method.localXtolRel);
    nlopt_set_ftol_rel(local, method.localFtolRel);
    nlopt_set_maxeval(local, evaluations);
    nlopt_set_local_optimizer(opt, local);  // copied into opt
    nlopt_destroy(local);
  }
  NloptScaling scaling;
  if (method.scaled) {
    scaling.wrenchUnit = std::max(1.0, problem.balanceTarget.cwiseAbs().maxCoeff());
    scaling.objectiveUnit = std::max(1.0, std::abs(nlp.objective(x.data())));
  }
  const NloptProblem bound(opt, nlp, settings, scaling);
  const double scale = nlp.problem().dataScale();
  nlopt_set_xtol_rel(opt, method.xtolRel);
  nlopt_set_ftol_rel(opt, method.ftolRel);
  nlopt_set_maxeval(opt, evaluations);
  // The solver may stop on its x tolerance a hair outside the constraints; a restart from its
  // own point finishes the job (at most a few times).
  RunOutcome out;
  nlopt_result code = NLOPT_FAILURE;
  for (int attempt = 0; attempt < 4; ++attempt) {
    double value = 0.0;
    if (method.scaled) x /= scaling.wrenchUnit;
    code = nlopt_optimize(opt, x.data(), &value);
    if (method.scaled) x *= scaling.wrenchUnit;
    const double violation = bound.violation(x);
    if (code == NLOPT_ROUNDOFF_LIMITED) continue;  // restart from where it stalled
    if (code < 0 || !x.allFinite() || violation <= settings.tolerance * scale) break;
  }
  out.iterations = bound.evaluations();
  // ROUNDOFF_LIMITED stops at a usable point more often than not: the common flow re-checks
  // feasibility, so it counts as a stop, not a failure.
  out.converged = nloptStopped(code) && x.allFinite();
  out.message = nloptMessage(code);
  nlopt_destroy(opt);
  return out;
}

namespace {

class NloptSolver final : public InnerSolver {
 public:
  NloptSolver(std::string name, NloptMethod method, const InnerSettings& settings)
      : name_(std::move(name)), method_(method), settings_(settings) {}
  std::string name() const override { return name_; }
  void solve(const ContactProblem& problem, InnerResult& result) override {
    const NloptMethod method = method_;
    solveWithElasticFallback(
        problem, settings_,
        [method](const ContactProblem& p, BalanceMode balance, double band, const InnerSettings& s, Eigen::VectorXd& x) {
          return runNlopt(method, p, balance, band, s, x);
        },
        result);
  }

 private:
  std::string name_;
  NloptMethod method_;
  InnerSettings settings_;
};

}  // namespace

std::unique_ptr<InnerSolver> makeNloptSolver(std::string name, NloptMethod method, const InnerSettings& settings) {
  return std::make_unique<NloptSolver>(std::move(name), method, settings);
}

}  // namespace mcopt::inner_detail
