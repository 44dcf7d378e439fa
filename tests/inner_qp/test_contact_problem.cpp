// SPDX-License-Identifier: BSD-3-Clause
// Assembly of the per-sample inner problem (formulation.md §5, §7): objective, balance and
// the three contact models' constraints, checked on hand-built wrenches.
#include <catch2/catch.hpp>

#include "common/test_support.hpp"
#include "core/errors.hpp"
#include "inner_qp/contact_problem.hpp"

using namespace mcopt;
using Catch::Matchers::Contains;

namespace {

std::vector<ContactSpec> twoContacts() {
  ContactSpec foot{"foot", {}, 0.7, -0.1, 0.13, -0.065, 0.065, 0.0, nullptr};
  ContactSpec hand{"hand", {}, 0.5, -0.04, 0.04, -0.025, 0.025, 0.0, nullptr};
  // A hand on a wall: normal into the robot along world −x.
  hand.pose.rotation = rotationFromRpy(0.0, -std::numbers::pi / 2, 0.3);
  hand.pose.translation = Vector3(0.4, -0.2, 1.0);
  foot.pose.translation = Vector3(0.0, 0.1, 0.0);
  return {foot, hand};
}

ContactProblem assemble(const std::string& model, std::mt19937& rng, int facets = 8) {
  const int n = 7;
  const Eigen::MatrixXd J1 = Eigen::MatrixXd::NullaryExpr(n, 12, [&] { return std::uniform_real_distribution<double>(-1, 1)(rng); });
  const Eigen::VectorXd tau0 = test::randomVector(rng, n, 20.0);
  const Eigen::VectorXd w = test::randomVector(rng, n, 1.0).cwiseAbs().array() + 0.1;
  const Eigen::VectorXd l = test::randomVector(rng, n, 2.0);
  ContactProblemSettings settings;
  settings.model = makeContactModel(model, {.pyramidFacets = facets});
  return assembleContactProblem(twoContacts(), J1, tau0, Vector6::Zero(), w, l, settings);
}

/// Linear and cone constraints only (balance excluded).
double contactViolation(const ContactProblem& p, const Eigen::VectorXd& F) {
  ContactProblem copy = p;
  copy.balanceTarget = p.balance * F;
  return copy.constraintViolation(F);
}

}  // namespace

TEST_CASE("objective is Σ w Γ² + l Γ with Γ = τ0 − J1 F, H and c are its quadratic form", "[inner]") {
  std::mt19937 rng(3);
  const int n = 5;
  const Eigen::MatrixXd J1 = Eigen::MatrixXd::Random(n, 12);
  const Eigen::VectorXd tau0 = test::randomVector(rng, n, 20.0), l = test::randomVector(rng, n, 2.0);
  const Eigen::VectorXd w = test::randomVector(rng, n, 1.0).cwiseAbs().array() + 0.1;
  const ContactProblem p = assembleContactProblem(twoContacts(), J1, tau0, Vector6::Zero(), w, l, {});
  for (int trial = 0; trial < 10; ++trial) {
    const Eigen::VectorXd F = test::randomVector(rng, 12, 50.0);
    const Eigen::VectorXd gamma = tau0 - J1 * F;
    const double expected = (w.cwiseProduct(gamma.cwiseProduct(gamma)) + l.cwiseProduct(gamma)).sum();
    CHECK(p.objective(F) == Approx(expected).epsilon(1e-12));
  }
  CHECK((p.hessian - p.hessian.transpose()).cwiseAbs().maxCoeff() <= 1e-14 * p.hessian.cwiseAbs().maxCoeff());
}

TEST_CASE("balance rows move each contact wrench to the world origin", "[inner]") {
  std::mt19937 rng(5);
  const ContactProblem p = assemble("report", rng);
  const auto contacts = twoContacts();
  const Eigen::VectorXd F = test::randomVector(rng, 12, 50.0);
  Vector6 total = Vector6::Zero();
  for (int i = 0; i < 2; ++i) {
    const Matrix3& R = contacts[i].pose.rotation;
    const Vector3 f = R * F.segment<3>(6 * i), m = R * F.segment<3>(6 * i + 3);
    total.head<3>() += f;
    total.tail<3>() += m + contacts[i].pose.translation.cross(f);
  }
  CHECK(test::scaledError(p.balance * F, total) <= 1e-12);
}

