// SPDX-License-Identifier: BSD-3-Clause
// `mcopt run` as a user meets it (issue 7, docs/theory/outer-problem.md): Ipopt's derivative checker on
// the bundled scenario, the result files, torques reproduced by `mcopt dynamics`, an
// interrupted run, a killed run's checkpoint, and a message naming file, line and field for every class of bad input.
#include <yaml-cpp/yaml.h>

#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>

#include "common/json_file.hpp"
#include "common/run_command.hpp"
#include "common/scenario_variant.hpp"
#include "common/temp_dir.hpp"
#include "common/verify_result.hpp"
#include "common/test_support.hpp"
#include "core/actuators.hpp"
#include "core/dynamics_model.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"
#include "core/robot_files.hpp"

using namespace mcopt;
using Catch::Matchers::Contains;
using Json = nlohmann::json;

namespace {

const std::filesystem::path kKick = test::sourceDir() / "scenarios/hrp2_kick.yaml";

using mcopt::test::kUnderSanitizers;

/// A bundled scenario with its side files made absolute, then `edit` applied, written to dir.
using test::scenarioVariant;

std::filesystem::path kickVariant(const test::TempDir& dir, const std::function<void(YAML::Node&)>& edit,
                                  const std::string& name = "scenario.yaml") {
  return scenarioVariant(kKick, dir, edit, name);
}

/// The kick with the smooth maximum (ε = 0.01 W) as its criterion and the stages it had before
/// the bundled kick took the epigraph form: for the tests of the smooth maximum's fields and of
/// stages that change ν, ε or the samples, which the epigraph form's per-sample slacks refuse.
void smoothMaximumKick(YAML::Node& root) {
  root["objective"] = YAML::Load("{energy: smooth_max, smoothing: 0.01}");
  root["hessian"] = "sample-differences";
  root["continuation"] = YAML::Load("[{hessian: gauss-newton, max_iterations: 500}]");
}

/// The offset-free kick's route on 20 samples: the epigraph with the exact Hessian after a
/// Gauss–Newton smooth-maximum stage of at most `stageIterations`.
void epigraphAfterSmoothMaximum(YAML::Node& root, int stageIterations) {
  root["samples"] = 20;
  root["objective"] = YAML::Load("{energy: epigraph}");
  root["hessian"] = "exact";
  root["continuation"] = YAML::Load("[{energy: smooth_max, smoothing: 0.01, hessian: gauss-newton}]");
  root["continuation"][0]["max_iterations"] = stageIterations;
}

/// Runs `scenario` into dir/out; REQUIREs exit 0 and returns result.json.
Json runToOptimal(const test::TempDir& dir, const std::filesystem::path& scenario) {
  const auto out = dir.path() / "out";
  const auto r = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(out));
  INFO(r.all());
  REQUIRE(r.exitCode == 0);
  const Json result = test::readJson(out / "result.json");
  CHECK(result["status"] == "optimal");
  return result;
}

/// Runs a shell command that ends by echoing an exit status (of a job it signalled) and returns it.
int exitStatusEchoed(const std::string& command) {
  FILE* pipe = ::popen(command.c_str(), "r");
  REQUIRE(pipe != nullptr);
  std::array<char, 256> buffer{};
  std::string echoed;
  while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr) echoed += buffer.data();
  ::pclose(pipe);
  return std::stoi(echoed);
}

using mcopt::test::readJson;

}  // namespace

TEST_CASE("run: Ipopt's derivative checker finds no error on the bundled scenario", "[cli][run]") {
  // Forward differences: Ipopt's default step 1e-8 is below the objective's round-off (an
  // energy summed over 3000 powers) and 1e-6 above its curvature; 5e-8 resolves both on the
  // periodic kick (docs/reference/scenario-file.md; at 1e-7 one Jacobian entry is flagged at 1.6e-4 and at
  // 3.3e-4 with 2e-7: the forward difference's truncation, which central differences in
  // tests/outer_nlp do not show). With configuration optimisation's end postures (a posture with CoM
  // over the sole), which fix the first and last control points; Ipopt draws the others
  // across the joints' ranges. The scenario's own postures: under the sanitizers
  // (configuration optimisation is slow there), and in Release through the second-order test
  // below, whose check includes the first-order one. Ipopt 3.11's checker costs time
  // quadratic in the Jacobian (40 s at 100 samples of the smooth maximum; the epigraph form's
  // slack a joint and sample took 88 s at 25): 16 samples here (at 12 one entry, 1.1e-4, was
  // the forward difference's own truncation), every kind of row still present; tests/outer_nlp
  // checks the full sampling against central differences.
  const test::TempDir dir;
  const auto scenario = kickVariant(dir, [](YAML::Node& root) {
    root["samples"] = 16;
    root["limits"]["torque_screening"] = 0;  // every row in the problem the checker sees
    root["solver"] = YAML::Node();
    root["solver"]["max_iter"] = 0;
    root["solver"]["derivative_test"] = "first-order";
    root["solver"]["derivative_test_perturbation"] = 5e-8;
    root["solver"]["print_level"] = 5;
    root["continuation"] = YAML::Load("[]");  // one stage, stopped at iteration 0
  });
  const std::string initialisation = kUnderSanitizers ? "off" : "on";
  const auto r = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(dir.path() / "out") +
                                " --configuration-optimisation " + initialisation);
  INFO(r.output.substr(0, 4000));
  CHECK_THAT(r.output, Contains("Starting derivative checker for first derivatives"));
  CHECK_THAT(r.output, Contains("No errors detected by derivative checker"));
}

TEST_CASE("run: Ipopt's second-order derivative checker finds no error on the bundled kick's exact Hessian",
          "[cli][run]") {
  // The bundled criterion (the epigraph form) and the smooth maximum of the first stage, with
  // `hessian: exact`, seen through the driver as Ipopt sees it (lower triangle, obj_factor and
  // multipliers applied). Ipopt checks at a random draw within point_perturbation_radius of
  // the start, clipped to the bounds: for the control points a draw across each joint's
  // range, a fast motion whose dry friction is saturated. Its forward differences err by
  // h ∂³L / 2, and the friction's third derivative at Ω = 0 is large: at 1e-7 one entry of
  // 8 samples' check came out at 1.7e-4 (3.4e-4 at 2e-7), at 5e-8 the whole check is clean
  // (docs/theory/outer-problem.md, "Ipopt's derivative checker"). Ipopt 3.11's second-order check costs
  // rows × variables² × Hessian entries (16 min at 8 samples): two samples and 7 control
  // points here, every kind of row present; tests/outer_nlp/test_motion_hessian.cpp holds
  // every entry at 100 samples.
  if (kUnderSanitizers) return;  // 22 s in Release; the sanitizer build runs the Hessian tests
  const test::TempDir dir;
  for (const char* objective : {"{energy: epigraph}", "{energy: smooth_max, smoothing: 0.01}"}) {
    const auto log = dir.path() / "ipopt.txt";
    const auto scenario = kickVariant(dir, [&](YAML::Node& root) {
      root["samples"] = 2;
      root["control_points"] = 7;
      root["objective"] = YAML::Load(objective);
      root["hessian"] = "exact";
      root["continuation"] = YAML::Load("[]");
      root["limits"]["torque_screening"] = 0;
      root["solver"] = YAML::Node();
      root["solver"]["max_iter"] = 0;
      root["solver"]["derivative_test"] = "second-order";
      root["solver"]["derivative_test_perturbation"] = 5e-8;
      root["solver"]["output_file"] = log.string();
      root["solver"]["file_print_level"] = 5;
    });
    const auto r = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(dir.path() / "out") +
                                  " --configuration-optimisation off");
    std::ifstream in(log);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    INFO(objective << "\n" << r.all().substr(0, 2000) << "\n" << text.substr(0, 4000));
    CHECK_THAT(text, Contains("Starting derivative checker for second derivatives"));
    CHECK_THAT(text, Contains("No errors detected by derivative checker"));
  }
}

TEST_CASE("run: result files, their fields, and torques that mcopt dynamics reproduces", "[cli][run]") {
  const test::TempDir dir;
  const int samples = kUnderSanitizers ? 20 : 40;
  const auto scenario = kickVariant(dir, [&](YAML::Node& root) {
    smoothMaximumKick(root);
    root["samples"] = samples;
    if (kUnderSanitizers) root["hessian"] = "limited-memory", root["continuation"] = YAML::Load("[]");
  });
  const auto out = dir.path() / "out";
  const auto r = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(out) + " --max-iterations 15");
  INFO(r.all());
  REQUIRE(r.exitCode == 4);  // stopped by the iteration limit: not optimal
  CHECK_THAT(r.output, Contains("configuration optimisation") && Contains("EXIT: Maximum Number of Iterations Exceeded"));
  CHECK(r.output.find("     15  ") != std::string::npos);  // a progress line per iteration
  const Json result = readJson(out / "result.json");
  CHECK(result["status"] == "maximum_iterations");
  CHECK(result["energy"].get<double>() > 0.0);
  CHECK(result["max_violation"].get<double>() >= 0.0);
  CHECK_THAT(result["reason"].get<std::string>(), Contains("Maximum Number of Iterations"));
  for (const char* key : {"parameters", "time", "q", "v", "a", "torques", "contacts", "power", "power_fine", "violation_by_kind", "solver", "timings", "configuration_optimisation"})
    CHECK(result.contains(key));
  CHECK(result["q"].size() == static_cast<std::size_t>(samples));
  CHECK(result["power_fine"]["power"].size() == 500);
  REQUIRE(result["contacts"].size() == 1);
  CHECK(result["contacts"][0]["name"] == "l_sole");
  CHECK(result["contacts"][0]["wrench"].size() == static_cast<std::size_t>(samples));
  CHECK(result["solver"]["iterations"] == 15);
  CHECK(result["configuration_optimisation"]["start"]["optimised"] == true);
  for (const char* file : {"trajectory.csv", "power_fine.csv", "states.json"}) CHECK(std::filesystem::exists(out / file));

  // The states, re-evaluated by `mcopt dynamics`, give the result's torques.
  const auto dynamics = test::runMcopt("dynamics --robot " + test::quoted(test::sourceDir() / "robots/hrp2/hrp2.urdf") +
                                       " --reference-body l_sole --states " + test::quoted(out / "states.json") +
                                       " --out " + test::quoted(dir.path() / "dynamics.json"));
  REQUIRE(dynamics.exitCode == 0);
  const Json evaluated = readJson(dir.path() / "dynamics.json");
  REQUIRE(evaluated["results"].size() == static_cast<std::size_t>(samples));
  double worst = 0.0, largest = 0.0;
  for (std::size_t s = 0; s < static_cast<std::size_t>(samples); ++s)
    for (std::size_t j = 0; j < 30; ++j) {
      const double expected = result["torques"][s][j].get<double>();
      worst = std::max(worst, std::abs(evaluated["results"][s]["tau"][j].get<double>() - expected));
      largest = std::max(largest, std::abs(expected));
    }
  INFO("largest torque " << largest << " N m, worst difference " << worst);
  CHECK(largest > 10.0);
  CHECK(worst <= 1e-9 * largest);
}

TEST_CASE("run: an interrupted run writes its last iterate and exits non-zero", "[cli][run]") {
  const test::TempDir dir;
  const auto scenario = kickVariant(dir, [](YAML::Node& root) {
    root["solver"]["max_iter"] = 100000;
    root["hessian"] = "limited-memory";  // short iterations: several are done when the signal comes
    root["continuation"] = YAML::Load("[]");  // one stage
  });
  const auto out = dir.path() / "out";
  // SIGINT once Ipopt iterates (configuration optimisation off to get there fast).
  const std::string command = "( " + std::string(MCOPT_EXECUTABLE) + " run " + test::quoted(scenario) + " --out " +
                              test::quoted(out) + " --configuration-optimisation off > " +
                              test::quoted(dir.path() / "log.txt") + " 2>&1 & pid=$!; sleep 5; kill -INT $pid; wait $pid; echo $? )";
  CHECK(exitStatusEchoed(command) == 130);
  const Json result = readJson(out / "result.json");
  CHECK(result["status"] == "interrupted");
  CHECK_THAT(result["reason"].get<std::string>(), Contains("interrupted"));
  CHECK(result["solver"]["iterations"].get<int>() > 0);
  CHECK(result["q"].size() == 100);
}

