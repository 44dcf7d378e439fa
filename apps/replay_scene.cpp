// SPDX-License-Identifier: BSD-3-Clause
#include "apps/replay_scene.hpp"

#include <cmath>
#include <map>

#include "apps/json_io.hpp"
#include "apps/robot_visuals.hpp"
#include "core/dynamics_data.hpp"
#include "core/dynamics_model.hpp"
#include "core/errors.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"
#include "core/robot_files.hpp"

namespace mcopt::cli {

namespace {

using Json = nlohmann::json;
using json_io::numbers;

// 10 µm and 1e-5 of a unit quaternion: finer than a pixel of any view, and it keeps the page
// small (JSON prints the shortest decimal that reads back as the rounded value).
double rounded(double v) { return std::round(v * 1e5) / 1e5; }

Json vector3(const Vector3& v) { return Json::array({rounded(v.x()), rounded(v.y()), rounded(v.z())}); }

/// Position and quaternion (x, y, z, w) of a pose, one flat array of 7.
Json pose7(const RigidTransform& pose) {
  const Eigen::Quaterniond q(pose.rotation);
  return Json::array({rounded(pose.translation.x()), rounded(pose.translation.y()), rounded(pose.translation.z()), rounded(q.x()),
                      rounded(q.y()), rounded(q.z()), rounded(q.w())});
}

const Json& member(const std::filesystem::path& file, const Json& node, const std::string& field) {
  if (!node.is_object() || !node.contains(field))
    throw InputError(file.string() + ": " + field + ": missing (a result of an older mcopt run? run it again)");
  return node[field];
}

std::string text(const std::filesystem::path& file, const Json& node, const std::string& field) {
  if (!node.is_string()) throw InputError(file.string() + ": " + field + ": expected a string");
  return node.get<std::string>();
}

Json shapeJson(const VisualShape& s) {
  static const char* kinds[] = {"box", "cylinder", "sphere"};
  return Json{{"kind", kinds[static_cast<int>(s.kind)]},
              {"size", vector3(s.size)},
              {"pose", pose7(s.placement)},
              {"rgba", s.rgba},
              {"source", s.source}};
}

}  // namespace

Json replayScene(const Json& result, const std::filesystem::path& file) {
  const Json& robotFiles = member(file, result, "robot_files");
  const std::filesystem::path urdf = text(file, member(file, robotFiles, "urdf"), "robot_files.urdf");
  const std::filesystem::path surfacesFile = text(file, member(file, robotFiles, "contact_surfaces"), "robot_files.contact_surfaces");
  UrdfOptions options;
  options.allowNonPhysicalInertia = true;  // drawn, not simulated
  RobotModel robot = loadUrdfFile(urdf, options);
  const int n = robot.jointCount();

  const Json& names = member(file, result, "joint_names");
  if (!names.is_array() || names.size() != static_cast<std::size_t>(n))
    throw InputError(file.string() + ": joint_names: expected the " + std::to_string(n) + " joints of " + urdf.string());
  for (int j = 0; j < n; ++j)
    if (names[static_cast<std::size_t>(j)] != robot.joints[static_cast<std::size_t>(j)].name)
      throw InputError(file.string() + ": joint_names[" + std::to_string(j) + "]: '" + names[static_cast<std::size_t>(j)].dump() +
                       "' where " + urdf.string() + " has '" + robot.joints[static_cast<std::size_t>(j)].name + "'");

  const Json& poseNode = member(file, result, "reference_pose");
  RigidTransform referencePose;
  referencePose.translation = numbers(file, member(file, poseNode, "position"), "reference_pose.position", 3);
  const Eigen::VectorXd quaternion = numbers(file, member(file, poseNode, "quaternion_xyzw"), "reference_pose.quaternion_xyzw", 4);
  referencePose.rotation = rotationFromQuaternionXyzw(quaternion[0], quaternion[1], quaternion[2], quaternion[3]);
  const Vector3 gravity = numbers(file, member(file, result, "gravity"), "gravity", 3);
  const std::string referenceBody = text(file, member(file, result, "reference_body"), "reference_body");

  const Eigen::VectorXd time = numbers(file, member(file, result, "time"), "time");
  const Json& q = member(file, result, "q");
  const auto N = static_cast<std::size_t>(time.size());
  if (N < 2) throw InputError(file.string() + ": time: a replay needs at least 2 samples");
  if (!q.is_array() || q.size() != N) throw InputError(file.string() + ": q: expected one posture per sample (" + std::to_string(N) + ")");
  std::vector<Eigen::VectorXd> postures(N);
  for (std::size_t k = 0; k < N; ++k) postures[k] = numbers(file, q[k], "q[" + std::to_string(k) + "]", n);

  const std::vector<std::vector<VisualShape>> shapes = bodyVisualShapes(urdf, robot);
  const std::vector<ContactSurface> surfaces = loadContactSurfaces(surfacesFile, robot);
  const DynamicsModel model(robot, referenceBody, referencePose, gravity);
  DynamicsData data(model);

  Json bodies = Json::array();
  std::vector<int> bodyFrames;
  for (std::size_t b = 0; b < robot.bodies.size(); ++b) {
    bodyFrames.push_back(robot.frameIndex(robot.bodies[b].name));
    Json body{{"name", robot.bodies[b].name}, {"shapes", Json::array()}, {"poses", Json::array()}};
    for (const VisualShape& s : shapes[b]) body["shapes"].push_back(shapeJson(s));
    bodies.push_back(body);
  }

  struct ContactTrack {
    const ContactSurface* surface;
    const Json* node;
    Json out;
  };
  const Json& contactNodes = member(file, result, "contacts");
  if (!contactNodes.is_array()) throw InputError(file.string() + ": contacts: expected a list");
  std::vector<ContactTrack> contacts;
  for (std::size_t c = 0; c < contactNodes.size(); ++c) {
    const std::string field = "contacts[" + std::to_string(c) + "]";
    const Json& node = contactNodes[c];
    const std::string name = text(file, member(file, node, "name"), field + ".name");
    const ContactSurface* surface = nullptr;
    for (const ContactSurface& s : surfaces) surface = s.name == name ? &s : surface;
    if (!surface) throw InputError(file.string() + ": " + field + ".name: '" + name + "' is not a surface of " + surfacesFile.string());
    const Json& active = member(file, node, "active");
    const Json& wrench = member(file, node, "wrench");
    const Json& cop = member(file, node, "center_of_pressure");
    if (!active.is_array() || active.size() != N || !wrench.is_array() || wrench.size() != N || !cop.is_array() || cop.size() != N)
      throw InputError(file.string() + ": " + field + ": active, wrench and center_of_pressure need one entry per sample");
    Json out{{"name", name},
             {"reference", node.value("reference", false)},
             {"rectangle", Json::array({surface->xMin, surface->xMax, surface->yMin, surface->yMax})},
             {"active", Json::array()},
             {"poses", Json::array()},
             {"force", Json::array()},
             {"cop", Json::array()}};
    contacts.push_back({surface, &node, out});
  }

  // A throw's ball (result.json `release`): carried by its body up to the release, then its
  // flight, which the page computes at any instant from the release state.
  const Json* release = result.contains("release") && !result["release"].is_null() ? &result["release"] : nullptr;
  int ballFrame = -1;
  Vector3 ballPoint = Vector3::Zero();
  Json ball;
  if (release) {
    const std::string body = text(file, member(file, *release, "body"), "release.body");
    ballFrame = robot.findFrame(body);
    if (ballFrame < 0) throw InputError(file.string() + ": release.body: '" + body + "' is not a link of " + urdf.string());
    ballPoint = numbers(file, member(file, *release, "point"), "release.point", 3);
    const double releaseTime = member(file, *release, "time").get<double>();
    ball = {{"release_time", releaseTime},
            {"position", vector3(numbers(file, member(file, *release, "position"), "release.position", 3))},
            {"velocity", vector3(numbers(file, member(file, *release, "velocity"), "release.velocity", 3))},
            {"flight_time", member(file, *release, "flight_time").get<double>()},
            {"target", vector3(numbers(file, member(file, *release, "target"), "release.target", 3))},
            {"carried", Json::array()}};
  }

  Json centerOfMassTrack = Json::array();
  double floorHeight = 0.0;
  for (std::size_t k = 0; k < N; ++k) {
    forwardKinematics(model, data, postures[k]);
    for (std::size_t b = 0; b < robot.bodies.size(); ++b) bodies[b]["poses"].push_back(pose7(framePose(model, data, bodyFrames[b])));
    centerOfMassTrack.push_back(vector3(centerOfMass(model, data)));
    if (release) ball["carried"].push_back(vector3(framePose(model, data, ballFrame).apply(ballPoint)));
    for (std::size_t c = 0; c < contacts.size(); ++c) {
      ContactTrack& track = contacts[c];
      const std::string field = "contacts[" + std::to_string(c) + "]";
      const RigidTransform pose = framePose(model, data, track.surface->frame) * track.surface->placement;
      if (k == 0 && track.out["reference"].get<bool>()) floorHeight = pose.translation.z();
      const Json& isActive = (*track.node)["active"][k];
      const bool on = isActive.is_boolean() && isActive.get<bool>();
      track.out["active"].push_back(on);
      track.out["poses"].push_back(pose7(pose));
      const Json& w = (*track.node)["wrench"][k];
      const Json& p = (*track.node)["center_of_pressure"][k];
      if (!on || w.is_null()) {
        track.out["force"].push_back(nullptr);
        track.out["cop"].push_back(nullptr);
        continue;
      }
      const Eigen::VectorXd wrench = numbers(file, w, field + ".wrench[" + std::to_string(k) + "]", 6);
      track.out["force"].push_back(vector3(pose.rotation * wrench.head<3>()));
      // Unloaded: no centre of pressure (the page draws no arrow for a zero force).
      Json copWorld = nullptr;
      if (!p.is_null()) {
        const Eigen::VectorXd xy = numbers(file, p, field + ".center_of_pressure[" + std::to_string(k) + "]", 2);
        copWorld = vector3(pose.apply(Vector3(xy[0], xy[1], 0.0)));
      }
      track.out["cop"].push_back(copWorld);
    }
  }

  Json scene;
  scene["robot"] = robot.name;
  scene["scenario"] = result.value("scenario", "");
  scene["status"] = result.value("status", "");
  scene["energy"] = result.value("energy", 0.0);
  scene["time"] = Json::array();
  for (std::size_t k = 0; k < N; ++k) scene["time"].push_back(time[static_cast<Eigen::Index>(k)]);
  scene["floor_height"] = rounded(floorHeight);
  scene["gravity"] = vector3(gravity);
  scene["bodies"] = bodies;
  scene["contacts"] = Json::array();
  for (const ContactTrack& track : contacts) scene["contacts"].push_back(track.out);
  scene["center_of_mass"] = centerOfMassTrack;
  scene["ball"] = release ? ball : Json(nullptr);
  return scene;
}

}  // namespace mcopt::cli
