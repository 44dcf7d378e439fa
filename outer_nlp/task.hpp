// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A task kind (formulation.md §10; docs/theory/outer-problem.md, "Tasks"): the quantity of the
// motion a task bounds at an instant or over a window, as a const model in the manner of a
// Crocoddyl residual. It declares its dimension (1 to kMaxTaskDimension rows), what it reads
// (a body's position, orientation or velocity, the centre of mass, a thrown ball), and computes
// its value (calc) and its exact derivatives in q and q̇ (calcDiff) from a DynamicsData filled
// by inverseDynamics. A task's own parameters (its body, point, target orientation…) live in
// the object; where and when it holds and its bounds live in TaskSpec (scenario.hpp).
//
// A new kind is one file (a class deriving from Task, and its reader) and one line in the
// registry, taskKinds() in task.cpp. The bundled kinds:
//   position          (position_task.cpp)          a point of a body, world frame [m]
//   orientation       (orientation_task.cpp)       ½ vee(Rtᵀ R − Rᵀ Rt): sin θ times the axis
//   orientation_angle (orientation_angle_task.cpp) 1 − cos θ of the angle θ to a target
//   linear_velocity   (velocity_tasks.cpp)         a point's velocity, world frame [m/s]
//   angular_velocity  (velocity_tasks.cpp)         a body's angular velocity [rad/s]
//   center_of_mass    (center_of_mass_task.cpp)    the centre of mass [m]
// and the two rows of a `throw` (ball_flight_task.hpp), which scenario files give through
// their own reader (outer_nlp/throw_task.cpp): a throw also loads the robot with its ball.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "core/dynamics_data.hpp"
#include "core/kinematics.hpp"
#include "core/motion_derivatives.hpp"
#include "core/robot_model.hpp"

namespace mcopt {

constexpr int kMaxTaskDimension = 6;
/// A task's value or bounds: dimension() entries, stored in place.
using TaskVector = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxTaskDimension, 1>;

/// What a task reads from the motion: the exact Hessian's stencils and the configuration
/// problem (postures alone) ask it.
enum class TaskQuantity { Position, Orientation, LinearVelocity, AngularVelocity, CenterOfMass, Ball };

/// Buffers of one thread for any task, sized once.
struct TaskWorkspace {
  explicit TaskWorkspace(const DynamicsModel& model);
  FrameJacobian jacobian;
  MotionDerivative dTwistDq, dTwistDv, dAccelerationDq, dAccelerationDv, dAccelerationDa;
  Eigen::Matrix3Xd comJacobian;
  Eigen::Matrix3Xd velocityDq;  ///< ∂v_p/∂q of a point
  /// A throw's exact Hessian: ∂k/∂(q, q̇) of the ball's state k = (p, v_p), and W times it.
  Eigen::Matrix<double, 6, Eigen::Dynamic> ballJacobian, weightedBallJacobian;
};

class BallFlightTask;

/// A three-row task's derivative rows as a fixed-size view: its products then take Eigen's
/// fixed-size kernels, the arithmetic the three-row kinds had before they were models (a
/// dynamic-size destination sums in another order, and moved bundled optima by rounding).
using ThreeRows = Eigen::Map<Eigen::Matrix3Xd, Eigen::Unaligned, Eigen::OuterStride<>>;
inline ThreeRows threeRows(Eigen::Ref<Eigen::MatrixXd> m) {
  return ThreeRows(m.data(), 3, m.cols(), Eigen::OuterStride<>(m.outerStride()));
}

/// va(M) = ½ vee(M − Mᵀ), vee(A) = (A₃₂, A₁₃, A₂₁): the orientation tasks' errors.
inline Vector3 antisymmetricPart(const Matrix3& m) {
  return 0.5 * Vector3(m(2, 1) - m(1, 2), m(0, 2) - m(2, 0), m(1, 0) - m(0, 1));
}

class Task {
 public:
  virtual ~Task() = default;
  /// The scenario file's `kind` (and the name results give it).
  virtual std::string kind() const = 0;
  virtual TaskQuantity reads() const = 0;
  /// Rows of the task, 1 to kMaxTaskDimension.
  virtual int dimension() const { return 3; }
  /// Row i's name in messages and results ("x", "y", "z" by default).
  virtual std::string componentName(int i) const;
  /// The RobotModel frame whose support path moves the task, or -1 when every joint does
  /// (the centre of mass).
  virtual int frame() const { return -1; }
  /// Whether the value depends on q̇ (else on q alone).
  bool readsVelocity() const;

