#include "outer_nlp/scenario.hpp"

#include <cmath>
#include <map>

#include "core/errors.hpp"
#include "core/spatial.hpp"
#include "core/yaml_fields.hpp"

namespace mcopt {

namespace {

using yaml::where;
constexpr double kInf = std::numeric_limits<double>::infinity();

int integerField(const std::filesystem::path& file, const YAML::Node& node, const std::string& field, int minimum) {
  const double value = yaml::number(file, node, field);
  if (value != std::floor(value) || value < minimum || value > 1e7)
    throw InputError(where(file, node, field) + "expected an integer ≥ " + std::to_string(minimum));
  return static_cast<int>(value);
}

bool flag(const std::filesystem::path& file, const YAML::Node& node, const std::string& field) {
  try {
    if (!node.IsScalar()) throw YAML::Exception(node.Mark(), "not a scalar");
    return node.as<bool>();
  } catch (const YAML::Exception&) {
    throw InputError(where(file, node, field) + "expected true or false");
  }
}

std::filesystem::path sideFile(const std::filesystem::path& file, const YAML::Node& root, const char* key) {
  const YAML::Node node = yaml::required(file, root, key, "");
  // Paths are relative to the scenario file, never to the working directory.
  const auto path = file.parent_path() / yaml::text(file, node, key);
  if (!std::filesystem::exists(path)) throw InputError(where(file, node, key) + "file not found: " + path.string());
  return path;
}

Eigen::VectorXd readPosture(const std::filesystem::path& file, const YAML::Node& node, const std::string& field,
                            const RobotModel& robot, const std::map<std::string, Eigen::VectorXd>& postures) {
  yaml::rejectUnknownKeys(file, node, field, {"posture", "offsets", "fixed"});
  return postureWithOffsets(file, node, field, robot, postures);
}

/// Three bounds, each a number or null (free).
Eigen::Vector3d boundList(const std::filesystem::path& file, const YAML::Node& node, const std::string& field,
                          double freeValue) {
  if (!node.IsSequence() || node.size() != 3)
    throw InputError(where(file, node, field) + "expected a list of 3 numbers (null for a free component)");
  Eigen::Vector3d v;
  for (std::size_t i = 0; i < 3; ++i)
    v[static_cast<Eigen::Index>(i)] =
        node[i].IsNull() ? freeValue : yaml::number(file, node[i], field + "[" + std::to_string(i) + "]");
  return v;
}

TaskSpec readTask(const std::filesystem::path& file, const YAML::Node& node, const std::string& field,
                  const RobotModel& robot, double duration) {
  yaml::rejectUnknownKeys(file, node, field,
                          {"name", "kind", "body", "point", "time", "window", "target", "tolerance", "lower", "upper"});
  TaskSpec t;
  t.origin = where(file, node, field);
  t.origin.resize(t.origin.size() - 2);  // without the trailing ": "
  t.name = node["name"] ? yaml::text(file, node["name"], field + ".name") : field;
  const YAML::Node kindNode = yaml::required(file, node, "kind", field);
  const std::string kind = yaml::text(file, kindNode, field + ".kind");
  static const std::map<std::string, TaskKind> kinds = {{"position", TaskKind::Position},
                                                        {"orientation", TaskKind::Orientation},
                                                        {"linear_velocity", TaskKind::LinearVelocity},
                                                        {"angular_velocity", TaskKind::AngularVelocity},
                                                        {"center_of_mass", TaskKind::CenterOfMass}};
  const auto k = kinds.find(kind);
  if (k == kinds.end())
    throw InputError(where(file, kindNode, field + ".kind") + "unknown task kind '" + kind +
                     "' (expected position, orientation, linear_velocity, angular_velocity, center_of_mass)");
  t.kind = k->second;

  if (t.kind == TaskKind::CenterOfMass) {
    if (node["body"]) throw InputError(where(file, node["body"], field + ".body") + "a centre-of-mass task has no body");
  } else {
    const YAML::Node bodyNode = yaml::required(file, node, "body", field);
    t.body = yaml::text(file, bodyNode, field + ".body");
    t.frame = robot.findFrame(t.body);
    if (t.frame < 0) throw InputError(where(file, bodyNode, field + ".body") + "unknown body '" + t.body + "'");
  }
  if (node["point"]) {
    if (t.kind != TaskKind::Position && t.kind != TaskKind::LinearVelocity)
      throw InputError(where(file, node["point"], field + ".point") + "only position and linear_velocity tasks take a point");
    const auto p = yaml::numbers(file, node["point"], field + ".point", 3);
    t.point = Vector3(p[0], p[1], p[2]);
  }

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
  if ((t.kind == TaskKind::LinearVelocity || t.kind == TaskKind::AngularVelocity) && t.window)
    throw InputError(where(file, node["window"], field + ".window") + "velocity tasks hold at an instant (use time)");

  const bool hasTarget = static_cast<bool>(node["target"]);
  if (hasTarget && (node["lower"] || node["upper"]))
    throw InputError(where(file, node["target"], field + ".target") + "give either target (and tolerance) or lower/upper");
  if (t.kind == TaskKind::Orientation) {
    // The error vector ½ vee(Rtᵀ R − Rᵀ Rt) is sin θ times the axis: bounded by the tolerance.
    if (!hasTarget) throw InputError(where(file, node, field + ".target") + "missing required field (rpy of the target)");
    const auto r = yaml::numbers(file, node["target"], field + ".target", 3);
    t.targetRotation = rotationFromRpy(r[0], r[1], r[2]);
    const double tol = node["tolerance"] ? yaml::nonNegative(file, node["tolerance"], field + ".tolerance") : 0.0;
    t.lower.setConstant(-tol), t.upper.setConstant(tol);
    return t;
  }
  if (hasTarget) {
    const Eigen::Vector3d target = boundList(file, node["target"], field + ".target", kInf);
    const double tol = node["tolerance"] ? yaml::nonNegative(file, node["tolerance"], field + ".tolerance") : 0.0;
    for (int i = 0; i < 3; ++i)
      if (std::isfinite(target[i])) t.lower[i] = target[i] - tol, t.upper[i] = target[i] + tol;
  } else {
    if (node["tolerance"])
      throw InputError(where(file, node["tolerance"], field + ".tolerance") + "a tolerance goes with a target");
    if (node["lower"]) t.lower = boundList(file, node["lower"], field + ".lower", -kInf);
    if (node["upper"]) t.upper = boundList(file, node["upper"], field + ".upper", kInf);
    for (int i = 0; i < 3; ++i)
      if (t.lower[i] > t.upper[i])
        throw InputError(where(file, node["upper"], field + ".upper") + "upper bound below lower bound");
  }
  if (!(t.lower.array() > -kInf).any() && !(t.upper.array() < kInf).any())
    throw InputError(t.origin + ": " + field + ": the task bounds nothing (give target, lower or upper)");
  return t;
}

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
    s.solverOptions.push_back(o);
  }
}

}  // namespace

