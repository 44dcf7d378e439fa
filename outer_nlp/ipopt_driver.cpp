// SPDX-License-Identifier: BSD-3-Clause
// Ipopt as the outer solver (outer_solver.hpp): exact first derivatives, the declared sparse
// Jacobian, a limited-memory Hessian unless the settings say otherwise, the scenario's options
// on top of ours (docs/reference/scenario-file.md, "Ipopt options we set"), the variables in
// the problem's units for Ipopt (NlpProblem::variableUnits). Registered as "ipopt" in
// outer_solver.cpp.
#include "outer_nlp/outer_solver.hpp"

#include <IpIpoptApplication.hpp>
#include <IpIpoptCalculatedQuantities.hpp>
#include <IpIpoptData.hpp>
#include <IpOrigIpoptNLP.hpp>
#include <IpSolveStatistics.hpp>
#include <IpTNLP.hpp>
#include <IpTNLPAdapter.hpp>

#include <chrono>
#include <iterator>
#include <sstream>
#include <stdexcept>

#include "core/errors.hpp"

namespace mcopt {

namespace {

using Ipopt::Index;
using Ipopt::Number;

/// Ipopt's words for each OuterStatus, in the enum's order.
constexpr const char* kIpoptMessages[] = {
    "Ipopt was running",
    "Optimal Solution Found",
    "Solved To Acceptable Level",
    "Maximum Number of Iterations Exceeded",
    "Maximum CPU time exceeded",
    "Search Direction is becoming Too Small",
    "Converged to a point of local infeasibility",
    "Stopping optimization at current point as requested by user",
    "Feasible point for square problem found",
    "Iterates diverging; problem might be unbounded",
    "Restoration Phase Failed",
    "Error in step computation",
    "Invalid number in NLP function or derivative detected",
    "Problem has too few degrees of freedom",
    "Invalid option",
    "Not enough memory",
    "Internal error",
    "Stage stalled (stopped by mcopt)",
};
static_assert(std::size(kIpoptMessages) == static_cast<std::size_t>(OuterStatus::Stalled) + 1);

OuterStatus fromIpopt(Ipopt::SolverReturn status) {
  switch (status) {
    case Ipopt::SUCCESS: return OuterStatus::Optimal;
    case Ipopt::MAXITER_EXCEEDED: return OuterStatus::MaximumIterations;
    case Ipopt::CPUTIME_EXCEEDED: return OuterStatus::MaximumCpuTime;
    case Ipopt::STOP_AT_TINY_STEP: return OuterStatus::TinyStep;
    case Ipopt::STOP_AT_ACCEPTABLE_POINT: return OuterStatus::Acceptable;
    case Ipopt::LOCAL_INFEASIBILITY: return OuterStatus::Infeasible;
    case Ipopt::USER_REQUESTED_STOP: return OuterStatus::Interrupted;
    case Ipopt::FEASIBLE_POINT_FOUND: return OuterStatus::FeasiblePointFound;
    case Ipopt::DIVERGING_ITERATES: return OuterStatus::Diverging;
    case Ipopt::RESTORATION_FAILURE: return OuterStatus::RestorationFailed;
    case Ipopt::ERROR_IN_STEP_COMPUTATION: return OuterStatus::ErrorInStepComputation;
    case Ipopt::INVALID_NUMBER_DETECTED: return OuterStatus::InvalidNumber;
    case Ipopt::TOO_FEW_DEGREES_OF_FREEDOM: return OuterStatus::TooFewDegreesOfFreedom;
    case Ipopt::INVALID_OPTION: return OuterStatus::InvalidOption;
    case Ipopt::OUT_OF_MEMORY: return OuterStatus::OutOfMemory;
    default: return OuterStatus::InternalError;
  }
}

/// Adds the time of its scope to a counter.
class Clock {
 public:
  explicit Clock(double& seconds) : seconds_(seconds), start_(std::chrono::steady_clock::now()) {}
  ~Clock() { seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }
  Clock(const Clock&) = delete;
  Clock& operator=(const Clock&) = delete;

