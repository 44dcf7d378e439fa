// SPDX-License-Identifier: BSD-3-Clause
#include "apps/run_output.hpp"

#include "apps/result_motion.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "apps/json_io.hpp"
#include "core/atomic_file.hpp"
#include "inner_qp/multi_contact_dynamics.hpp"

namespace mcopt::cli {

namespace {

// Insertion order kept: status, energy and max_violation lead result.json.
using Json = nlohmann::ordered_json;
Json toJson(const Eigen::Ref<const Eigen::VectorXd>& v) { return Json(json_io::toJson(v)); }
Json matrixToJson(const Eigen::Ref<const Eigen::MatrixXd>& m) { return Json(json_io::matrixToJson(m)); }

Json posture(const PostureOutcome& p) {
  Json j;
  j["optimised"] = p.optimised;
  if (!p.optimised) return j;
  j["status"] = toString(p.status);
  j["static_power_before_W"] = p.staticPowerBefore;
  j["static_power_after_W"] = p.staticPowerAfter;
  j["iterations"] = p.iterations;
  j["seconds"] = p.seconds;
  return j;
}

/// A JSON number, or null for NaN (a centre of pressure without a load).
Json numberOrNull(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

}  // namespace

std::string gravityWarning(const EnergyBalance& balance, double energy) {
  if (!(balance.gravityReleased() > energy)) return "";
  std::ostringstream what;
  what << std::setprecision(3) << "the motion draws " << balance.gravityReleased() << " J from gravity, more than its criterion's "
       << energy << " J: its start is higher than its end. Energies compare between motions that end where they start "
       << "(end: {same_as: start}; docs/reference/scenario-file.md, \"Energy balance\")";
  return what.str();
}

nlohmann::ordered_json energyBalanceJson(const EnergyBalance& b) {
  Json j;
  j["instants"] = b.instants;
  j["instants_per_interval"] = b.instantsPerInterval;
  j["wrenches_between_samples"] = b.wrenchesBetweenSamples;
  if (b.redistribution.applies) {
    const WrenchRedistribution& r = b.redistribution;
    j["wrenches_redistributed"] = {{"instants", r.instants},
                                   {"unreachable", r.unreachable},
                                   {"largest_change", r.largestChange},
                                   {"time", std::isnan(r.time) ? Json(nullptr) : Json(r.time)},
                                   {"contact", r.contact}};
  }
  j["joint_work_J"] = b.jointWork;
  j["joint_power_flow_J"] = b.jointPowerFlow;
  j["contact_work_J"] = b.contactWork;
  j["potential_energy_change_J"] = b.potentialChange;
  j["kinetic_energy_change_J"] = b.kineticChange;
  j["ball_energy_J"] = b.ballEnergy;
  j["mechanical_identity_residual_J"] = b.mechanicalResidual();
  j["rotor_kinetic_energy_change_J"] = b.rotorKineticChange;
  j["joule_losses_J"] = b.jouleLosses;
  j["friction_dissipation_J"] = b.frictionDissipation;
  j["electrical_energy_net_J"] = b.electricalEnergy;
  j["electrical_identity_residual_J"] = b.electricalResidual();
  j["energy_positive_J"] = b.positiveEnergy;
  j["braking_J"] = b.braking;
  j["gravity_released_J"] = b.gravityReleased();
  return j;
}

RunFiles makeRunFiles(MotionProblem& problem, const RunRecord& record, bool withEnergyBalance) {
  const Scenario& scenario = problem.scenario();
  const RobotModel& robot = scenario.robot;
  const Eigen::VectorXd parameters = problem.reportedMotionParameters(record.x);  // closing joints: a fit of their motion
  const double T = problem.duration(record.x);
  const int n = robot.jointCount();
  const SampledPhysics r = problem.sampledPhysics(record.x);
  const MotionProblem::Violations violations = problem.violations(record.x);
  const int N = static_cast<int>(r.time.size());
  const bool fine = r.fineTime.size() > 0;

  RunFiles files;
  Json& result = files.result;
  result["format"] = kResultFormat;
  result["status"] = toString(record.status);
  result["energy"] = r.energy;
  result["max_violation"] = violations.overall;
  result["message"] = record.message;
  if (!record.reason.empty()) result["reason"] = record.reason;
  result["scenario"] = std::filesystem::absolute(scenario.file).lexically_normal().string();
  result["objective_value"] = record.solver.objective;
  result["energy_form"] = scenario.energyForm == EnergyForm::Epigraph ? "epigraph" : "smooth_max";
  result["energy_fine"] = numberOrNull(r.fineEnergy);
  result["contact_forces"] = scenario.contactForces;
  result["force_units"] = toString(scenario.forceUnits);
  result["joint_names"] = robot.jointNames();
  result["reference_body"] = scenario.referenceBody;
  // What a result's motion is of, so that it can be drawn again (mcopt replay) from anywhere.
  Json referencePose;
  referencePose["position"] = toJson(scenario.referencePose.translation);
  referencePose["quaternion_xyzw"] = toJson(quaternionXyzwFromRotation(scenario.referencePose.rotation));
  result["reference_pose"] = referencePose;
  result["gravity"] = toJson(scenario.gravity);
  result["robot_files"] = {{"urdf", std::filesystem::absolute(robot.source).lexically_normal().string()},
                           {"contact_surfaces", std::filesystem::absolute(scenario.contactSurfacesFile).lexically_normal().string()}};
  result["duration"] = T;
  Json params = Json::object();
  const int m = problem.parametrization().parametersPerJoint();
  for (int j = 0; j < n; ++j) params[robot.joints[static_cast<std::size_t>(j)].name] = toJson(parameters.segment(j * m, m));
  result["parameters"] = params;
  // The splines and variables formulations' contact-force variables z (formulation.md §9), in
  // the problem's order: with the parameters, the whole motion (mcopt verify reads them).
  result["contact_force_variables"] = toJson(Eigen::VectorXd(record.x.segment(problem.forceVariableStart(), problem.forceVariableCount())));
  // The limits the problem holds the motion to, beside the motion (plots, checks by others).
  Json lower = Json::array(), upper = Json::array(), velocity = Json::array(), torque = Json::array();
  for (int j = 0; j < n; ++j) {
    const auto u = static_cast<std::size_t>(j);
    lower.push_back(numberOrNull(robot.joints[u].limits.lower));
    upper.push_back(numberOrNull(robot.joints[u].limits.upper));
    velocity.push_back(numberOrNull(scenario.actuators.joints[u].velocityLimit));
    torque.push_back(numberOrNull(scenario.actuators.joints[u].torqueLimit));
  }
  result["joint_limits"] = {{"position_lower", lower}, {"position_upper", upper}, {"velocity", velocity}, {"torque", torque}};
  result["time"] = toJson(r.time);
  result["q"] = matrixToJson(r.q.transpose());
  result["v"] = matrixToJson(r.v.transpose());
  result["a"] = matrixToJson(r.a.transpose());
  result["torques"] = matrixToJson(r.tau.transpose());
  result["reference_wrench"] = matrixToJson(r.referenceWrench.transpose());
  // Per contact: wrench in its frame, centre of pressure, friction-cone margin, closure drift.
  Json contacts = Json::array();
  for (std::size_t c = 0; c < r.contactNames.size(); ++c) {
    Json contact;
    contact["name"] = r.contactNames[c];
    contact["reference"] = c == 0;
    const ContactSurface& surface = c == 0 ? scenario.support : scenario.contacts[c - 1].surface;
    contact["rectangle_m"] = {{"x", {surface.xMin, surface.xMax}}, {"y", {surface.yMin, surface.yMax}}};
    contact["friction"] = surface.friction;
    contact["contact_model"] = contactModelOf(contactSpec(surface), scenario.inner.problem).name();
    Json active = Json::array(), wrench = Json::array(), copJson = Json::array();
    for (int s = 0; s < N; ++s) {
      const bool on = r.active[c][static_cast<std::size_t>(s)];
      active.push_back(on);
      wrench.push_back(on ? toJson(r.wrenches[c].col(s)) : Json(nullptr));
      copJson.push_back(on ? Json::array({numberOrNull(r.centerOfPressure[c](0, s)), numberOrNull(r.centerOfPressure[c](1, s))})
                           : Json(nullptr));
    }
    contact["active"] = active;
    contact["wrench"] = wrench;
    contact["center_of_pressure"] = copJson;
    contact["friction_margin_N"] = toJson(r.frictionMargin[c]);
    if (c > 0) {
      const EnvironmentContact& e = scenario.contacts[c - 1];
      contact["window"] = {e.start, e.end};
      contact["world_pose"] = {{"position", toJson(e.worldPose.translation)},
                               {"quaternion_xyzw", toJson(quaternionXyzwFromRotation(e.worldPose.rotation))}};
      contact["closure_drift_m"] = r.closureDrift[c - 1];
      contact["closure_drift_rad"] = r.closureRotationDrift[c - 1];
      contact["closure_speed_m_s"] = r.closureSpeed[c - 1];
      contact["closure_angular_speed_rad_s"] = r.closureAngularSpeed[c - 1];
      // Held over the whole motion: by construction, its loop closed by six joints (closed_chains.hpp).
      Json closing = Json::array();
      if (const ClosedChains* chains = problem.closedChains())
        for (const int j : chains->closingJoints())
          if (chains->contacts()[static_cast<std::size_t>(chains->contactOf(j))].name == e.surface.name)
            closing.push_back(scenario.robot.joints[static_cast<std::size_t>(j)].name);
      contact["closing_joints"] = closing;
    }
    contacts.push_back(contact);
  }
  result["contacts"] = contacts;
  if (!r.innerStatus.empty())
    result["inner"] = {{"solver", scenario.inner.solverName},
                       {"status", r.innerStatus},
                       {"infeasible_samples", r.infeasibleSamples},
                       {"failed_samples", r.failedSamples}};
  if (r.release) {
    // The ball at its release and its flight to the target's height (formulation.md §10).
    const ReleaseState& b = *r.release;
    result["release"] = {{"time", b.time},
                         {"body", scenario.ball->body},
                         {"ball_mass_kg", scenario.ball->mass},
                         {"point", toJson(scenario.ball->point)},
                         {"position", toJson(b.position)},
                         {"velocity", toJson(b.velocity)},
                         {"speed_m_s", b.speed},
                         {"elevation_deg", b.elevationDegrees()},
                         {"flight_time", b.flightTime},
                         {"apex_above_target_m", b.apexAboveTarget},
                         {"target", toJson(b.target)},
                         {"target_half_widths_m", toJson(b.targetHalfWidths)},
                         {"landing_point", toJson(b.landing)},
                         {"miss_distance_m", b.missDistance},
                         {"miss_outside_target_box_m", b.missOutsideBox}};
  }
  std::vector<std::string> warnings = record.warnings;
  if (withEnergyBalance) {
    files.balance = energyBalance(problem, record.x);
    result["energy_balance"] = energyBalanceJson(*files.balance);
    if (const std::string w = gravityWarning(*files.balance, r.energy); !w.empty()) warnings.push_back(w);
  }
  result["warnings"] = warnings;
  files.warnings = warnings;
  result["power"] = matrixToJson(r.power.transpose());
  if (fine)
    result["power_fine"] = {{"time", toJson(r.fineTime)}, {"power", matrixToJson(r.finePower.transpose())}};
  else
    result["power_fine"] = nullptr;
  Json byKind = Json::object();
  byKind["position_limit"] = violations.positionLimit;
  for (const auto& [kind, worst] : violations.byKind) byKind[kind] = worst;
  result["violation_by_kind"] = byKind;
  if (violations.worstRow >= 0) result["worst_constraint"] = problem.rowName(violations.worstRow);
  result["solver"] = {{"name", "ipopt"},
                      {"status", toString(record.solver.status)},
                      {"message", record.solver.message},
                      {"iterations", record.solver.iterations},
                      {"objective_evaluations", record.solver.objectiveEvaluations},
                      {"gradient_evaluations", record.solver.gradientEvaluations},
                      {"constraint_evaluations", record.solver.constraintEvaluations},
                      {"jacobian_evaluations", record.solver.jacobianEvaluations},
                      {"variables", problem.variableCount()},
                      {"constraints", problem.constraintCount()},
                      {"jacobian_nonzeros", problem.jacobianNonZeros()}};
  if (!record.solver.evaluationError.empty()) result["solver"]["evaluation_error"] = record.solver.evaluationError;
  result["solver"]["hessian"] = toString(scenario.solve.hessian);
  // Where the time went: per iteration (since the previous one) and for the whole solve.
  auto split = [](const SolveTimings& now, const SolveTimings& before) {
    return Json{{"functions", now.functions - before.functions},
                {"gradient_and_jacobian", now.derivatives - before.derivatives},
                {"hessian", now.hessian - before.hessian},
                {"ipopt", now.ipopt() - before.ipopt()}};
  };
  Json history = Json::array();
  SolveTimings previous;
  for (const IterationRecord& h : record.history) {
    if (h.iteration == 0) previous = SolveTimings{};  // each stage's solve counts from zero
    Json line = {{"stage", h.stage},
                 {"iteration", h.iteration},
                 {"objective", h.objective},
                 {"violation", h.violation},
                 {"dual_infeasibility", h.dualInfeasibility},
                 {"step_size", h.stepSize},
                 {"regularisation", h.regularisation},
                 {"barrier", h.barrier},
                 {"elapsed_seconds", h.elapsedSeconds},
                 {"seconds", split(h.timings, previous)}};
    previous = h.timings;
    if (problem.scenario().ball) line["miss_m"] = h.missDistance ? Json(*h.missDistance) : Json(nullptr);
    if (problem.bilevel())
      line["inner"] = {{"optimal", h.inner.optimal},
                       {"infeasible", h.inner.infeasible},
                       {"failed", h.inner.failed},
                       {"polished", h.inner.polished},
                       {"mean_iterations", h.inner.meanIterations},
                       {"solve_seconds", h.inner.solveSeconds}};
    history.push_back(line);
  }
  result["history"] = history;
  Json stages = Json::array();
  int totalIterations = 0;
  SolveTimings all;  // over every stage
  for (const StageOutcome& stage : record.stages) {
    all += stage.timings;
    stages.push_back({{"friction_sharpness", stage.frictionSharpness},
                      {"energy_form", stage.energyForm == EnergyForm::Epigraph ? "epigraph" : "smooth_max"},
                      {"smoothing", stage.energyForm == EnergyForm::Epigraph ? Json(nullptr) : Json(stage.smoothing)},
                      {"samples", stage.samples},
                      {"hessian", toString(stage.hessian)},
                      {"contact_forces", stage.contactForces.empty() ? Json(nullptr) : Json(stage.contactForces)},
                      {"inner_solver", stage.innerSolver.empty() ? Json(nullptr) : Json(stage.innerSolver)},
                      {"feasibility", stage.feasibility.empty() ? Json(nullptr) : Json(stage.feasibility)},
                      {"status", toString(stage.status)},
                      {"iterations", stage.iterations},
                      {"seconds", stage.seconds},
                      {"objective", stage.objective},
                      {"screening_rounds", stage.rounds},
                      {"torque_rows_checked_afterwards", stage.omittedTorqueRows},
                      {"closing_rows_checked_afterwards", stage.omittedClosingRows},
                      {"restarted_from_stage", stage.restartedFrom < 0 ? Json(nullptr) : Json(stage.restartedFrom + 1)}});
    totalIterations += stage.iterations;
  }
  result["continuation"] = stages;
  // Refinement (docs/reference/verify.md, "Refine"): each round's grid, outcome and what verify
  // found of its motion; the motion written is the last round's.
  if (!record.refinement.empty()) {
    Json rounds = Json::array();
    for (const RefinementRound& round : record.refinement) {
      Json failed = Json::array();
      for (const VerificationCheck& c : round.failed)
        failed.push_back({{"kind", c.kind}, {"worst", numberOrNull(c.worst)}, {"tolerance", c.tolerance}, {"where", c.where},
                          {"time", numberOrNull(c.time)}, {"failing_times", c.failingTimes}});
      rounds.push_back({{"round", round.round}, {"samples", round.samples}, {"status", toString(round.status)}, {"iterations", round.iterations},
                        {"seconds", round.seconds}, {"verified", round.verified}, {"failed_checks", failed}});
    }
    result["refinement"] = rounds;
  }
  result["samples"] = scenario.samples;
  result["solver"]["iterations_all_stages"] = totalIterations;
  if (!record.stages.empty()) {
    result["solver"]["screening_rounds"] = record.stages.back().rounds;
    result["solver"]["torque_rows_checked_afterwards"] = record.stages.back().omittedTorqueRows;
    result["solver"]["closing_rows_checked_afterwards"] = record.stages.back().omittedClosingRows;
  }
  Json fixed = Json::array();
  for (const PostureCheck& c : record.postureChecks) {
    Json torques = Json::array();
    for (const PostureCheck::TorqueExcess& t : c.torques)
      torques.push_back({{"joint", t.joint}, {"torque_Nm", t.torque}, {"limit_Nm", t.limit}});
    fixed.push_back({{"which", c.which},
                     {"time", c.time},
                     {"holdable", c.holdable()},
                     {"contacts", c.contacts},
                     {"center_of_mass", toJson(c.centerOfMass)},
                     {"support_margin_m", c.supportMargin},
                     {"torques_beyond_limits", torques},
                     {"inner_status", c.innerStatus.empty() ? Json(nullptr) : Json(c.innerStatus)}});
  }
  result["fixed_postures"] = fixed;
  Json reaches = Json::array();
  for (const RunRecord::ContactPosture& p : record.contactPostures) {
    Json entry = posture(p.outcome);
    entry["contact"] = p.contact;
    entry["time"] = p.time;
    entry["distance_rad"] = p.distance;
    reaches.push_back(entry);
  }
  result["configuration_optimisation"] = {{"start", posture(record.start)},
                                          {"end", scenario.periodic ? Json{{"same_as", "start"}} : posture(record.end)},
                                          {"contacts", reaches}};
  result["timings"] = {{"configuration_seconds", record.configurationSeconds},
                       {"optimisation_seconds", record.optimisationSeconds},
                       {"total_seconds", record.totalSeconds},
                       {"optimisation_split", split(all, SolveTimings{})}};

  // The states as a `mcopt dynamics` input: re-evaluating them reproduces `torques`.
  Json& states = files.states;
  states["joint_names"] = robot.jointNames();
  states["gravity"] = toJson(scenario.gravity);
  const RigidTransform& pose = problem.model().referencePose();
  states["reference_pose"] = {{"position", toJson(pose.translation)},
                              {"quaternion_xyzw", toJson(quaternionXyzwFromRotation(pose.rotation))}};
  states["states"] = Json::array();
  for (int s = 0; s < N; ++s)
    states["states"].push_back({{"q", toJson(r.q.col(s))}, {"v", toJson(r.v.col(s))}, {"a", toJson(r.a.col(s))}});

  // The contact wrenches as a `mcopt dynamics --contacts` input: with states.json it
  // reproduces `torques` (Γ = Γ0 − J1 F).
  Json& wrenchFile = files.contactWrenches;
  wrenchFile["contact_surfaces"] = std::filesystem::absolute(scenario.contactSurfacesFile).lexically_normal().string();
  wrenchFile["contacts"] = Json::array();
  for (std::size_t c = 0; c < r.contactNames.size(); ++c) {
    Json list = Json::array();
    for (int s = 0; s < N; ++s)
      list.push_back(r.active[c][static_cast<std::size_t>(s)] ? toJson(r.wrenches[c].col(s)) : Json(nullptr));
    wrenchFile["contacts"].push_back({{"surface", r.contactNames[c]}, {"wrenches", list}});
  }

  std::ostringstream csv;
  csv << std::setprecision(12) << "time";
  for (const char* kind : {"q", "v", "a", "tau", "power"})
    for (const Joint& joint : robot.joints) csv << "," << kind << ":" << joint.name;
  for (const std::string& contact : r.contactNames) {
    for (const char* c : {"fx", "fy", "fz", "mx", "my", "mz"}) csv << "," << contact << ":" << c;
    csv << "," << contact << ":cop_x," << contact << ":cop_y";
  }
  csv << "\n";
  for (int s = 0; s < N; ++s) {
    csv << r.time[s];
    for (const Eigen::MatrixXd* mat : {&r.q, &r.v, &r.a, &r.tau, &r.power})
      for (int j = 0; j < n; ++j) csv << "," << (*mat)(j, s);
    for (std::size_t c = 0; c < r.contactNames.size(); ++c) {
      for (int k = 0; k < 6; ++k) csv << "," << r.wrenches[c](k, s);
      csv << "," << r.centerOfPressure[c](0, s) << "," << r.centerOfPressure[c](1, s);
    }
    csv << "\n";
  }
  std::ostringstream fineCsv;
  fineCsv << std::setprecision(12) << "time";
  for (const Joint& joint : robot.joints) fineCsv << ",power:" << joint.name;
  fineCsv << "\n";
  for (Eigen::Index s = 0; s < r.fineTime.size(); ++s) {
    fineCsv << r.fineTime[s];
    for (int j = 0; j < n; ++j) fineCsv << "," << r.finePower(j, s);
    fineCsv << "\n";
  }

  files.trajectoryCsv = csv.str();
  files.powerFineCsv = fineCsv.str();
  files.energy = r.energy;
  files.maxViolation = violations.overall;
  files.release = r.release;
  return files;
}

void writeRunFiles(const std::filesystem::path& directory, const RunFiles& files) {
  std::filesystem::create_directories(directory);
  writeFileAtomically(directory / "trajectory.csv", files.trajectoryCsv);
  writeFileAtomically(directory / "power_fine.csv", files.powerFineCsv);
  writeFileAtomically(directory / "states.json", files.states.dump(1) + "\n");
  writeFileAtomically(directory / "contact_wrenches.json", files.contactWrenches.dump(1) + "\n");
  // result.json last: once it names this run, the other files are this run's too.
  writeFileAtomically(directory / "result.json", files.result.dump(1) + "\n");
}

void writeCheckpointFile(const std::filesystem::path& directory, const RunFiles& files) {
  std::filesystem::create_directories(directory);
  for (const char* side : {"trajectory.csv", "power_fine.csv", "states.json", "contact_wrenches.json"})
    std::filesystem::remove(directory / side);
  writeFileAtomically(directory / "result.json", files.result.dump(1) + "\n");
}

RunFiles writeRunOutput(const std::filesystem::path& directory, MotionProblem& problem, const RunRecord& record) {
  RunFiles files = makeRunFiles(problem, record);
  writeRunFiles(directory, files);
  return files;
}

}  // namespace mcopt::cli
