// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/scenario_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.hpp"
#include "inner_qp/inner_solver.hpp"
#include "outer_nlp/configuration_problem.hpp"
#include "outer_nlp/energy_balance.hpp"
#include "outer_nlp/motion_verification.hpp"

namespace mcopt {

namespace {

double secondsSince(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

/// Configuration optimisation of one end of the motion (report §3.5), or with `near` the reach
/// posture of a contact's window; returns the posture to start from (the guess when Ipopt
/// handed back nothing usable).
Eigen::VectorXd optimisePosture(const Scenario& scenario, const MotionProblem& motion, const Eigen::VectorXd& guess,
                                double instant, const ScenarioRunEvents& events, PostureOutcome& outcome,
                                std::optional<Eigen::VectorXd> near = std::nullopt) {
  ConfigurationProblem problem(scenario, motion.model(), motion.support(), instant, std::move(near));
  outcome.optimised = true;
  outcome.staticPowerBefore = problem.staticPower(guess);
  OuterSolverSettings settings;
  settings.maxIterations = scenario.solve.configurationIterations;  // initialisation.configuration_iterations
  const OuterOutcome result = solveOuter(problem, guess, settings, [&](const IterationReport&) {
    return !events.keepRunning || events.keepRunning();
  });
  outcome.status = result.status;
  outcome.iterations = result.iterations;
  outcome.seconds = result.seconds;
  const bool usable = result.x.size() == guess.size() && result.x.allFinite();
  outcome.staticPowerAfter = usable ? problem.staticPower(result.x) : outcome.staticPowerBefore;
  return usable ? result.x : guess;
}

/// `--hessian`: every stage takes the option; a stage that then differs from the next one (or
/// from the scenario) in nothing but its iteration limit would solve the same problem again,
/// so it goes and the next one solves it.
void overrideHessian(Scenario& scenario, HessianOption hessian) {
  scenario.solve.hessian = hessian;
  std::vector<ContinuationStage> kept;
  for (std::size_t k = 0; k < scenario.solve.continuation.size(); ++k)
    if (!posesScenarioProblem(continuationStage(scenario, k), continuationStage(scenario, k + 1))) {
      kept.push_back(scenario.solve.continuation[k]);
      kept.back().hessian = hessian;
    }
  scenario.solve.continuation = std::move(kept);
  if (hessian != HessianOption::Exact) return;
  // The scenario's own problem first, then its stages (one solved in another formulation has
  // reasons of its own).
  for (std::size_t k = scenario.solve.continuation.size() + 1; k-- > 0;)
    if (const std::string why = exactHessianRefusal(continuationStage(scenario, k)); !why.empty())
      throw InputError("--hessian: exact: " + why);
}

/// The warning of a posture whose configuration optimisation did not end optimal (empty when it did).
std::string postureWarning(const std::string& which, const PostureOutcome& p, const Scenario& scenario) {
  if (!p.optimised || p.status == OuterStatus::Optimal) return "";
  std::ostringstream what;
  what << "configuration optimisation of the " << which << " posture ended " << toString(p.status) << " after "
       << p.iterations << " iterations";
  if (p.status == OuterStatus::MaximumIterations)
    what << " (its cap, initialisation.configuration_iterations: " << scenario.solve.configurationIterations << ")";
  what << ", static power " << p.staticPowerBefore << " → " << p.staticPowerAfter
       << " W: the motion starts from a posture that is not the static optimum";
  return what.str();
}

}  // namespace

void applyOverrides(Scenario& scenario, const ScenarioOverrides& o) {
  if (o.configurationOptimisation) scenario.solve.configurationOptimisation = *o.configurationOptimisation;
  if (o.contactForces) scenario.contactForces = *o.contactForces;
  if (o.forceUnits) scenario.forceUnits = *o.forceUnits;
  if (o.refineRounds) {
    if (*o.refineRounds < 0) throw InputError("refine: expected a number of rounds ≥ 0, got " + std::to_string(*o.refineRounds));
    scenario.solve.refineRounds = *o.refineRounds;
  }
  if (o.innerSolver) {
    if (!isInnerSolverName(*o.innerSolver))
      throw InputError("inner.solver: unknown inner solver '" + *o.innerSolver + "' (expected " + innerSolverList() + ")");
    scenario.inner.solverName = *o.innerSolver;
    for (ContinuationStage& stage : scenario.solve.continuation) stage.innerSolver.clear();  // every stage's, as --hessian
    if (const std::string why = barrierModelRefusal(scenario); !why.empty()) throw InputError("--inner-solver: " + why);
  }
  if (o.hessian) overrideHessian(scenario, *o.hessian);
  if (o.maxIterations) {
    if (*o.maxIterations < 0)
      throw InputError("--max-iterations: expected a number ≥ 0, got " + std::to_string(*o.maxIterations));
    SolverOption limit;
    limit.name = "max_iter", limit.type = SolverOption::Type::Integer, limit.integer = *o.maxIterations;
    limit.origin = "--max-iterations: ";
    scenario.solve.solverOptions.push_back(limit);
    // Every continuation stage too: the override bounds the whole run's work, stage by stage.
    for (ContinuationStage& stage : scenario.solve.continuation)
      stage.maxIterations = stage.maxIterations < 0 ? *o.maxIterations : std::min(stage.maxIterations, *o.maxIterations);
  }
}

void startFromMotion(Scenario& scenario, const std::map<std::string, std::vector<double>>& parametersByJoint,
                     double duration, const std::string& origin) {
  const int n = static_cast<int>(scenario.robot.joints.size()), m = scenario.controlPoints - (scenario.periodic ? 5 : 4);
  const int endParameter = scenario.periodic ? 0 : m - 1;
  Scenario::InitialMotion motion;
  motion.parameters.resize(n * m);
  for (int j = 0; j < n; ++j) {
    const std::string& name = scenario.robot.joints[static_cast<std::size_t>(j)].name;
    const auto found = parametersByJoint.find(name);
    if (found == parametersByJoint.end())
      throw InputError(origin + ": parameters." + name + ": missing (the scenario's robot has this joint)");
    if (static_cast<int>(found->second.size()) != m)
      throw InputError(origin + ": parameters." + name + ": " + std::to_string(found->second.size()) +
                       " spline parameters, the scenario has " + std::to_string(m) + " (control_points " +
                       std::to_string(scenario.controlPoints) + (scenario.periodic ? " − 5: its end is its start)" : " − 4)"));
    for (int l = 0; l < m; ++l) {
      const double value = found->second[static_cast<std::size_t>(l)];
      if (!std::isfinite(value)) throw InputError(origin + ": parameters." + name + ": not a finite number");
      motion.parameters[j * m + l] = value;
    }
  }
  if (parametersByJoint.size() != static_cast<std::size_t>(n))
    throw InputError(origin + ": parameters: " + std::to_string(parametersByJoint.size()) + " joints, the scenario's robot has " +
                     std::to_string(n));
  const DurationSpec& T = scenario.duration;
  if (!std::isfinite(duration) || duration < T.lower - 1e-12 || duration > T.upper + 1e-12) {
    std::ostringstream what;
    what << origin << ": duration: " << duration << " s is outside the scenario's ";
    if (T.free())
      what << "[" << T.lower << ", " << T.upper << "] s";
    else
      what << T.initial << " s";
    throw InputError(what.str());
  }
  motion.duration = std::clamp(duration, T.lower, T.upper);
  for (int j = 0; j < n; ++j) scenario.start[j] = motion.parameters[j * m], scenario.end[j] = motion.parameters[j * m + endParameter];
  scenario.solve.configurationOptimisation = false;
  scenario.initialMotion = std::move(motion);
}

Eigen::VectorXd initialPointThroughContacts(MotionProblem& problem, const Eigen::VectorXd& start, const Eigen::VectorXd& end,
                                            std::vector<RunRecord::ContactPosture>* reaches, const ScenarioRunEvents& events) {
  // A contact with a window inside the motion is closed by its limb's joints there: the initial
  // motion holds a posture that reaches it over the window.
  const Scenario& scenario = problem.scenario();
  std::vector<MotionProblem::HeldPosture> held;
  const double T = scenario.duration.initial;
  for (const EnvironmentContact& c : scenario.contacts) {
    if (!c.window || (c.start <= 0.0 && c.end >= T)) continue;
    RunRecord::ContactPosture reach;
    reach.contact = c.surface.name;
    reach.time = 0.5 * (c.start + std::min(c.end, T));
    const double u = reach.time / T;
    const Eigen::VectorXd path = scenario.periodic ? Eigen::VectorXd(start) : Eigen::VectorXd((1.0 - u) * start + u * end);
    const Eigen::VectorXd posture = optimisePosture(scenario, problem, path, reach.time, events, reach.outcome, path);
    reach.distance = (posture - path).norm();
    if (events.onContactPosture) events.onContactPosture(reach);
    held.push_back({c.start / T, std::min(1.0, c.end / T), posture});
    if (reaches) reaches->push_back(reach);
  }
  return problem.initialPoint(start, end, held);
}

RunRecord runScenario(const Scenario& scenario, MotionProblem& problem, const ScenarioRunEvents& events) {
  const auto clock = std::chrono::steady_clock::now();
  RunRecord record;
  record.postureChecks = checkFixedPostures(problem);
  for (const PostureCheck& check : record.postureChecks)
    if (!check.holdable())
      record.warnings.push_back("the fixed " + check.message() + ": the robot cannot hold it at rest, so no motion of this problem is feasible");
  if (events.onPostureChecks) events.onPostureChecks(record.postureChecks);
  record.timingChecks = checkCenterOfMassTimings(problem);
  for (const TimingCheck& check : record.timingChecks)
    if (check.tooShort())
      record.warnings.push_back(check.message() + ": no motion of this problem reaches it (give the task more time or a nearer target)");
  if (events.onTimingChecks) events.onTimingChecks(record.timingChecks);
  Eigen::VectorXd start = scenario.start, end = scenario.end;
  if (scenario.solve.configurationOptimisation) {
    if (!scenario.fixStart) {
      start = optimisePosture(scenario, problem, start, 0.0, events, record.start);
      if (const std::string w = postureWarning("start", record.start, scenario); !w.empty()) record.warnings.push_back(w);
      if (events.onPosture) events.onPosture("start", record.start);
    }
    if (scenario.periodic) {
      end = start;  // one posture for both ends
    } else if (!scenario.fixEnd) {
      end = optimisePosture(scenario, problem, end, scenario.duration.initial, events, record.end);
      if (const std::string w = postureWarning("end", record.end, scenario); !w.empty()) record.warnings.push_back(w);
      if (events.onPosture) events.onPosture("end", record.end);
    }
  }
  record.configurationSeconds = secondsSince(clock);

  const Eigen::VectorXd x0 = scenario.initialMotion
                                 ? problem.pointFromMotion(scenario.initialMotion->parameters, scenario.initialMotion->duration)
                                 : initialPointThroughContacts(problem, start, end, &record.contactPostures, events);
  for (const RunRecord::ContactPosture& reach : record.contactPostures)
    if (reach.outcome.status != OuterStatus::Optimal)
      record.warnings.push_back("the posture reaching contact '" + reach.contact + "' over its window ended " +
                                toString(reach.outcome.status) + " after " + std::to_string(reach.outcome.iterations) +
                                " iterations: the initial motion may not close it there");
  solveScenarioFrom(scenario, problem, x0, events, record);
  record.totalSeconds = secondsSince(clock);
  return record;
}

void solveScenarioFrom(const Scenario& scenario, MotionProblem& problem, const Eigen::VectorXd& x0,
                       const ScenarioRunEvents& events, RunRecord& record) {
  const auto clock = std::chrono::steady_clock::now();
  const double before = record.totalSeconds;  // what the record already holds (a refinement's earlier rounds)
  OuterSolverSettings settings;
  settings.options = scenario.solve.solverOptions;
  settings.problemHessian = scenario.solve.hessian != HessianOption::LimitedMemory;
  const auto optimisationClock = std::chrono::steady_clock::now();
  MotionSolveEvents solveEvents;
  solveEvents.onSolve = events.onSolve;
  solveEvents.onIteration = [&](int stage, const MotionProblem& current, const IterationReport& r) {
    record.history.push_back({stage, r.iteration, r.objective, r.violation, r.dualInfeasibility, r.elapsedSeconds,
                              r.stepSize, r.regularisation, r.barrier, r.timings, current.innerStatistics(), std::nullopt});
    if (r.iterate != nullptr && current.scenario().ball) record.history.back().missDistance = current.release(*r.iterate)->missDistance;
    record.optimisationSeconds = secondsSince(optimisationClock);
    record.totalSeconds = before + secondsSince(clock);
    bool go = !events.onIteration || events.onIteration(record, current, r);
    if (go && events.keepRunning) go = events.keepRunning();
    return go;
  };
  MotionSolveOutcome solved = solveMotion(scenario, problem, x0, settings, solveEvents);
  record.solver = std::move(solved.solver);
  record.stages = std::move(solved.stages);
  record.reason = solved.reason;
  record.optimisationSeconds = secondsSince(optimisationClock);

  record.status = record.solver.status;
  record.message = record.solver.message;
  record.x = record.solver.x.size() == x0.size() && record.solver.x.allFinite() ? record.solver.x : x0;
  if (record.solver.x.size() != x0.size()) record.reason = "Ipopt returned no iterate; the initial motion is written";
  if (!record.solver.evaluationError.empty() && record.reason.empty())
    record.reason = "evaluation failed: " + record.solver.evaluationError;
  if (record.status == OuterStatus::Interrupted)
    record.reason = "interrupted; the last iterate is written";
  else if (!record.solver.optimal() && record.reason.empty())
    record.reason = "Ipopt: " + record.solver.message;
  record.totalSeconds = before + secondsSince(clock);
}

Scenario refinedScenario(const Scenario& scenario, const Eigen::VectorXd& parameters, double duration) {
  // The fine grid of two instants an interval (every sample kept, a throw's release where the
  // coarser grid had it, no continuation), with the scenario's own torque-limit screening.
  Scenario refined = fineGridScenario(scenario, 2);
  refined.solve.torqueScreening = scenario.solve.torqueScreening;
  refined.solve.configurationOptimisation = false;
  refined.initialMotion = Scenario::InitialMotion{parameters, duration};
  return refined;
}

RefinedRun refineRun(const Scenario& scenario, MotionProblem& problem, RunRecord record, int rounds,
                     const VerificationSettings& settings, const ScenarioRunEvents& events) {
  RefinedRun run;
  std::vector<RefinementRound> done;
  const Scenario* current = &scenario;
  MotionProblem* currentProblem = &problem;
  for (int round = 0;; ++round) {
    RefinementRound r;
    r.round = round;
    r.samples = current->samples;
    r.status = record.status;
    r.iterations = 0;
    for (const StageOutcome& stage : record.stages) r.iterations += stage.iterations;
    r.seconds = record.totalSeconds;
    if (record.status == OuterStatus::Optimal) {
      const MotionVerification v = verifyMotion(*currentProblem, record.x, settings);
      r.verified = v.passed();
      for (const VerificationCheck& c : v.checks)
        if (!c.passed()) r.failed.push_back(c);
    }
    done.push_back(r);
    if (events.onRefinementRound) events.onRefinementRound(r);
    // Done: verified, not optimal (nothing to refine from), out of rounds, or stopped.
    if (r.verified || record.status != OuterStatus::Optimal || round == rounds) break;
    auto next = std::make_unique<Scenario>(refinedScenario(*current, currentProblem->motionParameters(record.x),
                                                           currentProblem->duration(record.x)));
    auto nextProblem = std::make_unique<MotionProblem>(*next);
    const Eigen::VectorXd x0 = nextProblem->pointWithWrenchesFrom(*currentProblem, record.x);
    RunRecord refined;
    // What the run found before the motion (postures, reaches, warnings) is the first round's.
    refined.postureChecks = record.postureChecks;
    refined.start = record.start, refined.end = record.end;
    refined.contactPostures = record.contactPostures;
    refined.warnings = record.warnings;
    refined.configurationSeconds = record.configurationSeconds;
    refined.totalSeconds = record.totalSeconds;
    solveScenarioFrom(*next, *nextProblem, x0, events, refined);
    record = std::move(refined);
    run.scenario = std::move(next);
    run.problem = std::move(nextProblem);
    current = run.scenario.get();
    currentProblem = run.problem.get();
  }
  run.record = std::move(record);
  run.record.refinement = std::move(done);
  return run;
}

}  // namespace mcopt