TEST_CASE("run: a run killed outright leaves its latest checkpoint, the iterate a shorter run ends at", "[cli][run]") {
  const test::TempDir dir;
  const auto scenario = kickVariant(dir, [](YAML::Node& root) {
    root["samples"] = 40;
    root["solver"]["max_iter"] = 100000;
    root["hessian"] = "limited-memory";
    root["continuation"] = YAML::Load("[]");  // one stage: the checkpoint's iteration count is the run's
  });
  const auto out = dir.path() / "out";
  const std::string run = std::string(MCOPT_EXECUTABLE) + " run " + test::quoted(scenario) +
                          " --configuration-optimisation off --out ";
  // SIGKILL, which no handler sees, once a checkpoint or two have been written.
  const std::string command = "( " + run + test::quoted(out) + " --checkpoint-seconds 0 > " +
                              test::quoted(dir.path() / "log.txt") +
                              " 2>&1 & pid=$!; for i in $(seq 1 1200); do grep -qs '\"status\": \"running\"' " +
                              test::quoted(out / "result.json") + " && break; sleep 0.1; done; sleep 1; kill -KILL $pid; "
                              "wait $pid; echo $? ) 2> /dev/null";  // not the shell's "Killed"
  CHECK(exitStatusEchoed(command) == 128 + 9);
  const Json killed = readJson(out / "result.json");
  REQUIRE(killed["status"] == "running");
  const int iterations = killed["solver"]["iterations"].get<int>();
  REQUIRE(iterations >= 1);
  CHECK_THAT(killed["reason"].get<std::string>(), Contains("checkpoint after iteration " + std::to_string(iterations)));
  CHECK(killed["q"].size() == 40);
  CHECK(killed["energy"].get<double>() > 0.0);

  // The same run stopped by the iteration limit at that iteration ends where the checkpoint is.
  const auto limited = dir.path() / "limited";
  const auto r = test::runMcopt(run.substr(std::string(MCOPT_EXECUTABLE).size() + 1) + test::quoted(limited) +
                                " --checkpoint-seconds -1 --max-iterations " + std::to_string(iterations));
  INFO(r.all());
  REQUIRE(r.exitCode == 4);
  const Json ended = readJson(limited / "result.json");
  CHECK(ended["solver"]["iterations"] == iterations);
  double worst = 0.0, largest = 0.0;
  std::function<void(const Json&, const Json&)> compare = [&](const Json& a, const Json& b) {
    if (b.is_number()) {
      worst = std::max(worst, std::abs(a.get<double>() - b.get<double>()));
      largest = std::max(largest, std::abs(b.get<double>()));
      return;
    }
    REQUIRE(a.size() == b.size());
    if (b.is_object())
      for (const auto& [name, value] : b.items()) compare(a.at(name), value);
    else
      for (std::size_t i = 0; i < b.size(); ++i) compare(a[i], b[i]);
  };
  compare(killed["parameters"], ended["parameters"]);
  compare(killed["torques"], ended["torques"]);
  INFO("worst difference " << worst << " of " << largest);
  CHECK(largest > 1.0);
  CHECK(worst <= 1e-9 * largest);
  CHECK(killed["energy"].get<double>() == Approx(ended["energy"].get<double>()).epsilon(1e-9));

  // A checkpoint is result.json alone (one iterate, never side files of another); the
  // stopped run writes them all.
  for (const char* file : {"trajectory.csv", "power_fine.csv", "states.json", "contact_wrenches.json"}) {
    INFO(file);
    CHECK_FALSE(std::filesystem::exists(out / file));
    CHECK(std::filesystem::exists(limited / file));
  }
  // Byte for byte, result.json is the stopped run's but for what says how the run went
  // (status, its words, wall-clock times, Ipopt's counts and history) and the energy balance,
  // which a checkpoint goes without (its fine grid costs a whole evaluation more).
  CHECK_FALSE(killed.contains("energy_balance"));
  CHECK(ended.contains("energy_balance"));
  Json killedMotion = killed, endedMotion = ended;
  for (Json* j : {&killedMotion, &endedMotion}) {
    for (const char* key : {"status", "message", "reason", "timings", "solver", "history", "continuation", "configuration_optimisation",
                            "energy_balance", "warnings"})
      j->erase(key);
  }
  CHECK(killedMotion.dump(1) == endedMotion.dump(1));
  // What was left out differs only where it should.
  CHECK(killed["history"].size() == ended["history"].size());
  CHECK(killed["solver"]["objective_evaluations"] == ended["solver"]["objective_evaluations"]);
}

TEST_CASE("run: the main job ends optimal and exits 0", "[cli][run]") {
  // The bundled kick as scripts/run.sh runs it (configuration optimisation of its one posture,
  // the smooth maximum's Gauss–Newton stage, then the epigraph form with sample differences), on
  // fewer samples so that it converges in seconds, with a criterion that is the energy. Under
  // the sanitizers each of its two stages runs 10 iterations, the same code.
  const test::TempDir dir;
  const int samples = kUnderSanitizers ? 8 : 16;
  const auto scenario = kickVariant(dir, [&](YAML::Node& root) { root["samples"] = samples; });
  const auto out = dir.path() / "out";
  // Release: refined until its motion holds between its samples (docs/reference/verify.md,
  // "Refine"): on 16 samples its trapezoid energy missed 9 % of the fine grid's when this was
  // written, so one round on 31 samples follows.
  const auto r = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(out) +
                                (kUnderSanitizers ? " --max-iterations 10" : " --refine 2"));
  INFO(r.all());
  const Json result = readJson(out / "result.json");
  const int written = kUnderSanitizers ? samples : 2 * (samples - 1) + 1;  // the last round's grid
  if (!kUnderSanitizers) {
    const Json& rounds = result.at("refinement");
    REQUIRE(rounds.size() == 2);
    CHECK(rounds[0].at("samples") == samples);
    CHECK(rounds[0].at("verified") == false);
    REQUIRE(rounds[0].at("failed_checks").size() == 1);
    CHECK(rounds[0].at("failed_checks")[0].at("kind") == "energy_sampled_vs_fine");
    CHECK(rounds[1].at("samples") == written);
    CHECK(rounds[1].at("status") == "optimal");
    CHECK(rounds[1].at("verified") == true);
    CHECK(result.at("samples") == written);
    CHECK_THAT(r.output, Contains("round 1: 31 samples, optimal after") && Contains("refinement         1 round(s); 31 samples: verified"));
    // The written continuation is the last round's: its own problem alone, from round 0's optimum.
    CHECK(result["continuation"].size() == 1);
  } else {
    CHECK_FALSE(result.contains("refinement"));
  }
  REQUIRE(result["continuation"].size() == (kUnderSanitizers ? 2u : 1u));
  if (kUnderSanitizers) {
    CHECK(result["continuation"][0]["energy_form"] == "smooth_max");
    CHECK(result["continuation"][0]["hessian"] == "gauss-newton");
    CHECK(result["continuation"][1]["energy_form"] == "epigraph");
    CHECK(result["continuation"][1]["hessian"] == "sample-differences");
  } else {
    CHECK(result["continuation"][0]["energy_form"] == "epigraph");
    CHECK(result["continuation"][0]["hessian"] == "sample-differences");
  }
  if (kUnderSanitizers) {
    REQUIRE(r.exitCode == 4);  // stopped by the iteration limit
    CHECK(result["status"] == "maximum_iterations");
    CHECK(result["solver"]["iterations_all_stages"] == 20);
    CHECK(result["reason"] == "Ipopt: Maximum Number of Iterations Exceeded");
  } else {
    REQUIRE(r.exitCode == 0);
    CHECK_THAT(r.output, Contains("EXIT: Optimal Solution Found") && Contains("status             optimal"));
    CHECK(result["status"] == "optimal");
    CHECK(result["solver"]["status"] == "optimal");
    CHECK(result["max_violation"].get<double>() <= 1e-6);
    CHECK(!result.contains("reason"));
    CHECK(result["energy_form"] == "epigraph");
    const double energy = result["energy"].get<double>(), criterion = result["objective_value"].get<double>();
    CHECK(std::abs(criterion - energy) <= 0.1 * energy);  // the issue's 10 %
    // The refined optimum verifies, read back on its own grid (result.json `samples`).
    const test::Verified verified = test::verifyResult(out);
    INFO(verified.all);
    CHECK(verified.exitCode == 0);
    CHECK(verified.report.at("samples") == written);
  }
  CHECK(result["energy"].get<double>() > 0.0);
  REQUIRE(result["q"].size() == static_cast<std::size_t>(written));
  // The motion returns exactly to its start, at rest: its energy owes nothing to gravity.
  const Json& q = result["q"];
  const Json& v = result["v"];
  for (std::size_t j = 0; j < q[0].size(); ++j) {
    CHECK(std::abs(q[written - 1][j].get<double>() - q[0][j].get<double>()) <= 1e-9);
    CHECK(std::abs(v[0][j].get<double>()) <= 1e-12);
    CHECK(std::abs(v[written - 1][j].get<double>()) <= 1e-12);
  }
  CHECK(result["configuration_optimisation"]["start"]["optimised"] == true);
  CHECK(result["configuration_optimisation"]["end"]["same_as"] == "start");
  const Json& balance = result["energy_balance"];
  CHECK(std::abs(balance["potential_energy_change_J"].get<double>()) <= 1e-6);
  CHECK(std::abs(balance["kinetic_energy_change_J"].get<double>()) <= 1e-6);
  const double scale = std::max({std::abs(balance["joint_work_J"].get<double>()), balance["joule_losses_J"].get<double>(),
                                 std::abs(balance["friction_dissipation_J"].get<double>())});
  CHECK(std::abs(balance["mechanical_identity_residual_J"].get<double>()) <= 1e-4 * scale);
  CHECK(result["warnings"].empty());
  CHECK_THAT(r.all(), Contains("energy balance     joints' work") && !Contains("from gravity"));
}

TEST_CASE("run: the free-ends kick draws its energy from gravity, and the run says so", "[cli][run]") {
  // The report's convention (hrp2_kick_free_ends.yaml): start and end optimised apart. Its
  // optimum starts high and ends low, and more potential energy is released than the criterion
  // counts: the summary and result.json warn. (The periodic kick above does not.)
  if (kUnderSanitizers) return;  // a whole optimisation; its code is the main job's
  const test::TempDir dir;
  const auto scenario = scenarioVariant(test::sourceDir() / "scenarios/hrp2_kick_free_ends.yaml", dir,
                                        [](YAML::Node& root) { root["samples"] = 16; }, "free_ends.yaml");
  const auto out = dir.path() / "out";
  const auto r = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(out));
  INFO(r.all());
  REQUIRE(r.exitCode == 0);
  const Json result = readJson(out / "result.json");
  const Json& balance = result["energy_balance"];
  const double released = balance["gravity_released_J"].get<double>(), energy = result["energy"].get<double>();
  CHECK(released > energy);
  CHECK(balance["potential_energy_change_J"].get<double>() == Approx(-released));
  CHECK(std::abs(balance["mechanical_identity_residual_J"].get<double>()) <= 1e-4 * released);
  REQUIRE(result["warnings"].size() == 1);
  CHECK_THAT(result["warnings"][0].get<std::string>(), Contains("from gravity") && Contains("start is higher than its end"));
  CHECK_THAT(r.all(), Contains("mcopt: warning: the motion draws") && Contains("from gravity"));
}

TEST_CASE("run: a continuation solves its stages in turn, each from the last one's iterate", "[cli][run]") {
  // Two coarse stages (a smoother friction, then the scenario's) before the scenario's own
  // problem, a few iterations each: result.json lists the stages, the history says which
  // stage each iteration belongs to, and the time split adds up to the solve.
  const test::TempDir dir;
  const auto scenario = kickVariant(dir, [](YAML::Node& root) {
    smoothMaximumKick(root);
    root["samples"] = 20;
    root["continuation"] = YAML::Load("[{samples: 10, friction_sharpness: 0.01}, {samples: 10}]");
    root["solver"]["max_iter"] = 3;
  });
  const auto out = dir.path() / "out";
  const auto r = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(out) + " --configuration-optimisation off");
  INFO(r.all());
  // A stage stopped by its iteration limit hands its iterate on; the last one's status is the run's.
  REQUIRE(r.exitCode == 4);
  CHECK_THAT(r.output, Contains("stage 1 of 3: ν = 0.01 s/rad, ε = 0.01 W, 10 samples") &&
                           Contains("stage 3 of 3: ν = 1 s/rad, ε = 0.01 W, 20 samples") && Contains("(all stages: 3 + 3 + 3)"));
  const Json result = readJson(out / "result.json");
  REQUIRE(result["continuation"].size() == 3);
  CHECK(result["continuation"][0]["friction_sharpness"] == 0.01);
  CHECK(result["continuation"][0]["samples"] == 10);
  CHECK(result["continuation"][2]["samples"] == 20);
  CHECK(result["continuation"][2]["status"] == "maximum_iterations");
  CHECK(result["solver"]["iterations"] == 3);
  CHECK(result["solver"]["iterations_all_stages"] == 9);
  CHECK(result["solver"]["hessian"] == "sample-differences");
  REQUIRE(result["history"].size() == 12);  // iterations 0 … 3 of each stage
  CHECK(result["history"][4]["stage"] == 1);
  CHECK(result["history"][4]["iteration"] == 0);
  CHECK(result["history"][11]["stage"] == 2);
  double split = 0.0;
  for (const Json& line : result["history"])
    for (const char* part : {"functions", "gradient_and_jacobian", "hessian", "ipopt"}) {
      CHECK(line["seconds"][part].get<double>() >= 0.0);
      split += line["seconds"][part].get<double>();
    }
  CHECK(result["history"][3]["seconds"]["hessian"].get<double>() > 0.0);
  const double solve = result["timings"]["optimisation_seconds"].get<double>();
  const Json whole = result["timings"]["optimisation_split"];
  const double parts = whole["functions"].get<double>() + whole["gradient_and_jacobian"].get<double>() +
                       whole["hessian"].get<double>() + whole["ipopt"].get<double>();
  CHECK(parts <= solve);
  CHECK(parts >= 0.8 * solve);  // the stages' problems are built between the solves
  CHECK(split <= parts + 1e-9);
}

