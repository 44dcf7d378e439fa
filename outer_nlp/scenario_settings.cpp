// SPDX-License-Identifier: BSD-3-Clause
// How a scenario is solved, apart from what it asks (docs/reference/scenario-file.md): the
// Ipopt options of `solver:`, the inner problem's `inner:` settings, the Hessian options by
// name, and the continuation's stages.
#include <cstdlib>

#include "core/errors.hpp"
#include "core/yaml_fields.hpp"
#include "inner_qp/inner_solver.hpp"
#include "outer_nlp/formulation_registry.hpp"
#include "outer_nlp/scenario.hpp"
#include "outer_nlp/scenario_yaml.hpp"

namespace mcopt {

using yaml::where;

void readSolverOptions(const std::filesystem::path& file, const YAML::Node& node, Scenario& s) {
  if (!node.IsMap()) throw InputError(where(file, node, "solver") + "expected a mapping of Ipopt options");
  for (const auto& entry : node) {
    const std::string name = entry.first.as<std::string>();
    const std::string field = "solver." + name;
    if (!entry.second.IsScalar()) throw InputError(where(file, entry.second, field) + "expected a scalar value");
    SolverOption o;
    o.name = name;
    o.origin = where(file, entry.first, field);
    o.text = entry.second.as<std::string>();
    // YAML decides the type: 3000 is an integer, 1e-8 or 0.5 a number, anything else text.
    char* endPointer = nullptr;
    const long asLong = std::strtol(o.text.c_str(), &endPointer, 10);
    if (!o.text.empty() && *endPointer == '\0') {
      o.type = SolverOption::Type::Integer;
      o.integer = static_cast<int>(asLong);
    } else {
      const double asDouble = std::strtod(o.text.c_str(), &endPointer);
      if (!o.text.empty() && *endPointer == '\0') {
        o.type = SolverOption::Type::Number;
        o.number = asDouble;
      }
    }
    s.solve.solverOptions.push_back(o);
  }
}

InnerFeasibility readInnerFeasibility(const std::filesystem::path& file, const YAML::Node& node, const std::string& field) {
  const std::string name = yaml::text(file, node, field);
  if (name == "margin") return InnerFeasibility::Margin;
  if (name == "slack") return InnerFeasibility::Slack;
  throw InputError(where(file, node, field) + "expected slack or margin, got '" + name + "'");
}

void readInnerSettings(const std::filesystem::path& file, const YAML::Node& node, Scenario& s) {
  yaml::rejectUnknownKeys(file, node, "inner", {"solver", "contact_model", "pyramid_facets", "kkt_backend", "tolerance", "polish", "barrier", "feasibility"});
  if (node["solver"]) {
    const std::string name = yaml::text(file, node["solver"], "inner.solver");
    if (!isInnerSolverName(name))
      throw InputError(where(file, node["solver"], "inner.solver") + "unknown inner solver '" + name +
                       "' (expected " + innerSolverList() + ")");
    s.inner.solverName = name;
  }
  std::string modelName = s.inner.problem.model->name();
  if (node["contact_model"]) {
    modelName = yaml::text(file, node["contact_model"], "inner.contact_model");
    if (!isContactModelName(modelName))
      throw InputError(where(file, node["contact_model"], "inner.contact_model") + "unknown contact model '" +
                       modelName + "' (expected " + contactModelList() + ")");
  }
  ContactModelOptions options;
  if (node["pyramid_facets"]) {
    if (modelName != "pyramid")
      throw InputError(where(file, node["pyramid_facets"], "inner.pyramid_facets") +
                       "only the pyramid contact model has facets (the contact model is " + modelName + ")");
    options.pyramidFacets = yaml::integerAtLeast(file, node["pyramid_facets"], "inner.pyramid_facets", 3);
  }
  s.inner.problem.model = makeContactModel(modelName, options);
  if (s.inner.problem.model->wrenchSize() < 6)
    throw InputError(where(file, node["contact_model"], "inner.contact_model") + "the " + modelName +
                     " model holds a force alone, no moment: give it to a contact (contacts[k].model: " + modelName +
                     "), not to every contact — the reference contact carries moments");
  if (node["tolerance"]) s.inner.solver.tolerance = yaml::positive(file, node["tolerance"], "inner.tolerance");
  if (node["polish"]) s.inner.solver.polish = yaml::flag(file, node["polish"], "inner.polish");
  // Whether a solver reads it is checked once the continuation's stages are read (readScenario).
  if (node["barrier"]) s.inner.solver.barrier = yaml::positive(file, node["barrier"], "inner.barrier");
  if (node["feasibility"]) s.inner.feasibility = readInnerFeasibility(file, node["feasibility"], "inner.feasibility");
  if (node["kkt_backend"]) {
    try {
      s.sensitivity.backend = parseKktBackend(yaml::text(file, node["kkt_backend"], "inner.kkt_backend"));
    } catch (const InputError& e) {
      throw InputError(where(file, node["kkt_backend"], "inner.kkt_backend") + e.what());
    }
  }
}

namespace {
struct HessianName {
  HessianOption option;
  const char* name;
};
constexpr HessianName kHessianNames[] = {{HessianOption::LimitedMemory, "limited-memory"},
                                         {HessianOption::FiniteDifferences, "finite-differences"},
                                         {HessianOption::SampleDifferences, "sample-differences"},
                                         {HessianOption::ConvexSampleDifferences, "convex-sample-differences"},
                                         {HessianOption::GaussNewton, "gauss-newton"},
                                         {HessianOption::Exact, "exact"}};
}  // namespace

const char* toString(HessianOption hessian) {
  for (const HessianName& h : kHessianNames)
    if (h.option == hessian) return h.name;
  return "?";
}

const char* toString(ForceUnits units) { return units == ForceUnits::Weight ? "weight" : "newton"; }

ForceUnits parseForceUnits(const std::string& name) {
  for (const ForceUnits units : {ForceUnits::Newton, ForceUnits::Weight})
    if (name == toString(units)) return units;
  throw InputError("expected " + alternatives(forceUnitsNames()) + ", got '" + name + "'");
}

const std::vector<std::string>& forceUnitsNames() {
  static const std::vector<std::string> names = {toString(ForceUnits::Newton), toString(ForceUnits::Weight)};
  return names;
}

HessianOption parseHessianOption(const std::string& name) {
  for (const HessianName& h : kHessianNames)
    if (name == h.name) return h.option;
  throw InputError("expected " + alternatives(hessianOptionNames()) + ", got '" + name + "'");
}

const std::vector<std::string>& hessianOptionNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> all;
    for (const HessianName& h : kHessianNames) all.emplace_back(h.name);
    return all;
  }();
  return names;
}

