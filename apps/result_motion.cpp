// SPDX-License-Identifier: BSD-3-Clause
#include "apps/result_motion.hpp"

#include "apps/json_io.hpp"
#include "core/errors.hpp"
#include "outer_nlp/scenario_run.hpp"
#include "outer_nlp/formulation_registry.hpp"

namespace mcopt::cli {

namespace {

using json_io::Json;

std::vector<std::string> names(const std::filesystem::path& file, const Json& node, const std::string& field) {
  if (!node.is_array()) throw InputError(file.string() + ": " + field + ": expected a list of names");
  std::vector<std::string> out;
  for (std::size_t i = 0; i < node.size(); ++i) {
    if (!node[i].is_string()) throw InputError(file.string() + ": " + field + "[" + std::to_string(i) + "]: expected a name");
    out.push_back(node[i].get<std::string>());
  }
  return out;
}

std::string list(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& n : names) text += (text.empty() ? "" : ", ") + n;
  return text.empty() ? "none" : text;
}

}  // namespace

ResultMotion readResultMotion(const std::filesystem::path& folderOrFile, bool current) {
  ResultMotion r;
  r.file = std::filesystem::is_directory(folderOrFile) ? folderOrFile / "result.json" : folderOrFile;
  if (!std::filesystem::exists(r.file))
    throw InputError(r.file.string() + ": no such file (not a result folder of mcopt run?)");
  const Json result = json_io::readFile(r.file);
  const std::string file = r.file.string();
  if (!result.is_object()) throw InputError(file + ": expected a result.json object");
  if (result.contains("format")) {
    if (!result["format"].is_number_integer()) throw InputError(file + ": format: expected an integer");
    r.format = result["format"].get<int>();
    if (r.format > kResultFormat)
      throw InputError(file + ": format: " + std::to_string(r.format) + " is newer than this mcopt reads (" +
                       std::to_string(kResultFormat) + ")");
  }
  if (current && r.format < kResultFormat)
    throw InputError(file + ": format: a result of an older format (" + std::to_string(r.format) + ", this mcopt writes " +
                     std::to_string(kResultFormat) + ": without its contact-force variables); run its scenario again");
  for (const char* field : {"parameters", "duration"})
    if (!result.contains(field)) throw InputError(file + ": " + field + ": missing (not a result of mcopt run?)");
  const Json& parameters = result["parameters"];
  if (!parameters.is_object()) throw InputError(file + ": parameters: expected an object of joint names");
  for (const auto& [joint, values] : parameters.items()) {
    const Eigen::VectorXd v = json_io::numbers(r.file, values, "parameters." + joint);
    r.parameters[joint] = std::vector<double>(v.data(), v.data() + v.size());
  }
  if (!result["duration"].is_number()) throw InputError(file + ": duration: expected a number");
  r.duration = result["duration"].get<double>();
  if (!current) return r;

  for (const char* field : {"scenario", "contact_forces", "joint_names", "contacts", "contact_force_variables"})
    if (!result.contains(field)) throw InputError(file + ": " + field + ": missing");
  if (!result["scenario"].is_string()) throw InputError(file + ": scenario: expected a file name");
  r.scenario = result["scenario"].get<std::string>();
  if (!result["contact_forces"].is_string()) throw InputError(file + ": contact_forces: expected a formulation name");
  r.contactForces = result["contact_forces"].get<std::string>();
  r.jointNames = names(r.file, result["joint_names"], "joint_names");
  const Json& contacts = result["contacts"];
  if (!contacts.is_array()) throw InputError(file + ": contacts: expected a list");
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    if (!contacts[c].is_object() || !contacts[c].contains("name") || !contacts[c]["name"].is_string())
      throw InputError(file + ": contacts[" + std::to_string(c) + "].name: expected a name");
    r.contactNames.push_back(contacts[c]["name"].get<std::string>());
  }
  if (result.contains("inner")) {
    const Json& inner = result["inner"];
    if (!inner.is_object() || !inner.contains("solver") || !inner["solver"].is_string())
      throw InputError(file + ": inner.solver: expected an inner solver name");
    r.innerSolver = inner["solver"].get<std::string>();
  }
  r.forceVariables = json_io::numbers(r.file, result["contact_force_variables"], "contact_force_variables");
  // Absent: the scenario's (a result written before refinement existed).
  if (result.contains("samples")) {
    if (!result["samples"].is_number_integer() || result["samples"].get<int>() < 2)
      throw InputError(file + ": samples: expected an integer ≥ 2 (the grid the motion was optimised on)");
    r.samples = result["samples"].get<int>();
  }
  return r;
}

Scenario scenarioOfResult(const ResultMotion& result, const std::filesystem::path& scenarioFile) {
  const std::filesystem::path file = scenarioFile.empty() ? result.scenario : scenarioFile;
  if (!std::filesystem::exists(file))
    throw InputError(result.file.string() + ": scenario: " + file.string() + ": no such file");
  std::string forces;
  try {
    forces = contactForceFormulation(result.contactForces).name;
  } catch (const InputError& e) {
    throw InputError(result.file.string() + ": contact_forces: " + e.what());
  }
  Scenario scenario = loadScenario(file, forces);
  ScenarioOverrides overrides;
  overrides.contactForces = forces;
  if (!result.innerSolver.empty()) overrides.innerSolver = result.innerSolver;
  applyOverrides(scenario, overrides);
  // The same robot and the same contacts, in the same order: the motion means nothing otherwise.
  const std::vector<std::string> joints = scenario.robot.jointNames();
  if (joints != result.jointNames)
    throw InputError(result.file.string() + ": joint_names: the result's joints (" + list(result.jointNames) +
                     ") are not those of " + file.string() + " (" + list(joints) + ")");
  std::vector<std::string> contacts{scenario.support.name};
  for (const EnvironmentContact& c : scenario.contacts) contacts.push_back(c.surface.name);
  if (contacts != result.contactNames)
    throw InputError(result.file.string() + ": contacts: the result's contacts (" + list(result.contactNames) +
                     ") are not those of " + file.string() + " (" + list(contacts) + ")");
  startFromMotion(scenario, result.parameters, result.duration, result.file.string());
  // The grid it was optimised on: a refined run's is finer than its file's (scenario_run.hpp refineRun).
  if (result.samples != 0 && result.samples != scenario.samples) {
    const int intervals = scenario.samples - 1, refined = result.samples - 1;
    if (refined % intervals != 0 || ((refined / intervals) & (refined / intervals - 1)) != 0)
      throw InputError(result.file.string() + ": samples: " + std::to_string(result.samples) + " is not a refinement of " +
                       file.string() + "'s " + std::to_string(scenario.samples) + " samples");
    const Eigen::VectorXd parameters = scenario.initialMotion->parameters;
    scenario = refinedScenario(scenario, parameters, result.duration);
    while (scenario.samples < result.samples) scenario = refinedScenario(scenario, parameters, result.duration);
  }
  return scenario;
}

Eigen::VectorXd pointOfResult(MotionProblem& problem, const ResultMotion& result) {
  const Scenario& scenario = problem.scenario();
  if (result.forceVariables.size() != problem.forceVariableCount())
    throw InputError(result.file.string() + ": contact_force_variables: " + std::to_string(result.forceVariables.size()) +
                     " values, the scenario's " + scenario.contactForces + " formulation has " +
                     std::to_string(problem.forceVariableCount()));
  return problem.pointFromMotion(scenario.initialMotion->parameters, scenario.initialMotion->duration, result.forceVariables);
}

}  // namespace mcopt::cli