TEST_CASE("run: a smooth-maximum stage before the exact epigraph form, whose slacks start at max(P, 0) of its motion",
          "[cli][run]") {
  // The offset-free criterion (docs/theory/outer-problem.md, "Continuation"): the epigraph stage starts
  // at the smooth stage's motion with every slack at max(P, 0) and Ipopt told to keep it, so
  // its iterate 0 — the written result when its own limit is 0 — has the criterion of that
  // motion's exact energy. With Ipopt's default pushes of 1e-2 off the slacks' bound it did not.
  const test::TempDir dir;
  const auto scenario = kickVariant(dir, [](YAML::Node& root) {
    root["samples"] = 20;
    root["objective"] = YAML::Load("{energy: epigraph}");
    // Under the sanitizers 5 iterations (73 s with 20): the hand-over is the same.
    root["continuation"] = YAML::Load(std::string("[{energy: smooth_max, smoothing: 0.01, max_iterations: ") +
                                      (kUnderSanitizers ? "5" : "20") + "}]");
    root["solver"]["max_iter"] = 0;
  });
  const auto out = dir.path() / "out";
  const auto r = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(out) + " --configuration-optimisation off");
  INFO(r.all());
  REQUIRE(r.exitCode == 4);  // the epigraph stage's limit of 0 iterations
  CHECK_THAT(r.output, Contains("stage 1 of 2: ν = 1 s/rad, ε = 0.01 W, 20 samples") &&
                           Contains("stage 2 of 2: ν = 1 s/rad, epigraph, 20 samples"));
  const Json result = readJson(out / "result.json");
  REQUIRE(result["continuation"].size() == 2);
  CHECK(result["continuation"][0]["energy_form"] == "smooth_max");
  CHECK(result["continuation"][0]["smoothing"] == 0.01);
  CHECK(result["continuation"][1]["energy_form"] == "epigraph");
  CHECK(result["continuation"][1]["smoothing"].is_null());
  CHECK(result["energy_form"] == "epigraph");
  const Json& start = result["history"].back();
  REQUIRE(start["stage"] == 1);
  REQUIRE(start["iteration"] == 0);
  const double energy = result["energy"].get<double>();
  CHECK(energy > 0.0);
  CHECK(start["objective"].get<double>() == Approx(energy).epsilon(1e-6));
  // A stage's energy form is checked like the scenario's.
  const auto bad = kickVariant(dir, [](YAML::Node& root) {
    root["continuation"] = YAML::Load("[{energy: exact}]");
  });
  const auto refused = test::runMcopt("run " + test::quoted(bad) + " --out " + test::quoted(dir.path() / "no"));
  CHECK(refused.exitCode == 2);
  CHECK_THAT(refused.errors, Contains("continuation[0].energy: expected smooth_max or epigraph, got 'exact'"));
}

TEST_CASE("run: the offset-free kick — gauss-newton on the smooth maximum, then the epigraph with the exact Hessian — ends optimal",
          "[cli][run]") {
  // docs/theory/outer-problem.md, "Hessian options" and "Continuation": the route that makes the criterion the
  // energy. On 20 samples, measured: 459 + 58 iterations, criterion within 0.1 % of the energy. The
  // epigraph stage's barrier starts at 1e-6, low enough not to lift its slacks off the motion's
  // energy: its criterion rose 0.4 % at most (at 1e-4, by 91 % in its first 5 iterations).
  if (kUnderSanitizers) return;  // ~20 s in Release; the stages and the Hessian are tested on their own there
  const test::TempDir dir;
  const Json result = runToOptimal(dir, kickVariant(dir, [](YAML::Node& root) { epigraphAfterSmoothMaximum(root, 500); }));
  CHECK(result["solver"]["hessian"] == "exact");
  CHECK(result["continuation"][0]["hessian"] == "gauss-newton");
  CHECK(result["energy_form"] == "epigraph");
  const double energy = result["energy"].get<double>(), criterion = result["objective_value"].get<double>();
  CHECK(energy > 0.0);
  CHECK(std::abs(criterion - energy) <= 0.01 * energy);
  double start = 0.0, highest = 0.0;
  for (const Json& h : result["history"])
    if (h["stage"] == 1) {
      if (h["iteration"] == 0) start = h["objective"].get<double>();
      highest = std::max(highest, h["objective"].get<double>());
    }
  REQUIRE(start > 0.0);
  CHECK(highest <= 1.02 * start);
}

TEST_CASE("run: an orientation_angle task keeps the waist within its angle of level over its window, where it binds",
          "[cli][run]") {
  // The one-row task kind (outer_nlp/orientation_angle_task.cpp): 1 − cos θ ≤ 1 − cos(0.1). The
  // kick's statically optimal start posture has the waist 12.7° from the world axes, beyond the
  // task's 5.7°: the motion must turn it. Measured on 20 samples: optimal after 100 + 40
  // iterations, 5.97 J (3.63 J without the task), 5.73° at every sample.
  if (kUnderSanitizers) return;  // ~10 s in Release; the task's derivatives are tested on their own there
  const double tolerance = 0.1;
  const test::TempDir dir;
  const Json result = runToOptimal(dir, kickVariant(dir, [&](YAML::Node& root) {
    epigraphAfterSmoothMaximum(root, 100);
    YAML::Node task = YAML::Load("{name: level waist, kind: orientation_angle, body: BODY, target: [0, 0, 0], window: [0.2, 1.4]}");
    task["tolerance"] = tolerance;
    root["tasks"].push_back(task);
  }));
  CHECK(result["max_violation"].get<double>() <= 1e-6);

  const RobotModel robot = loadUrdfFile(result.at("robot_files").at("urdf").get<std::string>());
  const DynamicsModel model(robot, result.at("reference_body").get<std::string>());
  const int waist = robot.frameIndex("BODY");
  DynamicsData data(model);
  auto angle = [&](const Eigen::VectorXd& q) {  // from the world axes, by forward kinematics
    forwardKinematics(model, data, q);
    return std::acos(std::clamp((framePose(model, data, waist).rotation.trace() - 1.0) / 2.0, -1.0, 1.0));
  };
  auto row = [](const Json& matrix, std::size_t k) {
    const std::vector<double> v = matrix.at(k).get<std::vector<double>>();
    return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size())));
  };
  // Without the task, the posture the motion starts from (the static optimum, held still).
  const auto free = kickVariant(dir, [](YAML::Node& root) { root["samples"] = 20; }, "free.yaml");
  const auto freeOut = dir.path() / "free";
  const auto f = test::runMcopt("run " + test::quoted(free) + " --out " + test::quoted(freeOut) + " --max-iterations 0");
  INFO(f.all());
  REQUIRE(readJson(freeOut / "result.json").contains("q"));
  CHECK(angle(row(readJson(freeOut / "result.json").at("q"), 0)) > tolerance + 0.05);
  const std::vector<double> time = result.at("time").get<std::vector<double>>();
  double largest = 0.0;
  for (std::size_t k = 0; k < time.size(); ++k)
    if (time[k] >= 0.2 - 1e-9 && time[k] <= 1.4 + 1e-9) largest = std::max(largest, angle(row(result.at("q"), k)));
  INFO("largest angle in the window " << largest << " rad");
  CHECK(largest <= tolerance + 1e-6);
  CHECK(largest >= tolerance - 1e-4);  // it binds
}

TEST_CASE("run: a continuation stage with its own Hessian option and iteration limit", "[cli][run]") {
  // The bundled multi-contact scenarios start with a few hundred gauss-newton iterations and
  // finish with sample-differences (docs/reference/scenario-file.md): each stage says its option, stops at its
  // own limit (not the scenario's), and the next starts from its iterate.
  const test::TempDir dir;
  const auto scenario = kickVariant(dir, [](YAML::Node& root) {
    root["samples"] = 16;
    root["hessian"] = "sample-differences";
    root["continuation"] = YAML::Load("[{hessian: gauss-newton, max_iterations: 2}]");
    root["solver"]["max_iter"] = 3;
  });
  const auto out = dir.path() / "out";
  const auto r = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(out) + " --configuration-optimisation off");
  INFO(r.all());
  REQUIRE(r.exitCode == 4);
  CHECK_THAT(r.output, Contains("Hessian: gauss-newton; stage 1 of 2") && Contains("Hessian: sample-differences; stage 2 of 2") &&
                           Contains("(all stages: 2 + 3)"));
  const Json result = readJson(out / "result.json");
  REQUIRE(result["continuation"].size() == 2);
  CHECK(result["continuation"][0]["hessian"] == "gauss-newton");
  CHECK(result["continuation"][0]["iterations"] == 2);
  CHECK(result["continuation"][1]["hessian"] == "sample-differences");
  CHECK(result["continuation"][1]["iterations"] == 3);
  REQUIRE(result["history"].size() == 7);
  CHECK(result["history"][2]["seconds"]["hessian"].get<double>() > 0.0);  // the Gauss–Newton model was asked for
}

TEST_CASE("run: a Hessian-only stage that ends optimal ends the run", "[cli][run]") {
  // The stage differs from the scenario's problem only in its Hessian: optimal there is optimal
  // for the scenario (Ipopt's test reads the exact first derivatives), so no later stage runs;
  // a stage with another friction sharpness hands its iterate on to the scenario's problem.
  const test::TempDir dir;
  for (const bool sameProblem : {true, false}) {
    // Under the sanitizers neither (a Gauss–Newton kick to its optimum, ~100 s there): the
    // stage's code paths run in the test above; the Release build runs both cases.
    if (kUnderSanitizers) continue;
    // The free-ends kick: its epigraph form converges with Gauss–Newton steps (the periodic
    // bundled kick's needs the exact Hessian, docs/theory/outer-problem.md, "Boundary").
    const auto scenario = scenarioVariant(test::sourceDir() / "scenarios/hrp2_kick_free_ends.yaml", dir, [&](YAML::Node& root) {
      root["samples"] = 12;
      root["hessian"] = "sample-differences";  // the stage differs in its Hessian alone
      root["continuation"] = YAML::Load(sameProblem ? "[{hessian: gauss-newton}]"
                                                    : "[{hessian: gauss-newton, friction_sharpness: 0.5, max_iterations: 3}]");
    }, "free_ends.yaml");
    const auto out = dir.path() / (sameProblem ? "same" : "other");
    const auto r = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(out) + " --configuration-optimisation off");
    INFO(r.all());
    REQUIRE(r.exitCode == 0);
    const Json result = readJson(out / "result.json");
    CHECK(result["status"] == "optimal");
    REQUIRE(result["continuation"].size() == (sameProblem ? 1u : 2u));
    CHECK(result["continuation"][0]["status"] == (sameProblem ? "optimal" : "maximum_iterations"));
    CHECK(result["continuation"][0]["hessian"] == "gauss-newton");
    CHECK(result["solver"]["iterations"] == result["continuation"].back()["iterations"]);
    CHECK_FALSE(result.contains("reason"));
  }
}

TEST_CASE("run: a stage that ends worse than it began hands on its start, as if it had not run", "[cli][run]") {
  // The throw on 21 samples after its Gauss–Newton stage, with a middle stage of 3 iterations
  // on 11 samples: measured in the scenario's problem (21 samples), that stage's end violates
  // rows between its samples (4e-4 against 3e-7 at its start) and its criterion is higher, so
  // the scenario's problem starts where the middle stage started (docs/theory/outer-problem.md,
  // "Continuation"). It then takes the same iterates as a run without the middle stage: the
  // same energy to the bit. (Two throws, ≈ 9 s in Release; too slow under the sanitizers.)
  if (kUnderSanitizers) return;
  const test::TempDir dir;
  Json results[2];
  for (const bool middle : {false, true}) {
    const auto scenario = scenarioVariant(test::sourceDir() / "scenarios/hrp2_throw.yaml", dir, [&](YAML::Node& root) {
      root["samples"] = 21;
      root["continuation"] = YAML::Load(middle ? "[{hessian: gauss-newton, max_iterations: 500},"
                                                 " {hessian: sample-differences, samples: 11, max_iterations: 3}]"
                                               : "[{hessian: gauss-newton, max_iterations: 500}]");
    }, middle ? "with_middle.yaml" : "without.yaml");
    const auto out = dir.path() / (middle ? "with_middle" : "without");
    const auto r = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(out));
    INFO(r.all());
    REQUIRE(r.exitCode == 0);
    if (middle)
      CHECK_THAT(r.output, Contains("stage 2 ended worse than it began (violation ") &&
                               Contains("in stage 3's problem): stage 3 starts where stage 2 started"));
    else
      CHECK_THAT(r.output, !Contains("ended worse than it began"));
    results[middle ? 1 : 0] = readJson(out / "result.json");
  }
  const Json& without = results[0];
  const Json& with = results[1];
  CHECK(without["status"] == "optimal");
  CHECK(with["status"] == "optimal");
  REQUIRE(without["continuation"].size() == 2u);
  REQUIRE(with["continuation"].size() == 3u);
  CHECK(with["continuation"][1]["status"] == "maximum_iterations");
  CHECK(with["continuation"][1]["samples"] == 11);
  CHECK(with["continuation"][1]["restarted_from_stage"].is_null());
  CHECK(with["continuation"][2]["restarted_from_stage"] == 2);
  CHECK(without["continuation"][1]["restarted_from_stage"].is_null());
  // The first stages are the same problem from the same start; the last starts from that
  // stage's end in both runs.
  CHECK(with["continuation"][0]["iterations"] == without["continuation"][0]["iterations"]);
  CHECK(with["continuation"][2]["iterations"] == without["continuation"][1]["iterations"]);
  CHECK(with["continuation"][2]["objective"].get<double>() == without["continuation"][1]["objective"].get<double>());
  CHECK(with["energy"].get<double>() == without["energy"].get<double>());
}