std::string exactHessianRefusal(const Scenario& s) {
  if (!s.contacts.empty() && contactForceFormulation(s.contactForces).innerProblem)
    return "the " + s.contactForces + " formulation's inner optimum is not polynomial in the state; use hessian: "
           "sample-differences or gauss-newton";
  if (!s.contacts.empty())
    return "contact '" + s.contacts.front().surface.name + "' is held by construction, its loop's closing joints following the others "
           "(docs/theory/outer-problem.md, \"Closure by construction\"), and the stencils have no rule for that map; use "
           "hessian: sample-differences or gauss-newton";
  for (const Joint& joint : s.robot.joints)
    if (joint.type == JointType::Prismatic)
      return "prismatic joint '" + joint.name + "': its stencil assumes revolute joints";
  if (s.energyForm == EnergyForm::Epigraph && s.duration.free())
    return "the epigraph form with a free duration (its slack × duration term lies outside the Hessian's variables)";
  return {};
}

Scenario withStagesForItsFormulation(const Scenario& scenario) {
  Scenario kept = scenario;
  kept.solve.continuation.clear();
  for (const ContinuationStage& stage : scenario.solve.continuation)
    if (stage.runsWith(scenario.contactForces)) kept.solve.continuation.push_back(stage);
  return kept;
}

Scenario continuationStage(const Scenario& scenario, std::size_t k) {
  Scenario stage = scenario;
  stage.solve.continuation.clear();
  if (k < scenario.solve.continuation.size()) {
    stage.actuators.frictionSharpness = scenario.solve.continuation[k].frictionSharpness;
    stage.smoothing = scenario.solve.continuation[k].smoothing;
    stage.samples = scenario.solve.continuation[k].samples;
    stage.solve.hessian = scenario.solve.continuation[k].hessian;
    stage.energyForm = scenario.solve.continuation[k].energyForm;
    if (!scenario.solve.continuation[k].innerSolver.empty()) stage.inner.solverName = scenario.solve.continuation[k].innerSolver;
    if (scenario.solve.continuation[k].feasibility) stage.inner.feasibility = *scenario.solve.continuation[k].feasibility;
    if (!scenario.solve.continuation[k].contactForces.empty()) stage.contactForces = scenario.solve.continuation[k].contactForces;
  }
  return stage;
}

bool posesScenarioProblem(const Scenario& stage, const Scenario& scenario) {
  return stage.actuators.frictionSharpness == scenario.actuators.frictionSharpness && stage.smoothing == scenario.smoothing &&
         stage.samples == scenario.samples && stage.energyForm == scenario.energyForm &&
         stage.contactForces == scenario.contactForces &&
         (stage.contacts.empty() || !contactForceFormulation(stage.contactForces).innerProblem ||
          (stage.inner.solverName == scenario.inner.solverName && stage.inner.feasibility == scenario.inner.feasibility));
}

namespace {
/// Which contact model of the scenario has a second-order cone (empty: none).
std::string secondOrderConeModel(const Scenario& s) {
  if (s.inner.problem.model->hasSecondOrderCone())
    return "the " + s.inner.problem.model->name() + " model (inner.contact_model) has second-order friction cones";
  for (const auto& [contact, model] : s.inner.problem.byContact)
    if (model->hasSecondOrderCone())
      return "contact '" + contact + "' has the " + model->name() + " model, with a second-order friction cone";
  return {};
}
}  // namespace

std::string barrierModelRefusal(const Scenario& s) {
  if (s.inner.solverName != "barrier") return {};
  const std::string cone = secondOrderConeModel(s);
  return cone.empty() ? cone : "the barrier inner solver smooths linear contact models only (pyramid, wrench-cone): " + cone;
}

std::string marginModelRefusal(const Scenario& s) {
  if (s.inner.feasibility != InnerFeasibility::Margin) return {};
  const std::string cone = secondOrderConeModel(s);
  return cone.empty() ? cone : "the margin row shifts the rows of linear contact models only (pyramid, wrench-cone): " + cone;
}

}  // namespace mcopt
