// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// RobotModel: the robot as its URDF describes it, with fixed joints merged
// (formulation.md §1–§2). Immutable once loaded; the dynamics work on a
// DynamicsModel built from it for a chosen reference body.

#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "core/spatial.hpp"

namespace mcopt {

enum class JointType { Revolute, Continuous, Prismatic };

/// Mass properties of a body, in its own frame.
struct BodyInertia {
  double mass = 0.0;
  Vector3 com = Vector3::Zero();                 ///< centre of mass, body frame [m]
  Matrix3 inertiaAboutCom = Matrix3::Zero();     ///< rotational inertia about the com, body axes [kg m²]

  /// Adds `other`, whose frame sits at `placement` in this body's frame (parallel-axis theorem).
  void add(const BodyInertia& other, const RigidTransform& placement);
};

/// A rigid body: one URDF link plus every link attached to it by fixed joints.
struct Body {
  std::string name;        ///< the link whose frame is the body frame
  BodyInertia inertia;
  int parentJoint = -1;    ///< joint moving this body w.r.t. its URDF parent body; -1 for the URDF root body
};

struct JointLimits {
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
  double velocity = std::numeric_limits<double>::infinity();
  double effort = std::numeric_limits<double>::infinity();
};

/// An actuated joint, as written in the URDF.
struct Joint {
  std::string name;
  JointType type = JointType::Revolute;
  int parentBody = -1;
  int childBody = -1;
  RigidTransform placement;        ///< joint frame in the parent body frame at q = 0
  Vector3 axis = Vector3::UnitZ(); ///< unit axis in the joint frame (= child body frame)
  JointLimits limits;              ///< URDF <limit>; ±inf where absent
  double damping = 0.0;            ///< URDF <dynamics damping>, joint side [N m s/rad]
  double friction = 0.0;           ///< URDF <dynamics friction>, joint side [N m]
};

/// Every URDF link is a frame on the body it was merged into.
struct Frame {
  std::string name;
  int body = -1;
  RigidTransform placement;  ///< link frame in the body frame
};

class RobotModel {
 public:
  std::string name;
  std::string source;                 ///< file the model was read from, for messages
  std::vector<Body> bodies;           ///< bodies[0] is the URDF root body; bodies[j + 1] is moved by joints[j]
  std::vector<Joint> joints;          ///< actuated joints in URDF depth-first order (formulation.md §1)
  std::vector<Frame> frames;          ///< one per URDF link
  std::vector<std::string> warnings;  ///< things ignored while loading (mimic tags)

  int jointCount() const { return static_cast<int>(joints.size()); }
  int bodyCount() const { return static_cast<int>(bodies.size()); }
  double totalMass() const;

  /// Index of the frame (URDF link) or joint with that name; throws InputError naming
  /// the model's file when there is none.
  int frameIndex(const std::string& frameName) const;
  int jointIndex(const std::string& jointName) const;
  int findFrame(const std::string& frameName) const;  ///< -1 when absent
  int findJoint(const std::string& jointName) const;  ///< -1 when absent
  std::vector<std::string> jointNames() const;
  /// What to say after "unknown body 'NAME'": "(no such link in FILE; the nearest link
  /// names: a, b, c)" — the three link names closest to NAME by edit distance, so that a typo
  /// or another robot's naming convention (l_sole against left_sole_link) leads somewhere.
  std::string unknownFrameHint(const std::string& frameName) const;
};

/// The robot carrying a point mass `mass` [kg] at `point` of frame `frame` (its frame's
/// coordinates), added to the frame's body: a held object, e.g. the ball of a throw
/// (formulation.md §10).
RobotModel withPointMass(RobotModel robot, int frame, const Vector3& point, double mass);

struct UrdfOptions {
  /// Inertias that are not positive definite or break the triangle inequality by more than
  /// 1e-5 kg m² are errors; with this set they become warnings (Romeo's published URDF
  /// needs it: RShoulderYawLink is 80 % short of the inequality).
  bool allowNonPhysicalInertia = false;
};

/// Parses a URDF with urdfdom. Throws InputError naming the file and the element for:
/// a missing file, malformed XML, duplicate names, floating/planar joints, negative mass,
/// an inertia that is not physically valid for a positive mass (see UrdfOptions).
RobotModel loadUrdfFile(const std::filesystem::path& path, const UrdfOptions& options = {});
RobotModel loadUrdfString(const std::string& xml, const std::string& sourceName, const UrdfOptions& options = {});

}  // namespace mcopt
