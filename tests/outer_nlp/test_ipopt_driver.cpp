// SPDX-License-Identifier: BSD-3-Clause
// The outer solver interface and Ipopt behind it, on problems with known solutions: both
// Hessian modes reach them, the finite-difference Hessian in Newton-like iteration counts, a
// stop request is honoured, bad options are refused with the scenario's line, the settings in
// the interface's own terms (iteration limit, tolerances, a start to keep) act, and the
// registry names its solvers.
#include <catch2/catch.hpp>

#include <fstream>
#include <iterator>
#include <vector>

#include "common/temp_dir.hpp"
#include "core/errors.hpp"
#include "outer_nlp/outer_solver.hpp"

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

/// The same problem boxed in |x|, |y| ≤ 2 (inactive), in other units, u = (units_x x, units_y y),
/// and saying so (variableUnits): Ipopt, working on u / units, sees the same problem whatever they are.
class RescaledDiscRosenbrock final : public NlpProblem {
 public:
  explicit RescaledDiscRosenbrock(const Eigen::Vector2d& units) : units_(units) {}
  const Eigen::Vector2d& units() const { return units_; }
  int variableCount() const override { return 2; }
  int constraintCount() const override { return 1; }
  const Eigen::VectorXi& jacobianRows() const override { return rows_; }
  const Eigen::VectorXi& jacobianColumns() const override { return columns_; }
  void variableBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const override {
    lower = -2.0 * units(), upper = 2.0 * units();
  }
  void constraintBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const override {
    disc_.constraintBounds(lower, upper);
  }
  void variableUnits(Eigen::VectorXd& u) const override { u = units(); }
  double objective(const Eigen::VectorXd& v) override { return disc_.objective(disc(v)); }
  void objectiveGradient(const Eigen::VectorXd& v, Eigen::VectorXd& g) override {
    disc_.objectiveGradient(disc(v), g);
    g = g.cwiseQuotient(units());
  }
  void constraints(const Eigen::VectorXd& v, Eigen::VectorXd& g) override { disc_.constraints(disc(v), g); }
  void jacobianValues(const Eigen::VectorXd& v, Eigen::VectorXd& values) override {
    disc_.jacobianValues(disc(v), values);
    values = values.cwiseQuotient(units());
  }
  void lagrangianHessian(const Eigen::VectorXd& v, double objectiveFactor, const Eigen::Ref<const Eigen::VectorXd>& multipliers,
                         Eigen::VectorXd& values) override {
    // DiscRosenbrock's own (differences in x, y), in u: H_u = H / (unit_r unit_c).
    disc_.lagrangianHessian(disc(v), objectiveFactor, multipliers, values);
    for (int r = 0; r < 2; ++r)
      for (int c = 0; c <= r; ++c) values[lowerTriangleIndex(r, c)] /= units()[r] * units()[c];
  }
  std::string rowName(int) const override { return "disc"; }
  Eigen::VectorXd disc(const Eigen::VectorXd& v) const { return v.cwiseQuotient(units()); }

 private:
  Eigen::Vector2d units_;
  DiscRosenbrock disc_;
  Eigen::VectorXi rows_ = Eigen::VectorXi::Zero(2), columns_ = (Eigen::VectorXi(2) << 0, 1).finished();
};