TEST_CASE("run: torque-limit screening solves again with the rows that came near their limit", "[cli][run]") {
  // A fraction so small that rows left out at the start reach it at the optimum: the run
  // solves again with them, ends optimal, and every row still left out holds — checked here
  // on the result's own torques. (≈ 15 s in Release; too slow under the sanitizers.)
  if (kUnderSanitizers) return;
  const test::TempDir dir;
  const double fraction = 0.003;
  // The free-ends kick, whose optimum brings rows left out at its start near that fraction.
  const auto scenario = scenarioVariant(test::sourceDir() / "scenarios/hrp2_kick_free_ends.yaml", dir, [&](YAML::Node& root) {
    smoothMaximumKick(root);
    root["samples"] = 8;
    root["limits"]["torque_screening"] = fraction;
  }, "free_ends.yaml");
  const auto out = dir.path() / "out";
  const auto r = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(out) + " --configuration-optimisation off");
  INFO(r.all());
  REQUIRE(r.exitCode == 0);
  CHECK_THAT(r.output, Contains("torque-limit rows came within 0.003 of their limit: solving again with them"));
  const Json result = readJson(out / "result.json");
  const int rounds = result["solver"]["screening_rounds"].get<int>(), left = result["solver"]["torque_rows_checked_afterwards"].get<int>();
  CHECK(rounds >= 2);
  CHECK(left > 0);
  CHECK(left < 8 * 30);
  // The summary counts every solve's iterations, not the last one's alone.
  const int total = result["solver"]["iterations_all_stages"].get<int>();
  CHECK(total > result["solver"]["iterations"].get<int>());
  CHECK_THAT(r.output, Contains("(" + std::to_string(total) + " over " + std::to_string(rounds) + " screening solves)"));
  // At least `left` joint-samples are below the fraction of their limit, and none is beyond its limit.
  const RobotModel robot = loadUrdfFile(test::sourceDir() / "robots/hrp2/hrp2.urdf");
  const ActuatorSet actuators = loadActuators(test::sourceDir() / "robots/hrp2/actuators.yaml", robot);
  int below = 0;
  double worst = 0.0;
  for (std::size_t s = 0; s < 8; ++s)
    for (std::size_t j = 0; j < 30; ++j) {
      const double tau = std::abs(result["torques"][s][j].get<double>()), limit = actuators.joints[j].torqueLimit;
      below += tau < fraction * limit;
      worst = std::max(worst, tau / limit);
    }
  CHECK(below >= left);
  CHECK(worst <= 1.0);
  CHECK(result["max_violation"].get<double>() <= 1e-6);
}

TEST_CASE("run: closing-row screening solves again with the rows that left the middle of their range", "[cli][run]") {
  // The weight shift on 20 samples in one solve (no continuation), its right leg's position and
  // velocity rows left out while within 0.05 of their range's middle: it starts at rest in its
  // posture, so rows leave that middle on the way and join; the run ends optimal with every row
  // still left out inside it, checked on the result's own motion. (≈ 11 s in Release.)
  if (kUnderSanitizers) return;
  const test::TempDir dir;
  const double fraction = 0.05;
  const auto scenario = scenarioVariant(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml", dir, [&](YAML::Node& root) {
    root["samples"] = 20;
    root.remove("continuation");
    root["limits"]["closing_screening"] = fraction;
  }, "weight_shift.yaml");
  const auto out = dir.path() / "out";
  const auto r = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(out));
  INFO(r.all());
  REQUIRE(r.exitCode == 0);
  CHECK_THAT(r.output, Contains("closing joints' limit rows left the middle 0.05 of their range: solving again with them"));
  const Json result = readJson(out / "result.json");
  CHECK(result["status"] == "optimal");
  const int rounds = result["solver"]["screening_rounds"].get<int>(), left = result["solver"]["closing_rows_checked_afterwards"].get<int>();
  CHECK(rounds >= 2);
  CHECK(left > 0);
  CHECK(result["violation_by_kind"]["closing_joint_limit"].get<double>() <= 1e-8);
  // The right leg closes the right sole: at least `left` of its position and velocity values at
  // the samples are inside the middle fraction, and none is beyond its limit.
  const auto& names = result["joint_names"];
  const auto& limits = result["joint_limits"];
  int inside = 0;
  double worst = 0.0;
  for (std::size_t j = 0; j < names.size(); ++j) {
    if (names[j].get<std::string>().rfind("RLEG_", 0) != 0) continue;
    const double lower = limits["position_lower"][j], upper = limits["position_upper"][j], speed = limits["velocity"][j];
    for (std::size_t s = 0; s < 20; ++s) {
      const double q = result["q"][s][j], v = result["v"][s][j];
      inside += std::abs(q - 0.5 * (lower + upper)) < fraction * 0.5 * (upper - lower);
      inside += std::abs(v) < fraction * speed;
      worst = std::max({worst, q - upper, lower - q, std::abs(v) - speed});
    }
  }
  CHECK(inside >= left);
  CHECK(worst <= 1e-9);
}

