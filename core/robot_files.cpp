// SPDX-License-Identifier: BSD-3-Clause
#include "core/robot_files.hpp"

#include "core/yaml_fields.hpp"

namespace mcopt {

namespace {

std::vector<ContactSurface> readContactSurfaces(const std::filesystem::path& path, const RobotModel& robot) {
  const YAML::Node root = yaml::loadFile(path);
  yaml::rejectUnknownKeys(path, root, "", {"contact_surfaces", "sources"});
  const YAML::Node surfaces = yaml::required(path, root, "contact_surfaces", "");
  if (!surfaces.IsMap())
    throw InputError(yaml::where(path, surfaces, "contact_surfaces") + "expected a mapping name → surface");
  std::vector<ContactSurface> out;
  for (const auto& entry : surfaces) {
    const std::string name = entry.first.as<std::string>();
    const std::string field = "contact_surfaces." + name;
    const YAML::Node& node = entry.second;
    yaml::rejectUnknownKeys(path, node, field, {"link", "position", "rpy", "rectangle", "friction"});
    ContactSurface s;
    s.name = name;
    const YAML::Node link = yaml::required(path, node, "link", field);
    s.frame = robot.findFrame(yaml::text(path, link, field + ".link"));
    if (s.frame < 0)
      throw InputError(yaml::where(path, link, field + ".link") + "unknown body '" + link.as<std::string>() + "' " +
                       robot.unknownFrameHint(link.as<std::string>()));
    if (node["position"]) {
      const auto p = yaml::numbers(path, node["position"], field + ".position", 3);
      s.placement.translation = Vector3(p[0], p[1], p[2]);
    }
    if (node["rpy"]) {
      const auto r = yaml::numbers(path, node["rpy"], field + ".rpy", 3);
      s.placement.rotation = rotationFromRpy(r[0], r[1], r[2]);
    }
    const YAML::Node rectangleNode = yaml::required(path, node, "rectangle", field);
    const auto rect = yaml::numbers(path, rectangleNode, field + ".rectangle", 4);
    s.xMin = rect[0];
    s.xMax = rect[1];
    s.yMin = rect[2];
    s.yMax = rect[3];
    if (!(s.xMin < s.xMax && s.yMin < s.yMax))
      throw InputError(yaml::where(path, rectangleNode, field + ".rectangle") +
                       "expected [x_min, x_max, y_min, y_max] with x_min < x_max and y_min < y_max");
    if (node["friction"]) s.friction = yaml::positive(path, node["friction"], field + ".friction");
    out.push_back(s);
  }
  return out;
}

std::map<std::string, Eigen::VectorXd> readPostures(const std::filesystem::path& path, const RobotModel& robot) {
  const YAML::Node root = yaml::loadFile(path);
  yaml::rejectUnknownKeys(path, root, "", {"postures", "sources"});
  const YAML::Node postures = yaml::required(path, root, "postures", "");
  if (!postures.IsMap()) throw InputError(yaml::where(path, postures, "postures") + "expected a mapping name → joints");
  std::map<std::string, Eigen::VectorXd> out;
  for (const auto& entry : postures) {
    const std::string name = entry.first.as<std::string>();
    Eigen::VectorXd q = Eigen::VectorXd::Zero(robot.jointCount());
    if (entry.second.IsMap()) {
      for (const auto& joint : entry.second) {
        const std::string jointName = joint.first.as<std::string>();
        const std::string field = "postures." + name + "." + jointName;
        const int index = robot.findJoint(jointName);
        if (index < 0) throw InputError(yaml::where(path, joint.first, field) + "unknown joint");
        q[index] = yaml::number(path, joint.second, field);
      }
    } else if (!entry.second.IsNull()) {
      throw InputError(yaml::where(path, entry.second, "postures." + name) + "expected a mapping joint → value [rad]");
    }
    out.emplace(name, q);
  }
  return out;
}

}  // namespace

std::vector<ContactSurface> loadContactSurfaces(const std::filesystem::path& path, const RobotModel& robot) {
  return yaml::reading(path, [&] { return readContactSurfaces(path, robot); });
}

std::map<std::string, Eigen::VectorXd> loadPostures(const std::filesystem::path& path, const RobotModel& robot) {
  return yaml::reading(path, [&] { return readPostures(path, robot); });
}

Eigen::VectorXd yaml::postureWithOffsets(const std::filesystem::path& file, const YAML::Node& node,
                                         const std::string& field, const RobotModel& robot,
                                         const std::map<std::string, Eigen::VectorXd>& postures) {
  const YAML::Node nameNode = yaml::required(file, node, "posture", field);
  const std::string name = yaml::text(file, nameNode, field + ".posture");
  const auto found = postures.find(name);
  if (found == postures.end())
    throw InputError(yaml::where(file, nameNode, field + ".posture") + "unknown posture '" + name + "'");
  Eigen::VectorXd q = found->second;
  if (node["offsets"]) {
    if (!node["offsets"].IsMap())
      throw InputError(yaml::where(file, node["offsets"], field + ".offsets") + "expected a mapping joint → offset [rad]");
    for (const auto& entry : node["offsets"]) {
      const std::string joint = entry.first.as<std::string>();
      const int j = robot.findJoint(joint);
      if (j < 0) throw InputError(yaml::where(file, entry.first, field + ".offsets." + joint) + "unknown joint");
      q[j] += yaml::number(file, entry.second, field + ".offsets." + joint);
    }
  }
  return q;
}

}  // namespace mcopt
