// SPDX-License-Identifier: BSD-3-Clause
// Ipopt on the inner problem: the report's slow baseline (formulation.md §7). Ipopt's
// headers stay in this file. Exact Hessian of the Lagrangian: H plus, per cone, its
// multiplier times the cone constraint's Hessian (InnerNlp::coneHessian).
#include <IpIpoptApplication.hpp>
#include <IpSolveStatistics.hpp>
#include <IpTNLP.hpp>

#include <mutex>

#include "inner_qp/inner_nlp.hpp"

namespace mcopt {

namespace {

using inner_detail::BalanceMode;
using inner_detail::InnerNlp;
using inner_detail::RunOutcome;
using Ipopt::Index;
using Ipopt::Number;

class InnerTnlp final : public Ipopt::TNLP {
 public:
  InnerTnlp(const InnerNlp& nlp, Eigen::VectorXd& x, RunOutcome& outcome) : nlp_(nlp), x_(x), outcome_(outcome) {}

  bool get_nlp_info(Index& n, Index& m, Index& nnzJacobian, Index& nnzHessian, IndexStyleEnum& style) override {
    n = nlp_.variableCount();
    m = nlp_.equalityCount() + nlp_.inequalityCount();
    nnzJacobian = n * m;            // dense: the problem is tiny (6 nc ≤ 24 variables)
    nnzHessian = n * (n + 1) / 2;   // lower triangle
    style = C_STYLE;
    return true;
  }
  bool get_bounds_info(Index n, Number* xL, Number* xU, Index m, Number* gL, Number* gU) override {
    for (Index i = 0; i < n; ++i) xL[i] = -2e19, xU[i] = 2e19;
    for (Index i = 0; i < m; ++i) {
      gL[i] = i < nlp_.equalityCount() ? 0.0 : -2e19;
      gU[i] = 0.0;
    }
    return true;
  }
  bool get_starting_point(Index n, bool initX, Number* x, bool, Number*, Number*, Index, bool, Number*) override {
    if (initX) std::copy(x_.data(), x_.data() + n, x);
    return true;
  }
  bool eval_f(Index, const Number* x, bool, Number& value) override {
    value = nlp_.objective(x);
    return true;
  }
  bool eval_grad_f(Index, const Number* x, bool, Number* gradient) override {
    nlp_.objectiveGradient(x, gradient);
    return true;
  }
  bool eval_g(Index, const Number* x, bool, Index, Number* g) override {
    nlp_.equalities(x, g, nullptr);
    nlp_.inequalities(x, g + nlp_.equalityCount(), nullptr);
    return true;
  }
  bool eval_jac_g(Index n, const Number* x, bool, Index m, Index, Index* rows, Index* cols, Number* values) override {
    if (values == nullptr) {
      for (Index r = 0; r < m; ++r)
        for (Index c = 0; c < n; ++c) rows[r * n + c] = r, cols[r * n + c] = c;
      return true;
    }
    const Index e = nlp_.equalityCount();
    nlp_.equalities(x, scratch(static_cast<std::size_t>(e)), values);
    nlp_.inequalities(x, scratch(static_cast<std::size_t>(m - e)), values + e * n);
    return true;
  }
  bool eval_h(Index n, const Number* x, bool, Number objectiveFactor, Index, const Number* lambda, bool, Index,
              Index* rows, Index* cols, Number* values) override {
    if (values == nullptr) {
      Index k = 0;
      for (Index r = 0; r < n; ++r)
        for (Index c = 0; c <= r; ++c) rows[k] = r, cols[k] = c, ++k;
      return true;
    }
    const ContactProblem& p = nlp_.problem();
    Index k = 0;
    for (Index r = 0; r < n; ++r)
      for (Index c = 0; c <= r; ++c, ++k) values[k] = objectiveFactor * p.hessian(r, c);
    const Index coneStart = nlp_.equalityCount() + static_cast<Index>(p.inequality.rows());
    auto at = [](Index r, Index c) { return r * (r + 1) / 2 + c; };  // lower triangle, r ≥ c
    for (std::size_t i = 0; i < p.cones.size(); ++i) {
      const Index f = p.cones[i].index;
      const double nu = lambda[coneStart + static_cast<Index>(i)];
      Eigen::Matrix2d shear;
      double fz = 0.0;
      nlp_.coneHessian(x, i, shear, fz);
      values[at(f, f)] += nu * shear(0, 0);
      values[at(f + 1, f)] += nu * shear(1, 0);
      values[at(f + 1, f + 1)] += nu * shear(1, 1);
      values[at(f + 2, f + 2)] += nu * fz;
    }
    return true;
  }
  void finalize_solution(Ipopt::SolverReturn status, Index n, const Number* x, const Number*, const Number*, Index m,
                         const Number*, const Number* lambda, Number, const Ipopt::IpoptData*,
                         Ipopt::IpoptCalculatedQuantities*) override {
    x_ = Eigen::Map<const Eigen::VectorXd>(x, n);
    // Ipopt's word is not final: it may declare local infeasibility at a feasible point. The
    // common flow judges every finite point by feasibility and the KKT conditions.
    outcome_.converged = status != Ipopt::INTERNAL_ERROR && status != Ipopt::INVALID_NUMBER_DETECTED;
    outcome_.hasMultipliers = true;
    const Index e = nlp_.equalityCount();
    outcome_.equalityMultipliers.setZero();
    for (Index i = 0; i < e; ++i) outcome_.equalityMultipliers[i] = lambda[i];
    outcome_.inequalityMultipliers = Eigen::Map<const Eigen::VectorXd>(lambda + e, m - e);
  }