 private:
  double& seconds_;
  std::chrono::steady_clock::time_point start_;
};

class ProblemTnlp final : public Ipopt::TNLP {
 public:
  ProblemTnlp(NlpProblem& problem, const Eigen::VectorXd& start, OuterOutcome& outcome,
              const std::function<bool(const IterationReport&)>& onIteration, bool hessian)
      : problem_(problem), start_(start), outcome_(outcome), onIteration_(onIteration),
        clock_(std::chrono::steady_clock::now()), hessian_(hessian) {
    problem_.variableBounds(xLower_, xUpper_);
    problem_.constraintBounds(gLower_, gUpper_);
    problem_.variableUnits(units_);
    if (units_.size() != start_.size() || !(units_.array() > 0.0).all() || !units_.allFinite())
      throw std::logic_error("ipopt driver: the problem's variable units must be positive and finite, one a variable");
    scaled_ = (units_.array() != 1.0).any();
    if (!hessian_) return;
    problem_.hessianPattern(hessianRows_, hessianColumns_);
    const int curved = problem_.nonlinearVariableCount();
    bool valid = hessianColumns_.size() == hessianRows_.size();
    for (std::size_t k = 0; valid && k < hessianRows_.size(); ++k) {
      const int r = hessianRows_[k], c = hessianColumns_[k];
      const bool ordered = k == 0 || r > hessianRows_[k - 1] || (r == hessianRows_[k - 1] && c > hessianColumns_[k - 1]);
      valid = c >= 0 && c <= r && r < curved && ordered;
    }
    if (!valid)
      throw std::logic_error("ipopt driver: the problem's Hessian pattern must list lower-triangle entries of its nonlinear variables once each, row by row");
  }

  /// finalize_solution was called: the outcome holds Ipopt's status.
  bool finalized() const { return finalized_; }

  bool get_nlp_info(Index& n, Index& m, Index& nnzJacobian, Index& nnzHessian, IndexStyleEnum& style) override {
    n = problem_.variableCount();
    m = problem_.constraintCount();
    nnzJacobian = static_cast<Index>(problem_.jacobianRows().size());
    nnzHessian = static_cast<Index>(hessianRows_.size());  // the problem's pattern; none with limited memory
    style = C_STYLE;
    return true;
  }
  bool get_bounds_info(Index n, Number* xL, Number* xU, Index m, Number* gL, Number* gU) override {
    auto finite = [](double v) { return std::isfinite(v) ? v : (v > 0 ? 2e19 : -2e19); };
    for (Index i = 0; i < n; ++i) xL[i] = finite(xLower_[i] / units_[i]), xU[i] = finite(xUpper_[i] / units_[i]);
    for (Index i = 0; i < m; ++i) gL[i] = finite(gLower_[i]), gU[i] = finite(gUpper_[i]);
    return true;
  }
  bool get_starting_point(Index n, bool initX, Number* x, bool initZ, Number*, Number*, Index, bool initLambda,
                          Number*) override {
    if (!initX || initZ || initLambda) return false;
    Eigen::Map<Eigen::VectorXd>(x, n) = start_.cwiseQuotient(units_);
    return true;
  }
  bool eval_f(Index n, const Number* x, bool, Number& value) override {
    return guarded([&] {
      ++outcome_.objectiveEvaluations;
      const Clock clock(outcome_.timings.functions);
      value = problem_.objective(copy(x, n));
    });
  }
  bool eval_grad_f(Index n, const Number* x, bool, Number* gradient) override {
    return guarded([&] {
      ++outcome_.gradientEvaluations;
      const Clock clock(outcome_.timings.derivatives);
      problem_.objectiveGradient(copy(x, n), buffer_);
      if (scaled_) buffer_.array() *= units_.array();
      Eigen::Map<Eigen::VectorXd>(gradient, n) = buffer_;
    });
  }
  bool eval_g(Index n, const Number* x, bool, Index m, Number* g) override {
    return guarded([&] {
      ++outcome_.constraintEvaluations;
      const Clock clock(outcome_.timings.functions);
      problem_.constraints(copy(x, n), buffer_);
      Eigen::Map<Eigen::VectorXd>(g, m) = buffer_;
    });
  }
  bool eval_jac_g(Index n, const Number* x, bool, Index, Index nnz, Index* rows, Index* cols, Number* values) override {
    if (values == nullptr) {
      for (Index k = 0; k < nnz; ++k) rows[k] = problem_.jacobianRows()[k], cols[k] = problem_.jacobianColumns()[k];
      return true;
    }
    return guarded([&] {
      ++outcome_.jacobianEvaluations;
      const Clock clock(outcome_.timings.derivatives);
      problem_.jacobianValues(copy(x, n), buffer_);
      if (scaled_) {
        const Eigen::VectorXi& columns = problem_.jacobianColumns();
        for (Index k = 0; k < nnz; ++k) buffer_[k] *= units_[columns[k]];
      }
      Eigen::Map<Eigen::VectorXd>(values, nnz) = buffer_;
    });
  }
  bool eval_h(Index n, const Number* x, bool, Number objectiveFactor, Index m, const Number* lambda, bool, Index,
              Index* rows, Index* cols, Number* values) override {
    const std::size_t nnz = hessianRows_.size();
    if (values == nullptr) {
      for (std::size_t k = 0; k < nnz; ++k) rows[k] = hessianRows_[k], cols[k] = hessianColumns_[k];
      return true;
    }
    return guarded([&] {
      const Clock clock(outcome_.timings.hessian);
      // The problem's dense lower triangle, read at the pattern's entries (x / units: H_rc u_r u_c).
      problem_.lagrangianHessian(copy(x, n), objectiveFactor, Eigen::Map<const Eigen::VectorXd>(lambda, m), buffer_);
      for (std::size_t k = 0; k < nnz; ++k) {
        const int r = hessianRows_[k], c = hessianColumns_[k];
        const double value = buffer_[lowerTriangleIndex(r, c)];
        values[k] = scaled_ ? value * (units_[r] * units_[c]) : value;
      }
    });
  }
  bool intermediate_callback(Ipopt::AlgorithmMode mode, Index iteration, Number objective, Number primal, Number dual,
                             Number barrier, Number, Number regularisation, Number, Number primalStep, Index,
                             const Ipopt::IpoptData* data, Ipopt::IpoptCalculatedQuantities* quantities) override {
    IterationReport r;
    r.iteration = iteration;
    r.objective = objective;
    r.violation = primal;
    r.dualInfeasibility = dual;
    r.barrier = barrier;
    r.regularisation = regularisation;
    r.stepSize = primalStep;
    r.elapsedSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_).count();
    outcome_.timings.total = r.elapsedSeconds;
    r.timings = outcome_.timings;
    if (mode == Ipopt::RegularMode && currentIterate(data, quantities)) r.iterate = &iterate_;
    outcome_.iterations = iteration;
    r.progress = &outcome_;
    return !onIteration_ || onIteration_(r);
  }
  void finalize_solution(Ipopt::SolverReturn status, Index n, const Number* x, const Number*, const Number*, Index,
                         const Number*, const Number*, Number objective, const Ipopt::IpoptData*,
                         Ipopt::IpoptCalculatedQuantities*) override {
    outcome_.status = fromIpopt(status);
    outcome_.message = kIpoptMessages[static_cast<std::size_t>(outcome_.status)];
    finalized_ = true;
    outcome_.objective = objective;
    if (x != nullptr) outcome_.x = copy(x, n);
  }