TEST_CASE("run: every class of bad scenario is refused with file, line and field", "[cli][run]") {
  const test::TempDir dir;
  struct Case {
    const char* what;
    std::function<void(YAML::Node&)> edit;
    std::vector<std::string> expected;  ///< fragments of the message
  };
  const std::vector<Case> cases = {
      {"unknown key", [](YAML::Node& r) { r["sampels"] = 10; }, {"sampels: unknown key"}},
      {"wrong type", [](YAML::Node& r) { r["samples"] = "many"; }, {"samples: expected a number"}},
      {"not an integer", [](YAML::Node& r) { r["samples"] = 1.5; }, {"samples: expected an integer ≥ 2"}},
      {"negative refinement rounds", [](YAML::Node& r) { r["refine"] = -1; }, {"refine: expected an integer ≥ 0"}},
      {"impossible duration", [](YAML::Node& r) { r["duration"] = -1.0; }, {"duration: must be positive"}},
      {"duration bounds", [](YAML::Node& r) {
         r["duration"] = YAML::Load("{initial: 3.0, min: 1.0, max: 2.0}");
       }, {"duration: expected min ≤ initial ≤ max"}},
      {"unknown reference body", [](YAML::Node& r) { r["reference_body"] = "l_foot_typo"; },
       {"reference_body: unknown body 'l_foot_typo' (no such link in hrp2.urdf; the nearest link names: "}},
      // A typo leads to the link meant; a contact surface's name to the link it is on.
      {"reference body misspelt", [](YAML::Node& r) { r["reference_body"] = "l_sloe"; },
       {"reference_body: unknown body 'l_sloe' (no such link in hrp2.urdf; the nearest link names: l_sole, "}},
      {"a contact surface as the reference body", [](YAML::Node& r) { r["reference_body"] = "l_hand"; },
       {"reference_body: unknown body 'l_hand': 'l_hand' is a contact surface of contacts.yaml, on link 'l_palm'; "
        "reference_body takes a link"}},
      {"unknown task body", [](YAML::Node& r) { r["tasks"][0]["body"] = "r_hoof"; }, {"tasks[0].body: unknown body 'r_hoof'"}},
      {"task body misspelt", [](YAML::Node& r) { r["tasks"][0]["body"] = "R_SOLE_"; },
       {"tasks[0].body: unknown body 'R_SOLE_' (no such link in hrp2.urdf; the nearest link names: r_sole, "}},
      {"unknown task kind", [](YAML::Node& r) { r["tasks"][0]["kind"] = "acceleration"; },
       {"tasks[0].kind: unknown task kind 'acceleration'"}},
      {"task after the end", [](YAML::Node& r) { r["tasks"][0]["time"] = 9.0; }, {"tasks[0].time: after the end"}},
      // A field another kind takes names the kind's own; a window on a velocity task is refused.
      {"a field of another task kind", [](YAML::Node& r) { r["tasks"][1]["kind"] = "center_of_mass"; },
       {"tasks[1].body: 'body' is not a field of center_of_mass tasks (they take target, tolerance, lower, upper)"}},
      {"a velocity task over a window", [](YAML::Node& r) {
         r["tasks"][0].remove("time");
         r["tasks"][0]["window"] = YAML::Load("[0.2, 0.9]");
       }, {"tasks[0].window: velocity tasks hold at an instant (use time)"}},
      {"an orientation angle without its angle", [](YAML::Node& r) {
         r["tasks"].push_back(YAML::Load("{kind: orientation_angle, body: CHEST_LINK1, target: [0, 0, 0], time: 0.5}"));
       }, {"tasks[2]", "tolerance: missing required field (the angle [rad])"}},
      {"an orientation angle of zero", [](YAML::Node& r) {
         r["tasks"].push_back(YAML::Load("{kind: orientation_angle, body: CHEST_LINK1, target: [0, 0, 0], tolerance: 0, time: 0.5}"));
       }, {"tasks[2].tolerance: expected an angle in (0, π) rad"}},
      {"an orientation angle with a point", [](YAML::Node& r) {
         r["tasks"].push_back(YAML::Load(
             "{kind: orientation_angle, body: CHEST_LINK1, target: [0, 0, 0], tolerance: 0.1, point: [0, 0, 1], time: 0.5}"));
       }, {"tasks[2].point: 'point' is not a field of orientation_angle tasks (they take body, target, tolerance)"}},
      {"reversed window", [](YAML::Node& r) { r["tasks"][1]["window"] = YAML::Load("[1.0, 0.5]"); },
       {"tasks[1].window: expected [start, end]"}},
      {"task bounding nothing", [](YAML::Node& r) { r["tasks"][0]["target"] = YAML::Load("[null, null, null]"); },
       {"the task bounds nothing"}},
      {"unknown joint", [](YAML::Node& r) { r["start"]["offsets"]["KNEE"] = 0.1; }, {"start.offsets.KNEE: unknown joint"}},
      {"unknown posture", [](YAML::Node& r) { r["start"]["posture"] = "crouch"; }, {"start.posture: unknown posture 'crouch'"}},
      {"an end the same as something else than the start", [](YAML::Node& r) { r["end"] = YAML::Load("{same_as: finish}"); },
       {"end.same_as: expected start, got 'finish'"}},
      {"an end the same as the start, and a posture", [](YAML::Node& r) { r["end"]["posture"] = "half_sitting"; },
       {"end.posture: unknown key (expected one of same_as)"}},
      {"posture outside the limits", [](YAML::Node& r) { r["start"]["offsets"]["RLEG_JOINT3"] = 5.0; },
       {"start: joint RLEG_JOINT3", "outside its limits"}},
      {"unknown contact", [](YAML::Node& r) { r["contacts"][0] = "l_knee"; }, {"contacts[0]: unknown contact surface 'l_knee'"}},
      {"no contact on the reference body", [](YAML::Node& r) { r["contacts"][0] = "r_sole"; },
       {"contacts: no contact on the reference body 'l_sole'"}},
      {"duplicated contact", [](YAML::Node& r) { r["contacts"].push_back("r_hand"), r["contacts"].push_back("r_hand"); },
       {"contacts[2]: contact 'r_hand' is listed twice"}},
      {"window outside the motion", [](YAML::Node& r) {
         r["contacts"].push_back(YAML::Load("{surface: r_hand, window: [1.0, 2.0]}"));
       }, {"contacts[1].window: expected [start, end] with 0 ≤ start < end ≤ 1.6"}},
      {"empty window", [](YAML::Node& r) {
         r["contacts"].push_back(YAML::Load("{surface: r_hand, window: [0.801, 0.802]}"));
       }, {"contacts[1].window: holds no sample of the motion"}},
      {"window on the reference contact", [](YAML::Node& r) {
         r["contacts"][0] = YAML::Load("{surface: l_sole, window: [0.2, 0.4]}");
       }, {"contacts[0]: contact 'l_sole' is on the reference body", "takes no window"}},
      {"unknown formulation", [](YAML::Node& r) { r["contact_forces"] = "penalty"; },
       {"contact_forces: unknown contact-force formulation 'penalty' (expected bilevel, splines or variables)"}},
      {"unknown contact model", [](YAML::Node& r) { r["inner"]["contact_model"] = "cone"; },
       {"inner.contact_model: unknown contact model 'cone'", "(expected report, pyramid, wrench-cone or point)"}},
      {"a contact model of its own on the reference contact", [](YAML::Node& r) {
         r["contacts"][0] = YAML::Load("{surface: l_sole, model: point}");
       }, {"contacts[0].model: contact 'l_sole' is on the reference body", "inner.contact_model"}},
      {"an unknown contact model of its own", [](YAML::Node& r) {
         r["contacts"].push_back(YAML::Load("{surface: r_hand, model: soft}"));
       }, {"contacts[1].model: unknown contact model 'soft'"}},
      {"the point model for every contact", [](YAML::Node& r) { r["inner"]["contact_model"] = "point"; },
       {"inner.contact_model: the point model holds a force alone", "contacts[k].model: point"}},
      {"facets without the pyramid", [](YAML::Node& r) { r["inner"]["pyramid_facets"] = 6; },
       {"inner.pyramid_facets: only the pyramid contact model has facets"}},
      {"too few facets", [](YAML::Node& r) {
         r["inner"]["contact_model"] = "pyramid";
         r["inner"]["pyramid_facets"] = 2;
       }, {"inner.pyramid_facets"}},
      {"unknown inner solver", [](YAML::Node& r) { r["inner"]["solver"] = "qpoases"; },
       {"inner.solver: unknown inner solver 'qpoases'"}},
      {"inner polishing not a flag", [](YAML::Node& r) { r["inner"]["polish"] = "sometimes"; },
       {"inner.polish: expected true or false"}},
      {"a barrier parameter for another inner solver", [](YAML::Node& r) { r["inner"]["barrier"] = 1e-3; },
       {"inner.barrier: only the barrier inner solver has a barrier parameter, and neither inner.solver nor a "
        "continuation stage's inner_solver is barrier (inner.solver is active-set)"}},
      {"a barrier parameter not positive", [](YAML::Node& r) {
         r["inner"]["solver"] = "barrier";
         r["inner"]["contact_model"] = "wrench-cone";
         r["inner"]["barrier"] = 0.0;
       }, {"inner.barrier: must be positive"}},
      {"the barrier solver on second-order cones", [](YAML::Node& r) {
         r["inner"]["solver"] = "barrier";
         r["inner"]["contact_model"] = "report";
       }, {"inner.solver: the barrier inner solver smooths linear contact models only (pyramid, wrench-cone)",
           "the report model (inner.contact_model) has second-order friction cones"}},
      {"the barrier solver on a point hand", [](YAML::Node& r) {
         r["inner"]["solver"] = "barrier";
         r["inner"]["contact_model"] = "wrench-cone";
         r["contacts"].push_back(YAML::Load("{surface: r_hand, model: point}"));
       }, {"inner.solver: the barrier inner solver smooths linear contact models only",
           "contact 'r_hand' has the point model, with a second-order friction cone"}},
      {"an unknown inner feasibility row", [](YAML::Node& r) { r["inner"]["feasibility"] = "penalty"; },
       {"inner.feasibility: expected slack or margin, got 'penalty'"}},
      {"the margin row on second-order cones", [](YAML::Node& r) {
         r["inner"]["contact_model"] = "report";
         r["inner"]["feasibility"] = "margin";
       }, {"inner.feasibility: the margin row shifts the rows of linear contact models only (pyramid, wrench-cone)",
           "the report model (inner.contact_model) has second-order friction cones"}},
      {"the margin row with a point hand", [](YAML::Node& r) {
         r["inner"]["contact_model"] = "wrench-cone";
         r["inner"]["feasibility"] = "margin";
         r["contacts"].push_back(YAML::Load("{surface: r_hand, model: point}"));
       }, {"inner.feasibility: the margin row shifts the rows", "contact 'r_hand' has the point model"}},
      {"missing file", [](YAML::Node& r) { r["actuators"] = "/nonexistent/actuators.yaml"; },
       {"actuators: file not found"}},
      {"unknown energy form", [](YAML::Node& r) { r["objective"]["energy"] = "max"; }, {"objective.energy: expected smooth_max or epigraph"}},
      {"missing field", [](YAML::Node& r) { r.remove("duration"); }, {"duration: missing required field"}},
      {"unknown Ipopt option", [](YAML::Node& r) { r["solver"]["max_iterations"] = 10; },
       {"solver.max_iterations: Ipopt rejects option 'max_iterations'"}},
      {"Ipopt option out of range", [](YAML::Node& r) { r["solver"]["tol"] = -1.0; }, {"solver.tol: Ipopt rejects option 'tol'"}},
      {"unknown Hessian option", [](YAML::Node& r) { r["hessian"] = "newton"; },
       {"hessian: expected limited-memory, finite-differences, sample-differences, convex-sample-differences, gauss-newton "
        "or exact, got 'newton'"}},
      {"exact Hessian where its stencils do not hold", [](YAML::Node& r) {
         r["hessian"] = "exact";
         r["objective"]["energy"] = "epigraph";
         r["objective"].remove("smoothing");
         r["duration"] = YAML::Load("{initial: 1.6, min: 1.2, max: 2.0}");
       }, {"hessian: exact: the epigraph form with a free duration"}},
      {"continuation not a list", [](YAML::Node& r) { r["continuation"] = 3; }, {"continuation: expected a list"}},
      {"unknown continuation field", [](YAML::Node& r) { r["continuation"] = YAML::Load("[{tol: 1.0}]"); },
       {"continuation[0].tol: unknown key"}},
      {"continuation sharpness not positive", [](YAML::Node& r) {
         r["continuation"] = YAML::Load("[{samples: 25}, {friction_sharpness: 0.0}]");
       }, {"continuation[1].friction_sharpness: must be positive"}},
      {"unknown continuation Hessian", [](YAML::Node& r) { r["continuation"] = YAML::Load("[{hessian: newton}]"); },
       {"continuation[0].hessian: expected limited-memory"}},
      {"continuation stage for an unknown formulation", [](YAML::Node& r) {
         r["contacts"] = YAML::Load("[l_sole, r_sole]");
         r["continuation"] = YAML::Load("[{hessian: gauss-newton, for_contact_forces: [bilevel, splnes]}]");
       }, {"continuation[0].for_contact_forces[1]: unknown contact-force formulation 'splnes'"}},
      {"continuation stage formulation listed twice", [](YAML::Node& r) {
         r["contacts"] = YAML::Load("[l_sole, r_sole]");
         r["continuation"] = YAML::Load("[{hessian: gauss-newton, for_contact_forces: [splines, splines]}]");
       }, {"continuation[0].for_contact_forces[1]: 'splines' is listed twice"}},
      {"continuation stage formulations not a list", [](YAML::Node& r) {
         r["contacts"] = YAML::Load("[l_sole, r_sole]");
         r["continuation"] = YAML::Load("[{hessian: gauss-newton, for_contact_forces: bilevel}]");
       }, {"continuation[0].for_contact_forces: expected a non-empty list"}},
      {"continuation stage formulations without a second contact", [](YAML::Node& r) {
         r["continuation"] = YAML::Load("[{hessian: gauss-newton, for_contact_forces: [bilevel]}]");
       }, {"continuation[0].for_contact_forces: the scenario has no contact besides the reference body's"}},
      {"continuation stage in an unknown formulation", [](YAML::Node& r) {
         r["contacts"] = YAML::Load("[l_sole, r_sole]");
         r["continuation"] = YAML::Load("[{hessian: gauss-newton, contact_forces: bilevl}]");
       }, {"continuation[0].contact_forces: unknown contact-force formulation 'bilevl' (expected bilevel, splines or variables)"}},
      {"continuation stage in a formulation without a second contact", [](YAML::Node& r) {
         r["continuation"] = YAML::Load("[{hessian: gauss-newton, contact_forces: bilevel}]");
       }, {"continuation[0].contact_forces: the scenario has no contact besides the reference body's"}},
      {"continuation stage's unknown inner solver", [](YAML::Node& r) {
         r["contacts"] = YAML::Load("[l_sole, r_sole]");
         r["continuation"] = YAML::Load("[{hessian: gauss-newton, inner_solver: qpoases}]");
       }, {"continuation[0].inner_solver: unknown inner solver 'qpoases' (expected active-set"}},
      {"continuation stage's inner solver without a second contact", [](YAML::Node& r) {
         r["continuation"] = YAML::Load("[{hessian: gauss-newton, inner_solver: active-set}]");
       }, {"continuation[0].inner_solver: the scenario has no contact besides the reference body's"}},
      {"continuation stage's barrier solver on second-order cones", [](YAML::Node& r) {
         r["contacts"] = YAML::Load("[l_sole, r_sole]");
         r["inner"]["contact_model"] = "report";
         r["continuation"] = YAML::Load("[{hessian: gauss-newton, inner_solver: barrier}]");
       }, {"continuation[0].inner_solver: the barrier inner solver smooths linear contact models only",
           "the report model (inner.contact_model) has second-order friction cones"}},
      {"continuation stage's unknown feasibility row", [](YAML::Node& r) {
         r["contacts"] = YAML::Load("[l_sole, r_sole]");
         r["continuation"] = YAML::Load("[{hessian: gauss-newton, feasibility: penalty}]");
       }, {"continuation[0].feasibility: expected slack or margin, got 'penalty'"}},
      {"continuation stage's feasibility row without a second contact", [](YAML::Node& r) {
         r["continuation"] = YAML::Load("[{hessian: gauss-newton, feasibility: margin}]");
       }, {"continuation[0].feasibility: the scenario has no contact besides the reference body's"}},
      {"continuation stage's margin row on second-order cones", [](YAML::Node& r) {
         r["contacts"] = YAML::Load("[l_sole, r_sole]");
         r["inner"]["contact_model"] = "report";
         r["continuation"] = YAML::Load("[{hessian: gauss-newton, feasibility: margin}]");
       }, {"continuation[0].feasibility: the margin row shifts the rows of linear contact models only",
           "the report model (inner.contact_model) has second-order friction cones"}},
      {"continuation iteration limit not positive", [](YAML::Node& r) {
         r["continuation"] = YAML::Load("[{max_iterations: 0}]");
       }, {"continuation[0].max_iterations: expected an integer ≥ 1"}},
      {"continuation samples with per-sample variables", [](YAML::Node& r) {
         r["objective"]["energy"] = "epigraph";
         r["objective"].remove("smoothing");
         r["continuation"] = YAML::Load("[{samples: 25}]");
       }, {"continuation[0].samples: the epigraph form and contact_forces: variables have variables per sample"}},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    if (kUnderSanitizers && i % 3 != 0) continue;  // every third class; the Release build runs all
    const Case& c = cases[i];
    const auto file = kickVariant(dir, [&](YAML::Node& root) {
      smoothMaximumKick(root);
      c.edit(root);
    }, "bad.yaml");
    const auto r = test::runMcopt("run " + test::quoted(file) + " --out " + test::quoted(dir.path() / "never"));
    INFO(c.what << ": " << r.all());
    CHECK(r.exitCode == 2);
    // "file:LINE: field: what"
    const auto at = r.errors.find(file.string() + ":");
    REQUIRE(at != std::string::npos);
    CHECK(std::isdigit(static_cast<unsigned char>(r.errors[at + file.string().size() + 1])));
    for (const std::string& fragment : c.expected) CHECK_THAT(r.errors, Contains(fragment));
    CHECK_FALSE(std::filesystem::exists(dir.path() / "never" / "result.json"));
  }
  // Malformed YAML names the line.
  const auto malformed = dir.write("malformed.yaml", "robot: a.urdf\nsamples: [1, 2\n");
  const auto r = test::runMcopt("run " + test::quoted(malformed));
  CHECK(r.exitCode == 2);
  CHECK_THAT(r.errors, Contains(malformed.string() + ":") && Contains("malformed YAML"));
}

TEST_CASE("run: --hessian sets every stage's Hessian, drops the hand-over stages and refuses what exact cannot do", "[cli][run]") {
  const test::TempDir dir;
  // A Gauss–Newton stage then the scenario's sample differences: with --hessian exact the
  // stage would solve the same problem again, so one stage is left, and it runs exact.
  const auto handOver = scenarioVariant(kKick, dir, [](YAML::Node& root) {
    smoothMaximumKick(root);
    root["samples"] = 12;
    root["hessian"] = "sample-differences";
    root["continuation"] = YAML::Load("[{hessian: gauss-newton, max_iterations: 500}]");
  }, "kick_hand_over.yaml");
  const auto out = dir.path() / "exact";
  const auto r = test::runMcopt("run " + test::quoted(handOver) + " --hessian exact --out " + test::quoted(out) +
                                " --max-iterations 2 --configuration-optimisation off");
  INFO(r.all());
  REQUIRE(r.exitCode == 4);
  CHECK_THAT(r.output, Contains("motion optimisation (Ipopt, Hessian: exact;"));
  const Json result = readJson(out / "result.json");
  REQUIRE(result["continuation"].size() == 1);
  CHECK(result["continuation"][0]["hessian"] == "exact");
  CHECK(result["solver"]["hessian"] == "exact");
  CHECK(result["history"].size() == 3);
  const auto weightShift = scenarioVariant(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml", dir, [](YAML::Node& root) {
    root["samples"] = 12;
  }, "weight_shift.yaml");

  // A stage that changes something else stays, with the override's Hessian.
  const auto staged = scenarioVariant(kKick, dir, [](YAML::Node& root) {
    smoothMaximumKick(root);
    root["samples"] = 12;
    root["continuation"] = YAML::Load("[{smoothing: 1.0, hessian: sample-differences, max_iterations: 1}]");
  }, "kick_staged.yaml");
  const auto twoStages = test::runMcopt("run " + test::quoted(staged) + " --hessian gauss-newton --out " +
                                        test::quoted(dir.path() / "staged") + " --max-iterations 1 --configuration-optimisation off");
  INFO(twoStages.all());
  REQUIRE(twoStages.exitCode == 4);
  const Json stages = readJson(dir.path() / "staged" / "result.json")["continuation"];
  REQUIRE(stages.size() == 2);
  CHECK(stages[0]["smoothing"] == 1.0);
  CHECK(stages[0]["hessian"] == "gauss-newton");
  CHECK(stages[1]["hessian"] == "gauss-newton");

  // The bilevel formulation with environment contacts: the stencils do not hold; nothing runs.
  const auto refused = test::runMcopt("run " + test::quoted(weightShift) + " --hessian exact --out " +
                                      test::quoted(dir.path() / "never"));
  CHECK(refused.exitCode == 2);
  CHECK_THAT(refused.errors, Contains("--hessian: exact: ") && Contains("bilevel"));
  CHECK_FALSE(std::filesystem::exists(dir.path() / "never"));
  // The right sole, held by construction: refused whatever the formulation, with a window too.
  const auto windowed = scenarioVariant(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml", dir, [](YAML::Node& root) {
    root["contacts"] = YAML::Load("[l_sole, {surface: r_sole, window: [0.0, 2.4]}]");
  }, "weight_shift_window.yaml");
  for (const auto& file : {test::sourceDir() / "scenarios/hrp2_weight_shift.yaml", windowed}) {
    const auto held = test::runMcopt("run " + test::quoted(file) + " --contact-forces variables --hessian exact --out " +
                                     test::quoted(dir.path() / "never"));
    CHECK(held.exitCode == 2);
    CHECK_THAT(held.errors, Contains("--hessian: exact: ") && Contains("contact 'r_sole' is held by construction"));
  }
  CHECK_FALSE(std::filesystem::exists(dir.path() / "never"));
  const auto unknown = test::runMcopt("run " + test::quoted(weightShift) + " --hessian newton");
  CHECK(unknown.exitCode != 0);
  CHECK_THAT(unknown.errors, Contains("--hessian"));
}