 private:
  double* scratch(std::size_t size) {
    buffer_.resize(size);
    return buffer_.data();
  }
  const InnerNlp& nlp_;
  Eigen::VectorXd& x_;
  RunOutcome& outcome_;
  std::vector<double> buffer_;
};

/// One Ipopt application per solver object, its options set and initialised once (creating
/// and initialising one per solve cost ~8 ms, more than the solve itself: measured with
/// Inner/ipopt/*).
Ipopt::SmartPtr<Ipopt::IpoptApplication> makeApplication(const InnerSettings& settings) {
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  app->RethrowNonIpoptException(true);
  app->Options()->SetIntegerValue("print_level", 0);
  app->Options()->SetStringValue("sb", "yes");
  app->Options()->SetNumericValue("tol", settings.tolerance);
  app->Options()->SetNumericValue("constr_viol_tol", settings.tolerance);
  app->Options()->SetIntegerValue("max_iter", settings.maxIterations);
  // Monotone barrier updates: with the adaptive strategy Ipopt stalled at its iteration
  // limit on 33 of the 1002 catalogue problems (unloaded contacts), with monotone on 1.
  app->Options()->SetStringValue("mu_strategy", "monotone");
  // Feasibility is judged on the problem as given: no relaxed bounds, no internal scaling.
  app->Options()->SetNumericValue("bound_relax_factor", 0.0);
  app->Options()->SetStringValue("nlp_scaling_method", "none");
  if (app->Initialize() != Ipopt::Solve_Succeeded) return nullptr;
  return app;
}

RunOutcome runIpopt(Ipopt::IpoptApplication* app, const ContactProblem& problem, BalanceMode balance, double band,
                    Eigen::VectorXd& x) {
  // The smooth inner cone √(fx² + fy² + δ²) ≤ μ fz: with the report's quadratic form
  // fx² + fy² ≤ μ² fz² Ipopt failed on 11 of the first 180 catalogue problems (its gradient
  // vanishes at an unloaded contact, where constraint qualification fails), with the smooth
  // form on 4. δ = 1e-8 of the data's scale (its curvature 1/δ at the apex is what slows an
  // interior point; 1e-10 reached the optimum on 969 of 1002 problems, 1e-8 on 976, 1e-6 on
  // 959 as the optimum itself moves; tests/inner_qp/test_inner_solvers.cpp).
  const double smoothing = 1e-8 * problem.dataScale();
  const InnerNlp nlp(problem, balance, smoothing, band);
  RunOutcome outcome;
  outcome.coneSmoothing = smoothing;
  if (app == nullptr) {
    outcome.message = "ipopt: initialisation failed";
    return outcome;
  }
  Ipopt::SmartPtr<Ipopt::TNLP> tnlp = new InnerTnlp(nlp, x, outcome);
  // MUMPS is not thread-safe, and Ipopt 3.11 does not guard it (Ipopt only avoids calling
  // MUMPS from parallel threads since 3.14, coin-or/Ipopt#733): two samples solved at once on
  // two threads crashed the bilevel outer problem (SIGSEGV / SIGFPE). Every inner Ipopt solve
  // of the process is therefore serialised; the other inner solvers run in parallel.
  static std::mutex mumps;
  const std::lock_guard<std::mutex> lock(mumps);
  const Ipopt::ApplicationReturnStatus status = app->OptimizeTNLP(tnlp);
  const Ipopt::SmartPtr<Ipopt::SolveStatistics> statistics = app->Statistics();
  outcome.iterations = Ipopt::IsValid(statistics) ? statistics->IterationCount() : 0;
  outcome.message = "ipopt: return status " + std::to_string(static_cast<int>(status));
  outcome.converged = outcome.converged && x.allFinite() && status > Ipopt::Internal_Error;
  return outcome;
}

class IpoptSolver final : public InnerSolver {
 public:
  explicit IpoptSolver(const InnerSettings& settings) : settings_(settings), app_(makeApplication(settings)) {}
  std::string name() const override { return "ipopt"; }
  void solve(const ContactProblem& problem, InnerResult& result) override {
    Ipopt::IpoptApplication* app = Ipopt::GetRawPtr(app_);
    inner_detail::solveWithElasticFallback(
        problem, settings_,
        [app](const ContactProblem& p, BalanceMode balance, double band, const InnerSettings&, Eigen::VectorXd& x) {
          return runIpopt(app, p, balance, band, x);
        },
        result);
  }

 private:
  InnerSettings settings_;
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app_;
};

}  // namespace

std::unique_ptr<InnerSolver> makeIpoptSolver(const InnerSettings& settings) {
  return std::make_unique<IpoptSolver>(settings);
}

}  // namespace mcopt
