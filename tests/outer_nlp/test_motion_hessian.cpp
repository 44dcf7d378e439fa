// The motion problem's Lagrangian Hessian by per-sample differences (outer_nlp/motion_hessian.cpp)
// against central differences of the exact whole gradient ∇L = σ ∇f + Jᵀ λ, and against the
// generic differences of whole gradients: the kick (every task kind it has, the acceleration
// regularisation, fixed and free duration, smooth maximum and epigraph) and the multi-contact
// formulations with two and three contacts.
#include <catch2/catch.hpp>

#include <random>

#include "common/finite_differences.hpp"
#include "common/perturbed_motion.hpp"
#include "common/test_support.hpp"
#include "core/kinematics.hpp"
#include "outer_nlp/motion_problem.hpp"

namespace mcopt {

namespace {

Eigen::VectorXd randomMultipliers(const MotionProblem& problem, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> u(0.1, 1.0);
  Eigen::VectorXd lambda(problem.constraintCount());
  for (Eigen::Index r = 0; r < lambda.size(); ++r) lambda[r] = (r % 2 == 0 ? 1.0 : -1.0) * u(random);
  return lambda;
}

Eigen::MatrixXd dense(const Eigen::VectorXd& lower, int size) {
  Eigen::MatrixXd h(size, size);
  for (int r = 0; r < size; ++r)
    for (int c = 0; c <= r; ++c) h(r, c) = h(c, r) = lower[lowerTriangleIndex(r, c)];
  return h;
}

/// Largest |H − reference| relative to the reference's largest entry.
double hessianError(MotionProblem& problem, Eigen::VectorXd x, const Eigen::VectorXd& lambda, double sigma,
                    double* againstGeneric = nullptr) {
  const int curved = problem.nonlinearVariableCount();
  Eigen::VectorXd values;
  problem.lagrangianHessian(x, sigma, lambda, values);
  const Eigen::MatrixXd h = dense(values, curved);
  const Eigen::MatrixXd columns = test::centralDifferences(x, 1e-5, [&] {
    Eigen::VectorXd g;
    problem.lagrangianGradient(x, sigma, lambda, g);
    return Eigen::VectorXd(g.head(curved));
  });
  const Eigen::MatrixXd reference = 0.5 * (columns.leftCols(curved) + columns.leftCols(curved).transpose());
  const double scale = std::max(1.0, reference.cwiseAbs().maxCoeff());
  if (againstGeneric != nullptr) {
    Eigen::VectorXd generic;
    problem.NlpProblem::lagrangianHessian(x, sigma, lambda, generic);
    *againstGeneric = (dense(generic, curved) - h).cwiseAbs().maxCoeff() / scale;
  }
  Eigen::Index r, c;
  const double worst = (h - reference).cwiseAbs().maxCoeff(&r, &c);
  UNSCOPED_INFO("worst entry (" << r << ", " << c << "): " << h(r, c) << " against " << reference(r, c) << "; force variables from "
                               << problem.forceVariableStart() << ", scale " << scale);
  return worst / scale;
}

Scenario kick(int samples) {
  Scenario s = loadScenario(test::sourceDir() / "scenarios/hrp2_kick.yaml");
  s.samples = samples;
  s.outputSamples = 20;
  s.hessian = HessianOption::SampleDifferences;
  return s;
}


}  // namespace

TEST_CASE("sample-differences Hessian: the kick against differences of the exact gradient", "[outer][hessian]") {
  struct Case {
    const char* name;
    bool freeDuration, epigraph;
    double accelerationWeight;
  };
  for (const Case& c : {Case{"fixed T, smooth maximum", false, false, 0.0}, Case{"free T, smooth maximum", true, false, 0.0},
                        Case{"fixed T, epigraph", false, true, 0.0}, Case{"free T, regularised", true, false, 1e-3}}) {
#ifdef MCOPT_UNDER_SANITIZERS
    if (c.accelerationWeight == 0.0 && !c.epigraph) continue;  // the epigraph and the free, regularised T; Release runs all four
#endif
    Scenario s = kick(16);
    if (c.freeDuration) s.duration.lower = 1.2, s.duration.upper = 2.0;
    if (c.epigraph) s.energyForm = EnergyForm::Epigraph;
    s.accelerationWeight = c.accelerationWeight;
    MotionProblem problem(s);
    Eigen::VectorXd x = test::perturbedMotion(problem, 0.05, 3);
    if (c.freeDuration) x[problem.parametrization().parameterCount()] = 1.5;
    double generic = 0.0;
    const double error = hessianError(problem, x, randomMultipliers(problem, 5), 0.8, &generic);
    INFO(c.name << ": against central differences " << error << ", against the generic differences " << generic);
    CHECK(error < 1e-3);
    CHECK(generic < 1e-3);
  }
}

TEST_CASE("sample-differences Hessian: every contact-force formulation", "[outer][hessian][multi-contact]") {
  for (const ContactForces forces : {ContactForces::Splines, ContactForces::Variables, ContactForces::Bilevel}) {
#ifdef MCOPT_UNDER_SANITIZERS
    if (forces == ContactForces::Variables) continue;  // the splines' code path, more columns; Release runs it
#endif
    Scenario s = loadScenario(test::sourceDir() / "scenarios/hrp2_lean_reach.yaml");
    s.samples = 10;
    s.outputSamples = 20;
    s.forceControlPoints = 6;
    s.contactForces = forces;
    s.hessian = HessianOption::SampleDifferences;
    MotionProblem problem(s);
    const Eigen::VectorXd x = test::perturbedMotion(problem, 0.02, 11);
    double generic = 0.0;
    const double error = hessianError(problem, x, randomMultipliers(problem, 13), 1.0, &generic);
    INFO(toString(forces) << ": against central differences " << error << ", against the generic differences " << generic << "; infeasible samples "
                          << problem.infeasibleSamples());
    CHECK(error < 1e-3);
  }
}

}  // namespace mcopt
