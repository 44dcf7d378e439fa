// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// `mcopt robot init URDF --out DIR` (docs/tutorials/own-robot.md): a robot folder written from a
// URDF alone — actuators.yaml (the URDF's limits, motor constants as marked estimates),
// contacts.yaml (the soles found from the feet, the hands from the arms' ends, marked as
// estimated), postures.yaml (zero, and a standing posture found by optimisation:
// outer_nlp/standing_posture.hpp) and starter scenarios (a kick, a weight shift and a throw)
// whose timings and targets are scaled from the robot's own dimensions.
//
// What is found and how:
//   - the feet: the two lowest bodies at the ends of the kinematic tree, one on each side of
//     the root at the zero posture (x forward, y left, z up, as REP 103 has it);
//   - a sole: a link named *sole* fixed to the foot, with its z axis vertical at the zero
//     posture; otherwise a frame at the bottom of the foot's geometry, world-aligned. Its
//     rectangle: the footprint of the foot's collision boxes (cylinders, spheres), or where the
//     URDF has only meshes, of the uniform box with the foot's inertia;
//   - a hand: on each side, the link whose name says palm, then hand, then gripper, then wrist,
//     nearest the trunk among equals; an 8 × 5 cm rectangle at its origin, its z axis the normal (estimated).

#include <filesystem>
#include <string>
#include <vector>

#include "core/robot_files.hpp"
#include "core/robot_model.hpp"
#include "outer_nlp/standing_posture.hpp"

namespace mcopt::cli {

struct RobotInitSettings {
  std::filesystem::path urdf;
  std::filesystem::path out;                ///< the robot folder to create (absent or empty)
  bool allowNonPhysicalInertia = false;
  StandingPostureSettings standing;
};

/// One contact surface found, with where its values came from.
struct ContactEstimate {
  ContactSurface surface;
  std::string link;     ///< the URDF link it is attached to
  std::string source;   ///< "sole link left_sole_link; rectangle: collision boxes of …", …
};

/// The robot's dimensions that scale the starter scenarios, measured at the standing posture in
/// the left sole's frame [m, kg].
struct RobotDimensions {
  double legLength = 0.0;          ///< the root body above the soles at the zero posture
  double stanceWidth = 0.0;        ///< between the soles' origins
  double centerOfMassHeight = 0.0; ///< standing
  double armLength = 0.0;          ///< shoulder to hand along the right arm's joints (0: no hand)
  /// The right hand's speed with each joint between it and the root body (arm and trunk) at its
  /// URDF velocity limit, every joint's contribution |a_j × (p_hand − p_j)| ω_max,j added (a bound,
  /// at the zero posture) [m/s]; 0: no hand, or one of those joints without a velocity limit.
  double handSpeed = 0.0;
  double mass = 0.0;
};

struct RobotInitResult {
  RobotModel robot;
  std::vector<ContactEstimate> contacts;  ///< left sole, right sole, then the hands found
  StandingPosture standing;
  double rootLowering = 0.0;              ///< of the standing posture's root (the one reached)
  RobotDimensions dimensions;
  bool allowNonPhysicalInertia = false;   ///< the URDF read so (the scenarios then say so too)
  std::vector<std::string> files;         ///< written, relative to the folder
  std::vector<std::string> notes;         ///< what was estimated or left out, one sentence each
};

/// The feet, soles, hands and standing posture of the robot, without writing anything. Throws
/// InputError naming the file for a robot the tool cannot set up (no two feet it can find, soles
/// not on one ground at the zero posture, no standing posture).
RobotInitResult analyseRobot(const RobotInitSettings& settings);

/// analyseRobot, then the folder written at once: into a temporary sibling, renamed into place
/// (nothing half-written). Throws InputError when `out` exists and is not empty or cannot be
/// written.
RobotInitResult initRobotFolder(const RobotInitSettings& settings);

/// HRP-2's dimensions as analyseRobot measures them on robots/hrp2 (the reference the starter
/// scenarios are scaled from: the bundled HRP-2 scenarios' timings and targets).
RobotDimensions hrp2Dimensions();

}  // namespace mcopt::cli