TEST_CASE("contact models: inside, outside and the cone's inner pyramid", "[inner]") {
  std::mt19937 rng(7);
  for (const std::string model : {"report", "pyramid", "wrench-cone"}) {
    const ContactProblem p = assemble(model, rng);
    // Both contacts pushing, CoP well inside, friction well inside, no yaw torque.
    Eigen::VectorXd F(12);
    F << 5, -3, 300, 2, -4, 0, 1, 1, 40, 0.1, -0.2, 0;
    CHECK(contactViolation(p, F) == 0.0);
    Eigen::VectorXd pulling = F;
    pulling[2] = -10;  // a foot that pulls on the floor
    CHECK(contactViolation(p, pulling) > 0.0);
    Eigen::VectorXd copOut = F;
    copOut[4] = -0.2 * 300;  // −m_y / fz = 0.2 > x_max
    CHECK(contactViolation(p, copOut) > 0.0);
    Eigen::VectorXd slipping = F;
    slipping[0] = 0.75 * 300;  // |f_t| > μ fz
    CHECK(contactViolation(p, slipping) > 0.0);
  }
  // The pyramid is inscribed in the cone: what it admits, the cone admits.
  const ContactProblem pyramid = assemble("pyramid", rng, 6);
  const ContactProblem cone = assemble("report", rng);
  int admitted = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    Eigen::VectorXd F = Eigen::VectorXd::Zero(12);
    F[0] = std::uniform_real_distribution<double>(-1, 1)(rng);
    F[1] = std::uniform_real_distribution<double>(-1, 1)(rng);
    F[2] = 1.0;
    F[8] = 1.0;  // the hand carries a light, frictionless load
    if (contactViolation(pyramid, F) == 0.0) {
      ++admitted;
      CHECK(contactViolation(cone, F) <= 1e-12);
    }
  }
  CHECK(admitted > 100);
}

TEST_CASE("the wrench cone forbids a yaw slip that the report model allows", "[inner]") {
  std::mt19937 rng(11);
  const ContactProblem report = assemble("report", rng);
  const ContactProblem wrenchCone = assemble("wrench-cone", rng);
  // Foot: X = 0.115, Y = 0.065, μ̃ = 0.7/√2: yaw limit μ̃ (X + Y) fz = 0.0891 fz at zero shear.
  Eigen::VectorXd F = Eigen::VectorXd::Zero(12);
  F[2] = 100.0;
  F[4] = -0.015 * 100.0;  // centre of pressure at the rectangle's centre, x = 0.015
  F[8] = 10.0;
  F[5] = 0.085 * 100.0;  // within the yaw bound
  CHECK(contactViolation(report, F) == 0.0);
  CHECK(contactViolation(wrenchCone, F) == 0.0);
  F[5] = 0.095 * 100.0;  // beyond it: the foot would spin
  CHECK(contactViolation(report, F) == 0.0);
  CHECK(contactViolation(wrenchCone, F) > 0.0);
}

TEST_CASE("the wrench cone admits nothing the report model forbids", "[inner]") {
  std::mt19937 rng(17);
  const ContactProblem report = assemble("report", rng);
  const ContactProblem wrenchCone = assemble("wrench-cone", rng);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int admitted = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    // Loaded contacts with shear, centre of pressure and yaw torque spread over and beyond
    // what either model admits.
    Eigen::VectorXd F(12);
    for (int i = 0; i < 2; ++i) {
      const double fz = 10.0 + 100.0 * std::abs(u(rng));
      F.segment<6>(6 * i) << 0.5 * fz * u(rng), 0.5 * fz * u(rng), fz, 0.05 * fz * u(rng), 0.1 * fz * u(rng),
          0.05 * fz * u(rng);
    }
    if (contactViolation(wrenchCone, F) == 0.0) {
      ++admitted;
      CHECK(contactViolation(report, F) <= 1e-12);
    }
  }
  INFO(admitted << " of 20000 admitted by the wrench cone");
  CHECK(admitted > 100);
}

TEST_CASE("inner problem data errors name the field or contact", "[inner][input]") {
  std::mt19937 rng(13);
  const Eigen::MatrixXd J1 = Eigen::MatrixXd::Random(3, 12);
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(3);
  auto contacts = twoContacts();
  CHECK_THROWS_WITH(assembleContactProblem(contacts, Eigen::MatrixXd::Random(3, 6), ones, Vector6::Zero(), ones, ones, {}),
                    Contains("wrench_to_torque") && Contains("3 × 12"));
  CHECK_THROWS_WITH(assembleContactProblem(contacts, J1, ones, Vector6::Zero(), -ones, ones, {}),
                    Contains("torque_weights"));
  contacts[1].friction = 0.0;
  CHECK_THROWS_WITH(assembleContactProblem(contacts, J1, ones, Vector6::Zero(), ones, ones, {}),
                    Contains("contact 'hand'") && Contains("mu"));
  contacts[1].friction = 0.5;
  contacts[0].xMax = contacts[0].xMin;
  CHECK_THROWS_WITH(assembleContactProblem(contacts, J1, ones, Vector6::Zero(), ones, ones, {}),
                    Contains("contact 'foot'") && Contains("rectangle"));
  contacts[0].xMax = 0.1;
  Vector6 nan = Vector6::Zero();
  nan[2] = std::nan("");
  CHECK_THROWS_WITH(assembleContactProblem(contacts, J1, ones, nan, ones, ones, {}), Contains("NaN"));
}
