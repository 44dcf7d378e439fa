// SPDX-License-Identifier: BSD-3-Clause
// Uses an installed mcopt as a library: loads the bundled HRP-2 from the install's share folder,
// evaluates the torques of a spline motion with the dynamics rooted at the left sole, and
// solves one inner contact-force problem (both soles) with the active-set method, then checks
// the answer's KKT conditions. Exit 0 when the inner problem is solved to its tolerance.
#include <cstdio>
#include <filesystem>

#include <mcopt/core/actuators.hpp>
#include <mcopt/core/bspline.hpp>
#include <mcopt/core/inverse_dynamics.hpp>
#include <mcopt/core/robot_files.hpp>
#include <mcopt/core/trajectory_evaluation.hpp>
#include <mcopt/core/version.hpp>
#include <mcopt/inner_qp/inner_solver.hpp>
#include <mcopt/inner_qp/multi_contact_dynamics.hpp>

int main(int argc, char** argv) {
  using namespace mcopt;
  const std::filesystem::path robotDir =
      argc > 1 ? std::filesystem::path(argv[1]) : std::filesystem::path(MCOPT_DATA_DIR) / "robots" / "hrp2";
  const RobotModel robot = loadUrdfFile(robotDir / "hrp2.urdf");
  const ActuatorSet actuators = loadActuators(robotDir / "actuators.yaml", robot);
  const Eigen::VectorXd halfSitting = loadPostures(robotDir / "postures.yaml", robot).at("half_sitting");
  std::vector<ContactSurface> soles;
  for (const ContactSurface& surface : loadContactSurfaces(robotDir / "contacts.yaml", robot))
    if (surface.name == "l_sole" || surface.name == "r_sole") soles.push_back(surface);
  std::printf("mcopt %s: %s, %d joints, %zu soles\n", kVersion, robot.name.c_str(), robot.jointCount(), soles.size());

  // A motion: from half-sitting, every joint 0.05 rad further and back to rest at its end posture, in 1.5 s.
  const DynamicsModel model(robot, "l_sole");
  const MotionParametrization parametrization(robot.jointCount(), 9);
  const Eigen::VectorXd end = halfSitting.array() + 0.05;
  TrajectoryEvaluator evaluator(model, actuators, SampledTrajectory(parametrization, 31));
  TrajectoryResult motion;
  evaluator.evaluate(parametrization.interpolatedMotion(halfSitting, end), 1.5, motion);
  std::printf("motion: 31 samples, largest torque %.3f N m, energy %.4f J\n", motion.tau.cwiseAbs().maxCoeff(),
              motion.energy);

  // One inner problem at the motion's middle sample: the wrenches of both soles.
  ContactProblemSettings settings;
  settings.model = makeContactModel("wrench-cone");
  SampleProblem sample(model, soles, settings);
  DynamicsData data(model);
  const int middle = 15;
  inverseDynamics(model, data, motion.q.col(middle), motion.v.col(middle), motion.a.col(middle));
  sample.update(model, data, actuators, soles, motion.v.col(middle), motion.a.col(middle));
  const auto solver = makeInnerSolver("active-set");
  InnerResult result;
  solver->solve(sample.problem, result);
  const double residual = kktResidual(sample.problem, result);
  std::printf("inner problem: %s, KKT residual %.2e, normal forces %.1f N (left) %.1f N (right)\n",
              toString(result.status), residual, result.wrenches[2], result.wrenches[8]);
  return result.status == InnerStatus::Optimal && residual < 1e-6 ? 0 : 1;
}