/// Two discs side by side, (x0, x1) and (x2, x3), each Rosenbrock's: the Hessian block
/// diagonal. `pattern` says which entries the problem declares (NlpProblem::hessianPattern):
/// the two blocks, the dense triangle, or a malformed list.
class TwoDiscs final : public NlpProblem {
 public:
  enum class Pattern { Blocks, Dense, Unordered, Upper };
  explicit TwoDiscs(Pattern pattern) : pattern_(pattern) {}
  int variableCount() const override { return 4; }
  int constraintCount() const override { return 2; }
  const Eigen::VectorXi& jacobianRows() const override { return rows_; }
  const Eigen::VectorXi& jacobianColumns() const override { return columns_; }
  void variableBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const override {
    lower.setConstant(4, -std::numeric_limits<double>::infinity());
    upper.setConstant(4, std::numeric_limits<double>::infinity());
  }
  void constraintBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const override {
    lower.setConstant(2, -std::numeric_limits<double>::infinity());
    upper.setConstant(2, 1.0);
  }
  double objective(const Eigen::VectorXd& v) override { return disc_.objective(v.head<2>()) + disc_.objective(v.tail<2>()); }
  void objectiveGradient(const Eigen::VectorXd& v, Eigen::VectorXd& g) override {
    Eigen::VectorXd a, b;
    disc_.objectiveGradient(v.head<2>(), a), disc_.objectiveGradient(v.tail<2>(), b);
    g.resize(4);
    g << a, b;
  }
  void constraints(const Eigen::VectorXd& v, Eigen::VectorXd& g) override {
    g.resize(2);
    g << v.head<2>().squaredNorm(), v.tail<2>().squaredNorm();
  }
  void jacobianValues(const Eigen::VectorXd& v, Eigen::VectorXd& values) override { values = 2 * v; }
  void hessianPattern(std::vector<int>& rows, std::vector<int>& columns) const override {
    switch (pattern_) {
      case Pattern::Dense: return NlpProblem::hessianPattern(rows, columns);
      case Pattern::Blocks: rows = {0, 1, 1, 2, 3, 3}, columns = {0, 0, 1, 2, 2, 3}; return;
      case Pattern::Unordered: rows = {1, 0, 1, 2, 3, 3}, columns = {0, 0, 1, 2, 2, 3}; return;
      case Pattern::Upper: rows = {0, 0, 1, 2, 3, 3}, columns = {0, 1, 1, 2, 2, 3}; return;
    }
  }
  std::string rowName(int row) const override { return row == 0 ? "first disc" : "second disc"; }

 private:
  Pattern pattern_;
  DiscRosenbrock disc_;
  Eigen::VectorXi rows_ = (Eigen::VectorXi(4) << 0, 0, 1, 1).finished(), columns_ = (Eigen::VectorXi(4) << 0, 1, 2, 3).finished();
};

/// Ipopt's log of its second-order derivative checker at `start`, with the problem's Hessian
/// (no iteration).
std::string secondOrderCheck(NlpProblem& problem, const Eigen::VectorXd& start) {
  const test::TempDir dir;
  OuterSolverSettings settings;
  settings.problemHessian = true;
  auto option = [](const char* name, const std::string& text, SolverOption::Type type) {
    SolverOption o;
    o.name = name, o.text = text, o.type = type, o.origin = std::string(name) + ": ";
    if (type == SolverOption::Type::Integer) o.integer = std::stoi(text);
    return o;
  };
  const auto log = dir.path() / "ipopt.txt";
  settings.options = {option("derivative_test", "second-order", SolverOption::Type::Text),
                      option("max_iter", "0", SolverOption::Type::Integer),
                      option("output_file", log.string(), SolverOption::Type::Text),
                      option("file_print_level", "5", SolverOption::Type::Integer)};
  solveOuter(problem, start, settings, nullptr);
  std::ifstream in(log);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

}  // namespace

TEST_CASE("Ipopt driver: a problem in other units, saying so, takes the same path in its own units", "[outer]") {
  // Ipopt works on x / units: the rescaled disc is the plain one to it, iteration by
  // iteration, if the driver scales the bounds, the start, the gradient, the Jacobian's
  // columns and the Hessian, and reports every point back in the problem's units.
  RescaledDiscRosenbrock plain(Eigen::Vector2d::Ones()), rescaled(Eigen::Vector2d(1000.0, 1e-3));
  const Eigen::VectorXd start = (Eigen::VectorXd(2) << -0.5, 0.2).finished();
  const Eigen::VectorXd units = rescaled.units();
  for (const bool newton : {false, true}) {
    INFO("Hessian by differences: " << newton);
    OuterSolverSettings settings;
    settings.problemHessian = newton;
    std::vector<double> plainPath, rescaledPath;
    const OuterOutcome a = solveOuter(plain, start, settings, [&](const IterationReport& r) {
      if (r.iterate != nullptr) plainPath.push_back((*r.iterate)[0]);
      return true;
    });
    const OuterOutcome b = solveOuter(rescaled, start.cwiseProduct(units), settings, [&](const IterationReport& r) {
      if (r.iterate == nullptr) return true;
      CHECK(rescaled.objective(*r.iterate) == Approx(r.objective).epsilon(1e-12));  // in the problem's units
      rescaledPath.push_back((*r.iterate)[0] / units[0]);
      return true;
    });
    CHECK(a.status == OuterStatus::Optimal);
    CHECK(b.status == OuterStatus::Optimal);
    CHECK(b.iterations == a.iterations);
    REQUIRE(rescaledPath.size() == plainPath.size());
    for (std::size_t k = 0; k < plainPath.size(); ++k) CHECK(rescaledPath[k] == Approx(plainPath[k]).epsilon(1e-9));
    CHECK(b.x[0] == Approx(0.786415 * units[0]).epsilon(1e-5));
    CHECK(b.x[1] == Approx(0.617698 * units[1]).epsilon(1e-5));
  }
}

