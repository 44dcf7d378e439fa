// SPDX-License-Identifier: BSD-3-Clause
// Analytic derivatives of Γ0 and W0 against central finite differences (issue 4
// acceptance: relative error ≤ 1e-6 scaled by 1 + |value|) on random states of every robot,
// rooted at a sole so that reversed joints are exercised.
#include <catch2/catch.hpp>

#include "common/finite_differences.hpp"
#include "common/robots.hpp"
#include "core/dynamics_derivatives.hpp"

using namespace mcopt;

namespace {

struct Outputs {
  Eigen::VectorXd tau;
  Vector6 wrench;
};

Outputs evaluate(const DynamicsModel& model, DynamicsData& data, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                 const Eigen::VectorXd& a) {
  inverseDynamics(model, data, q, v, a);
  return {data.tau, data.referenceWrench};
}

}  // namespace

TEST_CASE("inverse dynamics derivatives match central differences", "[derivatives][dynamics]") {
  std::mt19937 rng(21);
  for (const auto& named : test::allRobots()) {
    const RobotModel robot = test::load(named);
    for (const std::string& root : {named.soles[0], robot.frames[0].name}) {
      const DynamicsModel model(robot, root);
      DynamicsData data(model), scratch(model);
      DynamicsDerivatives derivatives(model);
      const int n = robot.jointCount();
      for (int trial = 0; trial < 3; ++trial) {
        Eigen::VectorXd q, v, a;
        test::randomState(rng, robot, q, v, a);
        inverseDynamicsDerivatives(model, data, derivatives, q, v, a);
        // The derivative call leaves the plain results in `data`.
        const Outputs plain = evaluate(model, scratch, q, v, a);
        CHECK(test::scaledError(data.tau, plain.tau) <= 1e-12);

        for (Eigen::VectorXd* input : {&q, &v, &a}) {
          // Torques and wrench stacked: rows 0…n−1 torques, n…n+5 the wrench.
          const Eigen::MatrixXd fd = test::centralDifferences(*input, 1e-6, [&] {
            const Outputs o = evaluate(model, scratch, q, v, a);
            Eigen::VectorXd stacked(n + 6);
            stacked << o.tau, o.wrench;
            return stacked;
          });
          const Eigen::MatrixXd fdTau = fd.topRows(n);
          const Eigen::MatrixXd fdWrench = fd.bottomRows(6);
          const bool isQ = input == &q, isV = input == &v;
          const Eigen::MatrixXd& analytic = isQ ? derivatives.dtauDq : isV ? derivatives.dtauDv : derivatives.dtauDa;
          const auto& analyticWrench = isQ ? derivatives.dwrenchDq : isV ? derivatives.dwrenchDv : derivatives.dwrenchDa;
          INFO(named.name << " rooted at " << root << ", trial " << trial << ", w.r.t. " << (isQ ? "q" : isV ? "v" : "a"));
          CHECK(test::scaledError(analytic, fdTau) <= 1e-6);
          CHECK(test::scaledError(analyticWrench, fdWrench) <= 1e-6);
          CHECK(analytic.cwiseAbs().maxCoeff() > 1e-3);  // a map that really varies
        }
        // The mass matrix is symmetric positive definite.
        CHECK((derivatives.dtauDa - derivatives.dtauDa.transpose()).cwiseAbs().maxCoeff() <= 1e-12);
      }
    }
  }
}
