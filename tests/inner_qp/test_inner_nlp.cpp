// SPDX-License-Identifier: BSD-3-Clause
// The inner problem as the NLP solvers see it (inner_qp/inner_nlp.hpp): every value the
// callbacks report is written, and agrees with the Jacobian they report, in each balance mode.
// The elastic phase 2's band rows once had a Jacobian and no values, so SLSQP and Ipopt read
// whatever their buffers held (docs/theory/inner-problem.md, "Determinism").
#include <catch2/catch.hpp>
#include <limits>
#include <random>

#include "common/random_inner_problem.hpp"
#include "inner_qp/inner_nlp.hpp"

using namespace mcopt;
using inner_detail::BalanceMode;
using inner_detail::InnerNlp;

TEST_CASE("InnerNlp: every constraint value is written and matches its Jacobian, in each balance mode", "[inner][nlp]") {
  std::mt19937 rng(2027);
  const auto random = test::randomProblem(rng, 2);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::VectorXd wrenches = Eigen::VectorXd::NullaryExpr(12, [&] { return 100.0 * u(rng); });
  const double band = 0.25;
  for (const std::string& model : contactModelNames())
  for (const BalanceMode mode : {BalanceMode::Equality, BalanceMode::Dropped, BalanceMode::Band}) {
    INFO("contact model " << model << ", balance mode " << static_cast<int>(mode));
    const ContactProblem problem = test::assemble(random, model);
    const InnerNlp nlp(problem, mode, 1e-3, band);
    const int n = nlp.variableCount(), mi = nlp.inequalityCount(), me = nlp.equalityCount();
    const Eigen::VectorXd F = wrenches.head(n);  // the model's variables: 12, or 6 for two point contacts
    const double nan = std::numeric_limits<double>::quiet_NaN();
    // Buffers full of NaN: a value left unwritten stays NaN.
    Eigen::VectorXd g = Eigen::VectorXd::Constant(mi, nan), e = Eigen::VectorXd::Constant(std::max(me, 1), nan);
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> Jg(mi, n), Je(std::max(me, 1), n);
    Jg.setConstant(nan);
    Je.setConstant(nan);
    nlp.inequalities(F.data(), g.data(), Jg.data());
    nlp.equalities(F.data(), e.data(), Je.data());
    CHECK(g.allFinite());
    CHECK(Jg.allFinite());
    if (me > 0) {
      CHECK(e.head(me).allFinite());
      CHECK(Je.topRows(me).allFinite());
    }
    // Central differences of the values against the Jacobians.
    const double h = 1e-5;
    for (int k = 0; k < n; ++k) {
      Eigen::VectorXd plus = F, minus = F;
      plus[k] += h;
      minus[k] -= h;
      Eigen::VectorXd gp(mi), gm(mi), ep = Eigen::VectorXd::Zero(6), em = Eigen::VectorXd::Zero(6);
      nlp.inequalities(plus.data(), gp.data(), nullptr);
      nlp.inequalities(minus.data(), gm.data(), nullptr);
      nlp.equalities(plus.data(), ep.data(), nullptr);
      nlp.equalities(minus.data(), em.data(), nullptr);
      INFO("variable " << k);
      CHECK(((gp - gm) / (2 * h) - Jg.col(k)).cwiseAbs().maxCoeff() <= 1e-6 * (1.0 + Jg.col(k).cwiseAbs().maxCoeff()));
      if (me > 0)
        CHECK(((ep - em).head(me) / (2 * h) - Je.col(k).head(me)).cwiseAbs().maxCoeff() <=
              1e-6 * (1.0 + Je.col(k).cwiseAbs().maxCoeff()));
    }
    if (mode == BalanceMode::Band) {
      // The band's rows: balance F − target − band ≤ 0 and −(balance F − target) − band ≤ 0.
      const Vector6 residual = problem.balance * F - problem.balanceTarget;
      const Eigen::Index start = mi - 12;
      CHECK((g.segment<6>(start) - (residual.array() - band).matrix()).cwiseAbs().maxCoeff() <= 1e-9 * (1.0 + residual.cwiseAbs().maxCoeff()));
      CHECK((g.segment<6>(start + 6) - (-residual.array() - band).matrix()).cwiseAbs().maxCoeff() <= 1e-9 * (1.0 + residual.cwiseAbs().maxCoeff()));
    }
  }
}
