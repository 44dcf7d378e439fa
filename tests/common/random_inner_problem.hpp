// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Random inner problems (formulation.md §7) shared by the solver and command tests: nc
// contacts — a floor foot, then feet, a hand on a wall, a hand on a table — with a balance
// wrench produced by admissible wrenches, so the problem is feasible.
#include <numbers>
#include <random>
#include <vector>

#include "core/spatial.hpp"
#include "inner_qp/contact_problem.hpp"

namespace mcopt::test {

struct RandomProblem {
  std::vector<ContactSpec> contacts;
  Eigen::MatrixXd wrenchToTorque;
  Eigen::VectorXd tau0, weights, linear;
  Vector6 balance;
};

inline RandomProblem randomProblem(std::mt19937& rng, int nc, int joints = 12) {
  // 12 joints for up to 24 wrench components: H is singular on the balance's null space
  // (up to the Tikhonov term), the hard case for a QP method; the optimum is then not unique
  // in F, only in value.
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  RandomProblem r;
  for (int i = 0; i < nc; ++i) {
    ContactSpec c;
    c.name = "contact" + std::to_string(i);
    c.friction = 0.4 + 0.4 * std::abs(u(rng));
    const double halfX = 0.03 + 0.1 * std::abs(u(rng)), halfY = 0.02 + 0.05 * std::abs(u(rng));
    const double cx = 0.02 * u(rng), cy = 0.01 * u(rng);
    c.xMin = cx - halfX, c.xMax = cx + halfX, c.yMin = cy - halfY, c.yMax = cy + halfY;
    const double yaw = std::numbers::pi * u(rng);
    if (i == 2)  // a hand on a wall: the normal into the robot is horizontal
      c.pose.rotation = rotationFromRpy(0.0, -std::numbers::pi / 2, yaw);
    else
      c.pose.rotation = rotationFromRpy(0.1 * u(rng), 0.1 * u(rng), yaw);
    c.pose.translation = Vector3(0.5 * u(rng), 0.5 * u(rng), i >= 2 ? 1.0 + 0.2 * u(rng) : 0.05 * u(rng));
    r.contacts.push_back(c);
  }
  r.wrenchToTorque = Eigen::MatrixXd::NullaryExpr(joints, 6 * nc, [&] { return u(rng); });
  r.tau0 = Eigen::VectorXd::NullaryExpr(joints, [&] { return 30.0 * u(rng); });
  r.weights = Eigen::VectorXd::NullaryExpr(joints, [&] { return 0.01 + 0.1 * std::abs(u(rng)); });
  r.linear = Eigen::VectorXd::NullaryExpr(joints, [&] { return u(rng); });
  // An admissible wrench per contact (strictly inside cone and rectangle).
  Eigen::VectorXd admissible(6 * nc);
  for (int i = 0; i < nc; ++i) {
    const ContactSpec& c = r.contacts[i];
    const double fz = 50.0 + 200.0 * std::abs(u(rng));
    const double angle = std::numbers::pi * u(rng), shear = 0.8 * c.friction * fz * std::abs(u(rng));
    const double copX = 0.5 * (c.xMin + c.xMax) + 0.4 * (c.xMax - c.xMin) * u(rng);
    const double copY = 0.5 * (c.yMin + c.yMax) + 0.4 * (c.yMax - c.yMin) * u(rng);
    admissible.segment<6>(6 * i) << shear * std::cos(angle), shear * std::sin(angle), fz, copY * fz, -copX * fz, 0.0;
  }
  ContactProblem assembled = assembleContactProblem(r.contacts, r.wrenchToTorque, r.tau0, Vector6::Zero(), r.weights,
                                                    r.linear, {});
  r.balance = assembled.balance * admissible;
  return r;
}

/// The problem under a registered contact model ("report", "pyramid", "wrench-cone").
inline ContactProblem assemble(const RandomProblem& r, const std::string& model, int facets = 8) {
  ContactProblemSettings settings;
  settings.model = makeContactModel(model, {.pyramidFacets = facets});
  return assembleContactProblem(r.contacts, r.wrenchToTorque, r.tau0, r.balance, r.weights, r.linear, settings);
}

}  // namespace mcopt::test
