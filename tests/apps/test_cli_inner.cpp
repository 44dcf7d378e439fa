// SPDX-License-Identifier: BSD-3-Clause
// `mcopt inner` as a user meets it: the JSON problems of docs/theory/inner-problem.md in, one
// result per problem out, the same answers as the library, clear errors for bad input.
#include <catch2/catch.hpp>
#include <fstream>
#include <nlohmann/json.hpp>

#include "common/random_inner_problem.hpp"
#include "common/json_file.hpp"
#include "common/run_command.hpp"
#include "common/temp_dir.hpp"
#include "inner_qp/inner_solver.hpp"

using namespace mcopt;
using Catch::Matchers::Contains;
using Json = nlohmann::json;

namespace {

Json toJson(const Eigen::Ref<const Eigen::VectorXd>& v) { return std::vector<double>(v.data(), v.data() + v.size()); }

Json problemToJson(const test::RandomProblem& r) {
  Json p;
  for (const ContactSpec& c : r.contacts) {
    const Eigen::Quaterniond q(c.pose.rotation);
    p["contacts"].push_back({{"name", c.name},
                             {"position", toJson(c.pose.translation)},
                             {"quaternion_xyzw", {q.x(), q.y(), q.z(), q.w()}},
                             {"mu", c.friction},
                             {"rectangle", {c.xMin, c.xMax, c.yMin, c.yMax}}});
  }
  for (Eigen::Index i = 0; i < r.wrenchToTorque.rows(); ++i)
    p["wrench_to_torque"].push_back(toJson(r.wrenchToTorque.row(i).transpose()));
  p["tau0"] = toJson(r.tau0);
  p["balance_wrench"] = toJson(r.balance);
  p["torque_weights"] = toJson(r.weights);
  p["torque_linear"] = toJson(r.linear);
  return p;
}

using mcopt::test::readJson;

}  // namespace

TEST_CASE("inner: every solver through the command gives that solver's library answers", "[cli][inner]") {
  std::mt19937 rng(211);
  std::vector<test::RandomProblem> problems;
  for (int nc : {2, 3, 4}) problems.push_back(test::randomProblem(rng, nc));
  test::RandomProblem pulling = test::randomProblem(rng, 2);  // both feet on the floor, asked to pull
  for (ContactSpec& c : pulling.contacts) c.pose = RigidTransform{};
  pulling.balance << 0, 0, -300, 0, 0, 0;
  problems.push_back(pulling);
  Json input;
  for (const auto& r : problems) input["problems"].push_back(problemToJson(r));
  test::TempDir dir;
  const auto file = dir.write("problems.json", input.dump());

  for (const std::string& solver : innerSolverNames()) {  // every registered solver
    const auto out = dir.path() / (solver + ".json");
    // The barrier solver takes linear contact models only (its own test below refuses the report model).
    const std::string model = solver == "barrier" ? "wrench-cone" : "report";
    const auto r = test::runMcopt("inner --problems " + test::quoted(file) + " --solver " + solver + " --contact-model " +
                                  model + " --out " + test::quoted(out));
    INFO(solver << ": " << r.errors);
    CHECK_THAT(r.errors, Contains("4 problems"));
    const Json results = readJson(out)["results"];
    REQUIRE(results.size() == problems.size());
    bool anyFailed = false;
    for (const auto& result : results) anyFailed |= result["status"] == "failed";
    CHECK(r.exitCode == (anyFailed ? 1 : 0));  // a failed problem is the command's failure
    for (std::size_t k = 0; k < problems.size(); ++k) {
      const Json& result = results[k];
      INFO("problem " << k);
      const ContactProblem p = test::assemble(problems[k], model);
      InnerResult expected;
      makeInnerSolver(solver)->solve(p, expected);
      CHECK(result["status"] == toString(expected.status));
      REQUIRE(result["wrenches"].size() == problems[k].contacts.size());
      Eigen::VectorXd F(6 * p.contactCount);
      for (int i = 0; i < p.contactCount; ++i) {
        REQUIRE(result["wrenches"][static_cast<std::size_t>(i)].size() == 6);
        for (int c = 0; c < 6; ++c) F[6 * i + c] = result["wrenches"][static_cast<std::size_t>(i)][static_cast<std::size_t>(c)];
      }
      // The objective reported is the objective of the wrenches reported, without regularisation.
      CHECK(result["objective"].get<double>() == Approx(p.objective(F)).epsilon(1e-12));
      // The command warm-starts each problem from the previous answer, the library call here is
      // cold: certified answers agree; a failed one is nobody's optimum and may stop elsewhere.
      if (expected.status != InnerStatus::Failed)
        CHECK(std::abs(result["objective"].get<double>() - expected.objective) <= 1e-6 * (1 + std::abs(expected.objective)));
      if (solver == "active-set" || solver == "barrier") CHECK(result["status"] == (k < 3 ? "optimal" : "infeasible"));
      CHECK(result["barrier"].get<double>() == (solver == "barrier" && k < 3 ? 1e-3 : 0.0));
      for (const char* key : {"multipliers", "active_set", "iterations", "kkt_residual", "solve_time_us", "balance_slack"})
        CHECK(result.contains(key));
      CHECK(result["balance_slack"].size() == 6);
      for (const auto& name : result["active_set"]) CHECK_THAT(name.get<std::string>(), Contains("contact"));
    }
    if (results[3]["status"] == "infeasible") CHECK(results[3]["balance_slack"][2].get<double>() < -299.0);
  }
}

