// SPDX-License-Identifier: BSD-3-Clause
#include "apps/robot_init.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>

#include <unistd.h>

#include "apps/json_io.hpp"
#include "apps/robot_visuals.hpp"
#include "core/actuators.hpp"
#include "core/dynamics_data.hpp"
#include "core/dynamics_model.hpp"
#include "core/errors.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"

namespace mcopt::cli {

namespace {

namespace fs = std::filesystem;
using json_io::Json;

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string number(double x, int digits = 4) {
  if (std::abs(x) < 1e-12) x = 0.0;  // no "-0"
  std::ostringstream s;
  s << std::setprecision(digits) << x;
  return s.str();
}

std::string vector3(const Vector3& v) {
  return "[" + number(v.x(), 6) + ", " + number(v.y(), 6) + ", " + number(v.z(), 6) + "]";
}

std::string quoted(const std::string& s) { return Json(s).dump(); }

/// The robot at its zero posture, its root body's frame the world.
struct ZeroPosture {
  DynamicsModel model;
  DynamicsData data;
  explicit ZeroPosture(const RobotModel& robot)
      : model(robot, robot.bodies.front().name), data(model) {
    forwardKinematics(model, data, Eigen::VectorXd::Zero(robot.jointCount()));
  }
  RigidTransform frame(int f) const { return framePose(model, data, f); }
  RigidTransform body(int b) const { return frame(model.robot().findFrame(model.robot().bodies[static_cast<std::size_t>(b)].name)); }
};

/// Points of a body's geometry in its frame: the corners of bodyGeometryShapes (its collision
/// primitives, or its inertia's box along `axes`); `what` says which.
std::vector<Vector3> bodyGeometry(const RobotModel& robot, const std::vector<std::vector<VisualShape>>& collisions, int body,
                                  std::string& what, const Matrix3& axes = Matrix3::Identity()) {
  std::vector<Vector3> points;
  for (const VisualShape& shape : bodyGeometryShapes(robot, collisions, body, axes, what))
    for (const Vector3& c : shapeCorners(shape)) points.push_back(c);
  return points;
}

/// The words of a name, split at _ - . and lower-cased: "l_sole" → {"l", "sole"}.
std::vector<std::string> nameWords(const std::string& name) {
  std::vector<std::string> out(1);
  for (char c : lower(name)) {
    if (c == '_' || c == '-' || c == '.') out.emplace_back();
    else out.back() += c;
  }
  return out;
}

/// +1 when a name says left (a word "l" or "left", or a first letter L of a capitalised
/// word as in LLEG), −1 when it says right, 0 when it says neither.
int nameSide(const std::string& name) {
  for (const std::string& w : nameWords(name)) {
    if (w == "l" || w == "left") return 1;
    if (w == "r" || w == "right") return -1;
  }
  for (std::size_t k = 0; k + 1 < name.size(); ++k)
    if ((k == 0 || name[k - 1] == '_') && std::isupper(static_cast<unsigned char>(name[k])) &&
        std::isupper(static_cast<unsigned char>(name[k + 1]))) {
      if (name[k] == 'L') return 1;
      if (name[k] == 'R') return -1;
    }
  return 0;
}

/// The bodies from `body` up to the root, `body` first.
std::vector<int> chainToRoot(const RobotModel& robot, int body) {
  std::vector<int> chain{body};
  while (robot.bodies[static_cast<std::size_t>(body)].parentJoint >= 0) {
    body = robot.joints[static_cast<std::size_t>(robot.bodies[static_cast<std::size_t>(body)].parentJoint)].parentBody;
    chain.push_back(body);
  }
  return chain;
}

/// A sole on foot body `body`: a vertical *sole* link fixed to it, or a frame at the bottom of
/// its geometry; the rectangle: the geometry's footprint around the frame's origin.
ContactEstimate findSole(const RobotModel& robot, const ZeroPosture& zero,
                         const std::vector<std::vector<VisualShape>>& collisions, int body, const std::string& name,
                         double leftSign, std::vector<std::string>& notes) {
  // The URDF's sole link: fixed to the foot, named *sole*, horizontal at the zero posture.
  int soleLink = -1;
  for (std::size_t f = 0; f < robot.frames.size() && soleLink < 0; ++f) {
    if (robot.frames[f].body != body || lower(robot.frames[f].name).find("sole") == std::string::npos) continue;
    if (zero.frame(static_cast<int>(f)).rotation(2, 2) >= std::cos(0.02)) soleLink = static_cast<int>(f);
    else notes.push_back("the link " + robot.frames[f].name + " is not horizontal at the zero posture: not used as the sole");
  }
  // The inertia box (where the foot has no primitives) lies along the sole: the sole link's
  // axes, else the ground's (x forward, y left; the root's turned half a turn where its y
  // points right) at the zero posture.
  const RigidTransform bodyPose = zero.body(body);
  const Matrix3 groundAxes = soleLink >= 0  ? zero.frame(soleLink).rotation
                             : leftSign > 0 ? Matrix3::Identity()
                                            : Matrix3(Eigen::AngleAxisd(std::numbers::pi, Vector3::UnitZ()));
  std::string geometry;
  const std::vector<Vector3> local = bodyGeometry(robot, collisions, body, geometry, bodyPose.rotation.transpose() * groundAxes);
  std::vector<Vector3> world;
  for (const Vector3& p : local) world.push_back(bodyPose.apply(p));
  double bottom = world.front().z();
  for (const Vector3& p : world) bottom = std::min(bottom, p.z());

  ContactEstimate estimate;
  estimate.surface.name = name;
  estimate.surface.friction = 0.7;
  RigidTransform soleWorld;
  if (soleLink >= 0) {
    const RigidTransform pose = zero.frame(soleLink);
    estimate.link = robot.frames[static_cast<std::size_t>(soleLink)].name;
    estimate.surface.frame = soleLink;
    estimate.surface.placement = RigidTransform::identity();
    soleWorld = pose;
    estimate.source = "the URDF's sole link " + estimate.link;
    if (std::abs(pose.translation.z() - bottom) > 0.01)
      notes.push_back("the sole link " + estimate.link + " lies " + number(100.0 * (pose.translation.z() - bottom), 3) +
                      " cm above the lowest point of " + geometry);
  }
  if (estimate.link.empty()) {
    // A frame at the bottom of the geometry, under its footprint's centre, world-aligned.
    double xMin = 1e9, xMax = -1e9, yMin = 1e9, yMax = -1e9;
    for (const Vector3& p : world) xMin = std::min(xMin, p.x()), xMax = std::max(xMax, p.x()), yMin = std::min(yMin, p.y()), yMax = std::max(yMax, p.y());
    soleWorld.rotation = groundAxes;
    soleWorld.translation = Vector3(0.5 * (xMin + xMax), 0.5 * (yMin + yMax), bottom);
    estimate.link = robot.bodies[static_cast<std::size_t>(body)].name;
    estimate.surface.frame = robot.findFrame(estimate.link);
    estimate.surface.placement = bodyPose.inverse() * soleWorld;
    estimate.source = "a frame estimated at the bottom of " + geometry;
  }
  double xMin = 1e9, xMax = -1e9, yMin = 1e9, yMax = -1e9;
  for (const Vector3& p : world) {
    const Vector3 s = soleWorld.inverse().apply(p);
    xMin = std::min(xMin, s.x()), xMax = std::max(xMax, s.x()), yMin = std::min(yMin, s.y()), yMax = std::max(yMax, s.y());
  }
  estimate.surface.xMin = xMin, estimate.surface.xMax = xMax, estimate.surface.yMin = yMin, estimate.surface.yMax = yMax;
  estimate.source += "; rectangle: the footprint of " + geometry + " (estimated)";
  if (xMax - xMin < 0.05 || yMax - yMin < 0.03)
    notes.push_back("the sole " + name + " is only " + number(100.0 * (xMax - xMin), 3) + " × " +
                    number(100.0 * (yMax - yMin), 3) + " cm: check its rectangle in contacts.yaml");
  return estimate;
}

/// On each side, the link whose name says palm, then hand, gripper, wrist; among equals the one
/// nearest the trunk. Legs (the feet's chains) are left out.
std::vector<ContactEstimate> findHands(const RobotModel& robot, const ZeroPosture& zero, const std::vector<int>& legBodies,
                                       double leftSign) {
  const std::vector<std::string> words{"palm", "hand", "gripper", "wrist"};
  // Whole words of the name (split at _ - .): a sensor's or a finger's link is not the hand.
  const std::vector<std::string> refused{"camera", "sensor", "imu", "ft", "finger", "fingertip", "thumb", "tip"};
  std::vector<int> depth(robot.bodies.size(), 0);
  for (std::size_t b = 0; b < robot.bodies.size(); ++b) depth[b] = static_cast<int>(chainToRoot(robot, static_cast<int>(b)).size());
  std::vector<ContactEstimate> hands;
  for (const auto& [side, name] : {std::pair{1.0, std::string("left_hand")}, std::pair{-1.0, std::string("right_hand")}}) {
    int best = -1;
    std::size_t bestWord = words.size();
    double bestDistance = 1e9;
    for (std::size_t f = 0; f < robot.frames.size(); ++f) {
      const Frame& frame = robot.frames[f];
      if (std::find(legBodies.begin(), legBodies.end(), frame.body) != legBodies.end() || frame.body == 0) continue;
      const std::string n = lower(frame.name);
      const std::vector<std::string> parts = nameWords(n);
      if (std::any_of(refused.begin(), refused.end(),
                      [&](const std::string& r) { return std::find(parts.begin(), parts.end(), r) != parts.end(); }))
        continue;
      if (side * leftSign * zero.frame(static_cast<int>(f)).translation.y() < 0.02) continue;
      for (std::size_t w = 0; w < words.size(); ++w) {
        if (n.find(words[w]) == std::string::npos) continue;
        // Among equals the one nearest the trunk: the shallowest body, then nearest its origin.
        const double distance = 100.0 * depth[static_cast<std::size_t>(frame.body)] + frame.placement.translation.norm();
        if (w < bestWord || (w == bestWord && distance < bestDistance)) best = static_cast<int>(f), bestWord = w, bestDistance = distance;
        break;
      }
    }
    if (best < 0) continue;
    ContactEstimate hand;
    hand.link = robot.frames[static_cast<std::size_t>(best)].name;
    hand.surface.name = name;
    hand.surface.frame = best;
    hand.surface.xMin = -0.04, hand.surface.xMax = 0.04, hand.surface.yMin = -0.025, hand.surface.yMax = 0.025;
    hand.surface.friction = 0.5;
    hand.source = "the link " + hand.link + " (its name says " + words[bestWord] +
                  "): its origin and its z axis as the normal, an 8 × 5 cm rectangle (estimated: check the normal)";
    hands.push_back(hand);
  }
  return hands;
}

/// From a hand's frame up its arm's joints to the body where the arm leaves the trunk (the first
/// body carrying more than one joint) [m].
double armLength(const RobotModel& robot, const ZeroPosture& zero, int frame) {
  std::vector<int> children(robot.bodies.size(), 0);
  for (const Joint& j : robot.joints) ++children[static_cast<std::size_t>(j.parentBody)];
  Vector3 point = zero.frame(frame).translation;
  int body = robot.frames[static_cast<std::size_t>(frame)].body;
  double length = 0.0;
  while (robot.bodies[static_cast<std::size_t>(body)].parentJoint >= 0) {
    const Vector3 joint = zero.body(body).translation;
    length += (point - joint).norm();
    point = joint;
    body = robot.joints[static_cast<std::size_t>(robot.bodies[static_cast<std::size_t>(body)].parentJoint)].parentBody;
    if (children[static_cast<std::size_t>(body)] > 1) break;
  }
  return length;
}

/// The hand's speed with every joint between it and the root body (the arm's and the trunk's) at
/// its velocity limit, each joint's contribution (its column of the hand's Jacobian, ω_max,j
/// times |a_j × (p_hand − p_j)| for a revolute joint) added as if their directions aligned
/// [m/s]; 0 when one of them has no velocity limit.
double handSpeed(const RobotModel& robot, const ZeroPosture& zero, int frame) {
  FrameJacobian jacobian;
  frameJacobian(zero.model, zero.data, zero.model.framePosition(frame), zero.frame(frame).translation, jacobian);
  double speed = 0.0;
  for (int j = 0; j < robot.jointCount(); ++j) {
    const double lever = jacobian.col(j).head<3>().norm();
    if (lever == 0.0) continue;  // not between the root and the hand
    const double limit = robot.joints[static_cast<std::size_t>(j)].limits.velocity;
    if (!std::isfinite(limit)) return 0.0;
    speed += limit * lever;
  }
  return speed;
}

// ---------------------------------------------------------------------------------------------
// Writing the folder.

/// A motor class: catalogue-class values of brushed DC motors as recalled by the authors (the
/// same three classes as robots/hrp2/actuators.yaml), not checked against a datasheet.
struct MotorClass {
  const char* name;
  double torqueConstant, resistance, rotorInertia, viscousFriction, dryFriction;
};
constexpr MotorClass kMotorClasses[] = {
    {"20 W class (RE 25 size, 24 V winding)", 0.0234, 2.18, 1.08e-6, 1.0e-6, 0.003},
    {"90 W class (RE 35 size, 24 V winding)", 0.0261, 0.583, 6.96e-6, 2.0e-6, 0.005},
    {"150 W class (RE 40 size, 24 V winding)", 0.0302, 0.299, 1.34e-5, 3.0e-6, 0.008},
};
constexpr double kMotorSpeed = 838.0;  ///< 8000 rpm, the classes' maximum speed [rad/s]

std::string actuatorsYaml(const RobotModel& robot, const std::string& urdfName) {
  std::ostringstream y;
  y << "# Actuators of " << robot.name << ", written by `mcopt robot init` from " << urdfName << "\n"
    << "# (docs/reference/robot-files.md, docs/tutorials/own-robot.md).\n"
    << "#\n"
    << "# Joint side: torque_limit and velocity_limit are the URDF's <limit effort velocity>.\n"
    << "# Motor side: every other value is an ESTIMATE to replace with your datasheet's:\n"
    << "#   gear_ratio N        = 838 rad/s (8000 rpm) / the velocity limit, in [30, 400] (100 without one)\n"
    << "#   torque_constant K [N m/A], resistance R [Ω], rotor_inertia [kg m²] (motor side): the class of a\n"
    << "#     brushed DC motor chosen from the joint's peak power τ_max ω_max: below 300 W the 20 W class,\n"
    << "#     below 700 W the 90 W class, above the 150 W class (the classes of robots/hrp2/actuators.yaml);\n"
    << "#   viscous_friction [N m s/rad], dry_friction [N m]: MOTOR side, the class's; where the URDF has\n"
    << "#     <dynamics damping friction>, those act on the JOINT side and are carried over divided by\n"
    << "#     N² (damping) and N (friction), with a comment on the joint.\n"
    << "# A datasheet gives, per joint: the gear ratio; the motor's torque constant, terminal\n"
    << "# resistance, rotor inertia; its no-load current and speed (for the friction).\n"
    << "friction_sharpness: 100.0   # ν of (3.8) [s/rad], motor side\n"
    << "joints:\n";
  for (const Joint& joint : robot.joints) {
    const JointLimits& l = joint.limits;
    const bool hasVelocity = std::isfinite(l.velocity) && l.velocity > 0.0;
    const bool hasEffort = std::isfinite(l.effort) && l.effort > 0.0;
    const double n = hasVelocity ? std::clamp(std::round(kMotorSpeed / l.velocity), 30.0, 400.0) : 100.0;
    const double power = hasVelocity && hasEffort ? l.effort * l.velocity : 0.0;
    const MotorClass& motor = power >= 700.0 ? kMotorClasses[2] : power >= 300.0 ? kMotorClasses[1] : kMotorClasses[0];
    double viscous = motor.viscousFriction, dry = motor.dryFriction;
    y << "  # " << joint.name << ": ";
    if (hasEffort || hasVelocity)
      y << "URDF <limit" << (hasEffort ? " effort=\"" + number(l.effort, 6) + "\"" : "")
        << (hasVelocity ? " velocity=\"" + number(l.velocity, 6) + "\"" : "") << ">";
    else
      y << "no <limit> effort or velocity in the URDF";
    y << "; " << motor.name;
    if (power > 0.0) y << " (τ ω = " << number(power, 4) << " W)";
    y << "\n";
    if (joint.damping > 0.0 || joint.friction > 0.0) {
      y << "  #   URDF <dynamics damping=\"" << number(joint.damping, 6) << "\" friction=\"" << number(joint.friction, 6)
        << "\">: joint side; on the motor side damping / N² and friction / N\n";
      if (joint.damping > 0.0) viscous = joint.damping / (n * n);
      if (joint.friction > 0.0) dry = joint.friction / n;
    }
    y << "  " << quoted(joint.name) << ": {";
    if (hasEffort) y << "torque_limit: " << number(l.effort, 6) << ", ";
    if (hasVelocity) y << "velocity_limit: " << number(l.velocity, 6) << ", ";
    y << "gear_ratio: " << number(n, 6) << ", torque_constant: " << motor.torqueConstant
      << ", resistance: " << motor.resistance << ", rotor_inertia: " << number(motor.rotorInertia, 4)
      << ", viscous_friction: " << number(viscous, 4) << ", dry_friction: " << number(dry, 4) << "}\n";
  }
  return y.str();
}

std::string contactsYaml(const RobotModel& robot, const std::vector<ContactEstimate>& contacts, const std::string& urdfName) {
  std::ostringstream y;
  y << "# Contact surfaces of " << robot.name << ", written by `mcopt robot init` from " << urdfName << "\n"
    << "# (docs/reference/robot-files.md): a frame on a link (position [m], rpy [rad]), z the surface's\n"
    << "# normal into the robot, a rectangle [x_min, x_max, y_min, y_max] [m] in that frame, the\n"
    << "# Coulomb friction coefficient. ESTIMATED from the URDF: check them against your robot\n"
    << "# (`mcopt robot check --plot` draws the soles against the feet).\n"
    << "contact_surfaces:\n";
  for (const ContactEstimate& c : contacts) {
    const ContactSurface& s = c.surface;
    y << "  # " << c.surface.name << ": " << c.source << "\n"
      << "  " << s.name << ": {link: " << quoted(c.link);
    if (!s.placement.translation.isZero(1e-12)) y << ", position: " << vector3(s.placement.translation);
    if (!s.placement.rotation.isIdentity(1e-12)) y << ", rpy: " << vector3(rpyFromRotation(s.placement.rotation));
    y << ", rectangle: [" << number(s.xMin, 4) << ", " << number(s.xMax, 4) << ", " << number(s.yMin, 4) << ", "
      << number(s.yMax, 4) << "], friction: " << s.friction << "}\n";
  }
  return y.str();
}

std::string posturesYaml(const RobotModel& robot, const RobotInitResult& r, const std::string& urdfName) {
  std::ostringstream y;
  y << "# Named postures of " << robot.name << " [rad, m], written by `mcopt robot init` from " << urdfName << ";\n"
    << "# joints not listed are at zero.\n"
    << "# standing: found by optimisation (outer_nlp/standing_posture.hpp): the posture nearest the zero\n"
    << "# posture with both soles flat on the ground side by side, the centre of mass above the middle\n"
    << "# of the soles (" << number(100.0 * r.standing.centerOfMass.z(), 4) << " cm high), the root body upright and lowered "
    << number(100.0 * r.rootLowering, 3) << " % of its height\n"
    << "# at the zero posture (bent knees). `mcopt robot check` gives its margins, torques and power.\n"
    << "postures:\n";
  // The zero posture inside the limits (a joint whose range leaves out zero at its nearest bound).
  std::string clamped;
  y << "  zero:";
  for (const Joint& joint : robot.joints) {
    const double q = std::clamp(0.0, std::isfinite(joint.limits.lower) ? joint.limits.lower : 0.0,
                                std::isfinite(joint.limits.upper) ? joint.limits.upper : 0.0);
    if (q != 0.0) y << (clamped.empty() ? "\n" : "") << "    " << quoted(joint.name) << ": " << number(q, 9) << "\n", clamped += "x";
  }
  if (clamped.empty()) y << " {}\n";
  if (!clamped.empty()) y << "    # the joints above: at the bound of a range that leaves out zero\n";
  y << "  standing:\n";
  for (int j = 0; j < robot.jointCount(); ++j)
    if (std::abs(r.standing.q[j]) > 1e-6) y << "    " << quoted(robot.joints[static_cast<std::size_t>(j)].name) << ": " << number(r.standing.q[j], 7) << "\n";
  return y.str();
}

/// The scenario header every starter shares: files, reference body (the left sole's link, placed
/// so that the sole lies on the ground at the origin).
std::string scenarioHeader(const std::string& description, const std::string& urdfName, const ContactEstimate& left,
                           bool allowNonPhysicalInertia) {
  std::ostringstream y;
  const RigidTransform linkPose = left.surface.placement.inverse();
  y << "description: " << quoted(description) << "\n"
    << "robot: ../" << urdfName << "\n"
    << "actuators: ../actuators.yaml\n"
    << "contact_surfaces: ../contacts.yaml\n"
    << "postures: ../postures.yaml\n"
    << "reference_body: " << quoted(left.link) << "   # the link of the left sole\n"
    << "reference_pose: {position: " << vector3(linkPose.translation) << ", rpy: " << vector3(rpyFromRotation(linkPose.rotation))
    << "}   # the sole at the origin\n";
  if (allowNonPhysicalInertia)
    y << "allow_nonphysical_inertia: true   # as `robot init --allow-nonphysical-inertia` read the URDF: fix its inertias when you can\n";
  return y.str();
}

struct Scaling {
  double time = 1.0;   ///< √(h / h_HRP-2): the pendulum time of the standing centre of mass
  double length = 1.0; ///< h / h_HRP-2
};

std::string kickYaml(const RobotInitResult& r, const std::string& urdfName, const Scaling& s) {
  const ContactEstimate& left = r.contacts[0];
  const ContactEstimate& right = r.contacts[1];
  const double duration = std::round(1.6 * s.time * 20.0) / 20.0;
  const double toeSpeed = std::round(1.0 * s.time * 20.0) / 20.0;
  const double clearance = std::round(0.03 * s.length * 1000.0) / 1000.0;
  // The right sole's inner edge 1 cm clear of the left sole's inner edge.
  const double apart = std::round((left.surface.yMin - right.surface.yMax - 0.01) * 1000.0) / 1000.0;
  const double toe = right.surface.xMax;
  std::ostringstream y;
  y << "# Starter kick for " << r.robot.name << " (`mcopt robot init`): on its left sole, the right sole's toe\n"
    << "# reaches " << toeSpeed << " m/s forward at mid-motion, then the robot returns to the posture it started\n"
    << "# from. HRP-2's bundled kick (scenarios/hrp2_kick.yaml) scaled to this robot: times by\n"
    << "# √(h / h_HRP-2) = " << number(s.time, 3) << ", speeds likewise (a Froude number kept), heights by h / h_HRP-2 = "
    << number(s.length, 3) << ",\n# h the standing centre of mass's height. Every field: docs/reference/scenario-file.md.\n"
    << scenarioHeader(r.robot.name + " on its left sole kicks forward with the right foot and returns to where it started",
                      urdfName, left, r.allowNonPhysicalInertia)
    << "contacts: [" << left.surface.name << "]\n"
    << "friction_sharpness: 1.0\n"
    << "duration: " << duration << "\n"
    << "samples: 100\n"
    << "control_points: 9\n"
    << "objective: {energy: epigraph}\n"
    << "limits: {position: true, velocity: true, torque: true, contact: true}\n"
    << "tasks:\n"
    << "  - name: kick\n"
    << "    kind: linear_velocity\n"
    << "    body: " << quoted(right.link) << "\n"
    << "    point: " << vector3(right.surface.placement.apply(Vector3(toe, 0.5 * (right.surface.yMin + right.surface.yMax), 0.0)))
    << "   # the toe, in the link's frame [m]\n"
    << "    time: " << duration / 2 << "\n"
    << "    target: [" << toeSpeed << ", 0.0, 0.0]\n"
    << "  - name: right foot in the air\n"
    << "    kind: position\n"
    << "    body: " << quoted(right.link) << "\n"
    << "    point: " << vector3(right.surface.placement.translation) << "   # the sole's origin\n"
    << "    window: [0.0, " << duration << "]\n"
    << "    lower: [null, null, " << clearance << "]\n"
    << "    upper: [null, " << apart << ", null]   # the soles' inner edges 1 cm apart\n"
    << "start: {posture: standing}\n"
    << "end: {same_as: start}\n"
    << "initialisation: {configuration_optimisation: true}   # the start: the standing posture moved onto the left foot\n"
    << "hessian: exact\n"
    << "continuation:\n"
    << "  - {energy: smooth_max, smoothing: 0.01, hessian: gauss-newton, max_iterations: 500}\n"
    << "solver: {max_iter: 3000, tol: 1.0e-6}\n";
  return y.str();
}

std::string weightShiftYaml(const RobotInitResult& r, const std::string& urdfName, const Scaling& s) {
  const ContactEstimate& left = r.contacts[0];
  const ContactEstimate& right = r.contacts[1];
  const double duration = std::round(2.4 * s.time * 20.0) / 20.0;
  // Above each sole: between its centre and its inner edge (its rectangle's inner half).
  const double leftCentre = 0.5 * (left.surface.yMin + left.surface.yMax);
  const double rightCentre = r.standing.secondSole.y() + 0.5 * (right.surface.yMin + right.surface.yMax);
  const double leftInner = left.surface.yMin, rightInner = r.standing.secondSole.y() + right.surface.yMax;
  std::ostringstream y;
  y << "# Starter weight shift for " << r.robot.name << " (`mcopt robot init`): on both soles, the centre of mass\n"
    << "# goes above the left sole, the right one, the left one again, and the robot ends where it began.\n"
    << "# HRP-2's bundled weight shift (scenarios/hrp2_weight_shift.yaml) scaled to this robot: times by\n"
    << "# √(h / h_HRP-2) = " << number(s.time, 3) << " (h the standing centre of mass's height); \"above a sole\": between its\n"
    << "# centre and its inner edge, in the left sole's frame. Every field: docs/reference/scenario-file.md.\n"
    << scenarioHeader(r.robot.name + " on both soles shifts its centre of mass from the left foot to the right and back",
                      urdfName, left, r.allowNonPhysicalInertia)
    << "contacts: [" << left.surface.name << ", " << right.surface.name << "]\n"
    << "contact_forces: bilevel\n"
    // The right leg's loop (closed through the pelvis to the left sole) kept short of full
    // stretch, where the closure folds (docs/theory/outer-problem.md, "Closure by construction"):
    // JVRC-1's weight shift, whose knee is straight at 0.163 rad inside its range, stretched its
    // right leg to 8 mrad of the fold, and no Newton step there ends optimal
    // (docs/developers/lab-notes/robot-init.md).
    << "closure_reach_margin: 1.0e-3   # the right leg kept short of full stretch (about 5 degrees of knee bend)\n"
    // The barrier inner solver's smooth answers (docs/theory/inner-problem.md): with the active-set
    // solver Talos's weight shift cycled at a kink of the criterion; with μ = 0.01 W it ends
    // optimal, as HRP-2's and iCub's do (docs/developers/lab-notes/robot-init.md).
    << "inner: {solver: barrier, barrier: 1.0e-2, contact_model: wrench-cone, kkt_backend: dense}   # HRP-2's bundled file: "
       "active-set; the barrier's smooth answers do not cycle at a kink\n"
    << "friction_sharpness: 1.0\n"
    << "duration: " << duration << "\n"
    << "samples: 60\n"
    << "control_points: 13\n"
    << "objective: {energy: smooth_max, smoothing: 1.0}\n"
    << "limits: {position: true, velocity: true, torque: true, contact: true}\n"
    << "tasks:\n";
  const std::pair<const char*, std::pair<double, double>> targets[] = {
      {"centre of mass above the left sole", {leftInner, leftCentre}},
      {"centre of mass above the right sole", {rightCentre, rightInner}},
      {"centre of mass back above the left sole", {leftInner, leftCentre}}};
  for (int k = 0; k < 3; ++k)
    y << "  - name: " << targets[k].first << "\n"
      << "    kind: center_of_mass\n"
      << "    time: " << duration * (k + 1) / 4.0 << "\n"
      << "    lower: [null, " << number(std::round(targets[k].second.first * 1000.0) / 1000.0, 4) << ", null]\n"
      << "    upper: [null, " << number(std::round(targets[k].second.second * 1000.0) / 1000.0, 4) << ", null]\n";
  y << "start: {posture: standing, fixed: true}\n"
    << "end: {posture: standing, fixed: true}\n"
    << "initialisation: {configuration_optimisation: false}\n"
    << "hessian: sample-differences\n"
    << "continuation:\n"
    << "  - {hessian: gauss-newton, max_iterations: 500, for_contact_forces: [bilevel]}\n"
    << "solver: {max_iter: 1000, tol: 1.0e-6}\n";
  return y.str();
}

std::string throwYaml(const RobotInitResult& r, const std::string& urdfName, const Scaling& s, const ContactEstimate& hand,
                      const RobotDimensions& hrp2) {
  const ContactEstimate& left = r.contacts[0];
  const ContactEstimate& right = r.contacts[1];
  const double duration = std::round(2.0 * s.time * 20.0) / 20.0;
  const double release = duration * 30.0 / 50.0;  // sample 30 of 51: the release on the grid
  const double reach = r.dimensions.armLength / hrp2.armLength;
  // A ball's range goes as its release speed squared: an arm and trunk whose joints are slower
  // than HRP-2's throw shorter than the arm's length alone would say (Talos's arm: 2.7–4.6 rad/s
  // against 5; its hand 8.1 m/s against 13.3: 1.5 m instead of 4.6).
  const double speed = r.dimensions.handSpeed > 0.0 ? r.dimensions.handSpeed / hrp2.handSpeed : reach;
  const double scale = std::min(reach, speed * speed);
  const double distance = std::round(4.0 * scale * 10.0) / 10.0;
  const double ball = std::round(0.2 * r.dimensions.mass / hrp2.mass * 100.0) / 100.0;
  std::ostringstream y;
  y << "# Starter throw for " << r.robot.name << " (`mcopt robot init`): on both soles, a " << ball << " kg ball thrown with\n"
    << "# the right hand at a target on the floor " << distance << " m ahead. HRP-2's bundled throw\n"
    << "# (scenarios/hrp2_throw.yaml) scaled to this robot: times by √(h / h_HRP-2) = " << number(s.time, 3)
    << ", the distance (4 m for\n# HRP-2, 2 m short of its bundled 6 m) by the smaller of the arm's length over HRP-2's = " << number(reach, 3)
    << "\n# and the square of its hand's speed at its joints' velocity limits over HRP-2's = " << number(speed * speed, 3)
    << " (a range goes as v²),\n# the ball's mass by the robot's. Every field: docs/reference/scenario-file.md.\n"
    << scenarioHeader(r.robot.name + " on both soles throws a ball with its right hand at a target on the floor", urdfName, left, r.allowNonPhysicalInertia)
    << "contacts: [" << left.surface.name << ", " << right.surface.name << "]\n"
    << "contact_forces: bilevel\n"
    // The right leg's loop (closed through the pelvis to the left sole) kept short of full
    // stretch, where the closure folds (docs/theory/outer-problem.md, "Closure by construction"):
    // JVRC-1's weight shift, whose knee is straight at 0.163 rad inside its range, stretched its
    // right leg to 8 mrad of the fold, and no Newton step there ends optimal
    // (docs/developers/lab-notes/robot-init.md).
    << "closure_reach_margin: 1.0e-3   # the right leg kept short of full stretch (about 5 degrees of knee bend)\n"
    // The margin row (docs/theory/outer-problem.md, "Inner feasibility"): it has a gradient at the
    // edge of what the soles can hold, where the slack row's vanishes. JVRC-1's throw, whose
    // samples ran into infeasible inner problems with the slack row, ends optimal with it, and
    // HRP-2's, Talos's and iCub's stay optimal (docs/developers/lab-notes/robot-init.md).
    << "inner: {solver: active-set, contact_model: wrench-cone, kkt_backend: dense, feasibility: margin}   # the margin row: "
       "a gradient at the edge of what the soles hold\n"
    << "friction_sharpness: 1.0\n"
    << "duration: " << duration << "\n"
    << "samples: 51                  # the release on sample 30\n"
    << "control_points: 11\n"
    << "objective: {energy: smooth_max, smoothing: 1.0}\n"
    << "limits: {position: true, velocity: true, torque: true, contact: true}\n"
    << "tasks:\n"
    << "  - name: throw\n"
    << "    kind: throw\n"
    << "    body: " << quoted(hand.link) << "\n"
    << "    point: [0.0, 0.0, 0.0]\n"
    << "    ball_mass: " << ball << "\n"
    << "    time: " << number(release, 10) << "   # sample 30 of 51\n"
    << "    target: [" << distance << ", " << number(0.5 * r.standing.secondSole.y(), 3) << ", 0.0]\n"
    << "start: {posture: standing, fixed: true}\n"
    << "end: {posture: standing, fixed: true}\n"
    << "initialisation: {configuration_optimisation: false}\n"
    << "hessian: sample-differences\n"
    << "continuation:\n"
    << "  - {hessian: gauss-newton, max_iterations: 500}\n"
    << "solver: {max_iter: 1000, tol: 1.0e-6}\n";
  return y.str();
}

void writeText(const fs::path& file, const std::string& text) {
  std::ofstream out(file);
  out << text;
  out.close();
  if (!out) throw InputError(file.string() + ": cannot write");
}

}  // namespace

RobotDimensions hrp2Dimensions() {
  // Measured by analyseRobot on robots/hrp2/hrp2.urdf (tests/apps/test_robot_init.cpp checks
  // them against a new measurement).
  RobotDimensions d;
  d.legLength = 0.705;
  d.stanceWidth = 0.12;
  d.centerOfMassHeight = 0.8041;
  d.armLength = 0.660;
  d.handSpeed = 13.26;
  d.mass = 58.0;
  return d;
}

RobotInitResult analyseRobot(const RobotInitSettings& settings) {
  RobotInitResult r;
  r.allowNonPhysicalInertia = settings.allowNonPhysicalInertia;
  r.robot = loadUrdfFile(settings.urdf, {settings.allowNonPhysicalInertia});
  const RobotModel& robot = r.robot;
  const ZeroPosture zero(robot);
  const auto collisions = bodyCollisionShapes(settings.urdf, robot);

  // The feet: the lowest bodies at the tree's ends, one each side of the root.
  std::vector<bool> carries(robot.bodies.size(), false);
  for (const Joint& j : robot.joints) carries[static_cast<std::size_t>(j.parentBody)] = true;
  int feet[2] = {-1, -1};
  double footBottom[2] = {1e9, 1e9};
  for (int b = 1; b < robot.bodyCount(); ++b) {
    if (carries[static_cast<std::size_t>(b)]) continue;
    std::string what;
    double bottom = 1e9;
    const RigidTransform pose = zero.body(b);
    for (const Vector3& p : bodyGeometry(robot, collisions, b, what, pose.rotation.transpose())) bottom = std::min(bottom, pose.apply(p).z());
    const double y = pose.translation.y();
    const int side = y > 0.01 ? 0 : y < -0.01 ? 1 : -1;
    if (side >= 0 && bottom < footBottom[side]) feet[side] = b, footBottom[side] = bottom;
  }
  const double legLength = feet[0] >= 0 && feet[1] >= 0 ? -0.5 * (footBottom[0] + footBottom[1]) : 0.0;
  if (feet[0] < 0 || feet[1] < 0 || legLength < 0.15 || std::abs(footBottom[0] - footBottom[1]) > 0.03)
    throw InputError(settings.urdf.string() + ": cannot find the robot's two feet (the lowest bodies at the ends of the " +
                     "kinematic tree, one on each side of the root body " + robot.bodies.front().name +
                     ", at one height, at least 15 cm below it at the zero posture, x forward, y left, z up)" +
                     (feet[0] >= 0 && feet[1] >= 0 ? ": the lowest are " + robot.bodies[static_cast<std::size_t>(feet[0])].name +
                                                         " and " + robot.bodies[static_cast<std::size_t>(feet[1])].name
                                                   : ""));
  // Left is +y in REP 103; a robot whose names say the other (iCub's root frame: x backward,
  // y right) is turned half a turn.
  auto sideOf = [&](int foot) {
    for (int b : chainToRoot(robot, foot)) {
      for (const Frame& f : robot.frames)
        if (f.body == b && nameSide(f.name) != 0) return nameSide(f.name);
      const int j = robot.bodies[static_cast<std::size_t>(b)].parentJoint;
      if (j >= 0 && nameSide(robot.joints[static_cast<std::size_t>(j)].name) != 0) return nameSide(robot.joints[static_cast<std::size_t>(j)].name);
    }
    return 0;
  };
  double leftSign = 1.0;
  if (sideOf(feet[0]) == -1 && sideOf(feet[1]) == 1) {
    std::swap(feet[0], feet[1]);
    leftSign = -1.0;
    r.notes.push_back("the names say left where the root frame's y is negative: the robot's x axis points backward and "
                      "its y axis to the right (as iCub's do); left and right, forward and backward taken from the names");
  }
  r.contacts.push_back(findSole(robot, zero, collisions, feet[0], "left_sole", leftSign, r.notes));
  r.contacts.push_back(findSole(robot, zero, collisions, feet[1], "right_sole", leftSign, r.notes));
  std::vector<int> legs = chainToRoot(robot, feet[0]);
  for (int b : chainToRoot(robot, feet[1])) legs.push_back(b);
  for (ContactEstimate& hand : findHands(robot, zero, legs, leftSign)) r.contacts.push_back(hand);
  if (r.contacts.size() < 4) r.notes.push_back("no link on each side whose name says palm, hand, gripper or wrist: " +
                                               std::string(r.contacts.size() == 2 ? "no hands" : "one hand") +
                                               " in contacts.yaml" + (r.contacts.size() == 2 ? ", no starter throw" : ""));

  // Bent knees: the root lowered as asked, or less where the joints' ranges do not reach it (an
  // ankle that bends little).
  StandingPostureSettings standing = settings.standing;
  r.standing = findStandingPosture(robot, r.contacts[0].surface, r.contacts[1].surface, standing);
  while (!r.standing.found() && standing.rootLowering > 0.015) {
    standing.rootLowering *= 0.6;
    r.standing = findStandingPosture(robot, r.contacts[0].surface, r.contacts[1].surface, standing);
    if (r.standing.found())
      r.notes.push_back("the standing posture's root is lowered " + number(100.0 * standing.rootLowering, 2) + " % (not " +
                        number(100.0 * settings.standing.rootLowering, 2) + " %: the joints' ranges do not reach it)");
  }
  r.rootLowering = standing.rootLowering;
  if (!r.standing.found())
    throw InputError(settings.urdf.string() + ": no standing posture found (Ipopt: " + toString(r.standing.status) +
                     " after " + std::to_string(r.standing.iterations) + " iterations, largest row: " +
                     r.standing.violatedRow + " " + number(r.standing.violation, 3) + "): both soles flat, centre of mass between them, root lowered " +
                     number(100.0 * settings.standing.rootLowering, 3) + " %");
  // The root's height above the left sole at the zero posture (not above the geometry's lowest
  // point, which an inertia box can put under the sole).
  const ContactSurface& leftSole = r.contacts[0].surface;
  r.dimensions.legLength = zero.body(0).translation.z() - (zero.frame(leftSole.frame) * leftSole.placement).translation.z();
  r.dimensions.stanceWidth = std::abs(r.standing.secondSole.y());
  r.dimensions.centerOfMassHeight = r.standing.centerOfMass.z();
  r.dimensions.mass = robot.totalMass();
  const auto right = std::find_if(r.contacts.begin(), r.contacts.end(), [](const ContactEstimate& c) { return c.surface.name == "right_hand"; });
  if (right != r.contacts.end()) {
    r.dimensions.armLength = armLength(robot, zero, right->surface.frame);
    r.dimensions.handSpeed = handSpeed(robot, zero, right->surface.frame);
  }
  for (const std::string& n : urdfFrictionNotes(defaultActuators(robot), robot))
    r.notes.push_back(n.substr(0, n.find(": a joint-side")) + ": joint-side values, carried into actuators.yaml on the motor side (divided by N², N)");
  return r;
}

RobotInitResult initRobotFolder(const RobotInitSettings& settings) {
  const fs::path out = settings.out;
  std::error_code error;
  if (fs::exists(out, error) && !(fs::is_directory(out, error) && fs::is_empty(out, error)))
    throw InputError(out.string() + ": exists and is not an empty folder: nothing written (give a new folder)");
  RobotInitResult r = analyseRobot(settings);

  const std::string urdfName = settings.urdf.filename().string();
  const RobotDimensions hrp2 = hrp2Dimensions();
  Scaling scaling;
  scaling.length = r.dimensions.centerOfMassHeight / hrp2.centerOfMassHeight;
  scaling.time = std::sqrt(scaling.length);

  // Everything into a sibling folder first, then renamed into place.
  const fs::path parent = out.has_parent_path() ? out.parent_path() : fs::path(".");
  fs::create_directories(parent, error);
  if (error) throw InputError(out.string() + ": cannot create its parent folder (" + error.message() + "): nothing written");
  const fs::path staging = parent / ("." + out.filename().string() + ".mcopt-init-" + std::to_string(::getpid()));
  fs::remove_all(staging, error);
  if (!fs::create_directory(staging, error) || error)
    throw InputError(out.string() + ": cannot write in " + parent.string() + " (" + error.message() + "): nothing written");
  struct Cleanup {
    fs::path dir;
    ~Cleanup() {
      std::error_code ignored;
      if (!dir.empty()) fs::remove_all(dir, ignored);
    }
  } cleanup{staging};

  fs::copy_file(settings.urdf, staging / urdfName, error);
  if (error) throw InputError(settings.urdf.string() + ": cannot copy into the robot folder (" + error.message() + ")");
  writeText(staging / "actuators.yaml", actuatorsYaml(r.robot, urdfName));
  writeText(staging / "contacts.yaml", contactsYaml(r.robot, r.contacts, urdfName));
  writeText(staging / "postures.yaml", posturesYaml(r.robot, r, urdfName));
  fs::create_directory(staging / "scenarios");
  writeText(staging / "scenarios" / "kick.yaml", kickYaml(r, urdfName, scaling));
  writeText(staging / "scenarios" / "weight_shift.yaml", weightShiftYaml(r, urdfName, scaling));
  r.files = {urdfName, "actuators.yaml", "contacts.yaml", "postures.yaml", "scenarios/kick.yaml", "scenarios/weight_shift.yaml"};
  const auto hand = std::find_if(r.contacts.begin(), r.contacts.end(), [](const ContactEstimate& c) { return c.surface.name == "right_hand"; });
  if (hand != r.contacts.end()) {
    writeText(staging / "scenarios" / "throw.yaml", throwYaml(r, urdfName, scaling, *hand, hrp2));
    r.files.push_back("scenarios/throw.yaml");
  } else {
    r.notes.push_back("no right hand found: no starter throw");
  }

  // Each file read back as mcopt reads it: what is written loads.
  const RobotModel copy = loadUrdfFile(staging / urdfName, {settings.allowNonPhysicalInertia});
  loadActuators(staging / "actuators.yaml", copy);
  loadContactSurfaces(staging / "contacts.yaml", copy);
  loadPostures(staging / "postures.yaml", copy);

  if (fs::exists(out, error)) fs::remove(out, error);  // the empty folder given
  fs::rename(staging, out, error);
  if (error) throw InputError(out.string() + ": cannot create (" + error.message() + "): nothing written");
  cleanup.dir.clear();
  return r;
}

}  // namespace mcopt::cli