Scenario loadScenario(const std::filesystem::path& file) {
  const YAML::Node root = yaml::loadFile(file);
  if (!root.IsMap()) throw InputError(file.string() + ":1: expected a mapping of scenario fields");
  yaml::rejectUnknownKeys(file, root, "",
                          {"description", "robot", "actuators", "contact_surfaces", "postures", "reference_body",
                           "reference_pose", "gravity", "contacts", "friction_sharpness", "duration", "samples",
                           "control_points", "output_samples", "objective", "limits", "tasks", "start", "end",
                           "initialisation", "hessian", "solver"});
  Scenario s;
  s.file = file;
  if (root["description"]) s.description = yaml::text(file, root["description"], "description");
  s.robot = loadUrdfFile(sideFile(file, root, "robot"));
  s.actuators = loadActuators(sideFile(file, root, "actuators"), s.robot);
  const auto surfaces = loadContactSurfaces(sideFile(file, root, "contact_surfaces"), s.robot);
  const auto postures = loadPostures(sideFile(file, root, "postures"), s.robot);
  if (root["friction_sharpness"])
    s.actuators.frictionSharpness = yaml::positive(file, root["friction_sharpness"], "friction_sharpness");

  const YAML::Node referenceNode = yaml::required(file, root, "reference_body", "");
  s.referenceBody = yaml::text(file, referenceNode, "reference_body");
  if (s.robot.findFrame(s.referenceBody) < 0)
    throw InputError(where(file, referenceNode, "reference_body") + "unknown body '" + s.referenceBody + "'");
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

  // Contacts: the reference body's surface; more contacts need the bilevel outer problem.
  const YAML::Node contactsNode = yaml::required(file, root, "contacts", "");
  if (!contactsNode.IsSequence() || contactsNode.size() == 0)
    throw InputError(where(file, contactsNode, "contacts") + "expected a list of contact surface names");
  if (contactsNode.size() > 1)
    throw InputError(where(file, contactsNode[1], "contacts[1]") +
                     "mcopt run optimises motions on one contact, the reference body's; a second contact makes "
                     "the problem bilevel (formulation.md §7), which the outer problem does not support");
  const std::string contactName = yaml::text(file, contactsNode[0], "contacts[0]");
  bool found = false;
  for (const ContactSurface& c : surfaces)
    if (c.name == contactName) s.support = c, found = true;
  if (!found) throw InputError(where(file, contactsNode[0], "contacts[0]") + "unknown contact surface '" + contactName + "'");
  if (s.robot.frames[static_cast<std::size_t>(s.support.frame)].body !=
      s.robot.frames[static_cast<std::size_t>(s.robot.frameIndex(s.referenceBody))].body)
    throw InputError(where(file, contactsNode[0], "contacts[0]") + "contact '" + contactName +
                     "' is not on the reference body '" + s.referenceBody + "'");

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
  if (root["samples"]) s.samples = integerField(file, root["samples"], "samples", 2);
  if (root["control_points"]) s.controlPoints = integerField(file, root["control_points"], "control_points", 7);
  if (root["output_samples"]) s.outputSamples = integerField(file, root["output_samples"], "output_samples", 2);

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
    yaml::rejectUnknownKeys(file, l, "limits", {"position", "velocity", "torque", "contact", "minimum_normal_force"});
    if (l["position"]) s.positionLimits = flag(file, l["position"], "limits.position");
    if (l["velocity"]) s.velocityLimits = flag(file, l["velocity"], "limits.velocity");
    if (l["torque"]) s.torqueLimits = flag(file, l["torque"], "limits.torque");
    if (l["contact"]) s.contactConstraints = flag(file, l["contact"], "limits.contact");
    if (l["minimum_normal_force"])
      s.minimumNormalForce = yaml::nonNegative(file, l["minimum_normal_force"], "limits.minimum_normal_force");
  }
  if (root["tasks"]) {
    const YAML::Node tasks = root["tasks"];
    if (!tasks.IsSequence()) throw InputError(where(file, tasks, "tasks") + "expected a list of tasks");
    for (std::size_t i = 0; i < tasks.size(); ++i)
      s.tasks.push_back(readTask(file, tasks[i], "tasks[" + std::to_string(i) + "]", s.robot, s.duration.initial));
  }

  const YAML::Node startNode = yaml::required(file, root, "start", "");
  const YAML::Node endNode = yaml::required(file, root, "end", "");
  s.start = readPosture(file, startNode, "start", s.robot, postures);
  s.end = readPosture(file, endNode, "end", s.robot, postures);
  if (startNode["fixed"]) s.fixStart = flag(file, startNode["fixed"], "start.fixed");
  if (endNode["fixed"]) s.fixEnd = flag(file, endNode["fixed"], "end.fixed");
  if (s.positionLimits)
    for (int j = 0; j < s.robot.jointCount(); ++j) {
      const JointLimits& limit = s.robot.joints[static_cast<std::size_t>(j)].limits;
      for (const auto& [q, node, name] : {std::tuple{s.start[j], startNode, "start"}, std::tuple{s.end[j], endNode, "end"}})
        if (q < limit.lower - 1e-9 || q > limit.upper + 1e-9)
          throw InputError(where(file, node, name) + "joint " + s.robot.joints[static_cast<std::size_t>(j)].name + " at " +
                           std::to_string(q) + " rad is outside its limits [" + std::to_string(limit.lower) + ", " +
                           std::to_string(limit.upper) + "]");
    }
  if (root["initialisation"]) {
    const YAML::Node init = root["initialisation"];
    yaml::rejectUnknownKeys(file, init, "initialisation", {"configuration_optimisation", "configuration_iterations"});
    if (init["configuration_optimisation"])
      s.configurationOptimisation = flag(file, init["configuration_optimisation"], "initialisation.configuration_optimisation");
    if (init["configuration_iterations"])
      s.configurationIterations =
          integerField(file, init["configuration_iterations"], "initialisation.configuration_iterations", 1);
  }
  if (root["hessian"]) {
    const std::string hessian = yaml::text(file, root["hessian"], "hessian");
    if (hessian != "limited-memory" && hessian != "finite-differences")
      throw InputError(where(file, root["hessian"], "hessian") + "expected limited-memory or finite-differences, got '" +
                       hessian + "'");
    s.finiteDifferenceHessian = hessian == "finite-differences";
  }
  if (root["solver"]) readSolverOptions(file, root["solver"], s);
  return s;
}

}  // namespace mcopt
