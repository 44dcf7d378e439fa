// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/scenario.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "core/errors.hpp"
#include "core/path_status.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"
#include "core/spatial.hpp"
#include "inner_qp/inner_solver.hpp"
#include "outer_nlp/formulation_registry.hpp"
#include "core/yaml_fields.hpp"
#include "outer_nlp/scenario_yaml.hpp"

namespace mcopt {

namespace {

using yaml::where;
constexpr double kInf = std::numeric_limits<double>::infinity();

std::filesystem::path sideFile(const std::filesystem::path& file, const YAML::Node& root, const char* key) {
  const YAML::Node node = yaml::required(file, root, key, "");
  // Paths are relative to the scenario file, never to the working directory.
  const auto path = file.parent_path() / yaml::text(file, node, key);
  if (!pathExists(path)) throw InputError(where(file, node, key) + "file not found: " + path.string());
  return path;
}

Eigen::VectorXd readPosture(const std::filesystem::path& file, const YAML::Node& node, const std::string& field,
                            const RobotModel& robot, const std::map<std::string, Eigen::VectorXd>& postures) {
  yaml::rejectUnknownKeys(file, node, field, {"posture", "offsets", "fixed"});
  return yaml::postureWithOffsets(file, node, field, robot, postures);
}

/// A task entry of the `tasks` list as its kind's reader sees it (task.hpp).
class YamlTaskFields final : public TaskFields {
 public:
  YamlTaskFields(const std::filesystem::path& file, const YAML::Node& node, const std::string& field,
                 const RobotModel& robot, bool window)
      : file_(file), node_(node), field_(field), robot_(robot), window_(window) {}
  bool has(const std::string& key) const override { return static_cast<bool>(node_[key]); }
  double number(const std::string& key) const override { return yaml::number(file_, at(key), name(key)); }
  std::vector<double> numbers(const std::string& key, int count) const override {
    return yaml::numbers(file_, at(key), name(key), static_cast<std::size_t>(count));
  }
  std::vector<double> bounds(const std::string& key, int count, double freeValue) const override {
    const YAML::Node node = at(key);
    if (!node.IsSequence() || node.size() != static_cast<std::size_t>(count))
      throw InputError(where(file_, node, name(key)) + "expected a list of " + std::to_string(count) +
                       " numbers (null for a free component)");
    std::vector<double> v(static_cast<std::size_t>(count));
    for (std::size_t i = 0; i < v.size(); ++i)
      v[i] = node[i].IsNull() ? freeValue : yaml::number(file_, node[i], name(key) + "[" + std::to_string(i) + "]");
    return v;
  }
  int body(const std::string& key) const override {
    const YAML::Node node = at(key);
    const std::string body = yaml::text(file_, node, name(key));
    const int frame = robot_.findFrame(body);
    if (frame < 0)
      throw InputError(where(file_, node, name(key)) + "unknown body '" + body + "' " + robot_.unknownFrameHint(body));
    return frame;
  }
  [[noreturn]] void fail(const std::string& key, const std::string& message) const override {
    const YAML::Node node = node_[key];
    throw InputError(where(file_, node ? node : node_, name(key)) + message);
  }
  bool window() const override { return window_; }

