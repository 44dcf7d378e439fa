// SPDX-License-Identifier: BSD-3-Clause
// The Ipopt driver on problems with known solutions: both Hessian modes reach them, the
// finite-difference Hessian in Newton-like iteration counts, a stop request is honoured and
// bad options are refused with the scenario's line.
#include <catch2/catch.hpp>

#include <fstream>
#include <iterator>

#include "common/temp_dir.hpp"
#include "core/errors.hpp"
#include "outer_nlp/ipopt_driver.hpp"

namespace mcopt {

namespace {

/// Rosenbrock's function in the unit disc: min (1 − x)² + 100 (y − x²)² s.t. x² + y² ≤ 1.
/// Solution (0.786415, 0.617698) (the constraint active).
class DiscRosenbrock final : public NlpProblem {
 public:
  int variableCount() const override { return 2; }
  int constraintCount() const override { return 1; }
  const Eigen::VectorXi& jacobianRows() const override { return rows_; }
  const Eigen::VectorXi& jacobianColumns() const override { return columns_; }
  void variableBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const override {
    lower.setConstant(2, -std::numeric_limits<double>::infinity());
    upper.setConstant(2, std::numeric_limits<double>::infinity());
  }
  void constraintBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const override {
    lower.setConstant(1, -std::numeric_limits<double>::infinity());
    upper.setConstant(1, 1.0);
  }
  double objective(const Eigen::VectorXd& v) override {
    return (1 - v[0]) * (1 - v[0]) + 100 * (v[1] - v[0] * v[0]) * (v[1] - v[0] * v[0]);
  }
  void objectiveGradient(const Eigen::VectorXd& v, Eigen::VectorXd& g) override {
    g.resize(2);
    g[0] = -2 * (1 - v[0]) - 400 * v[0] * (v[1] - v[0] * v[0]);
    g[1] = 200 * (v[1] - v[0] * v[0]);
  }
  void constraints(const Eigen::VectorXd& v, Eigen::VectorXd& g) override { g = Eigen::VectorXd::Constant(1, v.squaredNorm()); }
  void jacobianValues(const Eigen::VectorXd& v, Eigen::VectorXd& values) override { values = 2 * v; }
  std::string rowName(int) const override { return "disc"; }

 private:
  Eigen::VectorXi rows_ = Eigen::VectorXi::Zero(2), columns_ = (Eigen::VectorXi(2) << 0, 1).finished();
};

/// The same problem behind a first variable fixed at 0.25 by its bounds, which Ipopt removes
/// from its own iterate: reported iterates must put it back.
class FixedThenDiscRosenbrock final : public NlpProblem {
 public:
  int variableCount() const override { return 3; }
  int constraintCount() const override { return 1; }
  const Eigen::VectorXi& jacobianRows() const override { return rows_; }
  const Eigen::VectorXi& jacobianColumns() const override { return columns_; }
  void variableBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const override {
    Eigen::VectorXd l, u;
    disc_.variableBounds(l, u);
    lower.resize(3), upper.resize(3);
    lower << 0.25, l;
    upper << 0.25, u;
  }
  void constraintBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const override {
    disc_.constraintBounds(lower, upper);
  }
  double objective(const Eigen::VectorXd& v) override {
    return (v[0] - 1) * (v[0] - 1) + disc_.objective(v.tail<2>());
  }
  void objectiveGradient(const Eigen::VectorXd& v, Eigen::VectorXd& g) override {
    Eigen::VectorXd tail;
    disc_.objectiveGradient(v.tail<2>(), tail);
    g.resize(3);
    g << 2 * (v[0] - 1), tail;
  }
  void constraints(const Eigen::VectorXd& v, Eigen::VectorXd& g) override { disc_.constraints(v.tail<2>(), g); }
  void jacobianValues(const Eigen::VectorXd& v, Eigen::VectorXd& values) override {
    disc_.jacobianValues(v.tail<2>(), values);
  }
  std::string rowName(int) const override { return "disc"; }