  /// The value (dimension() entries) from `data` after inverseDynamics (or forward kinematics
  /// with velocities) at the instant.
  virtual void calc(const DynamicsModel& model, const DynamicsData& data, TaskWorkspace& workspace,
                    Eigen::Ref<Eigen::VectorXd> value) const = 0;
  /// The value and its derivatives dq, dv (dimension() × jointCount) with respect to q and q̇.
  virtual void calcDiff(const DynamicsModel& model, const DynamicsData& data, TaskWorkspace& workspace,
                        Eigen::Ref<Eigen::VectorXd> value, Eigen::Ref<Eigen::MatrixXd> dq,
                        Eigen::Ref<Eigen::MatrixXd> dv) const = 0;
  /// A throw's rows, whose exact Hessian splits along the ball's state (ball_flight_task.hpp).
  virtual const BallFlightTask* ballFlight() const { return nullptr; }
};

/// A task of a scenario's `tasks` list as its kind's reader sees it: scenario.cpp answers
/// from a YAML entry, naming file, line and field in every error (InputError).
class TaskFields {
 public:
  virtual ~TaskFields() = default;
  virtual bool has(const std::string& key) const = 0;
  virtual double number(const std::string& key) const = 0;
  /// `count` numbers; with `freeValue`, a null entry reads as it (a free component).
  virtual std::vector<double> numbers(const std::string& key, int count) const = 0;
  virtual std::vector<double> bounds(const std::string& key, int count, double freeValue) const = 0;
  /// The RobotModel frame of the body (a URDF link) the key names, with the unknown-body hints.
  virtual int body(const std::string& key) const = 0;
  /// An InputError at the key ("file:line: tasks[i].key: message").
  [[noreturn]] virtual void fail(const std::string& key, const std::string& message) const = 0;
  /// Whether the task holds over a window (else at an instant).
  virtual bool window() const = 0;
};

/// What a kind's reader gives back: the task and its bounds (dimension() entries each, ±∞
/// where free).
struct ReadTask {
  std::shared_ptr<const Task> task;
  TaskVector lower, upper;
};

/// One registered task kind: its name, one line on what it bounds, the fields it takes beside
/// name, kind, time and window, and its reader.
struct TaskKindEntry {
  std::string kind;
  std::string description;
  std::vector<std::string> keys;
  ReadTask (*read)(const TaskFields& fields);
};

/// Every task kind scenario files name, in the order documents list them.
const std::vector<TaskKindEntry>& taskKinds();
/// The registered kind, or null.
const TaskKindEntry* findTaskKind(const std::string& kind);
/// "position, orientation, …, center_of_mass, or throw".
std::string taskKindList();

/// Bounds of a task of `dimension` rows from `target` (null entries free) and `tolerance`, or
/// from `lower` and `upper` (null for a free end): the reading of the vector kinds.
void readTargetOrBounds(const TaskFields& fields, int dimension, ReadTask& out);
/// The orientation kinds' required `target`, `[roll, pitch, yaw]`, as a rotation.
Matrix3 readTargetRotation(const TaskFields& fields);

// The bundled kinds, for the tasks the scenario makes itself (a contact's closure) and tests.
/// The point `point` (body frame) of `frame`'s body, world frame.
std::shared_ptr<const Task> makePositionTask(int frame, const Vector3& point);
/// ½ vee(Rtᵀ R − Rᵀ Rt) of `frame`'s world orientation R from `target` Rt.
std::shared_ptr<const Task> makeOrientationTask(int frame, const Matrix3& target);
/// 1 − cos θ, θ the angle between `frame`'s world orientation and `target`.
std::shared_ptr<const Task> makeOrientationAngleTask(int frame, const Matrix3& target);
std::shared_ptr<const Task> makeLinearVelocityTask(int frame, const Vector3& point);
std::shared_ptr<const Task> makeAngularVelocityTask(int frame);
std::shared_ptr<const Task> makeCenterOfMassTask();

}  // namespace mcopt