TEST_CASE("inner: the barrier solver's μ from --barrier, refused with another solver, a non-positive μ or second-order cones",
          "[cli][inner][barrier]") {
  std::mt19937 rng(227);
  Json input;
  for (int k = 0; k < 3; ++k) input["problems"].push_back(problemToJson(test::randomProblem(rng, 2, 30)));
  test::TempDir dir;
  const auto file = dir.write("problems.json", input.dump());
  const std::string head = "inner --problems " + test::quoted(file) + " ";
  const auto r = test::runMcopt(head + "--solver barrier --barrier 0.01 --contact-model pyramid");
  INFO(r.all());
  REQUIRE(r.exitCode == 0);
  for (const Json& result : Json::parse(r.output)["results"]) {
    CHECK(result["status"] == "optimal");
    CHECK(result["barrier"].get<double>() == 0.01);
    CHECK(result["active_set"].empty());
  }
  const auto other = test::runMcopt(head + "--solver active-set --barrier 0.01 --contact-model pyramid");
  CHECK(other.exitCode == 2);
  CHECK_THAT(other.errors, Contains("--barrier: only the barrier inner solver has a barrier parameter (the solver is active-set)"));
  const auto zero = test::runMcopt(head + "--solver barrier --barrier 0 --contact-model pyramid");
  CHECK(zero.exitCode == 2);
  CHECK_THAT(zero.errors, Contains("--barrier: must be a positive number"));
  const auto out = dir.path() / "cones.json";
  const auto cones = test::runMcopt(head + "--solver barrier --contact-model report --out " + test::quoted(out));
  CHECK(cones.exitCode == 2);
  CHECK_THAT(cones.errors, Contains("second-order friction cones") && Contains("pyramid or wrench-cone"));
  CHECK_FALSE(std::filesystem::exists(out));
}

TEST_CASE("inner: contact models, warm start on and off, standard output", "[cli][inner]") {
  std::mt19937 rng(223);
  Json input;
  for (int k = 0; k < 3; ++k) input["problems"].push_back(problemToJson(test::randomProblem(rng, 3)));
  test::TempDir dir;
  const auto file = dir.write("problems.json", input.dump());
  for (const char* model : {"report", "pyramid --pyramid-facets 12", "wrench-cone"}) {
    for (const char* warm : {"", " --cold"}) {
      const auto r = test::runMcopt("inner --problems " + test::quoted(file) + " --contact-model " + model + warm);
      INFO(model << warm << ": " << r.errors);
      REQUIRE(r.exitCode == 0);
      const Json results = Json::parse(r.output)["results"];
      REQUIRE(results.size() == 3);
      for (const auto& result : results) {
        CHECK(result["status"] == "optimal");
        CHECK(result["kkt_residual"].get<double>() <= 1e-9);
      }
    }
  }
}

