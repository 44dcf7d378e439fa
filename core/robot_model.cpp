// SPDX-License-Identifier: BSD-3-Clause
#include "core/robot_model.hpp"

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <set>
#include <sstream>

#include "core/errors.hpp"
#include "core/path_status.hpp"
#include "core/text_encoding.hpp"

namespace mcopt {

void BodyInertia::add(const BodyInertia& other, const RigidTransform& placement) {
  const double totalMass = mass + other.mass;
  const Vector3 otherCom = placement.apply(other.com);
  const Matrix3 otherInertia = placement.rotation * other.inertiaAboutCom * placement.rotation.transpose();
  if (totalMass <= 0.0) {  // two massless parts: keep only rotational terms (normally zero)
    inertiaAboutCom += otherInertia;
    return;
  }
  const Vector3 newCom = (mass * com + other.mass * otherCom) / totalMass;
  // Parallel-axis theorem: I_c' = I_c + m (|d|² 1 − d dᵀ), d from the new com.
  auto shifted = [&newCom](const Matrix3& inertia, double m, const Vector3& c) {
    const Vector3 d = c - newCom;
    return Matrix3(inertia + m * (d.squaredNorm() * Matrix3::Identity() - d * d.transpose()));
  };
  inertiaAboutCom = shifted(inertiaAboutCom, mass, com) + shifted(otherInertia, other.mass, otherCom);
  com = newCom;
  mass = totalMass;
}

RobotModel withPointMass(RobotModel robot, int frame, const Vector3& point, double mass) {
  if (frame < 0 || frame >= static_cast<int>(robot.frames.size()))
    throw InputError(robot.source + ": withPointMass: no frame " + std::to_string(frame));
  const Frame& f = robot.frames[static_cast<std::size_t>(frame)];
  BodyInertia pointMass;
  pointMass.mass = mass;
  pointMass.com = point;
  robot.bodies[static_cast<std::size_t>(f.body)].inertia.add(pointMass, f.placement);
  return robot;
}

double RobotModel::totalMass() const {
  double sum = 0.0;
  for (const Body& body : bodies) sum += body.inertia.mass;
  return sum;
}

int RobotModel::findFrame(const std::string& frameName) const {
  for (int i = 0; i < static_cast<int>(frames.size()); ++i)
    if (frames[i].name == frameName) return i;
  return -1;
}

int RobotModel::findJoint(const std::string& jointName) const {
  for (int i = 0; i < jointCount(); ++i)
    if (joints[i].name == jointName) return i;
  return -1;
}

namespace {

/// Levenshtein distance, case-insensitive: how many single-character edits turn a into b.
std::size_t editDistance(const std::string& a, const std::string& b) {
  auto lower = [](char c) { return static_cast<char>(std::tolower(static_cast<unsigned char>(c))); };
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

}  // namespace

std::string RobotModel::unknownFrameHint(const std::string& frameName) const {
  std::vector<std::pair<std::size_t, std::string>> ranked;
  for (const Frame& f : frames) ranked.emplace_back(editDistance(frameName, f.name), f.name);
  std::stable_sort(ranked.begin(), ranked.end(),
                   [](const auto& x, const auto& y) { return x.first < y.first; });
  std::string names;
  for (std::size_t k = 0; k < std::min<std::size_t>(3, ranked.size()); ++k)
    names += (k ? ", " : "") + ranked[k].second;
  const std::string file = source.empty() ? "the URDF" : std::filesystem::path(source).filename().string();
  return "(no such link in " + file + (names.empty() ? "" : "; the nearest link names: " + names) + ")";
}

int RobotModel::frameIndex(const std::string& frameName) const {
  const int index = findFrame(frameName);
  if (index < 0) throw InputError(source + ": unknown body '" + frameName + "' " + unknownFrameHint(frameName));
  return index;
}

int RobotModel::jointIndex(const std::string& jointName) const {
  const int index = findJoint(jointName);
  if (index < 0)
    throw InputError(source + ": unknown joint '" + jointName + "' (no such actuated joint in the URDF)");
  return index;
}

std::vector<std::string> RobotModel::jointNames() const {
  std::vector<std::string> names;
  names.reserve(joints.size());
  for (const Joint& joint : joints) names.push_back(joint.name);
  return names;
}

namespace {

// urdfdom reports its parse errors through console_bridge; collect them so the
// exception we throw carries urdfdom's own explanation.
class CollectingOutputHandler : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_WARN) messages.push_back(text);
  }
  std::vector<std::string> messages;
};

RigidTransform toTransform(const urdf::Pose& pose) {
  RigidTransform t;
  double x, y, z, w;
  pose.rotation.getQuaternion(x, y, z, w);
  t.rotation = Eigen::Quaterniond(w, x, y, z).normalized().toRotationMatrix();
  t.translation = Vector3(pose.position.x, pose.position.y, pose.position.z);
  return t;
}

