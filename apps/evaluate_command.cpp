// SPDX-License-Identifier: BSD-3-Clause
// `mcopt evaluate`: the main job until the optimiser lands (issue 2). Reads a motion
// file (docs/reference/input-files.md), evaluates torques, reference-body wrench and electrical
// energy at every sample, prints a summary and optionally writes results atomically.
#include <chrono>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "apps/commands.hpp"
#include "apps/json_io.hpp"
#include "core/atomic_file.hpp"
#include "core/robot_files.hpp"
#include "core/trajectory_evaluation.hpp"
#include "core/yaml_fields.hpp"

namespace mcopt::cli {

namespace {

struct EvaluateOptions {
  std::string motion, out;
};

/// A motion between two postures of the bundled robot, in a YAML file.
struct MotionFile {
  std::filesystem::path robot, actuators, postures;
  std::string referenceBody;
  RigidTransform referencePose;
  Vector3 gravity{0.0, 0.0, -9.81};
  double duration = 1.0;
  int samples = 100;
  int controlPoints = 9;
  YAML::Node start, end;
};

MotionFile readMotionFile(const std::filesystem::path& path) {
  const YAML::Node root = yaml::loadFile(path);
  yaml::rejectUnknownKeys(path, root, "",
                          {"robot", "actuators", "postures", "reference_body", "reference_pose", "gravity", "duration",
                           "samples", "control_points", "start", "end", "description"});
  const auto dir = path.parent_path();
  MotionFile m;
  // Paths are relative to the motion file, never to the working directory.
  auto file = [&](const char* key) {
    const auto p = dir / yaml::text(path, yaml::required(path, root, key, ""), key);
    if (!pathExists(p))
      throw InputError(yaml::where(path, root[key], key) + "file not found: " + p.string());
    return p;
  };
  m.robot = file("robot");
  m.actuators = file("actuators");
  m.postures = file("postures");
  m.referenceBody = yaml::text(path, yaml::required(path, root, "reference_body", ""), "reference_body");
  if (root["reference_pose"]) {
    const YAML::Node pose = root["reference_pose"];
    yaml::rejectUnknownKeys(path, pose, "reference_pose", {"position", "rpy"});
    if (pose["position"]) {
      const auto p = yaml::numbers(path, pose["position"], "reference_pose.position", 3);
      m.referencePose.translation = Vector3(p[0], p[1], p[2]);
    }
    if (pose["rpy"]) {
      const auto r = yaml::numbers(path, pose["rpy"], "reference_pose.rpy", 3);
      m.referencePose.rotation = rotationFromRpy(r[0], r[1], r[2]);
    }
  }
  if (root["gravity"]) {
    const auto g = yaml::numbers(path, root["gravity"], "gravity", 3);
    m.gravity = Vector3(g[0], g[1], g[2]);
  }
  m.duration = yaml::positive(path, yaml::required(path, root, "duration", ""), "duration");
  if (root["samples"]) {
    const double s = yaml::number(path, root["samples"], "samples");
    if (s < 2 || s != std::floor(s)) throw InputError(yaml::where(path, root["samples"], "samples") + "expected an integer ≥ 2");
    m.samples = static_cast<int>(s);
  }
  if (root["control_points"]) {
    const double n = yaml::number(path, root["control_points"], "control_points");
    if (n < 7 || n != std::floor(n))
      throw InputError(yaml::where(path, root["control_points"], "control_points") + "expected an integer ≥ 7");
    m.controlPoints = static_cast<int>(n);
  }
  m.start = yaml::required(path, root, "start", "");
  m.end = yaml::required(path, root, "end", "");
  return m;
}

Eigen::VectorXd readPosture(const std::filesystem::path& path, const YAML::Node& node, const std::string& field,
                            const RobotModel& robot, const std::map<std::string, Eigen::VectorXd>& postures) {
  yaml::rejectUnknownKeys(path, node, field, {"posture", "offsets"});
  return yaml::postureWithOffsets(path, node, field, robot, postures);
}

std::string trajectoryCsv(const RobotModel& robot, const TrajectoryResult& r) {
  std::ostringstream csv;
  csv << std::setprecision(12) << "time";
  for (const char* kind : {"q", "v", "a", "tau", "power"})
    for (const Joint& joint : robot.joints) csv << "," << kind << ":" << joint.name;
  for (const char* c : {"fx", "fy", "fz", "mx", "my", "mz"}) csv << ",reference_wrench:" << c;
  csv << "\n";
  for (Eigen::Index s = 0; s < r.time.size(); ++s) {
    csv << r.time[s];
    for (const Eigen::MatrixXd* m : {&r.q, &r.v, &r.a, &r.tau, &r.power})
      for (Eigen::Index j = 0; j < m->rows(); ++j) csv << "," << (*m)(j, s);
    for (int c = 0; c < 6; ++c) csv << "," << r.referenceWrench(c, s);
    csv << "\n";
  }
  return csv.str();
}

int runEvaluate(const EvaluateOptions& o) {
  const auto clockStart = std::chrono::steady_clock::now();
  const MotionFile motion = readMotionFile(o.motion);
  const RobotModel robot = loadUrdfFile(motion.robot);
  for (const std::string& w : robot.warnings) std::cerr << "mcopt: warning: " << w << "\n";
  const ActuatorSet actuators = loadActuators(motion.actuators, robot);
  const auto postures = loadPostures(motion.postures, robot);
  const Eigen::VectorXd start = readPosture(o.motion, motion.start, "start", robot, postures);
  const Eigen::VectorXd end = readPosture(o.motion, motion.end, "end", robot, postures);
  if (robot.findFrame(motion.referenceBody) < 0)
    throw InputError(o.motion + ": reference_body: unknown body '" + motion.referenceBody + "' " +
                     robot.unknownFrameHint(motion.referenceBody));
  const DynamicsModel model(robot, motion.referenceBody, motion.referencePose, motion.gravity);
  const MotionParametrization parametrization(robot.jointCount(), motion.controlPoints);
  TrajectoryEvaluator evaluator(model, actuators, SampledTrajectory(parametrization, motion.samples));
  const Eigen::VectorXd parameters = parametrization.interpolatedMotion(start, end);

  TrajectoryResult r;
  const auto evalStart = std::chrono::steady_clock::now();
  evaluator.evaluate(parameters, motion.duration, r);
  const double evalMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - evalStart).count();

