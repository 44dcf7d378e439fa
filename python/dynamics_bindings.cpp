// SPDX-License-Identifier: BSD-3-Clause
// mcopt.Dynamics: inverse dynamics with the reference body held fixed (formulation.md §4),
// the reference wrench, and their exact derivatives; what `mcopt dynamics` computes.
#include <pybind11/stl.h>

#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"
#include "python/bindings.hpp"
#include "python/dynamics_handle.hpp"

namespace mcopt::python {

namespace {

RigidTransform poseArgument(const py::object& position, const py::object& quaternion) {
  RigidTransform pose;
  if (!position.is_none()) pose.translation = vectorArgument(position, "reference_position", 3);
  if (!quaternion.is_none()) {
    const Eigen::VectorXd q = vectorArgument(quaternion, "reference_quaternion_xyzw", 4);
    if (q.norm() < 1e-9) throw py::value_error("reference_quaternion_xyzw: zero quaternion");
    pose.rotation = rotationFromQuaternionXyzw(q[0], q[1], q[2], q[3]);
  }
  return pose;
}

/// q, v, a as N × n (v and a zero when None, their batch shape following q's).
struct States {
  Eigen::MatrixXd q, v, a;
  bool batch = false;
};

States statesOf(const DynamicsHandle& d, const py::object& q, const py::object& v, const py::object& a) {
  States s;
  const Eigen::Index n = d.model.jointCount();
  s.q = statesArgument(q, "q", n, s.batch);
  auto other = [&](const py::object& value, const char* name) -> Eigen::MatrixXd {
    if (value.is_none()) return Eigen::MatrixXd::Zero(s.q.rows(), n);
    bool batch = false;
    Eigen::MatrixXd m = statesArgument(value, name, n, batch);
    if (batch != s.batch || m.rows() != s.q.rows())
      throw py::value_error(std::string(name) + ": expected the shape of q (" +
                            (s.batch ? std::to_string(s.q.rows()) + ", " : std::string()) + std::to_string(n) +
                            (s.batch ? ")" : ",)") + ", got " + std::to_string(m.rows()) + " state(s)" +
                            (batch ? " as a batch" : ""));
    return m;
  };
  s.v = other(v, "v");
  s.a = other(a, "a");
  return s;
}

/// One row per state (batch) or the single row as a vector.
py::array_t<double> rowsOut(const Eigen::MatrixXd& rows, bool batch) {
  return batch ? matrixToNumpy(rows) : vectorToNumpy(rows.row(0).transpose());
}

/// A stack of matrices: (N, r, c) in a batch, (r, c) otherwise.
py::array_t<double> stackOut(const std::vector<Eigen::MatrixXd>& mats, bool batch) {
  if (!batch) return matrixToNumpy(mats[0]);
  const auto N = static_cast<py::ssize_t>(mats.size()), r = mats[0].rows(), c = mats[0].cols();
  py::array_t<double> out({N, static_cast<py::ssize_t>(r), static_cast<py::ssize_t>(c)});
  auto a = out.mutable_unchecked<3>();
  for (py::ssize_t k = 0; k < N; ++k)
    for (py::ssize_t i = 0; i < r; ++i)
      for (py::ssize_t j = 0; j < c; ++j) a(k, i, j) = mats[static_cast<std::size_t>(k)](i, j);
  return out;
}

int frameIndex(const DynamicsHandle& d, const std::string& name) {
  const RobotModel& robot = d.model.robot();
  for (std::size_t f = 0; f < robot.frames.size(); ++f)
    if (robot.frames[f].name == name) return static_cast<int>(f);
  throw py::value_error("unknown frame '" + name + "' (Robot.frame_names lists them)");
}

}  // namespace

void bindDynamics(py::module_& m) {
  py::class_<DynamicsHandle, std::shared_ptr<DynamicsHandle>>(m, "Dynamics", R"doc(
The robot's Newton–Euler model with `reference_body` held at a fixed world pose
(formulation.md §4): the torques Γ0 that carry the robot from that body alone and the wrench W0
the environment applies to it. Any URDF link may be the reference (a sole frame re-roots the
tree there). States are arrays in the robot's joint order: one state of shape (n,), or N
states of shape (N, n); results come back with the same leading dimension.)doc")
      .def(py::init([](std::shared_ptr<RobotHandle> robot, const std::optional<std::string>& referenceBody,
                       const py::object& position, const py::object& quaternion, const py::object& gravity) {
             const std::string body = referenceBody ? *referenceBody : robot->model->frames[0].name;
             const Vector3 g = gravity.is_none() ? Vector3(0, 0, -9.81) : Vector3(vectorArgument(gravity, "gravity", 3));
             return std::make_shared<DynamicsHandle>(robot, DynamicsModel(*robot->model, body, poseArgument(position, quaternion), g));
           }),
           py::arg("robot"), py::arg("reference_body") = py::none(), py::arg("reference_position") = py::none(),
           py::arg("reference_quaternion_xyzw") = py::none(), py::arg("gravity") = py::none(),
           R"doc(`reference_body`: a link name (default: the URDF root); its frame is held at
`reference_position` (default 0) with orientation `reference_quaternion_xyzw` (x, y, z, w;
default identity). `gravity` defaults to (0, 0, -9.81) m/s².)doc")
      .def_property_readonly("robot", [](const DynamicsHandle& d) { return d.robot; }, "the mcopt.Robot this model was built on")
      .def_property_readonly("reference_body", [](const DynamicsHandle& d) {
        return d.model.robot().frames[static_cast<std::size_t>(d.model.referenceFrame())].name;
      }, "the link held fixed (formulation.md §4)")
      .def(
          "inverse_dynamics",
          [](DynamicsHandle& d, const py::object& q, const py::object& v, const py::object& a) {
            const States s = statesOf(d, q, v, a);
            Eigen::MatrixXd tau(s.q.rows(), d.model.jointCount()), wrench(s.q.rows(), 6);
            for (Eigen::Index k = 0; k < s.q.rows(); ++k) {
              inverseDynamics(d.model, d.data, s.q.row(k).transpose(), s.v.row(k).transpose(), s.a.row(k).transpose());
              tau.row(k) = d.data.tau.transpose();
              wrench.row(k) = referenceWrenchAtReferenceFrame(d.model, d.data).transpose();
            }
            py::dict out;
            out["tau"] = rowsOut(tau, s.batch);
            out["reference_wrench"] = rowsOut(wrench, s.batch);
            return out;
          },
          py::arg("q"), py::arg("v") = py::none(), py::arg("a") = py::none(),
          R"doc(Torques Γ0 (joint order, friction excluded) and the reference wrench W0 (force,
moment about the reference frame's origin, world axes) of each state; v and a default to zero.
Returns {"tau", "reference_wrench"}, what `mcopt dynamics` writes.)doc")
      .def(
          "derivatives",
          [](DynamicsHandle& d, const py::object& q, const py::object& v, const py::object& a) {
            const States s = statesOf(d, q, v, a);
            const auto N = static_cast<std::size_t>(s.q.rows());
            Eigen::MatrixXd tau(s.q.rows(), d.model.jointCount()), wrench(s.q.rows(), 6);
            std::vector<Eigen::MatrixXd> dq(N), dv(N), da(N), wq(N), wv(N), wa(N);
            Eigen::Matrix<double, 6, Eigen::Dynamic> moved;
            for (std::size_t k = 0; k < N; ++k) {
              const auto row = static_cast<Eigen::Index>(k);
              inverseDynamicsDerivatives(d.model, d.data, d.derivatives, s.q.row(row).transpose(),
                                         s.v.row(row).transpose(), s.a.row(row).transpose());
              tau.row(row) = d.data.tau.transpose();
              wrench.row(row) = referenceWrenchAtReferenceFrame(d.model, d.data).transpose();
              dq[k] = d.derivatives.dtauDq, dv[k] = d.derivatives.dtauDv, da[k] = d.derivatives.dtauDa;
              wrenchDerivativeAtReferenceFrame(d.model, d.derivatives.dwrenchDq, moved), wq[k] = moved;
              wrenchDerivativeAtReferenceFrame(d.model, d.derivatives.dwrenchDv, moved), wv[k] = moved;
              wrenchDerivativeAtReferenceFrame(d.model, d.derivatives.dwrenchDa, moved), wa[k] = moved;
            }
            py::dict out;
            out["tau"] = rowsOut(tau, s.batch);
            out["reference_wrench"] = rowsOut(wrench, s.batch);
            out["dtau_dq"] = stackOut(dq, s.batch), out["dtau_dv"] = stackOut(dv, s.batch);
            out["dtau_da"] = stackOut(da, s.batch);
            out["dwrench_dq"] = stackOut(wq, s.batch), out["dwrench_dv"] = stackOut(wv, s.batch);
            out["dwrench_da"] = stackOut(wa, s.batch);
            return out;
          },
          py::arg("q"), py::arg("v") = py::none(), py::arg("a") = py::none(),
          R"doc(inverse_dynamics plus its exact analytic derivatives (`mcopt dynamics
--derivatives`): dtau_dq, dtau_dv, dtau_da of shape (n, n) and dwrench_dq, dwrench_dv,
dwrench_da of shape (6, n) per state (rows: outputs, columns: joints).)doc")
      .def(
          "center_of_mass",
          [](DynamicsHandle& d, const py::object& q) {
            bool batch = false;
            const Eigen::MatrixXd states = statesArgument(q, "q", d.model.jointCount(), batch);
            Eigen::MatrixXd out(states.rows(), 3);
            for (Eigen::Index k = 0; k < states.rows(); ++k) {
              forwardKinematics(d.model, d.data, states.row(k).transpose());
              out.row(k) = centerOfMass(d.model, d.data).transpose();
            }
            return rowsOut(out, batch);
          },
          py::arg("q"), "Whole-body centre of mass [m] in the world frame, per state.")
      .def(
          "frame_pose",
          [](DynamicsHandle& d, const std::string& frame, const py::object& q) {
            const int f = frameIndex(d, frame);
            forwardKinematics(d.model, d.data, vectorArgument(q, "q", d.model.jointCount()));
            const RigidTransform pose = framePose(d.model, d.data, f);
            return py::make_tuple(vectorToNumpy(pose.translation), matrixToNumpy(pose.rotation));
          },
          py::arg("frame"), py::arg("q"), "World position (3,) and rotation matrix (3, 3) of a frame at one posture q.");
}

}  // namespace mcopt::python