 private:
  DiscRosenbrock disc_;
  Eigen::VectorXi rows_ = Eigen::VectorXi::Zero(2), columns_ = (Eigen::VectorXi(2) << 1, 2).finished();
};

}  // namespace

TEST_CASE("Ipopt driver: both Hessian modes reach a known constrained optimum", "[outer]") {
  DiscRosenbrock problem;
  const Eigen::VectorXd start = (Eigen::VectorXd(2) << -0.5, 0.2).finished();
  IpoptSettings limitedMemory, differences;
  differences.problemHessian = true;
  const IpoptOutcome quasiNewton = solveWithIpopt(problem, start, limitedMemory, nullptr);
  const IpoptOutcome newton = solveWithIpopt(problem, start, differences, nullptr);
  for (const IpoptOutcome* o : {&quasiNewton, &newton}) {
    CHECK(o->status == OuterStatus::Optimal);
    CHECK(o->optimal());
    CHECK(o->x[0] == Approx(0.786415).margin(1e-5));
    CHECK(o->x[1] == Approx(0.617698).margin(1e-5));
  }
  INFO("iterations: limited memory " << quasiNewton.iterations << ", finite-difference Hessian " << newton.iterations);
  CHECK(newton.iterations <= 30);
}

TEST_CASE("Ipopt driver: Ipopt's second-order checker accepts the finite-difference Hessian", "[outer]") {
  DiscRosenbrock problem;
  const test::TempDir dir;
  IpoptSettings settings;
  settings.problemHessian = true;
  auto option = [](const char* name, const std::string& text, SolverOption::Type type) {
    SolverOption o;
    o.name = name, o.text = text, o.type = type, o.origin = std::string(name) + ": ";
    if (type == SolverOption::Type::Integer) o.integer = std::stoi(text);
    if (type == SolverOption::Type::Number) o.number = std::stod(text);
    return o;
  };
  const auto log = dir.path() / "ipopt.txt";
  settings.options = {option("derivative_test", "second-order", SolverOption::Type::Text),
                      option("max_iter", "0", SolverOption::Type::Integer),
                      option("output_file", log.string(), SolverOption::Type::Text),
                      option("file_print_level", "5", SolverOption::Type::Integer)};
  solveWithIpopt(problem, (Eigen::VectorXd(2) << 0.3, 0.4).finished(), settings, nullptr);
  std::ifstream in(log);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK_THAT(text, Catch::Contains("Starting derivative checker for second derivatives"));
  CHECK_THAT(text, Catch::Contains("No errors detected by derivative checker"));
}

TEST_CASE("Ipopt driver: a stop request ends the solve as interrupted with its iterate", "[outer]") {
  DiscRosenbrock problem;
  const Eigen::VectorXd start = (Eigen::VectorXd(2) << -0.5, 0.2).finished();
  int seen = 0;
  const IpoptOutcome o = solveWithIpopt(problem, start, IpoptSettings{}, [&](const IterationReport& r) {
    seen = r.iteration;
    return r.iteration < 3;
  });
  CHECK(o.status == OuterStatus::Interrupted);
  CHECK_FALSE(o.optimal());
  CHECK(seen == 3);
  CHECK(o.x.size() == 2);
  CHECK(o.x.allFinite());
}

TEST_CASE("Ipopt driver: every iteration reports its iterate in the problem's variables", "[outer]") {
  FixedThenDiscRosenbrock problem;
  const Eigen::VectorXd start = (Eigen::VectorXd(3) << 0.25, -0.5, 0.2).finished();
  for (const bool newton : {false, true}) {
    IpoptSettings settings;
    settings.problemHessian = newton;
    int reported = 0;
    Eigen::VectorXd last;
    const IpoptOutcome o = solveWithIpopt(problem, start, settings, [&](const IterationReport& r) {
      if (r.iterate == nullptr) return true;  // restoration phase
      ++reported;
      REQUIRE(r.iterate->size() == 3);
      CHECK((*r.iterate)[0] == 0.25);                                          // the fixed variable put back
      CHECK(problem.objective(*r.iterate) == Approx(r.objective).epsilon(1e-12));  // it is the reported point
      last = *r.iterate;
      return true;
    });
    INFO("Hessian by differences: " << newton);
    CHECK(o.status == OuterStatus::Optimal);
    CHECK(reported == o.iterations + 1);  // iteration 0 included
    CHECK((last - o.x).norm() <= 1e-14);
  }
}

TEST_CASE("Ipopt driver: options Ipopt refuses are input errors naming their origin", "[outer]") {
  DiscRosenbrock problem;
  IpoptSettings settings;
  SolverOption bad;
  bad.name = "no_such_option", bad.type = SolverOption::Type::Integer, bad.integer = 3;
  bad.origin = "s.yaml:12: solver.no_such_option: ";
  settings.options = {bad};
  CHECK_THROWS_WITH(solveWithIpopt(problem, Eigen::VectorXd::Zero(2), settings, nullptr),
                    Catch::Contains("s.yaml:12: solver.no_such_option: Ipopt rejects option"));
}

}  // namespace mcopt
