// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// What a robot looks like, body by body, for drawing it (mcopt replay, docs/guides/replay.md): the
// URDF's visual primitives, or where a link has none, primitives made from its mass
// properties and its joints, so that a robot described for dynamics alone is drawn too.

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "core/robot_model.hpp"

namespace mcopt::cli {

struct VisualShape {
  enum class Kind { Box, Cylinder, Sphere };
  Kind kind = Kind::Box;
  /// Box: edge lengths along x, y, z; cylinder (axis z): radius, length, 0; sphere: radius, 0, 0 [m].
  Vector3 size = Vector3::Zero();
  RigidTransform placement;                    ///< shape frame in the body frame
  std::array<double, 4> rgba{0.7, 0.7, 0.75, 1.0};
  std::string source;                          ///< "visual", "inertia" or "link": where the shape came from
};

/// Shapes of every body of `robot` (indexed like robot.bodies; a body merges the URDF links
/// fixed to it). A link's URDF boxes, cylinders and spheres are kept; a link with no visual, or
/// only meshes (which a self-contained page cannot load), gets the box of its own inertia —
/// the uniform box with the same mass and principal moments, at its centre of mass along its
/// principal axes — and every body a thin cylinder to each joint it carries, so that the
/// chain shows. Throws InputError naming the file when it cannot be parsed.
std::vector<std::vector<VisualShape>> bodyVisualShapes(const std::filesystem::path& urdf, const RobotModel& robot);

/// The URDF's collision boxes, cylinders and spheres of every body (indexed like robot.bodies;
/// meshes left out: none for a body described by meshes alone), `source` "collision".
std::vector<std::vector<VisualShape>> bodyCollisionShapes(const std::filesystem::path& urdf, const RobotModel& robot);

/// The uniform box with the mass and the second moments of `inertia` about the axes `axes` (a
/// rotation in the body frame) rather than its principal axes: a foot's box lying in its sole's
/// plane, where the principal axes of a foot with an ankle motor in it are tilted. Its edges
/// from the diagonal of the inertia in those axes (each at least `minimumEdge`).
VisualShape alignedInertiaBox(const BodyInertia& inertia, const Matrix3& axes, double minimumEdge);

/// The geometry of body `body` (an index of robot.bodies): its collision primitives
/// (`collisions`, from bodyCollisionShapes), or where it has none the box of its inertia along
/// `axes` (body frame). `what` says which, naming the body.
std::vector<VisualShape> bodyGeometryShapes(const RobotModel& robot, const std::vector<std::vector<VisualShape>>& collisions,
                                            int body, const Matrix3& axes, std::string& what);

/// The eight corners of a shape's bounding box, in the shape's parent (body) frame.
std::vector<Vector3> shapeCorners(const VisualShape& shape);

/// The uniform box with the mass and principal moments of `inertia`, in the body frame (each
/// edge at least `minimumEdge`, for a link whose inertia is a point or a rod).
VisualShape inertiaBox(const BodyInertia& inertia, double minimumEdge);

}  // namespace mcopt::cli
