// SPDX-License-Identifier: BSD-3-Clause
// `mcopt robot check`: can the robot hold each of its named postures at rest, on both feet and
// on each foot alone? The same check `mcopt run` makes of a scenario's fixed postures
// (outer_nlp/posture_check.hpp), run for every posture and support: the centre of mass against
// the support polygon (its margin), the static torques against their limits (with both feet,
// the split of the load between them from the inner problem), and the static electrical power.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>

#include <unistd.h>

#include "apps/commands.hpp"
#include "apps/json_io.hpp"
#include "apps/python_script.hpp"
#include "apps/robot_info_json.hpp"
#include "apps/robot_visuals.hpp"
#include "core/actuators.hpp"
#include "core/atomic_file.hpp"
#include "core/dynamics_data.hpp"
#include "core/errors.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"
#include "core/robot_files.hpp"
#include "outer_nlp/closed_chains.hpp"
#include "outer_nlp/posture_check.hpp"
#include "outer_nlp/scenario.hpp"

namespace mcopt::cli {

namespace {

namespace fs = std::filesystem;
using json_io::Json;

struct RobotCheckOptions {
  std::string folder, robot, actuators, contacts, postures, out, plot;
  std::vector<std::string> feet;
  bool json = false;
  bool allowNonPhysicalInertia = false;  ///< load a URDF whose inertias a real body cannot have (with warnings)
};

/// One posture on one support.
struct SupportCheck {
  std::string posture;
  std::vector<std::string> support;
  bool checked = true;
  std::string note;        ///< why it was not checked, or what to know
  PostureCheck check;
  /// On both feet: the second leg's loop's reach as a fraction of its longest (fully
  /// stretched; closed_chains.hpp LoopReach), what `closure_reach_margin` bounds.
  std::optional<double> loopReach;
};

/// The robot folder's files: DIR holds one .urdf and actuators.yaml, contacts.yaml, postures.yaml
/// (the first optional); --robot, --actuators, --contacts, --postures name them one by one.
void resolveFiles(RobotCheckOptions& o) {
  if (!o.folder.empty()) {
    const fs::path dir(o.folder);
    if (!fs::is_directory(dir)) throw InputError(o.folder + ": not a folder");
    if (o.robot.empty()) {
      std::vector<fs::path> urdfs;
      for (const auto& entry : fs::directory_iterator(dir))
        if (entry.path().extension() == ".urdf") urdfs.push_back(entry.path());
      if (urdfs.size() != 1) {
        std::string names;
        for (const auto& u : urdfs) names += " " + u.filename().string();
        throw InputError(o.folder + ": expected one .urdf file in the robot folder, found " +
                         std::to_string(urdfs.size()) + (names.empty() ? "" : ":" + names) + " (or give --robot)");
      }
      o.robot = urdfs.front().string();
    }
    if (o.actuators.empty() && fs::exists(dir / "actuators.yaml")) o.actuators = (dir / "actuators.yaml").string();
    if (o.contacts.empty()) o.contacts = (dir / "contacts.yaml").string();
    if (o.postures.empty()) o.postures = (dir / "postures.yaml").string();
  }
  for (const auto& [file, what] : {std::pair{&o.robot, "--robot (or a robot folder)"},
                                   std::pair{&o.contacts, "--contacts (contacts.yaml in the robot folder)"},
                                   std::pair{&o.postures, "--postures (postures.yaml in the robot folder)"}}) {
    if (file->empty()) throw InputError(std::string("robot check: missing ") + what);
    if (!fs::exists(*file)) throw InputError(*file + ": file not found");
  }
  if (!o.actuators.empty() && !fs::exists(o.actuators)) throw InputError(o.actuators + ": file not found");
}

/// The two feet: --feet, or the two contact surfaces whose name says sole or foot.
std::vector<std::string> findFeet(const RobotCheckOptions& o, const std::vector<ContactSurface>& surfaces) {
  std::string all;
  for (const ContactSurface& s : surfaces) all += (all.empty() ? "" : ", ") + s.name;
  std::vector<std::string> feet = o.feet;
  if (feet.empty()) {
    for (const ContactSurface& s : surfaces)
      if (s.name.find("sole") != std::string::npos || s.name.find("foot") != std::string::npos) feet.push_back(s.name);
    if (feet.size() != 2)
      throw InputError(o.contacts + ": cannot tell the two feet among the contact surfaces (" + all +
                       "): name them with --feet LEFT,RIGHT");
  }
  if (feet.size() != 2 || feet[0] == feet[1]) throw InputError("--feet: expected two different contact surfaces");
  for (const std::string& f : feet)
    if (std::none_of(surfaces.begin(), surfaces.end(), [&](const ContactSurface& s) { return s.name == f; }))
      throw InputError("--feet: '" + f + "' is not a contact surface of " + o.contacts + " (it has " + all + ")");
  return feet;
}

std::string yamlPath(const std::string& file) { return Json(fs::absolute(file).string()).dump(); }

/// The posture at rest on `support` (the first the reference body), as `mcopt run` checks a
/// fixed posture: a scenario written for the purpose, never optimised.
SupportCheck checkSupport(const RobotCheckOptions& o, const fs::path& scratch, const std::string& posture,
                          const std::vector<std::string>& support, const RobotModel& robot, const ContactSurface& reference) {
  std::ostringstream yaml;
  yaml << "description: mcopt robot check, " << posture << "\n"
       << "robot: " << yamlPath(o.robot) << "\n";
  // Without an actuator file, the URDF's limits and no motor model (static power 0).
  yaml << "actuators: " << yamlPath(o.actuators.empty() ? (scratch / "actuators.yaml").string() : o.actuators) << "\n";
  yaml << "contact_surfaces: " << yamlPath(o.contacts) << "\n"
       << "postures: " << yamlPath(o.postures) << "\n"
       << "reference_body: " << Json(robot.frames[static_cast<std::size_t>(reference.frame)].name).dump() << "\n";
  // The surface's link placed so that the surface lies at the origin.
  const RigidTransform link = reference.placement.inverse();
  const Vector3 rpy = rpyFromRotation(link.rotation);
  yaml << std::setprecision(17) << "reference_pose: {position: [" << link.translation.x() << ", " << link.translation.y()
       << ", " << link.translation.z() << "], rpy: [" << rpy.x() << ", " << rpy.y() << ", " << rpy.z() << "]}\n"
       << "contacts: " << Json(support).dump() << "\n";
  if (support.size() > 1) yaml << "contact_forces: bilevel\ninner: {solver: active-set, contact_model: wrench-cone}\n";
  yaml << "duration: 1.0\nsamples: 5\ncontrol_points: 7\n"
       << "start: {posture: " << Json(posture).dump() << ", fixed: true}\n"
       << "end: {posture: " << Json(posture).dump() << ", fixed: true}\n"
       << "initialisation: {configuration_optimisation: false}\n";
  const fs::path file = scratch / "check.yaml";
  {
    std::ofstream out(file);
    out << yaml.str();
    if (!out) throw InputError(file.string() + ": cannot write");
  }
  SupportCheck result;
  result.posture = posture;
  result.support = support;
  try {
    const Scenario scenario = loadScenario(file, std::nullopt, o.allowNonPhysicalInertia);
    MotionProblem problem(scenario);
    result.check = checkFixedPostures(problem).front();
    if (const ClosedChains* chains = problem.closedChains()) {
      DynamicsData data(problem.model());
      forwardKinematics(problem.model(), data, scenario.start);
      result.loopReach = chains->reachRatio(data, 0);
    }
  } catch (const InputError& e) {
    // The robot's files were read before; what fails here is the posture on this support (a
    // closure singular at it: a straight knee). Said without the scratch file's name.
    std::string why = e.what();
    const std::string prefix = file.string() + ":";
    if (why.rfind(prefix, 0) == 0) why = why.substr(why.find(' ', prefix.size()) + 1);
    result.checked = false;
    result.note = why;
  }
  return result;
}

/// The second foot's pose in the first's frame at `q`: height and tilt between the soles.
std::pair<double, double> footOffset(const RobotModel& robot, const Eigen::VectorXd& q, const ContactSurface& a,
                                     const ContactSurface& b) {
  const DynamicsModel model(robot, robot.frames[static_cast<std::size_t>(a.frame)].name, RigidTransform{},
                            Vector3(0.0, 0.0, -9.81));
  DynamicsData data(model);
  forwardKinematics(model, data, q);
  const RigidTransform pa = framePose(model, data, a.frame) * a.placement;
  const RigidTransform pb = framePose(model, data, b.frame) * b.placement;
  const RigidTransform relative = pa.inverse() * pb;
  const double tilt = std::acos(std::clamp(relative.rotation(2, 2), -1.0, 1.0));
  return {relative.translation.z(), tilt};
}

/// One letter for where a value came from: f the actuator file, u the URDF, d mcopt's default.
char sourceLetter(const std::string& source) {
  if (source.rfind("actuator file", 0) == 0) return 'f';
  if (source.rfind("URDF", 0) == 0) return 'u';
  return 'd';
}

/// The values in use for every joint, each with its source letter.
void printJointValues(const RobotModel& robot, const ActuatorSet& actuators) {
  std::cout << "values in use (f: the actuator file, u: the URDF, d: mcopt's default; friction on the motor side)\n\n"
            << "  joint                      torque lim.   vel. lim.   gear     K [N m/A]   R [Ω]      rotor [kg m²]   viscous      dry [N m]\n";
  auto cell = [](double value, const std::string& source, int width) {
    std::ostringstream text;
    if (std::isfinite(value)) text << std::setprecision(4) << value;
    else text << "∞";
    text << " " << sourceLetter(source);
    std::ostringstream padded;
    padded << std::left << std::setw(width) << text.str();
    return padded.str();
  };
  for (int j = 0; j < robot.jointCount(); ++j) {
    const ActuatorParameters& a = actuators.joints[static_cast<std::size_t>(j)];
    const ActuatorSources& from = actuators.sources[static_cast<std::size_t>(j)];
    std::cout << "  " << std::left << std::setw(27) << robot.joints[static_cast<std::size_t>(j)].name << std::right
              << cell(a.torqueLimit, from.torqueLimit, 14) << cell(a.velocityLimit, from.velocityLimit, 12)
              << cell(a.gearRatio, from.gearRatio, 9) << cell(a.torqueConstant, from.torqueConstant, 12)
              << cell(a.resistance, from.resistance, 11) << cell(a.rotorInertia, from.rotorInertia, 16)
              << cell(a.viscousFriction, from.viscousFriction, 13) << cell(a.dryFriction, from.dryFriction, 10) << "\n";
  }
  std::cout << "\n";
}

/// What scripts/plot_contacts.py draws: each contact surface's rectangle and, in the surface's
/// frame, the corners of its body's geometry (collision primitives, or the inertia box).
Json contactGeometryJson(const RobotModel& robot, const std::string& urdf, const std::vector<ContactSurface>& surfaces) {
  const auto collisions = bodyCollisionShapes(urdf, robot);
  Json out = {{"robot", robot.name}, {"surfaces", Json::array()}};
  for (const ContactSurface& s : surfaces) {
    const Frame& frame = robot.frames[static_cast<std::size_t>(s.frame)];
    const std::size_t body = static_cast<std::size_t>(frame.body);
    // Body frame → surface frame; as `robot init` estimates a sole, an inertia box along the surface.
    const RigidTransform surfaceInBody = frame.placement * s.placement;
    std::string source;
    const std::vector<VisualShape> shapes = bodyGeometryShapes(robot, collisions, frame.body, surfaceInBody.rotation, source);
    const RigidTransform toSurface = surfaceInBody.inverse();
    Json boxes = Json::array();
    for (const VisualShape& shape : shapes) {
      Json corners = Json::array();
      for (const Vector3& c : shapeCorners(shape)) {
        const Vector3 p = toSurface.apply(c);
        corners.push_back({p.x(), p.y(), p.z()});
      }
      boxes.push_back(corners);
    }
    out["surfaces"].push_back({{"name", s.name}, {"link", frame.name}, {"body", robot.bodies[body].name},
                               {"rectangle", {s.xMin, s.xMax, s.yMin, s.yMax}}, {"geometry", source}, {"boxes", boxes}});
  }
  return out;
}

Json checkJson(const SupportCheck& c) {
  Json j = {{"posture", c.posture}, {"support", c.support}, {"checked", c.checked}};
  if (!c.note.empty()) j["note"] = c.note;
  if (!c.checked) return j;
  j["holdable"] = c.check.holdable();
  j["support_margin_m"] = c.check.supportMargin;
  j["center_of_mass_m"] = {c.check.centerOfMass.x(), c.check.centerOfMass.y(), c.check.centerOfMass.z()};
  j["largest_static_torque"] = {{"joint", c.check.nearestLimit.joint}, {"torque_N_m", c.check.nearestLimit.torque},
                                {"limit_N_m", std::isfinite(c.check.nearestLimit.limit) ? Json(c.check.nearestLimit.limit) : Json(nullptr)}};
  Json excess = Json::array();
  for (const auto& t : c.check.torques) excess.push_back({{"joint", t.joint}, {"torque_N_m", t.torque}, {"limit_N_m", t.limit}});
  j["torques_beyond_limits"] = excess;
  j["static_electrical_power_W"] = c.check.staticPower;
  if (!c.check.innerStatus.empty()) j["inner_status"] = c.check.innerStatus;
  if (c.loopReach) j["loop_reach"] = *c.loopReach;
  return j;
}

int runRobotCheck(RobotCheckOptions o) {
  resolveFiles(o);
  const RobotModel robot = loadUrdfFile(o.robot, {o.allowNonPhysicalInertia});
  for (const std::string& w : robot.warnings) std::cerr << "mcopt: warning: " << w << "\n";
  const ActuatorSet actuators = o.actuators.empty() ? defaultActuators(robot) : loadActuators(o.actuators, robot);
  for (const std::string& n : urdfFrictionNotes(actuators, robot)) std::cerr << "mcopt: note: " << n << "\n";
  const std::vector<ContactSurface> surfaces = loadContactSurfaces(o.contacts, robot);
  const std::map<std::string, Eigen::VectorXd> postures = loadPostures(o.postures, robot);
  const std::vector<std::string> feet = findFeet(o, surfaces);
  auto surface = [&](const std::string& name) {
    return *std::find_if(surfaces.begin(), surfaces.end(), [&](const ContactSurface& s) { return s.name == name; });
  };
  const fs::path scratch = fs::temp_directory_path() / ("mcopt-robot-check-" + std::to_string(::getpid()));
  fs::create_directories(scratch);
  if (o.actuators.empty()) std::ofstream(scratch / "actuators.yaml") << "joints: {}\n";
  struct Cleanup {
    fs::path dir;
    ~Cleanup() {
      std::error_code ignored;
      fs::remove_all(dir, ignored);
    }
  } cleanup{scratch};

  std::vector<SupportCheck> results;
  for (const auto& [name, q] : postures) {
    const auto [height, tilt] = footOffset(robot, q, surface(feet[0]), surface(feet[1]));
    // Both feet flat on one horizontal ground (a step is fine, a slope is not what the support
    // polygon seen from above measures).
    if (tilt > 0.01) {
      SupportCheck skipped;
      skipped.posture = name, skipped.support = feet, skipped.checked = false;
      std::ostringstream note;
      note << feet[1] << " tilted " << std::setprecision(3) << tilt << " rad from " << feet[0] << ": not on one ground";
      skipped.note = note.str();
      results.push_back(skipped);
    } else {
      results.push_back(checkSupport(o, scratch, name, feet, robot, surface(feet[0])));
      if (std::abs(height) > 1e-3) {
        std::ostringstream note;
        note << feet[1] << " " << std::setprecision(3) << 100.0 * height << " cm above " << feet[0];
        results.back().note = note.str();
      }
    }
    results.push_back(checkSupport(o, scratch, name, {feet[0]}, robot, surface(feet[0])));
    results.push_back(checkSupport(o, scratch, name, {feet[1]}, robot, surface(feet[1])));
  }

  Json report = {{"robot", robot.name},
                 {"files", {{"robot", o.robot}, {"actuators", o.actuators.empty() ? Json(nullptr) : Json(o.actuators)},
                            {"contacts", o.contacts}, {"postures", o.postures}}},
                 {"feet", feet},
                 {"joints", robotInfoJson(robot, actuators)["joints"]},
                 {"checks", Json::array()}};
  for (const SupportCheck& c : results) report["checks"].push_back(checkJson(c));
  if (!o.out.empty()) writeFileAtomically(o.out, report.dump(2) + "\n");
  if (!o.plot.empty()) {
    fs::create_directories(o.plot);
    const fs::path data = scratch / "contacts.json";
    std::ofstream(data) << contactGeometryJson(robot, o.robot, surfaces).dump() << "\n";
    const auto [exit, written] = runPythonScript("plot_contacts.py", {data.string(), o.plot});
    if (!exit.exited || exit.code != 0) {
      std::cerr << "mcopt: error: robot check --plot: the figure was not drawn (" << pythonFailure("plot_contacts.py", exit) << ")\n";
      return 1;
    }
    std::cerr << written;
  }
  if (o.json) {
    std::cout << report.dump(2) << "\n";
    return 0;
  }
  printJointValues(robot, actuators);
  std::cout << "robot " << robot.name << " (" << o.robot << "), feet " << feet[0] << " and " << feet[1]
            << "; each posture at rest (margin: the centre of mass inside (+) or outside (−) the support polygon;\n"
            << "stretch: on both feet, the second leg's hip-ankle distance over its longest, which closure_reach_margin bounds)\n\n"
            << "  posture               support                  margin    largest static torque / limit       power     stretch\n";
  for (const SupportCheck& c : results) {
    std::string support;
    for (const std::string& s : c.support) support += (support.empty() ? "" : " + ") + s;
    std::cout << "  " << std::left << std::setw(22) << c.posture << std::setw(25) << support << std::right;
    if (!c.checked) {
      std::cout << "not checked: " << c.note << "\n";
      continue;
    }
    std::ostringstream torque;
    torque << std::fixed << std::setprecision(1) << c.check.nearestLimit.joint << " " << c.check.nearestLimit.torque << " / "
           << (std::isfinite(c.check.nearestLimit.limit) ? std::to_string(static_cast<int>(std::lround(c.check.nearestLimit.limit))) : "∞");
    std::cout << std::fixed << std::setprecision(1) << std::showpos << std::setw(6) << 100.0 * c.check.supportMargin
              << " cm" << std::noshowpos << "   " << std::left << std::setw(32) << torque.str() << std::right
              << std::setw(8) << c.check.staticPower << " W";
    if (c.loopReach) std::cout << std::setprecision(4) << std::setw(10) << *c.loopReach;
    if (!c.check.holdable()) std::cout << "   cannot hold it";
    if (c.check.innerStatus == "infeasible") std::cout << " (no admissible wrenches)";
    for (const auto& t : c.check.torques) std::cout << "; " << t.joint << " beyond its limit";
    if (!c.note.empty()) std::cout << "   (" << c.note << ")";
    std::cout << "\n";
  }
  return 0;
}

}  // namespace

Runner addRobotCheck(CLI::App& command) {
  auto o = std::make_shared<RobotCheckOptions>();
  command.add_option("folder", o->folder,
                     "a robot folder: one .urdf, contacts.yaml, postures.yaml and (optional) actuators.yaml");
  command.add_option("--robot", o->robot, "URDF file (instead of the folder's)");
  command.add_option("--actuators", o->actuators, "actuator YAML file (docs/reference/robot-files.md)");
  command.add_option("--contacts", o->contacts, "contact surfaces YAML file");
  command.add_option("--postures", o->postures, "named postures YAML file");
  command.add_option("--feet", o->feet, "the two contact surfaces the robot stands on, the first the reference (default: the two named *sole* or *foot*, in the contact file's order)")
      ->delimiter(',');
  command.add_flag("--json", o->json, "print JSON instead of the table");
  command.add_flag("--allow-nonphysical-inertia", o->allowNonPhysicalInertia,
                   "load a URDF whose inertias a real body cannot have (not positive definite, or breaking the "
                   "triangle inequality), with a warning for each");
  command.add_option("--out", o->out, "also write the JSON to this file (atomically)");
  command.add_option("--plot", o->plot,
                     "draw each contact surface against its link's geometry (top and side views) into this folder: "
                     "contacts.png and contacts.svg (matplotlib)");
  return [o] { return runRobotCheck(*o); };
}

}  // namespace mcopt::cli