TEST_CASE("inner: bad input names the file and field", "[cli][inner][input]") {
  std::mt19937 rng(227);
  test::TempDir dir;
  const Json good = {{"problems", {problemToJson(test::randomProblem(rng, 2))}}};
  auto expectError = [&](const Json& input, const std::string& extra, const std::vector<std::string>& fragments) {
    const auto file = dir.write("bad.json", input.dump());
    const auto r = test::runMcopt("inner --problems " + test::quoted(file) + extra);
    INFO(r.errors);
    CHECK(r.exitCode == 2);
    for (const auto& fragment : fragments) CHECK_THAT(r.errors, Contains(fragment));
  };
  Json bad = good;
  bad["problems"][0]["contacts"][1]["rectangle"] = {0.1, 0.2, 0.3};
  expectError(bad, "", {"bad.json", "problems[0].contacts[1].rectangle", "4 numbers"});
  bad = good;
  bad["problems"][0]["contacts"][0]["friction"] = 0.5;
  expectError(bad, "", {"problems[0].contacts[0].friction", "unknown key"});
  bad = good;
  bad["problems"][0]["tau0"][3] = "x";
  expectError(bad, "", {"problems[0].tau0[3]", "expected a number"});
  bad = good;
  bad["problems"][0]["contacts"][0]["mu"] = -1.0;
  expectError(bad, "", {"problems[0]", "contact 'contact0'", "mu"});
  bad = good;
  bad["problems"][0].erase("balance_wrench");
  expectError(bad, "", {"problems[0]", "missing 'balance_wrench'"});
  expectError(good, " --solver qpoases", {"solver", "expected " + innerSolverList(), "'qpoases'"});
  expectError(good, " --contact-model soft", {"--contact-model", "report, pyramid, wrench-cone or point"});
  expectError(good, " --pyramid-facets 6", {"pyramid facets", "only the pyramid contact model has facets"});
  expectError(good, " --contact-model pyramid --pyramid-facets 2", {"pyramid facets", "at least 3"});
  const auto r = test::runMcopt("inner --problems " + test::quoted(dir.path() / "missing.json"));
  CHECK(r.exitCode == 2);
  CHECK_THAT(r.errors, Contains("missing.json") && Contains("cannot open"));
}

TEST_CASE("inner --sensitivity agrees with finite differences of mcopt inner itself", "[cli][inner][sensitivity]") {
  std::mt19937 rng(229);
  const test::RandomProblem base = test::randomProblem(rng, 3, 30);
  // One file: the problem, then each moved one way and the other (solved --cold, independently).
  const std::vector<int> moved = {0, 11, 29, 30 + 2, 30 + 4};  // τ0 entries, then W entries
  Json input;
  input["problems"].push_back(problemToJson(base));
  std::vector<double> steps;
  for (int which : moved) {
    const double step = which < 30 ? 3e-3 : 3e-2;
    steps.push_back(step);
    for (double sign : {1.0, -1.0}) {
      test::RandomProblem r = base;
      if (which < 30)
        r.tau0[which] += sign * step;
      else
        r.balance[which - 30] += sign * step;
      input["problems"].push_back(problemToJson(r));
    }
  }
  test::TempDir dir;
  const auto file = dir.write("problems.json", input.dump());
  for (const char* backend : {"dense", "klu", "umfpack"}) {
    const auto r = test::runMcopt("inner --cold --sensitivity --kkt-backend " + std::string(backend) + " --problems " +
                                  test::quoted(file));
    INFO(backend << ": " << r.errors);
    REQUIRE(r.exitCode == 0);
    const Json results = Json::parse(r.output)["results"];
    const Json& first = results[0];
    REQUIRE(first["status"] == "optimal");
    REQUIRE(first["dwrenches_dtau0"].size() == 18);
    REQUIRE(first["dwrenches_dtau0"][0].size() == 30);
    REQUIRE(first["dwrenches_dbalance"].size() == 18);
    REQUIRE(first["dwrenches_dbalance"][0].size() == 6);
    CHECK(first["sensitivity"]["degenerate"] == false);
    for (std::size_t k = 0; k < moved.size(); ++k) {
      const Json& plus = results[1 + 2 * k]["wrenches"];
      const Json& minus = results[2 + 2 * k]["wrenches"];
      for (std::size_t row = 0; row < 18; ++row) {
        const double difference = (plus[row / 6][row % 6].get<double>() - minus[row / 6][row % 6].get<double>()) /
                                  (2.0 * steps[k]);
        const double analytic = moved[k] < 30 ? first["dwrenches_dtau0"][row][static_cast<std::size_t>(moved[k])].get<double>()
                                              : first["dwrenches_dbalance"][row][static_cast<std::size_t>(moved[k] - 30)].get<double>();
        INFO("parameter " << moved[k] << ", row " << row);
        // The JSON's 17 significant digits and the solves' own accuracy bound the agreement.
        CHECK(std::abs(analytic - difference) <= 1e-6 * std::max(1.0, std::abs(difference)));
      }
    }
  }
}
