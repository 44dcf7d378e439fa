// SPDX-License-Identifier: BSD-3-Clause
// The outer rows as constraint terms (outer_nlp/constraint_term.hpp): every row's kind is one
// its term registers, every registered kind is laid out by some bundled scenario and documented
// (docs/reference/results.md, `violation_by_kind`), the rows of a sample follow the registry's
// order, and a row's bounds, name and value are its term's. The objective as cost terms
// (outer_nlp/cost_term.hpp): each energy form and the regularisation against the sampled motion.
#include <catch2/catch.hpp>

#include <algorithm>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <string>

#include "common/test_support.hpp"
#include "outer_nlp/motion_problem.hpp"

namespace mcopt {

namespace {

struct Variant {
  const char* label;
  Scenario scenario;
};

/// Between them, rows of every kind: the kick with the epigraph (velocity and torque limits,
/// its sole's report-model rows, its toe task, the epigraph), the lean reach bilevel (inner
/// feasibility, the hand's closure rows and closing joints; with the margin row and the loops'
/// reach) and with `variables` (the wrench-cone's yaw rows).
std::vector<Variant> variants() {
  std::vector<Variant> out;
  Scenario kick = loadScenario(test::sourceDir() / "scenarios/hrp2_kick.yaml");
  kick.samples = 12, kick.energyForm = EnergyForm::Epigraph, kick.solve.torqueScreening = 0.0;
  out.push_back({"kick, epigraph", kick});
  Scenario lean = loadScenario(test::sourceDir() / "scenarios/hrp2_lean_reach.yaml");
  lean.samples = 12;
  out.push_back({"lean reach, bilevel", lean});
  lean.inner.feasibility = InnerFeasibility::Margin;
  lean.closureReachMargin = 1e-3;
  out.push_back({"lean reach, bilevel, margin row, loop reach", lean});
  lean.inner.feasibility = InnerFeasibility::Slack;
  lean.closureReachMargin = 0.0;
  lean.contactForces = "variables";
  out.push_back({"lean reach, variables", lean});
  return out;
}

/// The keys of the `violation_by_kind` table in docs/reference/results.md (first column, each
/// key in backquotes), position_limit (variable bounds, not a term) left out.
std::set<std::string> documentedKinds() {
  std::ifstream file(test::sourceDir() / "docs/reference/results.md");
  REQUIRE(file.good());
  std::set<std::string> keys;
  std::string line;
  bool inSection = false;
  while (std::getline(file, line)) {
    if (line.rfind("### ", 0) == 0) inSection = line == "### `violation_by_kind`";
    if (!inSection || line.rfind("| `", 0) != 0) continue;
    // The first cell's words in backquotes.
    const std::string first = line.substr(1, line.find('|', 1) - 1);
    for (std::size_t open = first.find('`'); open != std::string::npos; open = first.find('`', open)) {
      const std::size_t close = first.find('`', open + 1);
      if (close == std::string::npos) break;
      keys.insert(first.substr(open + 1, close - open - 1));
      open = close + 1;
    }
  }
  keys.erase("position_limit");
  return keys;
}

}  // namespace

TEST_CASE("constraint terms: every row's kind is registered, every registered kind is laid out and documented",
          "[outer][terms]") {
  std::set<std::string> registered, laidOut;
  for (Variant& v : variants()) {
    INFO(v.label);
    MotionProblem problem(v.scenario);
    std::set<std::string> kinds;
    for (const ConstraintKindInfo& k : problem.rowKinds()) {
      CHECK(kinds.insert(std::string(k.name)).second);  // each kind from one term
      CHECK(!k.unit.empty());
    }
    if (registered.empty()) registered = kinds;
    CHECK(kinds == registered);  // the same terms whatever the scenario
    for (int r = 0; r < problem.constraintCount(); ++r) {
      const std::string kind(problem.rowKind(r));
      CHECK(kinds.count(kind) == 1);
      laidOut.insert(kind);
    }
    // violations() reports every registered kind, rows or not.
    const MotionProblem::Violations violations = problem.violations(problem.initialPoint(v.scenario.start, v.scenario.end));
    CHECK(violations.byKind.size() == kinds.size());
    for (const std::string& k : kinds) CHECK(violations.of(k) >= 0.0);
    CHECK_THROWS_WITH(violations.of("torque"), "no constraint term lays out rows of kind 'torque'");
  }
  CHECK(laidOut == registered);
  CHECK(documentedKinds() == registered);
  CHECK(registered.size() == 13);
}

TEST_CASE("constraint terms: a sample's rows follow the registry's order, and each row's bounds, name and instant are its term's",
          "[outer][terms]") {
  for (Variant& v : variants()) {
    INFO(v.label);
    MotionProblem problem(v.scenario);
    const Eigen::VectorXd x = problem.initialPoint(v.scenario.start, v.scenario.end);
    const double T = problem.duration(x);
    Eigen::VectorXd lower, upper, g;
    problem.constraintBounds(lower, upper);
    problem.constraints(x, g);
    const auto termOf = [&](int r) {
      const std::string_view kind = problem.rowKind(r);
      for (std::size_t t = 0; t < problem.terms().size(); ++t)
        for (const ConstraintKindInfo& k : problem.terms()[t]->kinds())
          if (k.name == kind) return static_cast<int>(t);
      return -1;
    };
    int lastTerm = -1;
    int lastSample = -1;
    double lastTime = 0.0;
    RowPlace lastPlace = RowPlace::ControlPoints;
    for (int r = 0; r < problem.constraintCount(); ++r) {
      const int t = termOf(r);
      REQUIRE(t >= 0);
      const RowPlace place = problem.terms()[static_cast<std::size_t>(t)]->place();
      const std::string name = problem.rowName(r);
      INFO(name);
      CHECK(name.rfind(problem.rowSubject(r), 0) == 0);
      CHECK(lower[r] <= upper[r]);
      CHECK(std::isfinite(g[r]));
      // Control points first, then the samples in time, then the task instants.
      CHECK(static_cast<int>(place) >= static_cast<int>(lastPlace));
      if (place == RowPlace::ControlPoints) {
        CHECK(std::isnan(problem.rowTime(r, T)));
        CHECK(name.find("(control points)") != std::string::npos);
      } else if (place == RowPlace::Sample) {
        const std::size_t at = name.find(" at sample ");
        REQUIRE(at != std::string::npos);
        const int sample = std::stoi(name.substr(at + 11));
        // Samples in order, in time; within one the terms keep the registry's order.
        const double time = problem.rowTime(r, T);
        CHECK(time >= lastTime);
        CHECK(time <= T);
        lastTime = time;
        CHECK(sample >= lastSample);
        if (lastPlace == RowPlace::Sample && sample == lastSample) CHECK(t >= lastTerm);
        lastSample = sample;
      } else {
        CHECK(name.find(" of the motion") != std::string::npos);
      }
      lastPlace = place, lastTerm = t;
    }
  }
}

}  // namespace mcopt