TEST_CASE("Ipopt driver: both Hessian modes reach a known constrained optimum", "[outer]") {
  DiscRosenbrock problem;
  const Eigen::VectorXd start = (Eigen::VectorXd(2) << -0.5, 0.2).finished();
  OuterSolverSettings limitedMemory, differences;
  differences.problemHessian = true;
  const OuterOutcome quasiNewton = solveOuter(problem, start, limitedMemory, nullptr);
  const OuterOutcome newton = solveOuter(problem, start, differences, nullptr);
  for (const OuterOutcome* o : {&quasiNewton, &newton}) {
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
  const std::string text = secondOrderCheck(problem, (Eigen::VectorXd(2) << 0.3, 0.4).finished());
  CHECK_THAT(text, Catch::Contains("Starting derivative checker for second derivatives"));
  CHECK_THAT(text, Catch::Contains("No errors detected by derivative checker"));
}

TEST_CASE("Ipopt driver: Ipopt's second-order checker accepts the derivatives of a problem in other units", "[outer]") {
  // It differences what Ipopt sees (x / units): the gradient, Jacobian and Hessian scaled alike.
  RescaledDiscRosenbrock problem(Eigen::Vector2d(1000.0, 1e-3));
  const std::string text = secondOrderCheck(problem, (Eigen::VectorXd(2) << 300.0, 4e-4).finished());
  CHECK_THAT(text, Catch::Contains("Starting derivative checker for second derivatives"));
  CHECK_THAT(text, Catch::Contains("No errors detected by derivative checker"));
}

TEST_CASE("Ipopt driver: a Hessian declared sparse is read at its entries", "[outer]") {
  // The two discs declared as two blocks reach both optima in as many iterations as declared
  // dense (the left-out entries are zero: the same Newton steps), Ipopt's checker finds the
  // declared entries right, and a malformed pattern is refused before Ipopt starts.
  TwoDiscs blocks(TwoDiscs::Pattern::Blocks), dense(TwoDiscs::Pattern::Dense);
  const Eigen::VectorXd start = (Eigen::VectorXd(4) << -0.5, 0.2, 0.3, -0.4).finished();
  OuterSolverSettings settings;
  settings.problemHessian = true;
  const OuterOutcome a = solveOuter(blocks, start, settings, nullptr), b = solveOuter(dense, start, settings, nullptr);
  CHECK(a.status == OuterStatus::Optimal);
  CHECK(b.status == OuterStatus::Optimal);
  CHECK(a.iterations == b.iterations);
  CHECK((a.x - b.x).norm() <= 1e-9);
  for (const int first : {0, 2}) {
    CHECK(a.x[first] == Approx(0.786415).margin(1e-5));
    CHECK(a.x[first + 1] == Approx(0.617698).margin(1e-5));
  }
  const std::string text = secondOrderCheck(blocks, start);
  CHECK_THAT(text, Catch::Contains("Number of nonzeros in Lagrangian Hessian.............:        6"));
  CHECK_THAT(text, Catch::Contains("No errors detected by derivative checker"));
  for (const TwoDiscs::Pattern bad : {TwoDiscs::Pattern::Unordered, TwoDiscs::Pattern::Upper}) {
    TwoDiscs malformed(bad);
    CHECK_THROWS_WITH(solveOuter(malformed, start, settings, nullptr), Catch::Contains("Hessian pattern must list lower-triangle entries"));
  }
}

TEST_CASE("Ipopt driver: a stop request ends the solve as interrupted with its iterate", "[outer]") {
  DiscRosenbrock problem;
  const Eigen::VectorXd start = (Eigen::VectorXd(2) << -0.5, 0.2).finished();
  int seen = 0;
  const OuterOutcome o = solveOuter(problem, start, OuterSolverSettings{}, [&](const IterationReport& r) {
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
    OuterSolverSettings settings;
    settings.problemHessian = newton;
    int reported = 0;
    Eigen::VectorXd last;
    const OuterOutcome o = solveOuter(problem, start, settings, [&](const IterationReport& r) {
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
  OuterSolverSettings settings;
  SolverOption bad;
  bad.name = "no_such_option", bad.type = SolverOption::Type::Integer, bad.integer = 3;
  bad.origin = "s.yaml:12: solver.no_such_option: ";
  settings.options = {bad};
  CHECK_THROWS_WITH(solveOuter(problem, Eigen::VectorXd::Zero(2), settings, nullptr),
                    Catch::Contains("s.yaml:12: solver.no_such_option: Ipopt rejects option"));
}

TEST_CASE("outer solver: the registry lists ipopt and refuses an unknown name with the list", "[outer]") {
  CHECK(outerSolverNames() == std::vector<std::string>{"ipopt"});
  CHECK(makeOuterSolver("ipopt")->name() == "ipopt");
  CHECK_THROWS_WITH(makeOuterSolver("snopt"), Catch::Contains("expected ipopt; got 'snopt'"));
  OuterSolverSettings settings;
  settings.solver = "snopt";
  DiscRosenbrock problem;
  CHECK_THROWS_AS(solveOuter(problem, Eigen::VectorXd::Zero(2), settings, nullptr), InputError);
}

TEST_CASE("outer solver: the iteration limit overrides the solver's own options", "[outer]") {
  DiscRosenbrock problem;
  const Eigen::VectorXd start = (Eigen::VectorXd(2) << -0.5, 0.2).finished();
  OuterSolverSettings settings;
  SolverOption many;
  many.name = "max_iter", many.type = SolverOption::Type::Integer, many.integer = 100, many.text = "100";
  settings.options = {many};
  settings.maxIterations = 4;
  const OuterOutcome o = solveOuter(problem, start, settings, nullptr);
  CHECK(o.status == OuterStatus::MaximumIterations);
  CHECK(o.iterations == 4);
}

TEST_CASE("outer solver: a start to keep is not pushed off its bounds", "[outer]") {
  // min (x − 2)² + y² over x ∈ [0, 1], y ∈ [−1, 1], from x on its bound: the optimum is that
  // start. Without a kept start Ipopt first pushes x inside (bound_push 1e-2), and the first
  // iterate moves; kept, the first iterate is the start itself and the solve stays there.
  class Boxed final : public NlpProblem {
   public:
    int variableCount() const override { return 2; }
    int constraintCount() const override { return 0; }
    const Eigen::VectorXi& jacobianRows() const override { return empty_; }
    const Eigen::VectorXi& jacobianColumns() const override { return empty_; }
    void variableBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const override {
      lower = Eigen::Vector2d(0.0, -1.0), upper = Eigen::Vector2d(1.0, 1.0);
    }
    void constraintBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const override { lower.resize(0), upper.resize(0); }
    double objective(const Eigen::VectorXd& v) override { return (v[0] - 2) * (v[0] - 2) + v[1] * v[1]; }
    void objectiveGradient(const Eigen::VectorXd& v, Eigen::VectorXd& g) override { g = Eigen::Vector2d(2 * (v[0] - 2), 2 * v[1]); }
    void constraints(const Eigen::VectorXd&, Eigen::VectorXd& g) override { g.resize(0); }
    void jacobianValues(const Eigen::VectorXd&, Eigen::VectorXd& values) override { values.resize(0); }
    std::string rowName(int) const override { return ""; }

   private:
    Eigen::VectorXi empty_;
  };
  Boxed problem;
  const Eigen::VectorXd start = Eigen::Vector2d(1.0, 0.0);
  auto firstIterate = [&](const OuterSolverSettings& settings) {
    Eigen::VectorXd first;
    solveOuter(problem, start, settings, [&](const IterationReport& r) {
      if (r.iteration == 0 && r.iterate != nullptr) first = *r.iterate;
      return true;
    });
    return first;
  };
  OuterSolverSettings pushed, kept;
  kept.warmStart = OuterSolverSettings::WarmStart{1e-9, "test: "};
  const Eigen::VectorXd a = firstIterate(pushed), b = firstIterate(kept);
  REQUIRE(a.size() == 2);
  REQUIRE(b.size() == 2);
  CHECK(1.0 - a[0] >= 1e-3);        // pushed inside by 1e-2 of the box
  CHECK(1.0 - b[0] <= 1e-8);        // kept
}

}  // namespace mcopt
