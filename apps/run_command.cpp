// SPDX-License-Identifier: BSD-3-Clause
// `mcopt run`: the project's main job (issue 7). Reads a scenario (docs/reference/scenario-file.md),
// optionally optimises the static start and end postures (report §3.5), then optimises the
// whole motion with Ipopt (formulation.md §10), printing a line per iteration, and writes
// the results atomically. Ctrl-C (SIGINT) or SIGTERM stops Ipopt at the end of the current
// iteration; the last iterate is then written with status "interrupted". While Ipopt runs,
// the current iterate is written every --checkpoint-seconds with status "running" (result.json
// alone), so that a run killed outright (SIGKILL, power loss) still leaves its latest
// complete result.
#include <atomic>
#include <csignal>
#include <filesystem>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <map>
#include <optional>
#include <memory>
#include <string>
#include <vector>

#include "apps/commands.hpp"
#include "core/errors.hpp"
#include "apps/json_io.hpp"
#include "apps/result_motion.hpp"
#include "apps/run_output.hpp"
#include "inner_qp/inner_solver.hpp"
#include "outer_nlp/outer_solver.hpp"
#include "outer_nlp/motion_problem.hpp"
#include "outer_nlp/motion_solve.hpp"
#include "outer_nlp/scenario_run.hpp"
#include "outer_nlp/scenario.hpp"
#include "outer_nlp/formulation_registry.hpp"

