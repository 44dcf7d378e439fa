// SPDX-License-Identifier: BSD-3-Clause
// A scenario's `contacts:` list (docs/reference/scenario-file.md, "Contacts"): each contact's
// surface, window, world pose and model, the reference contact first, and each environment
// contact's closure as tasks over its window (formulation.md §10).
#include <algorithm>
#include <cmath>

#include "core/errors.hpp"
#include "core/kinematics.hpp"
#include "core/spatial.hpp"
#include "core/yaml_fields.hpp"
#include "outer_nlp/scenario.hpp"
#include "outer_nlp/scenario_yaml.hpp"

namespace mcopt {

namespace {

using yaml::where;

/// The world pose of a contact frame in a posture (the reference body at its scenario pose).
RigidTransform contactPoseAt(const Scenario& s, const ContactSurface& surface, const Eigen::VectorXd& posture) {
  const DynamicsModel model(s.robot, s.referenceBody, s.referencePose, s.gravity);
  DynamicsData data(model);
  forwardKinematics(model, data, posture);
  return framePose(model, data, surface.frame) * surface.placement;
}

/// The closure of a contact as two tasks over its window (formulation.md §10): the contact
/// frame's origin at its world position, the body's orientation at the one that puts the
/// contact frame at its world orientation. The motion problem holds them by construction
/// (closed_chains.hpp); the configuration problem keeps them within the band. At each end of a
/// window inside the motion, where the splines meet the closure, four tasks of equality: the
/// frame at its pose and at rest (the motion C¹ there: its accelerations jump with the wrench).
void addClosureTasks(const EnvironmentContact& c, Scenario& s) {
  const int frame = c.surface.frame;
  TaskSpec position;
  position.name = "closure of " + c.surface.name + " (position)";
  position.origin = c.origin;
  position.closure = true;
  position.heldByConstruction = true;
  position.task = makePositionTask(frame, c.surface.placement.translation);
  position.start = c.start, position.end = c.end, position.window = c.end > c.start;
  position.lower = c.worldPose.translation.array() - s.closurePositionTolerance;
  position.upper = c.worldPose.translation.array() + s.closurePositionTolerance;
  TaskSpec orientation = position;
  orientation.name = "closure of " + c.surface.name + " (orientation)";
  orientation.task = makeOrientationTask(frame, c.worldPose.rotation * c.surface.placement.rotation.transpose());
  orientation.lower.setConstant(3, -s.closureOrientationTolerance);
  orientation.upper.setConstant(3, s.closureOrientationTolerance);
  s.tasks.push_back(position);
  s.tasks.push_back(orientation);
  if (!c.window) return;
  for (const double end : {c.start, c.end}) {
    if (end <= 0.0 || end >= s.duration.initial) continue;
    const std::string at = std::string(" at its window's ") + (end == c.start ? "start" : "end");
    TaskSpec meet = position;
    meet.heldByConstruction = false;
    meet.start = meet.end = end, meet.window = false;
    TaskSpec p = meet, o = orientation, v = meet, w = meet;
    p.name = "closure of " + c.surface.name + at + " (position)";
    p.lower = p.upper = c.worldPose.translation;
    o.heldByConstruction = false;
    o.start = o.end = end, o.window = false;
    o.name = "closure of " + c.surface.name + at + " (orientation)";
    o.lower.setZero(3), o.upper.setZero(3);
    v.name = "closure of " + c.surface.name + at + " (velocity)";
    v.task = makeLinearVelocityTask(frame, c.surface.placement.translation);
    v.lower.setZero(3), v.upper.setZero(3);
    w.name = "closure of " + c.surface.name + at + " (angular velocity)";
    w.task = makeAngularVelocityTask(frame);
    w.lower.setZero(3), w.upper.setZero(3);
    for (const TaskSpec* t : {&p, &o, &v, &w}) s.tasks.push_back(*t);
  }
}

}  // namespace

void readContacts(const std::filesystem::path& file, const YAML::Node& list, const std::vector<ContactSurface>& surfaces,
                  Scenario& s) {
  const int referenceBody = s.robot.frames[static_cast<std::size_t>(s.robot.frameIndex(s.referenceBody))].body;
  bool haveReference = false;
  std::vector<std::string> seen;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YAML::Node entry = list[i];
    const std::string field = "contacts[" + std::to_string(i) + "]";
    // (A YAML::Node handle is never re-assigned: assignment writes through to the node it refers to.)
    if (entry.IsMap()) yaml::rejectUnknownKeys(file, entry, field, {"surface", "window", "pose", "model"});
    const YAML::Node nameNode = entry.IsMap() ? yaml::required(file, entry, "surface", field) : entry;
    const std::string name = yaml::text(file, nameNode, entry.IsMap() ? field + ".surface" : field);
    const auto surface = std::find_if(surfaces.begin(), surfaces.end(), [&](const ContactSurface& c) { return c.name == name; });
    if (surface == surfaces.end())
      throw InputError(where(file, nameNode, field) + "unknown contact surface '" + name + "'");
    if (std::find(seen.begin(), seen.end(), name) != seen.end())
      throw InputError(where(file, nameNode, field) + "contact '" + name + "' is listed twice");
    seen.push_back(name);
    const bool onReference = s.robot.frames[static_cast<std::size_t>(surface->frame)].body == referenceBody;
    if (onReference) {
      if (haveReference)
        throw InputError(where(file, nameNode, field) + "a second contact on the reference body '" + s.referenceBody + "'");
      if (entry.IsMap() && (entry["window"] || entry["pose"]))
        throw InputError(where(file, entry["window"] ? entry["window"] : entry["pose"], field) + "contact '" + name +
                         "' is on the reference body, which is fixed in the world for the whole motion: it takes no "
                         "window and no pose (reference_pose places it)");
      if (entry.IsMap() && entry["model"])
        throw InputError(where(file, entry["model"], field + ".model") + "contact '" + name +
                         "' is on the reference body, whose contact model is the scenario's (inner.contact_model)");
      s.support = *surface;
      haveReference = true;
      continue;
    }
    EnvironmentContact c;
    c.surface = *surface;
    c.origin = where(file, entry, field);
    c.origin.resize(c.origin.size() - 2);
    if (entry.IsMap() && entry["model"]) {
      const YAML::Node model = entry["model"];
      const std::string modelName = yaml::text(file, model, field + ".model");
      if (!isContactModelName(modelName))
        throw InputError(where(file, model, field + ".model") + "unknown contact model '" + modelName + "' (expected " +
                         contactModelList() + ")");
      if (modelName == "pyramid")
        throw InputError(where(file, model, field + ".model") +
                         "a contact's own model takes no parameters: the pyramid is inner.contact_model's, with "
                         "inner.pyramid_facets");
      s.inner.problem.byContact[name] = makeContactModel(modelName);
    }
    c.end = s.duration.initial;
    if (entry.IsMap() && entry["window"]) {
      const YAML::Node w = entry["window"];
      const auto t = yaml::numbers(file, w, field + ".window", 2);
      const double T = s.duration.initial;
      if (!(t[0] >= 0.0 && t[0] < t[1] && t[1] <= T * (1 + 1e-12)))
        throw InputError(where(file, w, field + ".window") + "expected [start, end] with 0 ≤ start < end ≤ " +
                         std::to_string(T) + " s (the motion)");
      int inside = 0;
      for (int k = 0; k < s.samples; ++k) {
        const double tk = T * k / (s.samples - 1);
        inside += tk >= t[0] - 1e-9 * T && tk <= t[1] + 1e-9 * T;
      }
      if (inside == 0)
        throw InputError(where(file, w, field + ".window") + "holds no sample of the motion (" + std::to_string(s.samples) +
                         " samples over " + std::to_string(T) + " s)");
      c.start = t[0], c.end = t[1], c.window = true;
    }
    if (entry.IsMap() && entry["pose"]) {
      const YAML::Node pose = entry["pose"];
      yaml::rejectUnknownKeys(file, pose, field + ".pose", {"position", "rpy"});
      const auto p = yaml::numbers(file, yaml::required(file, pose, "position", field + ".pose"), field + ".pose.position", 3);
      const auto r = yaml::numbers(file, yaml::required(file, pose, "rpy", field + ".pose"), field + ".pose.rpy", 3);
      c.worldPose.translation = Vector3(p[0], p[1], p[2]);
      c.worldPose.rotation = rotationFromRpy(r[0], r[1], r[2]);
      c.poseGiven = true;
    } else {
      c.worldPose = contactPoseAt(s, c.surface, s.start);
    }
    s.contacts.push_back(c);
  }
  if (!haveReference)
    throw InputError(where(file, list, "contacts") + "no contact on the reference body '" + s.referenceBody +
                     "' (the reference body's surface must be one of the contacts)");
  for (const EnvironmentContact& c : s.contacts) addClosureTasks(c, s);
}

}  // namespace mcopt