  std::cout << "mcopt evaluate " << o.motion << "\n"
            << "  robot " << robot.name << ": " << robot.jointCount() << " joints, " << std::fixed
            << std::setprecision(2) << robot.totalMass() << " kg; reference body " << motion.referenceBody << "\n"
            << "  motion: " << motion.duration << " s, " << motion.samples << " samples, " << motion.controlPoints
            << " control points a joint (" << parametrization.parameterCount() << " free parameters)\n\n"
            << "  joint            peak |torque| [N m]  limit   peak power [W]\n";
  for (int j = 0; j < robot.jointCount(); ++j) {
    const double peak = r.tau.row(j).cwiseAbs().maxCoeff();
    if (peak < 1.0) continue;  // keep the table to the joints that work
    std::cout << "  " << std::left << std::setw(16) << robot.joints[j].name << std::right << std::setw(12) << peak
              << std::setw(14) << actuators.joints[j].torqueLimit << std::setw(12) << r.power.row(j).maxCoeff()
              << (peak > actuators.joints[j].torqueLimit ? "  ABOVE LIMIT" : "") << "\n";
  }
  std::cout << "  (joints with a peak torque under 1 N m not listed)\n\n"
            << "  reference-body wrench (world axes, at the reference frame):\n"
            << "    force z  min " << r.referenceWrench.row(2).minCoeff() << "  max "
            << r.referenceWrench.row(2).maxCoeff() << " N (weight " << robot.totalMass() * -motion.gravity.z()
            << " N)\n"
            << "    |moment| max " << r.referenceWrench.bottomRows<3>().colwise().norm().maxCoeff() << " N m\n\n"
            << std::setprecision(3) << "  electrical energy  " << r.energy << " J  (∫ Σ max(P, 0) dt, trapezoid)\n"
            << "  evaluation time    " << evalMs << " ms for " << motion.samples << " samples\n";

  if (!o.out.empty()) {
    std::filesystem::create_directories(o.out);
    json_io::Json result;
    result["status"] = "evaluated";
    result["energy"] = r.energy;
    result["joint_names"] = robot.jointNames();
    result["duration"] = motion.duration;
    result["parameters"] = json_io::toJson(parameters);
    result["time"] = json_io::toJson(r.time);
    result["q"] = json_io::matrixToJson(r.q.transpose());
    result["v"] = json_io::matrixToJson(r.v.transpose());
    result["a"] = json_io::matrixToJson(r.a.transpose());
    result["tau"] = json_io::matrixToJson(r.tau.transpose());
    result["power"] = json_io::matrixToJson(r.power.transpose());
    result["reference_wrench"] = json_io::matrixToJson(r.referenceWrench.transpose());
    result["evaluation_ms"] = evalMs;
    writeFileAtomically(std::filesystem::path(o.out) / "trajectory.csv", trajectoryCsv(robot, r));
    writeFileAtomically(std::filesystem::path(o.out) / "result.json", result.dump(1) + "\n");
    std::cout << "  results written to " << o.out << "/result.json and trajectory.csv\n";
  }
  const double totalMs =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - clockStart).count();
  std::cout << "  total time         " << totalMs << " ms\n";
  return 0;
}

}  // namespace

Runner addEvaluate(CLI::App& command) {
  auto o = std::make_shared<EvaluateOptions>();
  command.add_option("motion", o->motion, "motion YAML file (docs/reference/input-files.md)")->required()->check(CLI::ExistingFile);
  command.add_option("--out", o->out, "folder for result.json and trajectory.csv (written atomically)");
  return [o] { return runEvaluate(*o); };
}

}  // namespace mcopt::cli