TEST_CASE("run: a continuation stage for some formulations runs only with them", "[cli][run][multi-contact]") {
  // The bundled weight shift's Gauss–Newton hand-over stage is for the bilevel formulation
  // alone (docs/theory/outer-problem.md, "Multi-contact"); here on 12 samples, one iteration a stage.
  const test::TempDir dir;
  const auto weightShift = scenarioVariant(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml", dir, [](YAML::Node& root) {
    root["samples"] = 12;
    root["continuation"] = YAML::Load("[{hessian: gauss-newton, for_contact_forces: [bilevel, splines]}]");
  }, "weight_shift.yaml");
  const std::map<std::string, std::vector<std::string>> stageHessians = {
      {"bilevel", {"gauss-newton", "sample-differences"}},
      {"splines", {"gauss-newton", "sample-differences"}},
      {"variables", {"sample-differences"}}};
  for (const auto& [formulation, hessians] : stageHessians) {
    const auto out = dir.path() / formulation;
    const auto r = test::runMcopt("run " + test::quoted(weightShift) + " --contact-forces " + formulation + " --out " +
                                  test::quoted(out) + " --max-iterations 1");
    INFO(formulation << ": " << r.all());
    REQUIRE(r.exitCode == 4);
    const Json stages = readJson(out / "result.json")["continuation"];
    REQUIRE(stages.size() == hessians.size());
    for (std::size_t k = 0; k < hessians.size(); ++k) CHECK(stages[k]["hessian"] == hessians[k]);
    CHECK_THAT(r.output, Contains(hessians.size() == 1 ? "Hessian: sample-differences;" : "stage 1 of 2"));
  }
}

TEST_CASE("run: a continuation stage in the bilevel formulation hands a single-level run its motion, the forces the inner problem's "
          "along it",
          "[cli][run][multi-contact]") {
  // The bundled weight shift's layout on 12 samples: a Gauss–Newton stage solved bilevel, then
  // the run's own formulation from its motion (the force variables fitted to the inner
  // problem's exact optima at every sample), each stage a few iterations.
  const test::TempDir dir;
  const auto weightShift = scenarioVariant(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml", dir, [](YAML::Node& root) {
    root["samples"] = 12;
    root["solver"]["max_iter"] = 3;
    root["continuation"] = YAML::Load("[{hessian: gauss-newton, max_iterations: 15, contact_forces: bilevel, inner_solver: active-set}]");
  }, "weight_shift.yaml");
  for (const char* forces : {"variables", "splines", "bilevel"}) {
    const auto out = dir.path() / forces;
    const auto r = test::runMcopt("run " + test::quoted(weightShift) + " --contact-forces " + forces + " --out " + test::quoted(out));
    INFO(forces << ": " << r.all());
    REQUIRE((r.exitCode == 0 || r.exitCode == 4));
    const Json result = readJson(out / "result.json");
    const Json stages = result["continuation"];
    CHECK(result["contact_forces"] == forces);
    if (std::string(forces) == "bilevel" && stages.size() == 1) continue;  // its stage poses its problem and ended optimal
    REQUIRE(stages.size() == 2);
    CHECK(stages[0]["contact_forces"] == "bilevel");
    CHECK(stages[0]["inner_solver"] == "active-set");
    CHECK(stages[1]["contact_forces"] == forces);
    if (std::string(forces) == "bilevel") continue;
    CHECK(stages[1]["inner_solver"].is_null());
    CHECK_THAT(r.output, Contains("stage 1 of 2: ") && Contains(", contact forces bilevel"));
    if (std::string(forces) != "variables") continue;
    // The variables start where the bilevel stage ended: the same criterion, every row held
    // (the inner optima are admissible at every sample). (The force splines start from a
    // least-squares fit of those wrenches; here, worse than the stage's start, from that start.)
    CHECK(stages[1]["restarted_from_stage"].is_null());
    std::optional<Json> first;
    for (const Json& h : result["history"])
      if (h["stage"] == 1 && !first) first = h;
    REQUIRE(first);
    CHECK(first->at("objective").get<double>() == Approx(stages[0]["objective"].get<double>()).epsilon(1e-9));
    CHECK(first->at("violation").get<double>() <= 1e-6);
  }
}

TEST_CASE("run: a continuation stage's inner solver solves that stage and the scenario's solves its own problem while --inner-solver sets both",
          "[cli][run][multi-contact]") {
  // The bundled weight shift's layout (active-set optima in the Gauss–Newton stage, the barrier's
  // central path for the scenario's problem) on 12 samples, one iteration a stage.
  const test::TempDir dir;
  const auto staged = scenarioVariant(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml", dir, [](YAML::Node& root) {
    root["samples"] = 12;
    root["inner"]["solver"] = "barrier";
    root["inner"]["barrier"] = 1e-3;
    root["continuation"] = YAML::Load("[{hessian: gauss-newton, inner_solver: active-set}]");
  }, "weight_shift_staged.yaml");
  struct Case {
    std::string arguments;
    std::vector<Json> solvers;  ///< each stage's inner_solver in result.json
  };
  const std::vector<Case> cases = {{"", {"active-set", "barrier"}},
                                   {"--inner-solver slsqp", {"slsqp", "slsqp"}},
                                   {"--contact-forces variables", {nullptr, nullptr}}};
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const auto out = dir.path() / ("run" + std::to_string(i));
    const auto r = test::runMcopt("run " + test::quoted(staged) + " " + cases[i].arguments + " --out " + test::quoted(out) +
                                  " --max-iterations 1");
    INFO(cases[i].arguments << ": " << r.all());
    REQUIRE(r.exitCode == 4);
    const Json stages = readJson(out / "result.json")["continuation"];
    REQUIRE(stages.size() == cases[i].solvers.size());
    for (std::size_t k = 0; k < stages.size(); ++k) {
      CHECK(stages[k]["inner_solver"] == cases[i].solvers[k]);
      if (!cases[i].solvers[k].is_null())
        CHECK_THAT(r.output, Contains("stage " + std::to_string(k + 1) + " of 2: ") &&
                                 Contains(", inner solver " + cases[i].solvers[k].get<std::string>()));
    }
  }
  // The barrier parameter is the stage's when only a stage takes the barrier solver.
  const auto barrierStage = scenarioVariant(staged, dir, [](YAML::Node& root) {
    root["inner"]["solver"] = "active-set";
    root["continuation"][0]["inner_solver"] = "barrier";
  }, "weight_shift_barrier_stage.yaml");
  const auto r = test::runMcopt("run " + test::quoted(barrierStage) + " --out " + test::quoted(dir.path() / "barrier_stage") +
                                " --max-iterations 1");
  INFO(r.all());
  CHECK(r.exitCode == 4);
  CHECK_THAT(r.output, Contains(", inner solver barrier") && Contains(", inner solver active-set"));
}

TEST_CASE("run: a continuation stage's feasibility row holds that stage, the scenario's inner.feasibility its own problem",
          "[cli][run][multi-contact]") {
  // The slack row in a Gauss–Newton stage, then the margin row for the scenario's problem (and
  // the other way round), on the weight shift's 12 samples, one iteration a stage: result.json
  // and the console name each stage's row, and a stage that names none takes the scenario's.
  const test::TempDir dir;
  struct Case {
    std::string scenarioRow;        ///< inner.feasibility
    std::string stageEntry;         ///< the stage's feasibility key, or empty
    std::vector<std::string> rows;  ///< each stage's row in result.json
  };
  const std::vector<Case> cases = {{"margin", ", feasibility: slack", {"slack", "margin"}},
                                   {"slack", ", feasibility: margin", {"margin", "slack"}},
                                   {"margin", "", {"margin", "margin"}}};
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const auto staged = scenarioVariant(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml", dir, [&](YAML::Node& root) {
      root["samples"] = 12;
      root["inner"]["feasibility"] = cases[i].scenarioRow;
      root["continuation"] = YAML::Load("[{hessian: gauss-newton" + cases[i].stageEntry + "}]");
    }, "weight_shift_rows" + std::to_string(i) + ".yaml");
    const auto out = dir.path() / ("rows" + std::to_string(i));
    const auto r = test::runMcopt("run " + test::quoted(staged) + " --out " + test::quoted(out) + " --max-iterations 1");
    INFO(cases[i].scenarioRow << cases[i].stageEntry << ": " << r.all());
    REQUIRE(r.exitCode == 4);
    const Json stages = readJson(out / "result.json")["continuation"];
    REQUIRE(stages.size() == 2);
    for (std::size_t k = 0; k < 2; ++k) {
      CHECK(stages[k]["feasibility"] == cases[i].rows[k]);
      CHECK_THAT(r.output, Contains("stage " + std::to_string(k + 1) + " of 2: ") && Contains(", " + cases[i].rows[k] + " row"));
    }
  }
}

TEST_CASE("run: knuckles on the table as a point contact: a force alone, recorded with its model", "[cli][run][multi-contact]") {
  // The lean reach with its right hand's own contact model (contacts[2].model: point), a few
  // iterations of the bilevel and a single-level formulation: the file is read, the hand's
  // moments are zero at every sample, and result.json names each contact's model. (The full
  // run: docs/tutorials/multi-contact.md.)
  const test::TempDir dir;
  const auto scenario = scenarioVariant(test::sourceDir() / "scenarios/hrp2_lean_reach.yaml", dir, [](YAML::Node& root) {
    root["contacts"][2]["model"] = "point";
    root["samples"] = 24;
    root.remove("continuation");
    root["hessian"] = "gauss-newton";
  }, "lean_reach_point.yaml");
  for (const char* forces : {"bilevel", "variables"}) {
    const auto out = dir.path() / forces;
    const auto r = test::runMcopt("run " + test::quoted(scenario) + " --contact-forces " + forces + " --out " +
                                  test::quoted(out) + " --max-iterations 3");
    INFO(forces << ": " << r.all());
    REQUIRE(r.exitCode == 4);
    const Json result = readJson(out / "result.json");
    REQUIRE(result["contacts"].size() == 3);
    CHECK(result["contacts"][0]["contact_model"] == "wrench-cone");
    CHECK(result["contacts"][1]["contact_model"] == "wrench-cone");
    CHECK(result["contacts"][2]["contact_model"] == "point");
    int active = 0;
    double largest = 0.0;
    for (const Json& w : result["contacts"][2]["wrench"]) {
      if (w.is_null()) continue;
      ++active;
      for (int k = 3; k < 6; ++k) CHECK(w[static_cast<std::size_t>(k)].get<double>() == 0.0);
      largest = std::max(largest, w[2].get<double>());
    }
    CHECK(active > 5);
    CHECK(largest > 1.0);  // the hand does carry load
  }
}