 private:
  std::string name(const std::string& key) const { return field_ + "." + key; }
  YAML::Node at(const std::string& key) const {
    if (!node_[key]) fail(key, "missing required field");
    return node_[key];
  }
  const std::filesystem::path& file_;
  const YAML::Node& node_;
  const std::string& field_;
  const RobotModel& robot_;
  bool window_;
};

/// A task of the `tasks` list (not a throw): its name, kind and instant or window here, the
/// rest from its kind's reader (task.hpp's registry).
TaskSpec readTask(const std::filesystem::path& file, const YAML::Node& node, const std::string& field,
                  const RobotModel& robot, double duration) {
  TaskSpec t;
  t.origin = where(file, node, field);
  t.origin.resize(t.origin.size() - 2);  // without the trailing ": "
  const YAML::Node kindNode = yaml::required(file, node, "kind", field);
  const std::string kind = yaml::text(file, kindNode, field + ".kind");
  const TaskKindEntry* entry = findTaskKind(kind);
  if (!entry)
    throw InputError(where(file, kindNode, field + ".kind") + "unknown task kind '" + kind + "' (expected " +
                     taskKindList() + ")");
  // A field another kind takes is named as such; any other is unknown.
  std::vector<std::string> keys{"name", "kind", "time", "window"}, everyKey = keys;
  keys.insert(keys.end(), entry->keys.begin(), entry->keys.end());
  for (const TaskKindEntry& e : taskKinds())
    for (const std::string& key : e.keys)
      if (std::find(everyKey.begin(), everyKey.end(), key) == everyKey.end()) everyKey.push_back(key);
  yaml::rejectUnknownKeys(file, node, field, everyKey);
  for (const auto& item : node) {
    const std::string key = item.first.as<std::string>();
    if (std::find(keys.begin(), keys.end(), key) == keys.end()) {
      std::string takes;
      for (std::size_t i = 4; i < keys.size(); ++i) takes += (i > 4 ? ", " : "") + keys[i];
      throw InputError(where(file, item.first, field + "." + key) + "'" + key + "' is not a field of " + kind +
                       " tasks (they take " + (takes.empty() ? "none" : takes) + ")");
    }
  }
  t.name = node["name"] ? yaml::text(file, node["name"], field + ".name") : field;

  if (node["time"] && node["window"])
    throw InputError(where(file, node["window"], field + ".window") + "give either time or window, not both");
  if (node["time"]) {
    t.start = t.end = yaml::nonNegative(file, node["time"], field + ".time");
    if (t.start > duration * (1 + 1e-12))
      throw InputError(where(file, node["time"], field + ".time") + "after the end of the motion (" +
                       std::to_string(duration) + " s)");
  } else if (node["window"]) {
    const auto w = yaml::numbers(file, node["window"], field + ".window", 2);
    if (!(w[0] >= 0.0 && w[0] < w[1] && w[1] <= duration * (1 + 1e-12)))
      throw InputError(where(file, node["window"], field + ".window") + "expected [start, end] with 0 ≤ start < end ≤ " +
                       std::to_string(duration) + " s");
    t.start = w[0], t.end = w[1], t.window = true;
  } else {
    throw InputError(where(file, node, field + ".time") + "missing required field (time or window)");
  }

  const ReadTask read = entry->read(YamlTaskFields(file, node, field, robot, t.window));
  t.task = read.task;
  t.lower = read.lower, t.upper = read.upper;
  if (t.lower.size() != t.dimension() || t.upper.size() != t.dimension())
    throw std::logic_error("task kind '" + kind + "': its reader gave bounds of the wrong size");
  if (!(t.lower.array() > -kInf).any() && !(t.upper.array() < kInf).any())
    throw InputError(t.origin + ": " + field + ": the task bounds nothing (give target, lower or upper)");
  return t;
}

Scenario readScenario(const YAML::Node& root, const std::filesystem::path& file,
                      std::optional<std::string> contactForces, bool allowNonPhysicalInertia);

}  // namespace

Scenario loadScenario(const std::filesystem::path& file, std::optional<std::string> contactForces,
                      bool allowNonPhysicalInertia) {
  return loadScenario(yaml::loadFile(file), file, contactForces, allowNonPhysicalInertia);
}

Scenario loadScenario(const YAML::Node& root, const std::filesystem::path& file,
                      std::optional<std::string> contactForces, bool allowNonPhysicalInertia) {
  return yaml::reading(file, [&] { return readScenario(root, file, contactForces, allowNonPhysicalInertia); });
}

namespace {

/// A registered contact-force formulation's name at `node` (`field`), or an InputError there.
std::string readFormulation(const std::filesystem::path& file, const YAML::Node& node, const std::string& field) {
  try {
    return contactForceFormulation(yaml::text(file, node, field)).name;
  } catch (const InputError& e) {
    throw InputError(where(file, node, field) + e.what());
  }
}

/// Why a stage's formulation field means nothing with the reference contact alone (§9).
constexpr const char* kOneFormulation =
    "the scenario has no contact besides the reference body's, where every formulation is the same problem";

Scenario readScenario(const YAML::Node& root, const std::filesystem::path& file,
                      std::optional<std::string> contactForces, bool allowNonPhysicalInertia) {
  if (!root.IsMap()) throw InputError(file.string() + ":1: expected a mapping of scenario fields");
  yaml::rejectUnknownKeys(file, root, "",
                          {"description", "robot", "actuators", "contact_surfaces", "postures", "reference_body",
                           "reference_pose", "gravity", "contacts", "friction_sharpness", "duration", "samples",
                           "control_points", "output_samples", "objective", "limits", "tasks", "start", "end",
                           "initialisation", "hessian", "continuation", "solver", "contact_forces", "force_control_points", "force_units", "inner", "closure_tolerance",
                           "closure_reach_margin", "refine",
                           "allow_nonphysical_inertia"});
  Scenario s;
  s.file = file;
  if (root["description"]) s.description = yaml::text(file, root["description"], "description");
  // Inertias a real body cannot have (robot_model.hpp UrdfOptions): refused unless the file or the
  // command line allows them, then loaded with a warning each.
  s.allowNonPhysicalInertia = allowNonPhysicalInertia ||
      (root["allow_nonphysical_inertia"] && yaml::flag(file, root["allow_nonphysical_inertia"], "allow_nonphysical_inertia"));
  s.robot = loadUrdfFile(sideFile(file, root, "robot"), {s.allowNonPhysicalInertia});
  s.actuators = loadActuators(sideFile(file, root, "actuators"), s.robot);
  s.contactSurfacesFile = sideFile(file, root, "contact_surfaces");
  const auto surfaces = loadContactSurfaces(s.contactSurfacesFile, s.robot);
  const auto postures = loadPostures(sideFile(file, root, "postures"), s.robot);
  if (root["friction_sharpness"])
    s.actuators.frictionSharpness = yaml::positive(file, root["friction_sharpness"], "friction_sharpness");

  const YAML::Node referenceNode = yaml::required(file, root, "reference_body", "");
  s.referenceBody = yaml::text(file, referenceNode, "reference_body");
  if (s.robot.findFrame(s.referenceBody) < 0) {
    // A contact surface's name where a link is expected (l_sole on a robot whose sole link is
    // left_sole_link): say which link that surface is on.
    const auto surface = std::find_if(surfaces.begin(), surfaces.end(),
                                      [&](const ContactSurface& c) { return c.name == s.referenceBody; });
    if (surface != surfaces.end())
      throw InputError(where(file, referenceNode, "reference_body") + "unknown body '" + s.referenceBody + "': '" +
                       s.referenceBody + "' is a contact surface of " + s.contactSurfacesFile.filename().string() +
                       ", on link '" + s.robot.frames[static_cast<std::size_t>(surface->frame)].name +
                       "'; reference_body takes a link (its surface is listed in contacts)");
    throw InputError(where(file, referenceNode, "reference_body") + "unknown body '" + s.referenceBody + "' " +
                     s.robot.unknownFrameHint(s.referenceBody));
  }
  if (root["reference_pose"]) {
    const YAML::Node pose = root["reference_pose"];
    yaml::rejectUnknownKeys(file, pose, "reference_pose", {"position", "rpy"});
    if (pose["position"]) {
      const auto p = yaml::numbers(file, pose["position"], "reference_pose.position", 3);
      s.referencePose.translation = Vector3(p[0], p[1], p[2]);
    }
    if (pose["rpy"]) {
      const auto r = yaml::numbers(file, pose["rpy"], "reference_pose.rpy", 3);
      s.referencePose.rotation = rotationFromRpy(r[0], r[1], r[2]);
    }
  }
  if (root["gravity"]) {
    const auto g = yaml::numbers(file, root["gravity"], "gravity", 3);
    s.gravity = Vector3(g[0], g[1], g[2]);
  }

  // Contacts: the reference body's surface and any others; read once the duration and the
  // start posture are known (windows and default poses depend on them).
  const YAML::Node contactsNode = yaml::required(file, root, "contacts", "");
  if (!contactsNode.IsSequence() || contactsNode.size() == 0)
    throw InputError(where(file, contactsNode, "contacts") + "expected a list of contact surface names or entries");

  const YAML::Node durationNode = yaml::required(file, root, "duration", "");
  if (durationNode.IsMap()) {
    yaml::rejectUnknownKeys(file, durationNode, "duration", {"initial", "min", "max"});
    s.duration.initial = yaml::positive(file, yaml::required(file, durationNode, "initial", "duration"), "duration.initial");
    s.duration.lower = yaml::positive(file, yaml::required(file, durationNode, "min", "duration"), "duration.min");
    s.duration.upper = yaml::positive(file, yaml::required(file, durationNode, "max", "duration"), "duration.max");
    if (!(s.duration.lower <= s.duration.initial && s.duration.initial <= s.duration.upper))
      throw InputError(where(file, durationNode, "duration") + "expected min ≤ initial ≤ max");
  } else {
    s.duration.initial = s.duration.lower = s.duration.upper = yaml::positive(file, durationNode, "duration");
  }
  if (root["samples"]) s.samples = yaml::integerAtLeast(file, root["samples"], "samples", 2);
  if (root["control_points"]) s.controlPoints = yaml::integerAtLeast(file, root["control_points"], "control_points", 7);
  if (root["output_samples"]) s.outputSamples = yaml::integerAtLeast(file, root["output_samples"], "output_samples", 2);

  if (root["objective"]) {
    const YAML::Node o = root["objective"];
    yaml::rejectUnknownKeys(file, o, "objective", {"energy", "smoothing", "acceleration_weight"});
    if (o["acceleration_weight"])
      s.accelerationWeight = yaml::nonNegative(file, o["acceleration_weight"], "objective.acceleration_weight");
    if (o["energy"]) {
      const std::string form = yaml::text(file, o["energy"], "objective.energy");
      if (form == "smooth_max") s.energyForm = EnergyForm::SmoothMaximum;
      else if (form == "epigraph") s.energyForm = EnergyForm::Epigraph;
      else throw InputError(where(file, o["energy"], "objective.energy") + "expected smooth_max or epigraph, got '" + form + "'");
    }
    if (o["smoothing"]) {
      if (s.energyForm != EnergyForm::SmoothMaximum)
        throw InputError(where(file, o["smoothing"], "objective.smoothing") + "only the smooth_max form is smoothed");
      s.smoothing = yaml::positive(file, o["smoothing"], "objective.smoothing");
    }
  }
  if (root["limits"]) {
    const YAML::Node l = root["limits"];
    yaml::rejectUnknownKeys(file, l, "limits",
                            {"position", "velocity", "torque", "torque_screening", "closing_screening", "contact",
                             "minimum_normal_force"});
    if (l["position"]) s.positionLimits = yaml::flag(file, l["position"], "limits.position");
    if (l["velocity"]) s.velocityLimits = yaml::flag(file, l["velocity"], "limits.velocity");
    if (l["torque"]) s.torqueLimits = yaml::flag(file, l["torque"], "limits.torque");
    if (l["torque_screening"]) {
      s.solve.torqueScreening = yaml::nonNegative(file, l["torque_screening"], "limits.torque_screening");
      if (s.solve.torqueScreening >= 1.0)
        throw InputError(where(file, l["torque_screening"], "limits.torque_screening") +
                         "expected a fraction of the limit in [0, 1) (0: every row in the problem)");
    }
    if (l["closing_screening"]) {
      s.solve.closingScreening = yaml::nonNegative(file, l["closing_screening"], "limits.closing_screening");
      if (s.solve.closingScreening >= 1.0)
        throw InputError(where(file, l["closing_screening"], "limits.closing_screening") +
                         "expected a fraction of the range in [0, 1) (0: every row in the problem)");
    }
    if (l["contact"]) s.contactConstraints = yaml::flag(file, l["contact"], "limits.contact");
    if (l["minimum_normal_force"])
      s.minimumNormalForce = yaml::nonNegative(file, l["minimum_normal_force"], "limits.minimum_normal_force");
  }
  YAML::Node throwNode;  // the throw task, checked against the whole scenario at the end
  std::string throwField;
  if (root["tasks"]) {
    const YAML::Node tasks = root["tasks"];
    if (!tasks.IsSequence()) throw InputError(where(file, tasks, "tasks") + "expected a list of tasks");
    for (std::size_t i = 0; i < tasks.size(); ++i) {
      const std::string field = "tasks[" + std::to_string(i) + "]";
      if (tasks[i].IsMap() && tasks[i]["kind"] && tasks[i]["kind"].IsScalar() && tasks[i]["kind"].Scalar() == "throw") {
        readThrowTask(file, tasks[i], field, s);
        throwNode = tasks[i], throwField = field;
      } else {
        s.tasks.push_back(readTask(file, tasks[i], field, s.robot, s.duration.initial));
      }
    }
  }

  const YAML::Node startNode = yaml::required(file, root, "start", "");
  const YAML::Node endNode = yaml::required(file, root, "end", "");
  s.start = readPosture(file, startNode, "start", s.robot, postures);
  if (startNode["fixed"]) s.fixStart = yaml::flag(file, startNode["fixed"], "start.fixed");
  if (endNode.IsMap() && endNode["same_as"]) {
    // The periodic boundary: the end is the start's posture variables themselves.
    yaml::rejectUnknownKeys(file, endNode, "end", {"same_as"});
    const std::string same = yaml::text(file, endNode["same_as"], "end.same_as");
    if (same != "start")
      throw InputError(where(file, endNode["same_as"], "end.same_as") + "expected start, got '" + same + "'");
    s.periodic = true;
    s.end = s.start;
    s.fixEnd = s.fixStart;
  } else {
    s.end = readPosture(file, endNode, "end", s.robot, postures);
    if (endNode["fixed"]) s.fixEnd = yaml::flag(file, endNode["fixed"], "end.fixed");
  }
  if (s.positionLimits)
    for (int j = 0; j < s.robot.jointCount(); ++j) {
      const JointLimits& limit = s.robot.joints[static_cast<std::size_t>(j)].limits;
      for (const auto& [q, node, name] : {std::tuple{s.start[j], startNode, "start"}, std::tuple{s.end[j], endNode, "end"}})
        if (q < limit.lower - 1e-9 || q > limit.upper + 1e-9)
          throw InputError(where(file, node, name) + "joint " + s.robot.joints[static_cast<std::size_t>(j)].name + " at " +
                           std::to_string(q) + " rad is outside its limits [" + std::to_string(limit.lower) + ", " +
                           std::to_string(limit.upper) + "]");
    }
  if (root["closure_tolerance"]) {
    const YAML::Node node = root["closure_tolerance"];
    yaml::rejectUnknownKeys(file, node, "closure_tolerance", {"position", "orientation"});
    if (node["position"]) s.closurePositionTolerance = yaml::nonNegative(file, node["position"], "closure_tolerance.position");
    if (node["orientation"])
      s.closureOrientationTolerance = yaml::nonNegative(file, node["orientation"], "closure_tolerance.orientation");
  }
  if (root["closure_reach_margin"]) {
    const YAML::Node node = root["closure_reach_margin"];
    s.closureReachMargin = yaml::nonNegative(file, node, "closure_reach_margin");
    if (!(s.closureReachMargin < 1.0))
      throw InputError(where(file, node, "closure_reach_margin") + "expected a fraction of the longest reach in [0, 1), got " +
                       std::to_string(s.closureReachMargin));
  }
  readContacts(file, contactsNode, surfaces, s);
  if (s.closureReachMargin > 0.0 && s.contacts.empty())
    throw InputError(where(file, root["closure_reach_margin"], "closure_reach_margin") +
                     "the scenario holds no contact besides the reference body's: there is no loop to keep from full stretch");
  if (root["contact_forces"]) s.contactForces = readFormulation(file, root["contact_forces"], "contact_forces");
  if (contactForces) s.contactForces = contactForceFormulation(*contactForces).name;
  if (root["force_control_points"])
    s.forceControlPoints = yaml::integerAtLeast(file, root["force_control_points"], "force_control_points", 4);
  if (root["force_units"]) {
    try {
      s.forceUnits = parseForceUnits(yaml::text(file, root["force_units"], "force_units"));
    } catch (const InputError& e) {
      throw InputError(where(file, root["force_units"], "force_units") + e.what());
    }
  }
  if (root["inner"]) readInnerSettings(file, root["inner"], s);
  if (root["initialisation"]) {
    const YAML::Node init = root["initialisation"];
    yaml::rejectUnknownKeys(file, init, "initialisation", {"configuration_optimisation", "configuration_iterations"});
    if (init["configuration_optimisation"])
      s.solve.configurationOptimisation =
          yaml::flag(file, init["configuration_optimisation"], "initialisation.configuration_optimisation");
    if (init["configuration_iterations"])
      s.solve.configurationIterations =
          yaml::integerAtLeast(file, init["configuration_iterations"], "initialisation.configuration_iterations", 1);
  }
  if (root["refine"]) s.solve.refineRounds = yaml::integerAtLeast(file, root["refine"], "refine", 0);
  if (root["hessian"]) {
    const std::string hessian = yaml::text(file, root["hessian"], "hessian");
    try {
      s.solve.hessian = parseHessianOption(hessian);
    } catch (const InputError& e) {
      throw InputError(where(file, root["hessian"], "hessian") + e.what());
    }
  }

  if (const YAML::Node stages = root["continuation"]) {
    if (!stages.IsSequence())
      throw InputError(where(file, stages, "continuation") + "expected a list of {friction_sharpness, smoothing} stages");
    for (std::size_t k = 0; k < stages.size(); ++k) {
      const YAML::Node stage = stages[k];
      const std::string field = "continuation[" + std::to_string(k) + "]";
      if (!stage.IsMap()) throw InputError(where(file, stage, field) + "expected {friction_sharpness: ν, smoothing: ε}");
      yaml::rejectUnknownKeys(file, stage, field,
                              {"friction_sharpness", "smoothing", "samples", "hessian", "max_iterations", "energy",
                               "for_contact_forces", "contact_forces", "inner_solver", "feasibility"});
      ContinuationStage c{s.actuators.frictionSharpness, s.smoothing, s.samples, s.solve.hessian, -1, s.energyForm, {}, {}, {}, {}};
      if (stage["energy"]) {
        const std::string form = yaml::text(file, stage["energy"], field + ".energy");
        if (form == "smooth_max") c.energyForm = EnergyForm::SmoothMaximum;
        else if (form == "epigraph") c.energyForm = EnergyForm::Epigraph;
        else throw InputError(where(file, stage["energy"], field + ".energy") + "expected smooth_max or epigraph, got '" + form + "'");
      }
      if (stage["hessian"]) {
        try {
          c.hessian = parseHessianOption(yaml::text(file, stage["hessian"], field + ".hessian"));
        } catch (const InputError& e) {
          throw InputError(where(file, stage["hessian"], field + ".hessian") + e.what());
        }
      }
      if (const YAML::Node only = stage["for_contact_forces"]) {
        const std::string onlyField = field + ".for_contact_forces";
        // With the reference contact alone the three formulations are one problem (§9), and
        // whether such a stage ran would hang on a default that means nothing.
        if (s.contacts.empty()) throw InputError(where(file, only, onlyField) + kOneFormulation);
        if (!only.IsSequence() || only.size() == 0)
          throw InputError(where(file, only, onlyField) + "expected a non-empty list of formulations (" +
                           alternatives(contactForcesNames()) + ")");
        for (std::size_t i = 0; i < only.size(); ++i) {
          const std::string item = onlyField + "[" + std::to_string(i) + "]";
          const std::string forces = readFormulation(file, only[i], item);
          if (std::find(c.forContactForces.begin(), c.forContactForces.end(), forces) != c.forContactForces.end())
            throw InputError(where(file, only[i], item) + "'" + forces + "' is listed twice");
          c.forContactForces.push_back(forces);
        }
      }
      if (const YAML::Node forces = stage["contact_forces"]) {
        const std::string forcesField = field + ".contact_forces";
        if (s.contacts.empty()) throw InputError(where(file, forces, forcesField) + kOneFormulation);
        c.contactForces = readFormulation(file, forces, forcesField);
      }
      if (const YAML::Node inner = stage["inner_solver"]) {
        const std::string innerField = field + ".inner_solver";
        if (s.contacts.empty())
          throw InputError(where(file, inner, innerField) +
                           "the scenario has no contact besides the reference body's: no inner problem picks wrenches");
        c.innerSolver = yaml::text(file, inner, innerField);
        if (!isInnerSolverName(c.innerSolver))
          throw InputError(where(file, inner, innerField) + "unknown inner solver '" + c.innerSolver + "' (expected " +
                           innerSolverList() + ")");
      }
      if (const YAML::Node row = stage["feasibility"]) {
        const std::string rowField = field + ".feasibility";
        if (s.contacts.empty())
          throw InputError(where(file, row, rowField) +
                           "the scenario has no contact besides the reference body's: no inner problem picks wrenches");
        c.feasibility = readInnerFeasibility(file, row, rowField);
      }
      if (stage["max_iterations"]) c.maxIterations = yaml::integerAtLeast(file, stage["max_iterations"], field + ".max_iterations", 1);
      if (stage["friction_sharpness"])
        c.frictionSharpness = yaml::positive(file, stage["friction_sharpness"], field + ".friction_sharpness");
      if (stage["smoothing"]) {
        if (c.energyForm != EnergyForm::SmoothMaximum)
          throw InputError(where(file, stage["smoothing"], field + ".smoothing") + "only the smooth_max form is smoothed");
        c.smoothing = yaml::positive(file, stage["smoothing"], field + ".smoothing");
      }
      if (stage["samples"]) {
        // Per-sample variables (epigraph slacks, wrenches as variables) do not carry over
        // from one grid to another; the spline parameters and force splines do.
        if (s.energyForm == EnergyForm::Epigraph || c.energyForm == EnergyForm::Epigraph ||
            (!s.contacts.empty() && contactForceFormulation(s.contactForces).variablesPerSample))
          throw InputError(where(file, stage["samples"], field + ".samples") +
                           "the epigraph form and contact_forces: variables have variables per sample; a stage "
                           "cannot change the samples");
        c.samples = yaml::integerAtLeast(file, stage["samples"], field + ".samples", 2);
      }
      s.solve.continuation.push_back(c);
    }
  }

  if (root["solver"]) readSolverOptions(file, root["solver"], s);
  if (s.ball) checkThrowTask(file, throwNode, throwField, s);
  if (s.solve.hessian == HessianOption::Exact)
    if (const std::string why = exactHessianRefusal(s); !why.empty())
      throw InputError(where(file, root["hessian"], "hessian") + "exact: " + why);
  // Only the stages that run, with the run's formulation (the file's, or `contactForces`
  // from `mcopt run --contact-forces`): a stage for `splines` alone is no bilevel run's.
  for (std::size_t k = 0; k < s.solve.continuation.size(); ++k)
    if (s.solve.continuation[k].hessian == HessianOption::Exact && s.solve.continuation[k].runsWith(s.contactForces))
      if (const std::string why = exactHessianRefusal(continuationStage(s, k)); !why.empty()) {
        const std::string field = "continuation[" + std::to_string(k) + "]";
        const YAML::Node stage = root["continuation"][k];
        throw InputError(where(file, stage["hessian"] ? stage["hessian"] : root["hessian"], field + ".hessian") + "exact: " + why);
      }
  if (const std::string why = barrierModelRefusal(s); !why.empty()) {
    const YAML::Node inner = root["inner"];
    throw InputError(where(file, inner["contact_model"] ? inner["contact_model"] : inner["solver"], "inner.solver") + why);
  }
  bool barrierUsed = s.inner.solverName == "barrier";
  for (std::size_t k = 0; k < s.solve.continuation.size(); ++k) {
    if (s.solve.continuation[k].innerSolver != "barrier") continue;
    barrierUsed = true;
    if (const std::string why = barrierModelRefusal(continuationStage(s, k)); !why.empty()) {
      const std::string field = "continuation[" + std::to_string(k) + "].inner_solver";
      throw InputError(where(file, root["continuation"][k]["inner_solver"], field) + why);
    }
  }
  if (const YAML::Node inner = root["inner"]; inner && inner["barrier"] && !barrierUsed)
    throw InputError(where(file, inner["barrier"], "inner.barrier") +
                     "only the barrier inner solver has a barrier parameter, and neither inner.solver nor a continuation "
                     "stage's inner_solver is barrier (inner.solver is " + s.inner.solverName + ")");
  if (const std::string why = marginModelRefusal(s); !why.empty())
    throw InputError(where(file, root["inner"]["feasibility"], "inner.feasibility") + why);
  for (std::size_t k = 0; k < s.solve.continuation.size(); ++k) {
    if (!s.solve.continuation[k].feasibility) continue;
    if (const std::string why = marginModelRefusal(continuationStage(s, k)); !why.empty()) {
      const std::string field = "continuation[" + std::to_string(k) + "].feasibility";
      throw InputError(where(file, root["continuation"][k]["feasibility"], field) + why);
    }
  }
  return s;
}

}  // namespace

}  // namespace mcopt