namespace mcopt {

TEST_CASE("cost terms: each energy form's objective is the sampled energy, and the regularisation adds w ∫ Σ q̈² dt",
          "[outer][terms]") {
  // Against the motion's own samples (sampledPhysics: P and q̈ at each sample, max(P, 0)
  // integrated by the trapezoid rule), not against the terms' code.
  Scenario s = loadScenario(test::sourceDir() / "scenarios/hrp2_kick.yaml");
  s.samples = 15, s.solve.torqueScreening = 0.0;
  const auto integrate = [](const MotionProblem& problem, double T, const auto& integrand) {
    double sum = 0.0;
    for (int k = 0; k < problem.sampleCount(); ++k) sum += problem.sampleWeight(k) * T * integrand(k);
    return sum;
  };
  for (const EnergyForm form : {EnergyForm::SmoothMaximum, EnergyForm::Epigraph}) {
    s.energyForm = form, s.accelerationWeight = 0.0;
    MotionProblem plain(s);
    // A motion that moves (the kick's start and end postures are the same), the epigraph's
    // slacks at max(P, 0) of it.
    const Eigen::VectorXd start = plain.initialPoint(s.start, s.end);
    std::mt19937 rng(7);
    const Eigen::VectorXd motion =
        plain.motionParameters(start) + test::randomVector(rng, static_cast<int>(plain.motionParameters(start).size()), 0.05);
    const Eigen::VectorXd x = plain.pointFromMotion(motion, plain.duration(start));
    const SampledPhysics physics = plain.sampledPhysics(x);
    const double T = plain.duration(x);
    REQUIRE(plain.costs().size() == 2);
    CHECK(plain.costs()[0]->name() == (form == EnergyForm::Epigraph ? "energy (epigraph)" : "energy (smooth maximum)"));
    CHECK(plain.costs()[1]->name() == "acceleration regularisation");
    // The epigraph's slacks are its term's own variables: one per joint and sample, after every
    // other variable, ≥ 0 (and started at max(P, 0) above: E equals the sampled energy).
    const int own = plain.costs()[0]->variablesPerSample();
    CHECK(own == (form == EnergyForm::Epigraph ? s.robot.jointCount() : 0));
    CHECK(plain.costs()[1]->variablesPerSample() == 0);
    CHECK(plain.variableCount() == plain.nonlinearVariableCount() + own * plain.sampleCount());
    Eigen::VectorXd lower, upper;
    plain.variableBounds(lower, upper);
    CHECK((lower.tail(own * plain.sampleCount()).array() == 0.0).all());
    CHECK((upper.tail(own * plain.sampleCount()).array() == std::numeric_limits<double>::infinity()).all());
    const double E = plain.objective(x);
    if (form == EnergyForm::Epigraph) {
      CHECK(E == Approx(physics.energy).epsilon(1e-12));
    } else {
      // σ(P) − max(P, 0) lies in (0, ε/2]: the smooth maximum is above the energy by at most
      // ε/2 per joint and instant.
      const double gap = E - physics.energy;
      CHECK(gap > 0.0);
      CHECK(gap <= integrate(plain, T, [&](int) { return 0.5 * s.smoothing * s.robot.jointCount(); }) * (1.0 + 1e-12));
    }
    // The regularisation: w Σ_s c_s T Σ_j q̈_js² on top, whatever the energy form.
    s.accelerationWeight = 1e-3;
    MotionProblem regularised(s);
    const double added = integrate(regularised, T, [&](int k) { return s.accelerationWeight * physics.a.col(k).squaredNorm(); });
    INFO((form == EnergyForm::Epigraph ? "epigraph" : "smooth maximum"));
    CHECK(added > 0.0);
    CHECK(regularised.objective(x) - E == Approx(added).epsilon(1e-9));
  }
}

}  // namespace mcopt
