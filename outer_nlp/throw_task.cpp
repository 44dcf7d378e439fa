// SPDX-License-Identifier: BSD-3-Clause
// The `throw` task of a scenario file, read into the ball and its two rows (declared in
// outer_nlp/scenario_yaml.hpp, outer_nlp's one header with yaml-cpp types).
#include <array>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/errors.hpp"
#include "core/yaml_fields.hpp"
#include "outer_nlp/ball_flight_task.hpp"
#include "outer_nlp/scenario.hpp"
#include "outer_nlp/scenario_yaml.hpp"

namespace mcopt {

namespace {

using yaml::where;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.14159265358979323846;

/// [lower, upper] with null for an open end; lower ≤ upper.
std::array<double, 2> interval(const std::filesystem::path& file, const YAML::Node& node, const std::string& field) {
  if (!node.IsSequence() || node.size() != 2)
    throw InputError(where(file, node, field) + "expected [lower, upper] (null for an open end)");
  const double lower = node[0].IsNull() ? -kInf : yaml::number(file, node[0], field + "[0]");
  const double upper = node[1].IsNull() ? kInf : yaml::number(file, node[1], field + "[1]");
  if (lower > upper) throw InputError(where(file, node, field) + "the lower bound is above the upper bound");
  return {lower, upper};
}

}  // namespace

void readThrowTask(const std::filesystem::path& file, const YAML::Node& node, const std::string& field, Scenario& s) {
  yaml::rejectUnknownKeys(file, node, field,
                          {"name", "kind", "body", "point", "ball_mass", "time", "target", "tolerance", "speed", "elevation",
                           "flight_time"});
  if (s.ball) throw InputError(where(file, node, field) + "a scenario has one throw (the first is " + s.ball->origin + ")");
  ThrownBall ball;
  ball.origin = where(file, node, field);
  ball.origin.resize(ball.origin.size() - 2);  // without the trailing ": "
  const YAML::Node bodyNode = yaml::required(file, node, "body", field);
  ball.body = yaml::text(file, bodyNode, field + ".body");
  ball.frame = s.robot.findFrame(ball.body);
  if (ball.frame < 0)
    throw InputError(where(file, bodyNode, field + ".body") + "unknown body '" + ball.body + "' " +
                     s.robot.unknownFrameHint(ball.body));
  if (node["point"]) {
    const auto p = yaml::numbers(file, node["point"], field + ".point", 3);
    ball.point = Vector3(p[0], p[1], p[2]);
  }
  const YAML::Node massNode = yaml::required(file, node, "ball_mass", field);
  ball.mass = yaml::positive(file, massNode, field + ".ball_mass");

  // The release: strictly inside the motion (before it nothing is carried, after it nothing flies).
  const YAML::Node timeNode = yaml::required(file, node, "time", field);
  ball.releaseTime = yaml::number(file, timeNode, field + ".time");
  if (!(ball.releaseTime > 0.0 && ball.releaseTime < s.duration.initial))
    throw InputError(where(file, timeNode, field + ".time") + "the release must be inside the motion, 0 < t_r < " +
                     std::to_string(s.duration.initial) + " s");

  // Flight under gravity along −z: the analytic flight time needs it (formulation.md §10).
  if (s.gravity.head<2>().norm() > 1e-12 * s.gravity.norm() || !(s.gravity.z() < 0.0))
    throw InputError(where(file, node, field) + "a throw needs gravity along −z (gravity: [0, 0, −g])");

  const YAML::Node targetNode = yaml::required(file, node, "target", field);
  const auto target = yaml::numbers(file, targetNode, field + ".target", 3);
  ball.target = Vector3(target[0], target[1], target[2]);
  ball.gravity = -s.gravity.z();

  TaskSpec landing;
  landing.name = node["name"] ? yaml::text(file, node["name"], field + ".name") : field;
  landing.origin = ball.origin;
  landing.task = std::make_shared<BallFlightTask>(BallFlightTask::Part::Landing, ball.frame, ball.point, ball.target,
                                                  ball.gravity);
  landing.start = landing.end = ball.releaseTime;
  landing.lower.setConstant(3, -kInf), landing.upper.setConstant(3, kInf);
  // A point target, or a box: half-widths in x and y of the landing point at the target's height.
  Eigen::Vector2d tolerance = Eigen::Vector2d::Zero();
  if (const YAML::Node t = node["tolerance"]) {
    if (t.IsSequence()) {
      const auto v = yaml::numbers(file, t, field + ".tolerance", 2);
      for (int i = 0; i < 2; ++i)
        if (v[static_cast<std::size_t>(i)] < 0.0)
          throw InputError(where(file, t, field + ".tolerance") + "half-widths must not be negative");
      tolerance = Eigen::Vector2d(v[0], v[1]);
    } else {
      tolerance.setConstant(yaml::nonNegative(file, t, field + ".tolerance"));
    }
  }
  landing.lower.head<2>() = -tolerance, landing.upper.head<2>() = tolerance;
  if (const YAML::Node t = node["flight_time"]) {
    const auto b = interval(file, t, field + ".flight_time");
    if (!(b[1] > 0.0)) throw InputError(where(file, t, field + ".flight_time") + "a flight takes a positive time");
    landing.lower[2] = b[0], landing.upper[2] = b[1];
  }

  TaskSpec release = landing;
  release.task = std::make_shared<BallFlightTask>(BallFlightTask::Part::Release, ball.frame, ball.point, ball.target,
                                                  ball.gravity);
  release.lower.setConstant(3, -kInf), release.upper.setConstant(3, kInf);
  if (const YAML::Node t = node["speed"]) {
    const auto b = interval(file, t, field + ".speed");
    if (!(b[1] > 0.0)) throw InputError(where(file, t, field + ".speed") + "a release speed is positive");
    release.lower[0] = b[0], release.upper[0] = b[1];
  }
  if (const YAML::Node t = node["elevation"]) {
    const auto b = interval(file, t, field + ".elevation");
    if (b[0] > 90.0 || b[1] < -90.0)
      throw InputError(where(file, t, field + ".elevation") + "an elevation lies in [−90°, 90°]");
    release.lower[1] = b[0] * kPi / 180.0, release.upper[1] = b[1] * kPi / 180.0;
  }
  release.lower[2] = 0.0;  // the ball reaches the target's height (ballistic_flight.hpp)
  s.tasks.push_back(landing);
  s.tasks.push_back(release);
  s.ball = ball;
}

void checkThrowTask(const std::filesystem::path& file, const YAML::Node& node, const std::string& field, const Scenario& s) {
  const ThrownBall& ball = *s.ball;
  const int body = s.robot.frames[static_cast<std::size_t>(ball.frame)].body;
  auto contactBody = [&](const ContactSurface& c) { return s.robot.frames[static_cast<std::size_t>(c.frame)].body; };
  if (contactBody(s.support) == body)
    throw InputError(where(file, node["body"], field + ".body") + "the ball would be on the body of contact '" +
                     s.support.name + "' (the reference body)");
  for (const EnvironmentContact& c : s.contacts)
    if (contactBody(c.surface) == body)
      throw InputError(where(file, node["body"], field + ".body") + "the ball would be on the body of contact '" +
                       c.surface.name + "'");
  // The payload changes the dynamics at the release: the two torques there are a sample's.
  std::vector<int> grids{s.samples};
  for (const ContinuationStage& c : s.solve.continuation) grids.push_back(c.samples);
  for (const int N : grids) {
    const double k = ball.releaseTime / s.duration.initial * (N - 1);
    if (std::abs(k - std::round(k)) > 1e-9 * (N - 1)) {
      std::ostringstream message;
      message << "the release t_r = " << ball.releaseTime << " s is not a sample of the " << N << "-sample grid (every "
              << s.duration.initial / (N - 1) << " s; nearest " << std::round(k) * s.duration.initial / (N - 1) << " s)";
      throw InputError(where(file, node["time"], field + ".time") + message.str());
    }
  }
}

}  // namespace mcopt