// Below this excess over the triangle inequality an inertia slip changes no humanoid
// torque measurably (1e-5 kg m² ≈ 0.1 kg at 1 cm): published CAD exports round small
// parts (Talos' gripper motor, 5.7e-6) and stand-in links carry token values (iCub).
constexpr double kNegligibleInertiaExcess = 1e-5;  // kg m²

BodyInertia readInertia(const urdf::Link& link, const std::string& source, const UrdfOptions& options,
                        std::vector<std::string>& warnings) {
  BodyInertia inertia;
  if (!link.inertial) return inertia;  // massless link: allowed (formulation.md §1)
  const urdf::Inertial& in = *link.inertial;
  const std::string where = source + ": link '" + link.name + "' <inertial>";
  if (!std::isfinite(in.mass)) throw InputError(where + ": mass is not a finite number");
  if (in.mass < 0.0) throw InputError(where + ": negative mass " + std::to_string(in.mass) + " kg");
  Matrix3 local;
  local << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
  if (!local.allFinite()) throw InputError(where + ": inertia has a non-finite entry");
  if (in.mass > 0.0) {
    // A real body's inertia is positive definite with principal moments obeying the
    // triangle inequality; its limits (a point mass, a thin rod) are accepted.
    const Eigen::Vector3d moments = Eigen::SelfAdjointEigenSolver<Matrix3>(local).eigenvalues();  // ascending
    const double tolerance = std::max(1e-9 * moments.cwiseAbs().maxCoeff(), 1e-12);  // round-off on zero moments
    auto report = [&](const std::string& what, double excess) {
      std::ostringstream msg;
      msg << where << ": " << what << " for mass " << in.mass << " kg (principal moments " << moments.transpose()
          << " kg m²)";
      if (excess <= kNegligibleInertiaExcess || options.allowNonPhysicalInertia)
        warnings.push_back(msg.str());
      else
        throw InputError(msg.str() + "; fix the file or allow non-physical inertias explicitly (--allow-nonphysical-inertia, "
                         "or a scenario's allow_nonphysical_inertia: true)");
    };
    if (moments(0) < -tolerance) report("inertia is not positive definite", -moments(0));
    const double excess = moments(2) - moments(0) - moments(1);
    if (excess > tolerance)
      report("inertia breaks the triangle inequality (the two smallest principal moments must add up to at "
             "least the largest)",
             excess);
  }
  const RigidTransform comFrame = toTransform(in.origin);
  inertia.mass = in.mass;
  inertia.com = comFrame.translation;
  inertia.inertiaAboutCom = comFrame.rotation * local * comFrame.rotation.transpose();
  return inertia;
}

