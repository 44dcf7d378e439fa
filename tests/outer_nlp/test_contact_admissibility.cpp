// SPDX-License-Identifier: BSD-3-Clause
// The single-level formulations' contact rows (outer_nlp/contact_admissibility.hpp): the
// scenario's contact model on each wrench, the same rows as the inner problem's
// (inner_qp/contact_problem.hpp), with exact derivatives; the wrench cone's yaw rows present
// in the NLP and biting where the report model's rows do not.
#include <catch2/catch.hpp>

#include <map>
#include <random>

#include "common/finite_differences.hpp"
#include "common/test_support.hpp"
#include "core/contact_maps.hpp"
#include "inner_qp/contact_problem.hpp"
#include "outer_nlp/contact_admissibility.hpp"
#include "outer_nlp/motion_problem.hpp"

namespace mcopt {

namespace {

ContactSurface sole() {
  ContactSurface s;
  s.name = "sole";
  s.xMin = -0.08, s.xMax = 0.13, s.yMin = -0.07, s.yMax = 0.06, s.friction = 0.7;
  return s;
}

RigidTransform tiltedPose() {
  RigidTransform pose;
  pose.rotation = (Eigen::AngleAxisd(0.4, Vector3::UnitZ()) * Eigen::AngleAxisd(-0.3, Vector3::UnitX())).toRotationMatrix();
  pose.translation << 0.3, -0.2, 0.05;
  return pose;
}

ContactProblemSettings modelSettings(const std::string& model) {
  ContactProblemSettings s;
  s.model = makeContactModel(model, {.pyramidFacets = 6});
  return s;
}

/// Violation of the inner problem's rows (balance held: its target is the wrench itself).
double innerViolation(const ContactSurface& surface, const RigidTransform& pose, const ContactProblemSettings& settings,
                      const Vector6& contactWrench, const Vector6& worldWrench) {
  ContactSpec spec;
  spec.name = surface.name, spec.pose = pose, spec.friction = surface.friction;
  spec.xMin = surface.xMin, spec.xMax = surface.xMax, spec.yMin = surface.yMin, spec.yMax = surface.yMax;
  const Eigen::MatrixXd toTorque = Eigen::MatrixXd::Zero(1, 6);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(1), one = Eigen::VectorXd::Ones(1);
  const ContactProblem p = assembleContactProblem({spec}, toTorque, zero, worldWrench, one, zero, settings);
  return p.constraintViolation(contactWrench);
}

}  // namespace

TEST_CASE("contact admissibility rows: the scenario's contact model, as the inner problem holds it", "[outer][contact]") {
  const ContactSurface surface = sole();
  const RigidTransform pose = tiltedPose();
  const double weight = 58.0 * 9.81;
  Matrix6 toWorld;
  wrenchToWorld(pose, toWorld);  // the wrench maps' own transform, not the rows'
  std::mt19937 rng(5);
  for (const std::string model : {"report", "pyramid", "wrench-cone"}) {
    const ContactAdmissibilityRows rows(surface, pose, weight, modelSettings(model));
    const int expected = model == "report" ? 6 : model == "pyramid" ? 5 + 6 : 17;
    REQUIRE(rows.rowCount() == expected);
    CHECK(rows.rowKind(0) == ContactRowKind::NormalForce);
    int admitted = 0, refused = 0;
    for (int trial = 0; trial < 400; ++trial) {
      // Wrenches in C around a standing load, half of them outside the model.
      Vector6 contact = test::randomVector(rng, 6, 1.0);
      contact[2] = 300.0 + 200.0 * contact[2];
      contact.head<2>() *= 250.0, contact.segment<2>(3) *= 30.0, contact[5] *= 25.0;
      const Vector6 world = toWorld * contact;
      Eigen::VectorXd values(rows.rowCount());
      rows.evaluate(world, values);
      CHECK((rows.contactWrench(world) - contact).norm() < 1e-9 * contact.norm());
      CHECK(values[0] == Approx(contact[2]).epsilon(1e-12));
      const double inner = innerViolation(surface, pose, modelSettings(model), contact, world);
      const double outer = std::max(0.0, -values.minCoeff());
      if (model == "report") {
        // The inner problem keeps the cone as ‖f_xy‖ ≤ μ f_z, the outer row squares it: the
        // same set, other units; decided the same way away from its boundary.
        if (inner > 1e-6 || outer > 1e-9) CHECK((inner > 0.0) == (outer > 0.0));
      } else {
        CHECK(outer == Approx(inner).margin(1e-9));  // the same rows, the same values
      }
      (outer > 0.0 ? refused : admitted) += 1;
    }
    CHECK(admitted > 20);
    CHECK(refused > 20);

    // ∂rows/∂W against central differences.
    Eigen::VectorXd w = toWorld * (Vector6() << 40.0, -25.0, 450.0, 6.0, -9.0, 3.0).finished();
    Eigen::VectorXd values(rows.rowCount());
    ContactRowsByWrench exact(rows.rowCount(), 6);
    rows.evaluate(w, values, exact);
    const Eigen::MatrixXd fd = test::centralDifferences(w, 1e-3, [&] {
      Eigen::VectorXd v(rows.rowCount());
      rows.evaluate(Vector6(w), v);
      return v;
    });
    CHECK(test::scaledError(exact, fd) < 1e-8);
  }
}

TEST_CASE("contact admissibility rows: a model written outside the registry reaches the outer rows as it is",
          "[outer][contact]") {
  // A strip contact (the rectangle's x extent only, the friction pyramid): no bundled layout.
  class StripContactModel final : public ContactModel {
   public:
    std::string name() const override { return "strip"; }
    int rowCount() const override { return 7; }

   protected:
    void writeRows(const ContactSpec& c, ContactRowWriter& out) const override {
      using W = ContactRowWriter;
      out.add("fz_min", ContactRowKind::NormalForce, {{W::Fz, -1.0}}, -c.minNormalForce);
      for (const double s : {1.0, -1.0}) {
        out.add(s > 0 ? "fx_max" : "fx_min", ContactRowKind::Friction, {{W::Fx, s}, {W::Fz, -c.friction}});
        out.add(s > 0 ? "fy_max" : "fy_min", ContactRowKind::Friction, {{W::Fy, s}, {W::Fz, -c.friction}});
      }
      out.add("cop_x_max", ContactRowKind::CenterOfPressure, {{W::My, -1.0}, {W::Fz, -c.xMax}});
      out.add("cop_x_min", ContactRowKind::CenterOfPressure, {{W::My, 1.0}, {W::Fz, c.xMin}});
    }
  };
  ContactProblemSettings settings;
  settings.model = std::make_shared<StripContactModel>();
  const ContactSurface surface = sole();
  const RigidTransform pose = tiltedPose();
  const ContactAdmissibilityRows rows(surface, pose, 58.0 * 9.81, settings);
  REQUIRE(rows.rowCount() == 7);
  CHECK_FALSE(rows.hasQuadraticRows());
  CHECK(rows.rowName(4) == "fy_min");
  CHECK(rows.rowKind(5) == ContactRowKind::CenterOfPressure);
  Matrix6 toWorld;
  wrenchToWorld(pose, toWorld);
  const Vector6 contact = (Vector6() << 30.0, -20.0, 400.0, 3.0, -8.0, 1.0).finished();
  Eigen::VectorXd values(7);
  rows.evaluate(toWorld * contact, values);
  ContactSpec spec;
  spec.friction = surface.friction, spec.xMin = surface.xMin, spec.xMax = surface.xMax;
  spec.yMin = surface.yMin, spec.yMax = surface.yMax;
  const ContactModelRows inner = settings.model->rows(spec);
  const Eigen::VectorXd expected = inner.bound - inner.rows * contact;  // b − G W_C ≥ 0, f_z first
  CHECK((values - expected).cwiseAbs().maxCoeff() <= 1e-9 * contact.norm());
  CHECK(values[0] == Approx(400.0));
}

TEST_CASE("contact admissibility rows: the wrench cone refuses a yaw slip that the report model admits", "[outer][contact]") {
  const ContactSurface surface = sole();
  const double weight = 58.0 * 9.81;
  const ContactAdmissibilityRows report(surface, RigidTransform{}, weight, modelSettings("report"));
  const ContactAdmissibilityRows cone(surface, RigidTransform{}, weight, modelSettings("wrench-cone"));
  // Standing on the rectangle's centre, twisted about the normal: the most the wrench cone
  // admits is μ̃ (X + Y) f_z = 0.7/√2 · 0.235 · 500 ≈ 58 N m.
  const double cx = 0.5 * (surface.xMin + surface.xMax), cy = 0.5 * (surface.yMin + surface.yMax);
  const double fz = 500.0;
  for (const double twist : {20.0, 100.0}) {
    const Vector6 w = (Vector6() << 0.0, 0.0, fz, cy * fz, -cx * fz, twist).finished();
    Eigen::VectorXd byReport(report.rowCount()), byCone(cone.rowCount());
    report.evaluate(w, byReport);
    cone.evaluate(w, byCone);
    CHECK(byReport.minCoeff() >= 0.0);
    INFO("twist " << twist << " N m");
    if (twist < 50.0) {
      CHECK(byCone.minCoeff() >= 0.0);
    } else {
      Eigen::Index worst = 0;
      CHECK(byCone.minCoeff(&worst) < 0.0);
      CHECK(cone.rowKind(static_cast<int>(worst)) == ContactRowKind::Yaw);
      CHECK(cone.rowName(static_cast<int>(worst)).rfind("yaw_", 0) == 0);
    }
  }
}

TEST_CASE("single-level formulations: every wrench holds the scenario's contact model, yaw rows included",
          "[outer][contact][multi-contact]") {
  for (const std::string forces : {"variables", "splines"}) {
    std::map<std::string, MotionProblem::Violations> twisted;
    for (const std::string model : {"report", "wrench-cone"}) {
      Scenario s = loadScenario(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml");
      s.samples = 8, s.outputSamples = 20, s.forceControlPoints = 5;
      s.contactForces = forces;
      s.inner.solverName = "active-set";  // the barrier (the bundled one) refuses the report model's cones
      s.inner.problem = modelSettings(model);
      MotionProblem problem(s);
      int yawRows = 0;
      for (int r = 0; r < problem.constraintCount(); ++r)
        if (problem.rowKind(r) == "contact_yaw") {
          ++yawRows;
          if (yawRows == 1) CHECK(problem.rowName(r).find("yaw_") != std::string::npos);
        }
      // Two contacts (the soles) at every sample, eight yaw rows each.
      CHECK(yawRows == (model == "wrench-cone" ? 8 * 2 * s.samples : 0));
      Eigen::VectorXd x = problem.initialPoint(s.start, s.end);
      const MotionProblem::Violations start = problem.violations(x);
      // Twist the right sole about its normal by 150 N m (each component m_z of its wrench
      // variables or spline coefficients): the left sole's wrench, W0 minus it, twists back.
      for (int k = problem.forceVariableStart() + 5; k < problem.forceVariableStart() + problem.forceVariableCount(); k += 6)
        x[k] += 150.0;
      twisted[model] = problem.violations(x);
      INFO(forces << (model == "report" ? ", report" : ", wrench-cone"));
      CHECK(start.of("contact_yaw") < 1e-9);
      for (const char* k : {"contact_unilateral", "contact_cop"})
        CHECK(twisted[model].of(k) == Approx(start.of(k)).margin(1e-9));
      if (model == "report") CHECK(twisted[model].of("contact_yaw") == 0.0);
      else CHECK(twisted[model].of("contact_yaw") > 50.0);
    }
  }
}

}  // namespace mcopt