 private:
  /// Ipopt 3.11 hands the callback its internal iterate only: undo the variable scaling and
  /// put back the variables it fixed (the TNLP adapter's own mapping) to get our x.
  bool currentIterate(const Ipopt::IpoptData* data, Ipopt::IpoptCalculatedQuantities* quantities) {
    if (data == nullptr || quantities == nullptr || !Ipopt::IsValid(data->curr())) return false;
    auto* original = dynamic_cast<Ipopt::OrigIpoptNLP*>(Ipopt::GetRawPtr(quantities->GetIpoptNLP()));
    if (original == nullptr) return false;
    auto* adapter = dynamic_cast<Ipopt::TNLPAdapter*>(Ipopt::GetRawPtr(original->nlp()));
    if (adapter == nullptr) return false;
    const Ipopt::SmartPtr<const Ipopt::Vector> x = original->NLP_scaling()->unapply_vector_scaling_x(data->curr()->x());
    iterate_.resize(start_.size());
    adapter->ResortX(*x, iterate_.data());
    if (scaled_) iterate_.array() *= units_.array();
    return true;
  }
  /// Ipopt's x in the problem's own units.
  Eigen::VectorXd copy(const Number* x, Index n) const {
    Eigen::VectorXd ours = Eigen::Map<const Eigen::VectorXd>(x, n);
    if (scaled_) ours.array() *= units_.array();
    return ours;
  }
  template <class F>
  bool guarded(F&& f) {
    // An exception must not cross Ipopt's C++ frames: report it as a failed evaluation.
    try {
      f();
      return true;
    } catch (const std::exception& e) {
      if (outcome_.evaluationError.empty()) outcome_.evaluationError = e.what();
      return false;
    }
  }

  NlpProblem& problem_;
  Eigen::VectorXd start_, xLower_, xUpper_, gLower_, gUpper_, buffer_;
  OuterOutcome& outcome_;
  const std::function<bool(const IterationReport&)>& onIteration_;
  std::chrono::steady_clock::time_point clock_;
  bool hessian_;
  Eigen::VectorXd iterate_;
  Eigen::VectorXd units_;  ///< NlpProblem::variableUnits: Ipopt works on x / units_
  std::vector<int> hessianRows_, hessianColumns_;  ///< NlpProblem::hessianPattern, read once a solve (none: limited memory)
  bool scaled_ = false;    ///< some unit is not 1
  bool finalized_ = false;
};

void apply(Ipopt::IpoptApplication& app, const SolverOption& o) {
  bool accepted = false;
  switch (o.type) {
    case SolverOption::Type::Integer:
      // Ipopt also takes integers for its numeric options (tol: 1).
      accepted = app.Options()->SetIntegerValue(o.name, o.integer) || app.Options()->SetNumericValue(o.name, o.integer);
      break;
    case SolverOption::Type::Number: accepted = app.Options()->SetNumericValue(o.name, o.number); break;
    case SolverOption::Type::Text: accepted = app.Options()->SetStringValue(o.name, o.text); break;
  }
  if (!accepted)
    throw InputError(o.origin + "Ipopt rejects option '" + o.name + "' = " + o.text +
                     " (unknown option, wrong type or out of range; see Ipopt's option list)");
}

/// An option of ours, in Ipopt's terms (`origin` for the message should Ipopt reject it).
SolverOption ours(const std::string& name, double value, const std::string& origin) {
  SolverOption o;
  o.name = name, o.type = SolverOption::Type::Number, o.number = value, o.origin = origin;
  std::ostringstream text;
  text << value;
  o.text = text.str();
  return o;
}

class IpoptSolver final : public OuterSolver {
 public:
  std::string_view name() const override { return "ipopt"; }