TEST_CASE("run: multi-contact results, torques reproduced from states and contact wrenches", "[cli][run][multi-contact]") {
  // Each formulation on the two-sole weight shift, a few iterations: result.json's torques
  // are Γ0 − J1 F of its own states and wrenches, as `mcopt dynamics --contacts` computes them.
  const test::TempDir dir;
  for (const char* forces : {"bilevel", "splines", "variables"}) {
    if (kUnderSanitizers && std::string(forces) != "variables") continue;
    const auto scenario = scenarioVariant(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml", dir, [](YAML::Node& root) {
      root["samples"] = 16;
      root["hessian"] = "limited-memory";
      root.remove("continuation");
    }, "weight_shift.yaml");
    const auto out = dir.path() / forces;
    // The start and end postures as the scenario gives them: what is checked here is the
    // motion's result files, not the configuration optimisation (tested on the kick).
    const auto r = test::runMcopt("run " + test::quoted(scenario) + " --contact-forces " + forces + " --out " +
                                  test::quoted(out) + " --max-iterations 3 --configuration-optimisation off");
    INFO(forces << ": " << r.all());
    REQUIRE(r.exitCode == 4);
    CHECK_THAT(r.output, Contains("contacts l_sole, r_sole; contact forces: " + std::string(forces)));
    const Json result = readJson(out / "result.json");
    CHECK(result["contact_forces"] == forces);
    REQUIRE(result["contacts"].size() == 2);
    CHECK(result["contacts"][1]["name"] == "r_sole");
    CHECK(result["contacts"][1]["closure_drift_m"].get<double>() >= 0.0);
    CHECK(result["contacts"][1]["closure_speed_m_s"].get<double>() >= 0.0);
    CHECK(result["contacts"][1]["closure_angular_speed_rad_s"].get<double>() >= 0.0);
    CHECK(result["contacts"][1]["wrench"].size() == 16);
    CHECK(result["violation_by_kind"].contains("closure"));
    CHECK(result["power_fine"].is_null());
    // The iteration history, with the inner problems' counts in the bilevel formulation.
    REQUIRE(result["history"].size() == 4);  // iterations 0 … 3
    CHECK(result["history"][3]["iteration"] == 3);
    if (std::string(forces) == "bilevel") {
      CHECK(result["inner"]["status"].size() == 16);
      const Json& inner = result["history"][3]["inner"];
      CHECK(inner["optimal"].get<int>() + inner["infeasible"].get<int>() + inner["failed"].get<int>() == 16);
      CHECK(inner["mean_iterations"].get<double>() >= 0.0);
    } else {
      CHECK_FALSE(result["history"][3].contains("inner"));
    }

    const auto dynamics = test::runMcopt(
        "dynamics --robot " + test::quoted(test::sourceDir() / "robots/hrp2/hrp2.urdf") + " --reference-body l_sole --states " +
        test::quoted(out / "states.json") + " --contacts " + test::quoted(out / "contact_wrenches.json") + " --out " +
        test::quoted(dir.path() / "dynamics.json"));
    REQUIRE(dynamics.exitCode == 0);
    const Json evaluated = readJson(dir.path() / "dynamics.json");
    REQUIRE(evaluated["results"].size() == 16);
    double worst = 0.0, largest = 0.0, contactShare = 0.0;
    for (std::size_t s = 0; s < 16; ++s)
      for (std::size_t j = 0; j < 30; ++j) {
        const double expected = result["torques"][s][j].get<double>();
        worst = std::max(worst, std::abs(evaluated["results"][s]["tau"][j].get<double>() - expected));
        largest = std::max(largest, std::abs(expected));
        contactShare = std::max(contactShare, std::abs(evaluated["results"][s]["tau0"][j].get<double>() - expected));
      }
    INFO("largest torque " << largest << " N m, worst difference " << worst << ", largest Γ0 − Γ " << contactShare);
    CHECK(largest > 10.0);
    CHECK(contactShare > 1.0);  // the second sole does carry load: the check is not Γ0 against Γ0
    CHECK(worst <= 1e-9 * largest);
  }
  // Every inner solver in the bilevel formulation, samples solved on two threads: Ipopt's
  // inner solves share MUMPS, which is not thread-safe (they crashed before being serialised).
  for (const char* solver : {"slsqp", "ipopt"}) {
    // Under the sanitizers the Ipopt inner solver alone (the one that shares MUMPS).
    if (kUnderSanitizers && std::string(solver) == "slsqp") continue;
    // Ipopt as the inner solver takes ~1.7 s a sample and iteration here (30 s for 16 samples
    // and 3 iterations in Release, 5 min under the sanitizers): 8 samples, one iteration.
    const bool ipopt = std::string(solver) == "ipopt";
    const int iterations = ipopt ? 1 : 3;
    const auto scenario = scenarioVariant(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml", dir, [&](YAML::Node& root) {
      root["samples"] = ipopt ? 8 : 16;
      root["hessian"] = "limited-memory";
      root.remove("continuation");
      root["inner"]["solver"] = solver;
    }, std::string("weight_shift_") + solver + ".yaml");
    const auto out = dir.path() / solver;
    const auto r = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(out) + " --max-iterations " +
                                      std::to_string(iterations) + " --configuration-optimisation off",
                                  "OMP_NUM_THREADS=2");
    INFO(solver << ": " << r.all());
    CHECK(r.exitCode == 4);
    CHECK_THAT(r.output, Contains("(inner solver " + std::string(solver) + ")"));
    CHECK(readJson(out / "result.json")["history"].size() == static_cast<std::size_t>(iterations + 1));
  }
  // Bad contact wrench files name the file and the field.
  const auto bad = dir.write("bad_wrenches.json", "{\"contact_surfaces\": \"" +
                                                     (test::sourceDir() / "robots/hrp2/contacts.yaml").string() +
                                                     "\", \"contacts\": [{\"surface\": \"r_sole\", \"wrenches\": [[1, 2]]}]}");
  const auto states = dir.write("one_state.json", "{\"states\": [{}]}");
  const auto r = test::runMcopt("dynamics --robot " + test::quoted(test::sourceDir() / "robots/hrp2/hrp2.urdf") +
                                " --states " + test::quoted(states) + " --contacts " + test::quoted(bad));
  CHECK(r.exitCode == 2);
  CHECK_THAT(r.errors, Contains(bad.string() + ": contacts[0].wrenches[0]"));
}

TEST_CASE("run: --force-units hands Ipopt the force variables in newtons or weights (the default), recorded, and leaves the bilevel problem alone",
          "[cli][run][multi-contact]") {
  const test::TempDir dir;
  const auto scenario = scenarioVariant(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml", dir, [](YAML::Node& root) {
    root["samples"] = 8;
    root["continuation"] = YAML::Load("[]");
  }, "weight_shift.yaml");
  // The objective along the first iterations: the same problem, and from the same start, so the
  // first entry agrees; after it the steps are Ipopt's in other units.
  auto run = [&](const std::string& forces, const std::string& units) {
    const auto out = dir.path() / (forces + "_" + (units.empty() ? "file" : units));
    const auto r = test::runMcopt("run " + test::quoted(scenario) + " --contact-forces " + forces +
                                  (units.empty() ? "" : " --force-units " + units) + " --out " + test::quoted(out) +
                                  " --max-iterations 3 --configuration-optimisation off");
    INFO(r.all());
    REQUIRE(r.exitCode == 4);
    const Json result = readJson(out / "result.json");
    CHECK(result["force_units"] == (units.empty() ? "weight" : units));
    std::vector<double> objective;
    for (const Json& h : result["history"]) objective.push_back(h["objective"].get<double>());
    return objective;
  };
  const std::vector<double> newtons = run("variables", "newton"), weights = run("variables", "weight");
  REQUIRE(newtons.size() == 4);
  REQUIRE(weights.size() == 4);
  CHECK(weights[0] == Approx(newtons[0]).epsilon(1e-12));  // x / m g · m g: the start to rounding
  CHECK(weights.back() != newtons.back());
  CHECK(run("variables", "") == weights);  // the default
  CHECK(run("bilevel", "newton") == run("bilevel", ""));  // no force variables: the same iterates, to the bit
}

TEST_CASE("run: --inner-solver overrides the scenario's inner.solver", "[cli][run][multi-contact]") {
  const test::TempDir dir;
  const auto scenario = scenarioVariant(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml", dir, [](YAML::Node& root) {
    root["samples"] = 8;
    root["hessian"] = "limited-memory";
  }, "weight_shift.yaml");
  for (const char* solver : {"slsqp", "active-set", "barrier"}) {
    const auto out = dir.path() / solver;
    const auto r = test::runMcopt("run " + test::quoted(scenario) + " --contact-forces bilevel --inner-solver " + solver +
                                  " --out " + test::quoted(out) + " --max-iterations 0 --configuration-optimisation off");
    INFO(r.all());
    REQUIRE(r.exitCode == 4);
    CHECK(readJson(out / "result.json")["inner"]["solver"] == solver);
  }
  // The barrier solver on the report model's cones: refused before anything runs.
  const auto report = scenarioVariant(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml", dir, [](YAML::Node& root) {
    root["samples"] = 8;
    root["inner"]["solver"] = "active-set";  // the file's own barrier would be refused first
    root["inner"]["contact_model"] = "report";
  }, "weight_shift_report.yaml");
  const auto onCones = test::runMcopt("run " + test::quoted(report) + " --inner-solver barrier --out " +
                                      test::quoted(dir.path() / "refused") + " --max-iterations 0");
  CHECK(onCones.exitCode == 2);
  CHECK_THAT(onCones.errors, Contains("--inner-solver: the barrier inner solver smooths linear contact models only") &&
                                 Contains("the report model (inner.contact_model)"));
  CHECK_FALSE(std::filesystem::exists(dir.path() / "refused"));
  // inner.polish reaches the inner solver: SLSQP's answers polished on their active sets
  // (docs/theory/inner-problem.md, "Polishing"), counted per iteration; never the active-set method's.
  for (const bool polish : {false, true}) {
    const auto variant = scenarioVariant(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml", dir, [&](YAML::Node& root) {
      root["samples"] = 8;
      root["hessian"] = "limited-memory";
      root["inner"]["polish"] = polish;
    }, std::string("weight_shift_polish_") + (polish ? "on" : "off") + ".yaml");
    for (const char* solver : {"slsqp", "active-set"}) {
      const auto out = dir.path() / (std::string(solver) + (polish ? "_polished" : "_raw"));
      const auto r = test::runMcopt("run " + test::quoted(variant) + " --inner-solver " + solver + " --out " +
                                    test::quoted(out) + " --max-iterations 0 --configuration-optimisation off");
      INFO(solver << ", polish " << polish << ": " << r.all());
      REQUIRE(r.exitCode == 4);
      const Json inner = readJson(out / "result.json")["history"][0]["inner"];
      CHECK(inner["optimal"] == 8);
      if (polish && std::string(solver) == "slsqp")
        CHECK(inner["polished"].get<int>() > 0);
      else
        CHECK(inner["polished"] == 0);
    }
  }
  const auto refused = test::runMcopt("run " + test::quoted(scenario) + " --inner-solver fsqp --out " + test::quoted(dir.path() / "no"));
  CHECK(refused.exitCode != 0);
  CHECK_THAT(refused.errors, Contains("--inner-solver"));
  CHECK_FALSE(std::filesystem::exists(dir.path() / "no"));
  // A negative iteration cap is refused, not read as "the scenario's" (it was, silently).
  const auto negative = test::runMcopt("run " + test::quoted(scenario) + " --max-iterations -1 --out " + test::quoted(dir.path() / "no"));
  CHECK(negative.exitCode == 2);
  CHECK_THAT(negative.errors, Contains("--max-iterations: expected a number ≥ 0, got -1"));
  CHECK_FALSE(std::filesystem::exists(dir.path() / "no"));
}

namespace {

const std::filesystem::path kLeanReach = test::sourceDir() / "scenarios/hrp2_lean_reach.yaml";

/// `scenario` run to its optimum into dir/name: its result.
Json optimumOf(const std::filesystem::path& scenario, const test::TempDir& dir, const std::string& name) {
  const auto r = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(dir.path() / name));
  INFO(r.all());
  REQUIRE(r.exitCode == 0);
  return readJson(dir.path() / name / "result.json");
}

/// The bundled `scenario`'s optimum `left` (rooted at the left sole) against the same scenario
/// rooted at the right sole (the reference where the left-rooted start posture puts it,
/// half-sitting's 0.12 m to the right; the left sole held), run from its own start: the same
/// optimum, within 0.5 % of the energy.
void checkRootingIndependence(const std::filesystem::path& scenario, const test::TempDir& dir, const Json& left) {
  // Physics does not know which sole is the reference (closed_chains.hpp): the same motion has
  // the same torques rooted at either (test_closed_chains.cpp). The two rootings discretise the
  // motion differently — the other leg's six joints are splines in one and follow the closure
  // in the other — so their optima meet only with control points enough that this choice does
  // not decide (docs/tutorials/multi-contact.md, "What is exact, and what depends on the rooting").
  const auto rightRooted = scenarioVariant(scenario, dir, [](YAML::Node& root) {
    root["reference_body"] = "r_sole";
    root["reference_pose"] = YAML::Load("{position: [0.0, -0.12, 0.0], rpy: [0.0, 0.0, 0.0]}");
    root["contacts"][0] = "r_sole";
    root["contacts"][1] = "l_sole";
  }, "right_rooted.yaml");
  const Json right = optimumOf(rightRooted, dir, "right_rooted");
  for (const Json* r : {&left, &right}) {
    CHECK(r->at("status") == "optimal");
    // Every contact held exactly, the right-rooted run's left sole among them.
    for (const Json& c : r->at("contacts"))
      if (!c.at("reference").get<bool>()) CHECK(c.at("closure_drift_m").get<double>() <= 1e-9);
  }
  const double energyLeft = left.at("energy").get<double>(), energyRight = right.at("energy").get<double>();
  INFO("energy rooted left " << energyLeft << " J, right " << energyRight << " J");
  CHECK(std::abs(energyRight - energyLeft) <= 5e-3 * energyLeft);
  // Both optima hold between their samples (mcopt verify, docs/reference/verify.md).
  for (const char* name : {"left", "right_rooted"}) {
    if (!std::filesystem::exists(dir.path() / name)) continue;  // the lean reach's left optimum is dir/bilevel
    const test::Verified verified = test::verifyResult(dir.path() / name);
    INFO(name << ": " << verified.all);
    CHECK(verified.exitCode == 0);
  }
}

}  // namespace

