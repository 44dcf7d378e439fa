// SPDX-License-Identifier: BSD-3-Clause
// `mcopt dynamics`: inverse dynamics of given states with the reference body held
// fixed (formulation.md §4), and with --contacts the torques that given contact wrenches
// leave to the motors (§5). Formats: docs/reference/input-files.md.
#include <algorithm>
#include <iostream>
#include <optional>

#include "apps/commands.hpp"
#include "apps/json_io.hpp"
#include "core/atomic_file.hpp"
#include "core/contact_maps.hpp"
#include "core/robot_files.hpp"
#include "core/dynamics_derivatives.hpp"

namespace mcopt::cli {

namespace {

struct DynamicsOptions {
  std::string robot, referenceBody, states, out, contacts;
  bool allowNonPhysicalInertia = false;
  bool derivatives = false;
};

RigidTransform readPose(const std::filesystem::path& file, const json_io::Json& node, const std::string& field) {
  RigidTransform pose;
  if (!node.is_object()) throw InputError(file.string() + ": " + field + ": expected an object");
  for (const auto& [key, value] : node.items())
    if (key != "position" && key != "quaternion_xyzw")
      throw InputError(file.string() + ": " + field + "." + key + ": unknown key (expected position, quaternion_xyzw)");
  if (node.contains("position")) pose.translation = json_io::numbers(file, node["position"], field + ".position", 3);
  if (node.contains("quaternion_xyzw")) {
    const Eigen::VectorXd q = json_io::numbers(file, node["quaternion_xyzw"], field + ".quaternion_xyzw", 4);
    if (q.norm() < 1e-9) throw InputError(file.string() + ": " + field + ".quaternion_xyzw: zero quaternion");
    pose.rotation = rotationFromQuaternionXyzw(q[0], q[1], q[2], q[3]);
  }
  return pose;
}

/// Contact wrenches per state (docs/reference/input-files.md, "Contact wrenches"): each listed surface
/// with its wrench in its own frame at every state, or null where it is not in contact.
struct StateContacts {
  std::vector<ContactSurface> surfaces;
  std::vector<std::vector<std::optional<Vector6>>> wrenches;  ///< [contact][state]
};

StateContacts readContacts(const std::filesystem::path& file, const RobotModel& robot, std::size_t stateCount) {
  const json_io::Json input = json_io::readFile(file);
  if (!input.is_object()) throw InputError(file.string() + ": expected a JSON object");
  for (const auto& [key, value] : input.items())
    if (key != "contact_surfaces" && key != "contacts")
      throw InputError(file.string() + ": " + key + ": unknown key (expected contact_surfaces, contacts)");
  if (!input.contains("contact_surfaces") || !input["contact_surfaces"].is_string())
    throw InputError(file.string() + ": contact_surfaces: expected the path of a contact surface file");
  // Relative to the contacts file, never to the working directory.
  const std::filesystem::path surfacesFile = file.parent_path() / input["contact_surfaces"].get<std::string>();
  const std::vector<ContactSurface> surfaces = loadContactSurfaces(surfacesFile, robot);
  if (!input.contains("contacts") || !input["contacts"].is_array())
    throw InputError(file.string() + ": contacts: expected a list of {surface, wrenches}");
  StateContacts out;
  for (std::size_t i = 0; i < input["contacts"].size(); ++i) {
    const auto& entry = input["contacts"][i];
    const std::string field = "contacts[" + std::to_string(i) + "]";
    if (!entry.is_object() || !entry.contains("surface") || !entry["surface"].is_string() || !entry.contains("wrenches"))
      throw InputError(file.string() + ": " + field + ": expected {surface: NAME, wrenches: [...]}");
    const std::string name = entry["surface"];
    const auto surface =
        std::find_if(surfaces.begin(), surfaces.end(), [&](const ContactSurface& c) { return c.name == name; });
    if (surface == surfaces.end())
      throw InputError(file.string() + ": " + field + ".surface: unknown contact surface '" + name + "' (in " +
                       surfacesFile.string() + ")");
    const auto& list = entry["wrenches"];
    if (!list.is_array() || list.size() != stateCount)
      throw InputError(file.string() + ": " + field + ".wrenches: expected one wrench (or null) per state, " +
                       std::to_string(stateCount) + " in all");
    out.surfaces.push_back(*surface);
    out.wrenches.emplace_back();
    for (std::size_t s = 0; s < list.size(); ++s) {
      if (list[s].is_null()) {
        out.wrenches.back().push_back(std::nullopt);
        continue;
      }
      const Eigen::VectorXd w =
          json_io::numbers(file, list[s], field + ".wrenches[" + std::to_string(s) + "]", 6);
      out.wrenches.back().push_back(Vector6(w));
    }
  }
  return out;
}

int runDynamics(const DynamicsOptions& o) {
  const RobotModel robot = loadUrdfFile(o.robot, {o.allowNonPhysicalInertia});
  for (const std::string& w : robot.warnings) std::cerr << "mcopt: warning: " << w << "\n";
  const std::filesystem::path file = o.states;
  const json_io::Json input = json_io::readFile(file);
  if (!input.is_object()) throw InputError(file.string() + ": expected a JSON object");
  for (const auto& [key, value] : input.items())
    if (key != "joint_names" && key != "gravity" && key != "reference_pose" && key != "states")
      throw InputError(file.string() + ": " + key + ": unknown key (expected joint_names, gravity, reference_pose, states)");

  std::vector<int> columns;  // input position → URDF joint index
  std::vector<std::string> names;
  if (input.contains("joint_names")) {
    if (!input["joint_names"].is_array()) throw InputError(file.string() + ": joint_names: expected a list of names");
    std::vector<bool> seen(static_cast<std::size_t>(robot.jointCount()), false);
    for (std::size_t k = 0; k < input["joint_names"].size(); ++k) {
      const auto& name = input["joint_names"][k];
      const std::string field = "joint_names[" + std::to_string(k) + "]";
      if (!name.is_string()) throw InputError(file.string() + ": " + field + ": expected a joint name");
      const int j = robot.findJoint(name);
      if (j < 0) throw InputError(file.string() + ": " + field + ": unknown joint '" + name.get<std::string>() + "'");
      if (seen[static_cast<std::size_t>(j)])
        throw InputError(file.string() + ": " + field + ": joint '" + name.get<std::string>() + "' listed twice");
      seen[static_cast<std::size_t>(j)] = true;
      columns.push_back(j);
      names.push_back(name);
    }
  } else {
    for (int j = 0; j < robot.jointCount(); ++j) columns.push_back(j);
    names = robot.jointNames();
  }
  const Vector3 gravity =
      input.contains("gravity") ? Vector3(json_io::numbers(file, input["gravity"], "gravity", 3)) : Vector3(0, 0, -9.81);
  const RigidTransform referencePose =
      input.contains("reference_pose") ? readPose(file, input["reference_pose"], "reference_pose") : RigidTransform{};
  const std::string referenceBody = o.referenceBody.empty() ? robot.frames[0].name : o.referenceBody;
  const DynamicsModel model(robot, referenceBody, referencePose, gravity);
  DynamicsData data(model);
  DynamicsDerivatives derivatives(model);
  Eigen::Matrix<double, 6, Eigen::Dynamic> wrenchDerivative;
  // Rows: outputs in joint_names order (or wrench components); columns: inputs in joint_names order.
  auto selectTau = [&](const Eigen::MatrixXd& full) {
    Eigen::MatrixXd out(static_cast<Eigen::Index>(columns.size()), static_cast<Eigen::Index>(columns.size()));
    for (std::size_t r = 0; r < columns.size(); ++r)
      for (std::size_t c = 0; c < columns.size(); ++c)
        out(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = full(columns[r], columns[c]);
    return json_io::matrixToJson(out);
  };
  auto selectWrench = [&](const Eigen::Matrix<double, 6, Eigen::Dynamic>& atOrigin) {
    wrenchDerivativeAtReferenceFrame(model, atOrigin, wrenchDerivative);
    Eigen::MatrixXd out(6, static_cast<Eigen::Index>(columns.size()));
    for (std::size_t c = 0; c < columns.size(); ++c)
      out.col(static_cast<Eigen::Index>(c)) = wrenchDerivative.col(columns[c]);
    return json_io::matrixToJson(out);
  };

  if (!input.contains("states") || !input["states"].is_array())
    throw InputError(file.string() + ": states: expected a list of {q, v, a}");
  const long count = static_cast<long>(columns.size());
  const StateContacts contacts =
      o.contacts.empty() ? StateContacts{} : readContacts(o.contacts, robot, input["states"].size());
  if (!contacts.surfaces.empty() && o.derivatives)
    throw InputError("--derivatives and --contacts: the derivatives are those of Γ0 and W0 only; give one or the other");
  WrenchToTorque toTorque = WrenchToTorque::Zero(robot.jointCount(), 6);
  Eigen::VectorXd withContacts(robot.jointCount());
  json_io::Json results = json_io::Json::array();
  Eigen::VectorXd q(robot.jointCount()), v(robot.jointCount()), a(robot.jointCount()), tau(count);
  for (std::size_t s = 0; s < input["states"].size(); ++s) {
    const auto& state = input["states"][s];
    const std::string field = "states[" + std::to_string(s) + "]";
    if (!state.is_object()) throw InputError(file.string() + ": " + field + ": expected an object {q, v, a}");
    q.setZero();
    v.setZero();
    a.setZero();
    for (const char* key : {"q", "v", "a"}) {
      if (!state.contains(key)) continue;  // absent: zero
      const Eigen::VectorXd values = json_io::numbers(file, state[key], field + "." + key, count);
      Eigen::VectorXd& target = key[0] == 'q' ? q : key[0] == 'v' ? v : a;
      for (long k = 0; k < count; ++k) target[columns[static_cast<std::size_t>(k)]] = values[k];
    }
    if (o.derivatives)
      inverseDynamicsDerivatives(model, data, derivatives, q, v, a);
    else
      inverseDynamics(model, data, q, v, a);
    for (long k = 0; k < count; ++k) tau[k] = data.tau[columns[static_cast<std::size_t>(k)]];
    json_io::Json result = {{"tau", json_io::toJson(tau)},
                            {"reference_wrench", json_io::toJson(referenceWrenchAtReferenceFrame(model, data))}};
    if (!contacts.surfaces.empty()) {
      // Γ = Γ0 − Σ_i J1_i F_i (formulation.md §5) over the contacts given at this state.
      withContacts = data.tau;
      for (std::size_t i = 0; i < contacts.surfaces.size(); ++i) {
        const std::optional<Vector6>& wrench = contacts.wrenches[i][s];
        if (!wrench) continue;
        const ContactSurface& c = contacts.surfaces[i];
        wrenchToTorque(model, data, contactFrame(model, data, c.frame, c.placement), toTorque);
        withContacts.noalias() -= toTorque * *wrench;
      }
      result["tau0"] = result["tau"];
      for (long k = 0; k < count; ++k) tau[k] = withContacts[columns[static_cast<std::size_t>(k)]];
      result["tau"] = json_io::toJson(tau);
    }
    if (o.derivatives) {
      result["dtau_dq"] = selectTau(derivatives.dtauDq);
      result["dtau_dv"] = selectTau(derivatives.dtauDv);
      result["dtau_da"] = selectTau(derivatives.dtauDa);
      result["dwrench_dq"] = selectWrench(derivatives.dwrenchDq);
      result["dwrench_dv"] = selectWrench(derivatives.dwrenchDv);
      result["dwrench_da"] = selectWrench(derivatives.dwrenchDa);
    }
    results.push_back(result);
  }
  json_io::Json out;
  out["joint_names"] = names;
  out["results"] = results;
  const std::string text = out.dump(1) + "\n";
  if (o.out.empty())
    std::cout << text;
  else
    writeFileAtomically(o.out, text);
  return 0;
}

}  // namespace

Runner addDynamics(CLI::App& command) {
  auto o = std::make_shared<DynamicsOptions>();
  command.add_option("--robot", o->robot, "URDF file")->required()->check(CLI::ExistingFile);
  command.add_option("--reference-body", o->referenceBody,
                     "link held fixed at reference_pose (default: the URDF root); any link, sole frames included");
  command.add_option("--states", o->states, "input JSON (docs/reference/input-files.md)")->required();
  command.add_option("--out", o->out, "output JSON (default: standard output)");
  command.add_option("--contacts", o->contacts,
                     "contact wrenches per state (JSON, docs/reference/input-files.md): tau becomes Γ = Γ0 − J1 F, tau0 is Γ0")
      ->check(CLI::ExistingFile);
  command.add_flag("--derivatives", o->derivatives,
                   "add dtau_dq, dtau_dv, dtau_da, dwrench_dq, dwrench_dv, dwrench_da (exact, analytic)");
  command.add_flag("--allow-nonphysical-inertia", o->allowNonPhysicalInertia,
                   "load inertias that break positivity or the triangle inequality, with a warning");
  return [o] { return runDynamics(*o); };
}

}  // namespace mcopt::cli