RobotModel buildModel(const urdf::ModelInterface& urdfModel, const std::string& source, const UrdfOptions& options) {
  RobotModel model;
  model.name = urdfModel.getName();
  model.source = source;
  const urdf::LinkConstSharedPtr root = urdfModel.getRoot();
  if (!root) throw InputError(source + ": the URDF has no root link");

  model.bodies.push_back(Body{root->name, readInertia(*root, source, options, model.warnings), -1});
  model.frames.push_back(Frame{root->name, 0, RigidTransform::identity()});

  // Depth-first from the root, children in urdfdom's order (formulation.md §1).
  std::vector<std::string> mimicOnFixed;  // a <mimic> tag on a fixed joint: merged, the tag has no effect
  std::function<void(const urdf::Link&, int, const RigidTransform&)> visit =
      [&](const urdf::Link& link, int body, const RigidTransform& linkInBody) {
        for (const urdf::JointSharedPtr& urdfJoint : link.child_joints) {
          const urdf::LinkConstSharedPtr child = urdfModel.getLink(urdfJoint->child_link_name);
          const RigidTransform origin = toTransform(urdfJoint->parent_to_joint_origin_transform);
          const std::string where = source + ": joint '" + urdfJoint->name + "'";
          if (urdfJoint->mimic && urdfJoint->type != urdf::Joint::FIXED)
            model.warnings.push_back(where + ": <mimic> ignored, the joint is independent");
          if (urdfJoint->type == urdf::Joint::FIXED) {
            if (urdfJoint->mimic) mimicOnFixed.push_back(urdfJoint->name);
            const RigidTransform childInBody = linkInBody * origin;
            model.bodies[body].inertia.add(readInertia(*child, source, options, model.warnings), childInBody);
            model.frames.push_back(Frame{child->name, body, childInBody});
            visit(*child, body, childInBody);
            continue;
          }
          Joint joint;
          joint.name = urdfJoint->name;
          switch (urdfJoint->type) {
            case urdf::Joint::REVOLUTE: joint.type = JointType::Revolute; break;
            case urdf::Joint::CONTINUOUS: joint.type = JointType::Continuous; break;
            case urdf::Joint::PRISMATIC: joint.type = JointType::Prismatic; break;
            case urdf::Joint::FLOATING:
              throw InputError(where + ": floating joints are not supported (the robot is rooted at a fixed "
                                       "reference body, formulation.md §2)");
            case urdf::Joint::PLANAR: throw InputError(where + ": planar joints are not supported");
            default: throw InputError(where + ": unknown joint type");
          }
          const Vector3 axis(urdfJoint->axis.x, urdfJoint->axis.y, urdfJoint->axis.z);
          if (!axis.allFinite() || axis.norm() < 1e-12) throw InputError(where + ": <axis> is zero or not finite");
          joint.axis = axis.normalized();
          joint.placement = linkInBody * origin;
          joint.parentBody = body;
          joint.childBody = model.bodyCount();
          if (urdfJoint->limits) {
            if (joint.type != JointType::Continuous) {
              joint.limits.lower = urdfJoint->limits->lower;
              joint.limits.upper = urdfJoint->limits->upper;
              if (joint.limits.lower > joint.limits.upper)
                throw InputError(where + ": <limit> lower is above upper");
            }
            if (urdfJoint->limits->velocity > 0.0) joint.limits.velocity = urdfJoint->limits->velocity;
            if (urdfJoint->limits->effort > 0.0) joint.limits.effort = urdfJoint->limits->effort;
          }
          if (urdfJoint->dynamics) {
            joint.damping = urdfJoint->dynamics->damping;
            joint.friction = urdfJoint->dynamics->friction;
          }
          const int jointIndex = model.jointCount();
          model.joints.push_back(joint);
          model.bodies.push_back(Body{child->name, readInertia(*child, source, options, model.warnings), jointIndex});
          model.frames.push_back(Frame{child->name, joint.childBody, RigidTransform::identity()});
          visit(*child, joint.childBody, RigidTransform::identity());
        }
      };
  visit(*root, 0, RigidTransform::identity());
  if (!mimicOnFixed.empty()) {
    std::string names;
    for (const std::string& n : mimicOnFixed) names += (names.empty() ? "" : ", ") + n;
    model.warnings.push_back(source + ": <mimic> on " + std::to_string(mimicOnFixed.size()) + " fixed joint" +
                             (mimicOnFixed.size() > 1 ? "s" : "") + " (" + names +
                             "): a fixed joint is merged into its parent body, the tag has no effect");
  }
  // Every link must hang from the root: urdfdom accepts links whose joints form a loop apart
  // from it (found by fuzzing, tests/fuzz/regressions/), and they would be silently missing.
  if (model.frames.size() != urdfModel.links_.size()) {
    std::string missing;
    for (const auto& entry : urdfModel.links_)
      if (std::none_of(model.frames.begin(), model.frames.end(), [&](const Frame& f) { return f.name == entry.first; }))
        missing += (missing.empty() ? "" : ", ") + entry.first;
    throw InputError(source + ": links not connected to the root link '" + root->name + "' (their joints form a loop): " + missing);
  }
  return model;
}

}  // namespace

RobotModel loadUrdfString(const std::string& xml, const std::string& sourceName, const UrdfOptions& options) {
  // XML without an encoding declaration is UTF-8, and names go on to JSON (text_encoding.hpp).
  if (const auto fault = firstInvalidUtf8(xml)) {
    char hex[8];
    std::snprintf(hex, sizeof hex, "0x%02X", fault->byte);
    throw InputError(sourceName + ":" + std::to_string(fault->line) + ": not valid UTF-8 (byte " + hex +
                     "); mcopt reads URDF files as UTF-8");
  }
  // console_bridge's output handler is global: serialise loads.
  static std::mutex parseMutex;
  std::lock_guard<std::mutex> lock(parseMutex);
  CollectingOutputHandler handler;
  console_bridge::useOutputHandler(&handler);
  urdf::ModelInterfaceSharedPtr parsed;
  try {
    parsed = urdf::parseURDF(xml);
  } catch (const std::exception& e) {
    handler.messages.push_back(e.what());
  }
  console_bridge::restorePreviousOutputHandler();
  if (!parsed) {
    std::string why;
    for (const std::string& m : handler.messages) why += (why.empty() ? "" : "; ") + m;
    if (why.empty()) why = "malformed URDF";
    throw InputError(sourceName + ": not a valid URDF: " + why);
  }
  // urdfdom links parents and children by shared pointers: a kinematic loop in the file (which
  // it accepts) would keep its links alive for ever. Unlink them once the model is read.
  struct Unlink {
    urdf::ModelInterface& model;
    ~Unlink() {
      for (auto& [name, link] : model.links_) link->child_links.clear(), link->child_joints.clear();
    }
  } unlink{*parsed};
  return buildModel(*parsed, sourceName, options);
}

RobotModel loadUrdfFile(const std::filesystem::path& path, const UrdfOptions& options) {
  if (pathExists(path) && !isRegularFile(path)) throw InputError(path.string() + ": not a file");
  std::ifstream in(path);
  if (!in) throw InputError(path.string() + ": cannot open URDF file (missing or unreadable)");
  std::stringstream content;
  content << in.rdbuf();
  return loadUrdfString(content.str(), path.string(), options);
}

}  // namespace mcopt