TEST_CASE("run: the lean reach rooted at the right sole ends at the same optimum, and the variables formulation from it starts "
          "feasible at its criterion and ends no higher",
          "[cli][run][multi-contact]") {
  // formulation.md §9: the bilevel optimum's wrenches are a feasible point of the single-level
  // formulations, so from it `variables` (which optimises the wrenches with the motion) can only
  // do as well or better. docs/theory/outer-problem.md, "Multi-contact: the same physics".
  if (kUnderSanitizers) return;  // three whole optimisations: the Release build runs them
  const test::TempDir dir;
  const Json first = optimumOf(kLeanReach, dir, "bilevel");
  checkRootingIndependence(kLeanReach, dir, first);
  {
    // Verified between its samples (mcopt verify, docs/reference/verify.md) …
    const test::Verified verified = test::verifyResult(dir.path() / "bilevel");
    INFO(verified.all);
    CHECK(verified.exitCode == 0);
    // … and against the scenario with the hand's window widened by hand after the run, [1.0, 2.2]
    // to [0.95, 2.25] s: the hand is not at rest on the table at the new window's ends.
    const auto widened = scenarioVariant(kLeanReach, dir, [](YAML::Node& root) {
      root["contacts"][2]["window"] = YAML::Load("[0.95, 2.25]");
    }, "widened.yaml");
    const test::Verified broken = test::verifyResult(dir.path() / "bilevel", "--scenario " + test::quoted(widened) +
                                                                               " --out " + test::quoted(dir.path() / "widened.json"));
    INFO(broken.all);
    CHECK(broken.exitCode == 1);
    const Json& closure = test::checkOf(broken.report, "closure");
    CHECK(closure.at("passed") == false);
    CHECK_THAT(closure.at("where").get<std::string>(), Contains("closure of r_hand at its window's end"));
    const Json& times = closure.at("failing_times");
    REQUIRE(times.size() == 2);
    CHECK(times[0].get<double>() == Approx(0.95).margin(1e-12));
    CHECK(times[1].get<double>() == Approx(2.25).margin(1e-12));
    CHECK(broken.report.at("failed_checks") == Json({"closure"}));
  }
  REQUIRE(first.at("contact_forces") == "bilevel");
  const auto single = test::runMcopt("run " + test::quoted(kLeanReach) + " --contact-forces variables --start-from " +
                                     test::quoted(dir.path() / "bilevel") + " --out " + test::quoted(dir.path() / "variables"));
  INFO(single.all());
  CHECK_THAT(single.output, Contains("starting from the motion of"));
  CHECK(single.exitCode == 0);
  const Json second = readJson(dir.path() / "variables/result.json");
  CHECK(second.at("status") == "optimal");
  CHECK(second.at("max_violation").get<double>() <= 1e-6);
  // Its first iterate is the bilevel optimum, feasible, at the same criterion.
  const Json& start = second.at("history").at(0);
  CHECK(start.at("objective").get<double>() == Approx(first.at("objective_value").get<double>()).epsilon(1e-9));
  CHECK(start.at("violation").get<double>() <= 1e-6);
  const double bilevelCriterion = first.at("objective_value").get<double>();
  CHECK(second.at("objective_value").get<double>() <= bilevelCriterion * (1.0 + 1e-6));
  // Both optima's energy balance (docs/reference/scenario-file.md, "Energy balance"): the joints' and contacts'
  // work is the change of mechanical energy (fixed start and end: none), the contacts held.
  for (const Json* optimum : {&first, &second}) {
    const Json& balance = optimum->at("energy_balance");
    INFO(optimum->at("contact_forces") << ": " << balance.dump());
    const double scale = std::max(std::abs(balance.at("joint_work_J").get<double>()), balance.at("joint_power_flow_J").get<double>());
    CHECK(std::abs(balance.at("mechanical_identity_residual_J").get<double>()) <= 1e-4 * scale);
    CHECK(std::abs(balance.at("potential_energy_change_J").get<double>()) <= 1e-9);
    CHECK(optimum->at("warnings").empty());
    REQUIRE(optimum->at("fixed_postures").size() == 2);
    CHECK(optimum->at("fixed_postures")[0].at("holdable") == true);
  }
}

TEST_CASE("run: the weight shift rooted at either sole ends at the same optimum", "[cli][run][multi-contact]") {
  if (kUnderSanitizers) return;  // two whole optimisations: the Release build runs them
  const test::TempDir dir;
  const auto weightShift = test::sourceDir() / "scenarios/hrp2_weight_shift.yaml";
  checkRootingIndependence(weightShift, dir, optimumOf(weightShift, dir, "left"));
}

TEST_CASE("run: --start-from refuses a motion that does not fit the scenario, naming the file and field", "[cli][run]") {
  const test::TempDir dir;
  // A real result of the kick (a few iterations), then copies of it with one field broken.
  const auto out = dir.path() / "kick";
  const auto r = test::runMcopt("run " + test::quoted(kKick) + " --out " + test::quoted(out) +
                                " --max-iterations 1 --configuration-optimisation off");
  INFO(r.all());
  REQUIRE(std::filesystem::exists(out / "result.json"));
  const Json result = readJson(out / "result.json");
  struct Case {
    const char* what;
    std::function<void(Json&)> edit;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"a joint missing", [](Json& j) { j["parameters"].erase("RLEG_JOINT3"); }, "parameters.RLEG_JOINT3: missing"},
      {"too few parameters", [](Json& j) { j["parameters"]["RLEG_JOINT3"].erase(0); },
       "parameters.RLEG_JOINT3: 3 spline parameters, the scenario has 4 (control_points 9 − 5: its end is its start)"},
      {"a parameter that is not a number", [](Json& j) { j["parameters"]["RLEG_JOINT3"][1] = "fast"; },
       "parameters.RLEG_JOINT3[1]: expected a number"},
      {"a duration the scenario does not have", [](Json& j) { j["duration"] = 2.5; },
       "duration: 2.5 s is outside the scenario's 1.6 s"},
      {"no duration", [](Json& j) { j.erase("duration"); }, "duration: missing"},
  };
  // A loop, not sections: Catch runs a test case again from its top for each section, and the
  // kick's run above would run once a case (28 s under the sanitizers).
  for (const Case& c : cases) {
    INFO(c.what);
    Json broken = result;
    c.edit(broken);
    const auto file = dir.write(std::string("broken.json"), broken.dump());
    const auto refused = test::runMcopt("run " + test::quoted(kKick) + " --start-from " + test::quoted(file) +
                                        " --out " + test::quoted(dir.path() / "refused"));
    INFO(refused.all());
    CHECK(refused.exitCode == 2);
    CHECK_THAT(refused.errors, Contains(file.string() + ": " + c.expected));
    CHECK_FALSE(std::filesystem::exists(dir.path() / "refused"));
  }
}

TEST_CASE("run: a fixed posture the robot cannot hold is reported before the run, and --strict refuses it", "[cli][run]") {
  // The kick's one-foot stance fixed at the half-sitting posture with both hips rolled toward the
  // right foot: its centre of mass is 4 cm beyond the edge of the left sole that alone carries
  // the robot. The report names the posture and the margin; the run still starts (here stopped
  // at once); --strict refuses it.
  const test::TempDir dir;
  const auto scenario = kickVariant(dir, [](YAML::Node& root) {
    root["samples"] = 8;
    root["start"] = YAML::Load("{posture: half_sitting, fixed: true, offsets: {LLEG_JOINT1: 0.1, LLEG_JOINT5: -0.1, "
                               "RLEG_JOINT1: 0.1, RLEG_JOINT5: -0.1}}");
    root["continuation"] = YAML::Load("[]");
  });
  const auto out = dir.path() / "out";
  const auto r = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(out) + " --max-iterations 0");
  INFO(r.all());
  CHECK(r.exitCode == 4);
  CHECK_THAT(r.output, Contains("fixed start and end posture (t = 0 s): centre of mass") && Contains("cm OUTSIDE the support polygon of l_sole") &&
                           Contains("CANNOT BE HELD"));
  const Json result = readJson(out / "result.json");
  REQUIRE(result["fixed_postures"].size() == 1);
  const Json& check = result["fixed_postures"][0];
  CHECK(check["which"] == "start and end");
  CHECK(check["holdable"] == false);
  CHECK(check["support_margin_m"].get<double>() == Approx(-0.041).margin(0.001));
  CHECK(check["contacts"] == Json::array({"l_sole"}));
  REQUIRE(!result["warnings"].empty());
  CHECK_THAT(result["warnings"][0].get<std::string>(), Contains("the robot cannot hold it at rest"));
  CHECK_THAT(r.errors, Contains("mcopt: warning: the fixed start and end posture"));

  const auto refusedOut = dir.path() / "refused";
  const auto refused = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(refusedOut) + " --strict");
  INFO(refused.all());
  CHECK(refused.exitCode == 2);
  CHECK_THAT(refused.errors, Contains("the robot cannot hold the fixed start and end posture") && Contains("OUTSIDE") &&
                                 Contains("--strict: nothing is run or written"));
  CHECK_FALSE(std::filesystem::exists(refusedOut / "result.json"));

  // The same posture where the robot stands on both soles is held, and --strict lets it run.
  const auto held = scenarioVariant(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml", dir, [](YAML::Node& root) {
    root["samples"] = 8;
  }, "held.yaml");
  const auto ok = test::runMcopt("run " + test::quoted(held) + " --out " + test::quoted(dir.path() / "held") +
                                 " --max-iterations 0 --strict --configuration-optimisation off");
  INFO(ok.all());
  CHECK(ok.exitCode == 4);
  CHECK_THAT(ok.output, Contains("cm inside the support polygon of l_sole, r_sole"));
  CHECK(readJson(dir.path() / "held/result.json")["fixed_postures"][0]["holdable"] == true);
}

TEST_CASE("run: a posture problem stopped at its iteration cap says so, and the result keeps it", "[cli][run]") {
  // The kick's configuration optimisation cut to 5 iterations: the posture is not the static
  // optimum, the run goes on from it and says so, at once and at the end, and result.json keeps it.
  const test::TempDir dir;
  const auto scenario = kickVariant(dir, [](YAML::Node& root) {
    root["samples"] = 8;
    root["initialisation"]["configuration_iterations"] = 5;
    root["continuation"] = YAML::Load("[]");
  });
  const auto out = dir.path() / "out";
  const auto r = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(out) + " --max-iterations 0");
  INFO(r.all());
  CHECK(r.exitCode == 4);
  CHECK_THAT(r.output, Contains("start and end posture: maximum_iterations after 5 iterations") && Contains("NOT OPTIMAL"));
  CHECK_THAT(r.errors, Contains("mcopt: warning: configuration optimisation of the start posture ended maximum_iterations after 5 "
                                "iterations (its cap, initialisation.configuration_iterations: 5)"));
  const Json result = readJson(out / "result.json");
  CHECK(result["configuration_optimisation"]["start"]["status"] == "maximum_iterations");
  REQUIRE(result["warnings"].size() == 1);
  CHECK_THAT(result["warnings"][0].get<std::string>(), Contains("not the static optimum"));
}

TEST_CASE("run: a centre-of-mass task due sooner than the robot can get there is reported before the run, and --strict refuses it",
          "[cli][run]") {
  // The bundled weight shift four times faster: its three targets 0.15 s apart, where a linear
  // inverted pendulum of HRP-2's height needs about 0.2 s (outer_nlp/timing_check.hpp).
  const test::TempDir dir;
  const auto scenario = scenarioVariant(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml", dir, [](YAML::Node& root) {
    root["samples"] = 8;
    for (std::size_t k = 0; k < 3; ++k) root["tasks"][k]["time"] = 0.15 * static_cast<double>(k + 1);
  }, "fast.yaml");
  const auto out = dir.path() / "out";
  const auto r = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(out) + " --max-iterations 0");
  INFO(r.all());
  CHECK(r.exitCode == 4);
  CHECK_THAT(r.output, Contains("timing: task 'centre of mass above the left sole' (t = 0.15 s): 0.15 s after the start posture at rest, "
                                "the centre of mass needs at least 0.227 s") &&
                           Contains("too short for this robot"));
  const Json result = readJson(out / "result.json");
  int timing = 0;
  for (const Json& w : result["warnings"]) timing += w.get<std::string>().find("needs at least") != std::string::npos;
  CHECK(timing == 3);

  const auto refused = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(dir.path() / "refused") + " --strict");
  CHECK(refused.exitCode == 2);
  CHECK_THAT(refused.errors, Contains("needs at least") && Contains("--strict: nothing is run or written"));
  CHECK_FALSE(std::filesystem::exists(dir.path() / "refused" / "result.json"));

  // The bundled timings pass: no timing line.
  const auto bundled = scenarioVariant(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml", dir, [](YAML::Node& root) {
    root["samples"] = 8;
  }, "bundled.yaml");
  const auto ok = test::runMcopt("run " + test::quoted(bundled) + " --out " + test::quoted(dir.path() / "ok") + " --max-iterations 0");
  CHECK(ok.exitCode == 4);
  CHECK_THAT(ok.output, !Contains("timing:"));
}
