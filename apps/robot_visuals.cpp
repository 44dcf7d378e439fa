// SPDX-License-Identifier: BSD-3-Clause
#include "apps/robot_visuals.hpp"

#include <urdf_parser/urdf_parser.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "core/errors.hpp"

namespace mcopt::cli {

namespace {

RigidTransform toTransform(const urdf::Pose& pose) {
  double x, y, z, w;
  pose.rotation.getQuaternion(x, y, z, w);
  RigidTransform t;
  t.rotation = Eigen::Quaterniond(w, x, y, z).normalized().toRotationMatrix();
  t.translation = Vector3(pose.position.x, pose.position.y, pose.position.z);
  return t;
}

/// The primitive of one URDF visual or collision element, or false for a mesh (or an empty
/// primitive).
bool primitiveShape(const urdf::GeometrySharedPtr& geometry, const urdf::Pose& origin, const RigidTransform& linkInBody,
                    VisualShape& shape) {
  if (!geometry) return false;
  switch (geometry->type) {
    case urdf::Geometry::BOX: {
      const auto& box = static_cast<const urdf::Box&>(*geometry);
      shape.kind = VisualShape::Kind::Box;
      shape.size = Vector3(box.dim.x, box.dim.y, box.dim.z);
      break;
    }
    case urdf::Geometry::CYLINDER: {
      const auto& cylinder = static_cast<const urdf::Cylinder&>(*geometry);
      shape.kind = VisualShape::Kind::Cylinder;
      shape.size = Vector3(cylinder.radius, cylinder.length, 0.0);
      break;
    }
    case urdf::Geometry::SPHERE:
      shape.kind = VisualShape::Kind::Sphere;
      shape.size = Vector3(static_cast<const urdf::Sphere&>(*geometry).radius, 0.0, 0.0);
      break;
    default:
      return false;
  }
  if (!(shape.size.maxCoeff() > 0.0)) return false;
  shape.placement = linkInBody * toTransform(origin);
  return true;
}

/// The shape of one URDF visual, or false for a mesh (or an empty primitive).
bool visualShape(const urdf::Visual& visual, const RigidTransform& linkInBody, VisualShape& shape) {
  if (!primitiveShape(visual.geometry, visual.origin, linkInBody, shape)) return false;
  if (visual.material) {
    const urdf::Color& c = visual.material->color;
    shape.rgba = {c.r, c.g, c.b, c.a > 0.0 ? c.a : 1.0};
  }
  shape.source = "visual";
  return true;
}

/// A thin cylinder from `from` to `to` (body frame), or false when they coincide.
bool linkCylinder(const Vector3& from, const Vector3& to, double radius, VisualShape& shape) {
  const Vector3 d = to - from;
  const double length = d.norm();
  if (length < 1e-4) return false;
  shape.kind = VisualShape::Kind::Cylinder;
  shape.size = Vector3(radius, length, 0.0);
  shape.placement.rotation = Eigen::Quaterniond::FromTwoVectors(Vector3::UnitZ(), d / length).toRotationMatrix();
  shape.placement.translation = 0.5 * (from + to);
  shape.rgba = {0.35, 0.38, 0.45, 1.0};
  shape.source = "link";
  return true;
}

}  // namespace

VisualShape inertiaBox(const BodyInertia& inertia, double minimumEdge) {
  // Along the principal axes, where the inertia is diagonal: its eigenvalues.
  const Eigen::SelfAdjointEigenSolver<Matrix3> principal(0.5 * (inertia.inertiaAboutCom + inertia.inertiaAboutCom.transpose()));
  Matrix3 axes = principal.eigenvectors();
  if (axes.determinant() < 0.0) axes.col(2) = -axes.col(2);
  return alignedInertiaBox(inertia, inertia.mass > 0.0 ? axes : Matrix3::Identity(), minimumEdge);
}

namespace {

urdf::ModelInterfaceSharedPtr parseUrdf(const std::filesystem::path& urdf) {
  std::ifstream in(urdf);
  if (!in) throw InputError(urdf.string() + ": cannot read the robot description");
  std::stringstream text;
  text << in.rdbuf();
  urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(text.str());
  if (!model) throw InputError(urdf.string() + ": not a URDF urdfdom can parse");
  return model;
}

/// `visit(frame, link)` for every frame of `robot` and its urdfdom link.
template <class Visit>
void forEachLink(const std::filesystem::path& urdf, const RobotModel& robot, Visit visit) {
  const urdf::ModelInterfaceSharedPtr model = parseUrdf(urdf);
  for (const Frame& frame : robot.frames) {
    const urdf::LinkConstSharedPtr link = model->getLink(frame.name);
    if (!link) throw InputError(urdf.string() + ": link '" + frame.name + "' is not in the file the robot was loaded from");
    visit(frame, *link);
  }
}

}  // namespace

std::vector<std::vector<VisualShape>> bodyCollisionShapes(const std::filesystem::path& urdf, const RobotModel& robot) {
  std::vector<std::vector<VisualShape>> shapes(robot.bodies.size());
  forEachLink(urdf, robot, [&](const Frame& frame, const urdf::Link& link) {
    for (const urdf::CollisionSharedPtr& collision : link.collision_array) {
      VisualShape shape;
      if (collision && primitiveShape(collision->geometry, collision->origin, frame.placement, shape)) {
        shape.source = "collision";
        shapes[static_cast<std::size_t>(frame.body)].push_back(shape);
      }
    }
  });
  return shapes;
}

std::vector<VisualShape> bodyGeometryShapes(const RobotModel& robot, const std::vector<std::vector<VisualShape>>& collisions,
                                            int body, const Matrix3& axes, std::string& what) {
  const std::size_t b = static_cast<std::size_t>(body);
  if (!collisions[b].empty()) {
    what = "the collision primitives of " + robot.bodies[b].name;
    return collisions[b];
  }
  what = "the uniform box with the inertia of " + robot.bodies[b].name + " (its URDF geometry is meshes or nothing)";
  return {alignedInertiaBox(robot.bodies[b].inertia, axes, 0.01)};
}

std::vector<Vector3> shapeCorners(const VisualShape& shape) {
  Vector3 half = 0.5 * shape.size;
  switch (shape.kind) {
    case VisualShape::Kind::Box: break;
    case VisualShape::Kind::Cylinder: half = Vector3(shape.size.x(), shape.size.x(), 0.5 * shape.size.y()); break;
    case VisualShape::Kind::Sphere: half = Vector3::Constant(shape.size.x()); break;
  }
  std::vector<Vector3> corners;
  for (int k = 0; k < 8; ++k)
    corners.push_back(shape.placement.apply(Vector3((k & 1 ? 1 : -1) * half.x(), (k & 2 ? 1 : -1) * half.y(),
                                                (k & 4 ? 1 : -1) * half.z())));
  return corners;
}

VisualShape alignedInertiaBox(const BodyInertia& inertia, const Matrix3& axes, double minimumEdge) {
  VisualShape box;
  box.kind = VisualShape::Kind::Box;
  box.source = "inertia";
  box.placement.translation = inertia.com;
  box.placement.rotation = axes;
  if (!(inertia.mass > 0.0)) {
    box.size = Vector3::Constant(minimumEdge);
    return box;
  }
  // A uniform box of edges a, b, c has I_x = m (b² + c²) / 12, …, so a² = 6 (I_y + I_z − I_x) / m,
  // with the inertia's diagonal along `axes`.
  const Matrix3 I = axes.transpose() * inertia.inertiaAboutCom * axes;
  for (int i = 0; i < 3; ++i) {
    const double squared = 6.0 * (I((i + 1) % 3, (i + 1) % 3) + I((i + 2) % 3, (i + 2) % 3) - I(i, i)) / inertia.mass;
    box.size(i) = std::max(minimumEdge, std::sqrt(std::max(squared, 0.0)));
  }
  return box;
}

std::vector<std::vector<VisualShape>> bodyVisualShapes(const std::filesystem::path& urdf, const RobotModel& robot) {
  std::vector<std::vector<VisualShape>> shapes(robot.bodies.size());
  forEachLink(urdf, robot, [&](const Frame& frame, const urdf::Link& link) {
    for (const urdf::VisualSharedPtr& visual : link.visual_array) {
      VisualShape shape;
      if (visual && visualShape(*visual, frame.placement, shape)) shapes[static_cast<std::size_t>(frame.body)].push_back(shape);
    }
  });
  for (std::size_t b = 0; b < robot.bodies.size(); ++b) {
    if (!shapes[b].empty()) continue;
    // Drawn from dynamics alone: the inertia box, and a cylinder to each joint the body
    // carries (its frame's origin is its own joint's axis point).
    shapes[b].push_back(inertiaBox(robot.bodies[b].inertia, 0.02));
    for (const Joint& joint : robot.joints) {
      VisualShape link;
      if (static_cast<std::size_t>(joint.parentBody) == b && linkCylinder(Vector3::Zero(), joint.placement.translation, 0.012, link))
        shapes[b].push_back(link);
    }
  }
  return shapes;
}

}  // namespace mcopt::cli