namespace mcopt::cli {

namespace {

volatile std::sig_atomic_t stopRequested = 0;
extern "C" void requestStop(int) { stopRequested = 1; }

struct RunOptions {
  std::string scenario, out = "mcopt-run";
  // The command line's text of the overrides (ScenarioOverrides types them): "" when not given.
  std::string configurationOptimisation;  ///< "on" or "off"
  std::string contactForces;              ///< a formulation
  std::string forceUnits;                 ///< "newton" or "weight"
  std::optional<int> maxIterations;
  std::string innerSolver;                ///< an inner solver
  std::string hessian;                    ///< a Hessian option: every stage's
  double checkpointSeconds = 30.0;  ///< 0: after every iteration; negative: never
  std::string startFrom;            ///< "", or a result folder (or its result.json) to start from
  int refineRounds = -1;            ///< --refine [ROUNDS]; < 0: the scenario's
  bool allowNonPhysicalInertia = false;  ///< or the scenario's allow_nonphysical_inertia
  bool strict = false;              ///< refuse a fixed posture the robot cannot hold (exit 2, nothing written)
};

/// A result's motion (result.json `parameters` by joint, `duration`) as the run's start: any
/// format (the force variables are fitted again to the inner problem's wrenches).
void startFromResult(Scenario& scenario, const std::filesystem::path& from) {
  const ResultMotion result = readResultMotion(from, false);
  startFromMotion(scenario, result.parameters, result.duration, result.file.string());
}


constexpr int kExitNotOptimal = 4;
constexpr int kExitInterrupted = 130;

/// The run so far, written as its result with status "running": what a killed run leaves.
/// A failed write costs the checkpoint, not the run (it is reported and Ipopt goes on).
void writeCheckpoint(const std::string& out, MotionProblem& problem, const RunRecord& sofar, const IterationReport& r,
                     double optimisationSeconds, double totalSeconds) {
  RunRecord checkpoint = sofar;
  checkpoint.status = OuterStatus::Running;
  checkpoint.message = "Ipopt was running when this was written";
  checkpoint.reason = "checkpoint after iteration " + std::to_string(r.iteration) +
                      "; the run had not ended (a run that ends overwrites it)";
  // A continuation stage of another energy form has its own variables after the motion's.
  checkpoint.x = r.iterate->size() == problem.variableCount() ? *r.iterate : problem.pointFrom(problem, *r.iterate);
  if (r.progress != nullptr) checkpoint.solver = *r.progress;
  checkpoint.solver.status = checkpoint.status;
  checkpoint.solver.message = checkpoint.message;
  checkpoint.solver.iterations = r.iteration;
  checkpoint.solver.objective = r.objective;
  checkpoint.optimisationSeconds = optimisationSeconds;
  checkpoint.totalSeconds = totalSeconds;
  try {
    writeCheckpointFile(out, makeRunFiles(problem, checkpoint, false));
  } catch (const std::exception& e) {
    std::cerr << "mcopt: warning: checkpoint after iteration " << r.iteration << " not written: " << e.what() << "\n";
  }
}

int runMotion(const RunOptions& o) {
  // The formulation first: the file's checks that depend on it see the one that will run.
  std::optional<std::string> contactForces;
  if (!o.contactForces.empty()) contactForces = contactForceFormulation(o.contactForces).name;
  Scenario scenario = loadScenario(o.scenario, contactForces, o.allowNonPhysicalInertia);
  ScenarioOverrides overrides;
  if (!o.configurationOptimisation.empty()) overrides.configurationOptimisation = o.configurationOptimisation == "on";
  overrides.contactForces = contactForces;
  if (!o.forceUnits.empty()) overrides.forceUnits = parseForceUnits(o.forceUnits);  // a member of the list: checked by CLI11
  overrides.maxIterations = o.maxIterations;
  if (!o.innerSolver.empty()) overrides.innerSolver = o.innerSolver;
  if (!o.hessian.empty()) overrides.hessian = parseHessianOption(o.hessian);  // a member of the list: checked by CLI11
  if (o.refineRounds >= 0) overrides.refineRounds = o.refineRounds;
  applyOverrides(scenario, overrides);
  if (!o.startFrom.empty()) startFromResult(scenario, o.startFrom);
  for (const std::string& w : scenario.robot.warnings) std::cerr << "mcopt: warning: " << w << "\n";
  for (const std::string& n : urdfFrictionNotes(scenario.actuators, scenario.robot)) std::cerr << "mcopt: note: " << n << "\n";
  MotionProblem problem(scenario);
  std::cout << "mcopt run " << o.scenario << "\n";
  if (!scenario.description.empty()) std::cout << "  " << scenario.description << "\n";
  std::cout << "  robot " << scenario.robot.name << ": " << scenario.robot.jointCount() << " joints, "
            << std::setprecision(4) << scenario.robot.totalMass() << " kg; reference body " << scenario.referenceBody
            << ", contacts " << scenario.support.name;
  for (const EnvironmentContact& c : scenario.contacts) {
    std::cout << ", " << c.surface.name;
    if (c.window) std::cout << " [" << c.start << ", " << c.end << "] s";
  }
  std::cout << (scenario.contacts.empty() ? "" : std::string("; contact forces: ") + scenario.contactForces +
                                                     (problem.bilevel() ? " (inner solver " + scenario.inner.solverName + ")" : ""))
            << "\n"
            << "  " << problem.variableCount() << " variables, " << problem.constraintCount() << " constraints, "
            << problem.jacobianNonZeros() << " Jacobian non-zeros; " << scenario.samples << " samples over "
            << scenario.duration.initial << " s" << (problem.durationIsFree() ? " (duration free)" : "") << "\n";

  stopRequested = 0;
  std::signal(SIGINT, requestStop);
  std::signal(SIGTERM, requestStop);

  if (scenario.solve.configurationOptimisation) std::cout << "configuration optimisation (report §3.5)\n";
  if (scenario.initialMotion) std::cout << "  starting from the motion of " << o.startFrom << "\n";
  double lastCheckpoint = 0.0;
  ScenarioRunEvents events;
  events.onPostureChecks = [&](const std::vector<PostureCheck>& checks) {
    std::string refused;
    for (const PostureCheck& c : checks) {
      std::cout << "  fixed " << c.message() << (c.holdable() ? "" : "  — CANNOT BE HELD") << "\n";
      if (!c.holdable()) refused += (refused.empty() ? "" : "; ") + c.message();
    }
    if (o.strict && !refused.empty())
      throw InputError(o.scenario + ": the robot cannot hold the fixed " + refused + " (--strict: nothing is run or written)");
  };
  events.onTimingChecks = [&](const std::vector<TimingCheck>& checks) {
    std::string refused;
    for (const TimingCheck& c : checks) {
      if (!c.tooShort()) continue;
      std::cout << "  timing: " << c.message() << "\n";
      refused += (refused.empty() ? "" : "; ") + c.message();
    }
    if (o.strict && !refused.empty())
      throw InputError(o.scenario + ": " + refused + " (--strict: nothing is run or written)");
  };
  events.onPosture = [&](const std::string& which, const PostureOutcome& p) {
    std::cout << "  " << which << (scenario.periodic ? " and end" : "") << " posture: " << toString(p.status) << " after "
              << p.iterations << " iterations, static power " << std::setprecision(4) << p.staticPowerBefore << " → "
              << p.staticPowerAfter << " W (" << std::setprecision(3) << p.seconds << " s)"
              << (p.status == OuterStatus::Optimal ? "" : "  — NOT OPTIMAL (warning at the end)") << "\n";
  };
  events.onContactPosture = [&](const RunRecord::ContactPosture& p) {
    std::cout << "  posture reaching " << p.contact << " at " << std::setprecision(3) << p.time << " s: "
              << toString(p.outcome.status) << " after " << p.outcome.iterations << " iterations, " << std::setprecision(3)
              << p.distance << " rad from the start–end path (" << p.outcome.seconds << " s)"
              << (p.outcome.status == OuterStatus::Optimal ? "" : "  — NOT OPTIMAL (warning at the end)") << "\n";
  };
  events.onSolve = [&](const SolveStart& solve) {
    if (solve.joinedTorqueRows > 0)
      std::cout << "  " << solve.joinedTorqueRows << " torque-limit rows came within " << scenario.solve.torqueScreening
                << " of their limit: solving again with them\n";
    if (solve.joinedClosingRows > 0)
      std::cout << "  " << solve.joinedClosingRows << " closing joints' limit rows left the middle " << scenario.solve.closingScreening
                << " of their range: solving again with them\n";
    if (solve.restartedFrom >= 0)
      std::cout << "  stage " << solve.restartedFrom + 1 << " ended worse than it began (violation " << std::setprecision(3)
                << solve.handed.violation << " against " << solve.restart.violation << ", criterion " << std::setprecision(7)
                << solve.handed.objective << " against " << solve.restart.objective << " in stage " << solve.stage + 1
                << "'s problem): stage " << solve.stage + 1 << " starts where stage " << solve.restartedFrom + 1
                << " started\n";
    std::cout << "motion optimisation (Ipopt, Hessian: " << toString(solve.scenario.solve.hessian);
    if (solve.stages > 1) {
      std::cout << "; stage " << solve.stage + 1 << " of " << solve.stages << ": ν = "
                << solve.scenario.actuators.frictionSharpness << " s/rad";
      if (solve.scenario.energyForm == EnergyForm::SmoothMaximum)
        std::cout << ", ε = " << solve.scenario.smoothing << " W";
      else
        std::cout << ", epigraph";
      std::cout << ", " << solve.scenario.samples << " samples";
      if (solve.scenario.contactForces != scenario.contactForces) std::cout << ", contact forces " << solve.scenario.contactForces;
      if (solve.problem.bilevel())
        std::cout << ", inner solver " << solve.scenario.inner.solverName << ", " << toString(solve.scenario.inner.feasibility)
                  << " row";
    }
    if (solve.problem.omittedTorqueRowCount() > 0)
      std::cout << "; " << solve.problem.omittedTorqueRowCount() << " torque-limit rows below " << scenario.solve.torqueScreening
                << " of their limit checked afterwards";
    if (solve.problem.omittedClosingRowCount() > 0)
      std::cout << "; " << solve.problem.omittedClosingRowCount() << " closing joints' limit rows inside the middle "
                << solve.scenario.solve.closingScreening << " of their range checked afterwards";
    std::cout << ")\n"
              << "   iter      energy [J]   violation   dual inf.     elapsed"
              << (solve.problem.bilevel() ? "   infeasible samples" : "") << (scenario.ball ? "   miss [m]" : "") << "\n";
    lastCheckpoint = 0.0;
  };
  std::unique_ptr<MotionProblem> checkpointProblem;
  events.onIteration = [&](const RunRecord& sofar, const MotionProblem& current, const IterationReport& r) {
    std::printf("  %5d  %14.6f  %10.3e  %10.3e  %8.2f s", r.iteration, r.objective, r.violation, r.dualInfeasibility,
                r.elapsedSeconds);
    if (current.bilevel()) std::printf("   %d", sofar.history.back().inner.infeasible);
    if (const std::optional<double>& miss = sofar.history.back().missDistance) std::printf("   %.3e", *miss);
    else if (scenario.ball) std::printf("   (restoration)");
    std::printf("\n");
    std::fflush(stdout);
    if (o.checkpointSeconds >= 0 && r.iterate != nullptr && r.iteration > 0 &&
        r.elapsedSeconds - lastCheckpoint >= o.checkpointSeconds) {
      // On a problem of its own: a bilevel sample's inner answer is warm-started from its last
      // one, so evaluating the run's problem at the checkpoints — when the clock says, at
      // iterates that depend on the machine's speed — would change the last bits of the
      // result's torques and wrenches (docs/developers/determinism.md).
      if (!checkpointProblem) checkpointProblem = std::make_unique<MotionProblem>(scenario);
      writeCheckpoint(o.out, *checkpointProblem, sofar, r, sofar.optimisationSeconds, sofar.totalSeconds);
      lastCheckpoint = r.elapsedSeconds;
    }
    return true;
  };
  events.keepRunning = [] { return stopRequested == 0; };
  RunRecord record = runScenario(scenario, problem, events);
  // Refinement (docs/reference/verify.md, "Refine"): the optimum verified, solved again on a finer
  // grid while it does not hold between its samples. Round 0's result is written first, so a run
  // killed during a round leaves it; the rounds write no checkpoints.
  std::optional<RefinedRun> refined;
  MotionProblem* finalProblem = &problem;
  if (scenario.solve.refineRounds > 0 && record.status == OuterStatus::Optimal) {
    writeRunOutput(o.out, problem, record);
    std::cout << "refinement (up to " << scenario.solve.refineRounds << " rounds): verifying the optimum between its samples\n";
    ScenarioRunEvents roundEvents;
    roundEvents.keepRunning = events.keepRunning;
    roundEvents.onRefinementRound = [](const RefinementRound& r) {
      std::cout << "  round " << r.round << ": " << r.samples << " samples, " << toString(r.status) << " after " << r.iterations
                << " iterations; ";
      if (r.verified) {
        std::cout << "verified\n";
        return;
      }
      if (r.status != OuterStatus::Optimal) {
        std::cout << "not verified (not optimal)\n";
        return;
      }
      std::cout << "broken:";
      for (const VerificationCheck& c : r.failed)
        std::cout << " " << c.kind << " " << std::setprecision(3) << c.worst << (c.where.empty() ? "" : " (" + c.where + ")");
      std::cout << "\n";
    };
    refined = refineRun(scenario, problem, std::move(record), scenario.solve.refineRounds, VerificationSettings{}, roundEvents);
    record = std::move(refined->record);
    if (refined->problem) finalProblem = refined->problem.get();
  }
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  if (record.status == OuterStatus::Interrupted) record.reason = "interrupted by a signal; the last iterate is written";
  const RunFiles written = writeRunOutput(o.out, *finalProblem, record);
  const double energy = written.energy, violation = written.maxViolation;

  std::cout << "\nEXIT: " << record.message << "\n"
            << "  status             " << toString(record.status) << "\n"
            << std::setprecision(6) << "  energy             " << energy << " J  (∫ Σ max(P, 0) dt at the samples)\n"
            << "  max violation      " << std::setprecision(3) << violation << "\n"
            << "  iterations         " << record.solver.iterations;
  if (record.stages.size() > 1) {
    std::cout << " (all stages:";
    for (std::size_t k = 0; k < record.stages.size(); ++k) std::cout << (k == 0 ? " " : " + ") << record.stages[k].iterations;
    std::cout << ")";
  } else if (record.stages.size() == 1 && record.stages.front().rounds > 1) {
    // Rows that joined after an optimum were solved again: the last solve's count alone hides the others.
    std::cout << " (" << record.stages.front().iterations << " over " << record.stages.front().rounds << " screening solves)";
  }
  std::cout << "\n"
            << "  time               " << record.totalSeconds << " s (configuration " << record.configurationSeconds
            << " s, motion " << record.optimisationSeconds << " s)\n"
            << "  results            " << o.out << "/result.json, trajectory.csv, power_fine.csv, states.json, contact_wrenches.json\n";
  if (!record.refinement.empty()) {
    const RefinementRound& last = record.refinement.back();
    std::cout << "  refinement         " << record.refinement.size() - 1 << " round(s); " << last.samples << " samples: "
              << (last.verified ? "verified between the samples" : "NOT verified between the samples") << "\n";
  }
  if (const std::optional<ReleaseState>& ball = written.release) {
    // formulation.md §10: what a throw that did not converge got closest to is its written iterate.
    std::cout << "  release            " << std::setprecision(3) << ball->speed << " m/s at "
              << ball->elevationDegrees() << "°, landing "
              << ball->landing.x() << ", " << ball->landing.y() << " m; miss " << ball->missDistance << " m"
              << (record.solver.optimal() ? "" : " (target not reached: the written iterate's miss)") << "\n";
  }
  if (const std::optional<EnergyBalance>& b = written.balance) {
    std::cout << std::setprecision(4) << "  energy balance     joints' work " << b->jointWork << " J = ΔE_pot "
              << b->potentialChange << " + ΔE_kin " << b->kineticChange << " J";
    if (scenario.ball) std::cout << " + ball " << b->ballEnergy << " J";
    if (!scenario.contacts.empty()) std::cout << " − contacts' work " << b->contactWork << " J";
    std::cout << " (residual " << std::setprecision(2) << b->mechanicalResidual() << " J)\n" << std::setprecision(4)
              << "                     Joule " << b->jouleLosses << " J, friction " << b->frictionDissipation
              << " J, braking fed back " << -b->braking << " J (" << b->instants << " instants)\n";
  }
  for (const std::string& w : written.warnings) std::cerr << "mcopt: warning: " << w << "\n";
  if (!record.reason.empty() && !record.solver.optimal()) std::cerr << "mcopt: run not optimal: " << record.reason << "\n";
  if (record.status == OuterStatus::Interrupted) return kExitInterrupted;
  return record.solver.optimal() ? 0 : kExitNotOptimal;
}

}  // namespace

Runner addRun(CLI::App& command) {
  auto o = std::make_shared<RunOptions>();
  command.add_option("scenario", o->scenario, "scenario YAML file (docs/reference/scenario-file.md)")->required()->check(CLI::ExistingFile);
  command.add_option("--out", o->out, "folder for result.json, trajectory.csv, power_fine.csv, states.json")
      ->capture_default_str();
  command.add_option("--configuration-optimisation", o->configurationOptimisation,
                     "on or off: override the scenario's initialisation.configuration_optimisation")
      ->check(CLI::IsMember({"on", "off"}));
  command.add_option("--contact-forces", o->contactForces,
                     alternatives(contactForcesNames()) + ": override the scenario's contact_forces (formulation.md §9)")
      ->check(CLI::IsMember(contactForcesNames()));
  command.add_option("--force-units", o->forceUnits,
                     "newton or weight: override the scenario's force_units, the unit in which Ipopt sees the splines and "
                     "variables formulations' force variables (docs/theory/outer-problem.md, \"Units of the force variables\")")
      ->check(CLI::IsMember(forceUnitsNames()));
  command.add_option("--max-iterations", o->maxIterations,
                     "override Ipopt's max_iter for the motion (each continuation stage: at most this many)");
  command.add_option("--inner-solver", o->innerSolver,
                     innerSolverList() + ": override the scenario's inner.solver and every continuation stage's inner_solver (bilevel, formulation.md §7; " +
                         "`mcopt inner --help` says what each is)")
      ->check(CLI::IsMember(innerSolverNames()));
  command.add_option("--hessian", o->hessian,
                     "override the scenario's hessian and every continuation stage's; stages left differing in "
                     "nothing else are dropped (docs/theory/outer-problem.md, \"Hessian options\")")
      ->check(CLI::IsMember(hessianOptionNames()));
  command.add_option("--start-from", o->startFrom,
                     "a result folder (or its result.json): start from its motion instead of the interpolated one; "
                     "configuration optimisation off; with another contact-force formulation its forces from the "
                     "inner problem along it");
  command.add_option("--refine", o->refineRounds,
                     "after the optimum, verify it between its samples and, while a check fails, solve again on twice "
                     "the sample intervals from the motion reached, at most ROUNDS times (default 3 with the flag "
                     "alone; 0: none; overrides the scenario's refine)")
      ->expected(0, 1)
      ->default_str("3");
  command.add_flag("--allow-nonphysical-inertia", o->allowNonPhysicalInertia,
                   "load a URDF whose inertias a real body cannot have (not positive definite, or breaking the "
                   "triangle inequality), with a warning for each, as the scenario's allow_nonphysical_inertia: true");
  command.add_flag("--strict", o->strict,
                   "refuse a scenario whose fixed start or end posture the robot cannot hold at rest (centre of mass "
                   "outside the support polygon, a static torque beyond its limit), or whose centre-of-mass task is due "
                   "sooner than a linear inverted pendulum can get there: exit 2, nothing written");
  command.add_option("--checkpoint-seconds", o->checkpointSeconds,
                     "write the current iterate (status running) at most this often; 0: every iteration, "
                     "negative: never")
      ->capture_default_str();
  return [o] { return runMotion(*o); };
}

}  // namespace mcopt::cli