  OuterOutcome solve(NlpProblem& problem, const Eigen::VectorXd& start, const OuterSolverSettings& settings,
                     const IterationCallback& onIteration) const override {
    Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
    app->RethrowNonIpoptException(false);
    // Ours first (formulation.md §10); the scenario's options override them.
    app->Options()->SetIntegerValue("print_level", settings.printLevel);
    app->Options()->SetStringValue("sb", "yes");
    app->Options()->SetStringValue("hessian_approximation", settings.problemHessian ? "exact" : "limited-memory");
    app->Options()->SetNumericValue("tol", 1e-6);
    app->Options()->SetNumericValue("constr_viol_tol", 1e-8);
    app->Options()->SetIntegerValue("max_iter", 3000);
    // MUMPS's maximum-transversal permutation made each factorisation of the motion problem's
    // KKT system 5× slower (0.5 s against 0.1 s an iteration, HRP-2 kick; docs/reference/scenario-file.md).
    app->Options()->SetIntegerValue("mumps_permuting_scaling", 0);
    // MUMPS's automatic choice of ordering was not the same from one run to the next on the
    // epigraph form's KKT system: the offset-free kick's epigraph stage took 3 s in some runs and
    // 74-107 s in others (its dense fronts factorised pivot by pivot), with results that differed
    // in their last bits. AMF, the one it chose on the smooth kick, gives the same iterate and
    // time every run (docs/reference/scenario-file.md, "Ipopt options we set").
    app->Options()->SetIntegerValue("mumps_pivot_order", 2);
    if (settings.tolerance) apply(*app, ours("tol", *settings.tolerance, "mcopt: "));
    if (settings.constraintTolerance) apply(*app, ours("constr_viol_tol", *settings.constraintTolerance, "mcopt: "));
    // A start to keep: Ipopt's default pushes of 1e-2 off the bounds (of variables and of
    // inequality rows) would move it off its own point, and a small barrier parameter keeps
    // Ipopt near it instead of re-centring it (docs/theory/outer-problem.md, "Continuation").
    if (settings.warmStart) {
      for (const char* push : {"bound_push", "bound_frac", "slack_bound_push", "slack_bound_frac"})
        apply(*app, ours(push, 1e-9, settings.warmStart->origin));
      apply(*app, ours("mu_init", settings.warmStart->barrier, settings.warmStart->origin));
    }
    for (const SolverOption& o : settings.options) apply(*app, o);
    if (settings.maxIterations) {
      SolverOption limit;
      limit.name = "max_iter", limit.type = SolverOption::Type::Integer, limit.integer = *settings.maxIterations;
      limit.text = std::to_string(limit.integer), limit.origin = "mcopt: ";
      apply(*app, limit);
    }
    if (app->Initialize() != Ipopt::Solve_Succeeded) throw InputError("Ipopt could not be initialised");

    OuterOutcome outcome;
    const auto clock = std::chrono::steady_clock::now();
    auto* adapter = new ProblemTnlp(problem, start, outcome, onIteration, settings.problemHessian);
    Ipopt::SmartPtr<Ipopt::TNLP> tnlp = adapter;  // owns it
    const Ipopt::ApplicationReturnStatus status = app->OptimizeTNLP(tnlp);
    outcome.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock).count();
    outcome.timings.total = outcome.seconds;
    const Ipopt::SmartPtr<Ipopt::SolveStatistics> statistics = app->Statistics();
    if (Ipopt::IsValid(statistics)) outcome.iterations = statistics->IterationCount();
    if (!adapter->finalized()) {
      outcome.status = status == Ipopt::Invalid_Option ? OuterStatus::InvalidOption : OuterStatus::InternalError;
      outcome.message = "Ipopt stopped before it had an iterate (return code " + std::to_string(static_cast<int>(status)) + ")";
    }
    return outcome;
  }
};

}  // namespace

std::unique_ptr<OuterSolver> makeIpoptSolver() { return std::make_unique<IpoptSolver>(); }

}  // namespace mcopt
