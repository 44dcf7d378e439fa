// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Clamped uniform cubic B-splines for joint trajectories (formulation.md §3).
//   q_j(t) = Σ_k p_jk b_k(t/T),  t ∈ [0, T],  n control points (default 9, 6 spans).
// Zero velocity and acceleration at both ends: p_1 = p_2 = p_3 = q_start and
// p_{n-2} = p_{n-1} = p_n = q_end, so a joint has n − 4 free parameters
// (q_start, p_4 … p_{n-3}, q_end): 5 for n = 9.

#include <Eigen/Core>
#include <array>
#include <vector>

namespace mcopt {

/// The 4 basis functions that are non-zero at one normalised time u ∈ [0, 1].
struct LocalBasis {
  int first = 0;                   ///< index of the first non-zero basis function (0-based)
  std::array<double, 4> value{};   ///< b_{first+i}(u)
  std::array<double, 4> d1{};      ///< d b / du
  std::array<double, 4> d2{};      ///< d² b / du²
};

class BSplineBasis {
 public:
  explicit BSplineBasis(int controlPointCount = 9);
  int controlPointCount() const { return n_; }
  int spanCount() const { return n_ - 3; }
  const std::vector<double>& knots() const { return knots_; }  ///< n + 4 normalised knots
  /// u outside [0, 1] is clamped.
  LocalBasis evaluate(double u) const;

 private:
  int n_;
  std::vector<double> knots_;
};

/// Maps the free parameters of a joint to its n control points and back (formulation.md §3).
/// Parameter vector layout: joint-major, x[j·perJoint + k]. Per joint: the start posture
/// (control points 0–2: at rest), the n − 6 inner control points, the end posture (the last
/// three); `periodic`: the end is the start (one parameter for both, n − 5 a joint), so the
/// motion returns exactly to where it started.
class MotionParametrization {
 public:
  MotionParametrization(int jointCount, int controlPointCount = 9, bool periodic = false);
  int jointCount() const { return joints_; }
  int controlPointCount() const { return basis_.controlPointCount(); }
  bool periodic() const { return periodic_; }
  int parametersPerJoint() const { return basis_.controlPointCount() - (periodic_ ? 5 : 4); }
  /// The parameter (within its joint) of the end posture: the last one, or the start's when periodic.
  int endParameter() const { return periodic_ ? 0 : parametersPerJoint() - 1; }
  int parameterCount() const { return joints_ * parametersPerJoint(); }
  const BSplineBasis& basis() const { return basis_; }

  /// Free parameter (within its joint) that sets control point k.
  int parameterOfControlPoint(int k) const;
  /// controlPoints: jointCount × n, written.
  void controlPoints(const Eigen::Ref<const Eigen::VectorXd>& parameters, Eigen::MatrixXd& controlPoints) const;
  /// Parameters that hold a joint still at `posture` (jointCount values).
  Eigen::VectorXd constantMotion(const Eigen::Ref<const Eigen::VectorXd>& posture) const;
  /// Parameters moving from `start` to `end` with the inner control points spaced linearly
  /// (periodic: from `start` out to `end` at mid-motion and back).
  Eigen::VectorXd interpolatedMotion(const Eigen::Ref<const Eigen::VectorXd>& start,
                                     const Eigen::Ref<const Eigen::VectorXd>& end) const;
  /// Control points of the velocity (a quadratic B-spline): n − 1 per joint,
  /// 3 (p_{k+1} − p_k) / (T (u_{k+4} − u_{k+1})). Joint velocity limits hold on the whole
  /// motion when they hold here (convex hull). velocity: jointCount × (n − 1), written.
  void velocityControlPoints(const Eigen::MatrixXd& controlPoints, double duration, Eigen::MatrixXd& velocity) const;

 private:
  int joints_;
  BSplineBasis basis_;
  bool periodic_ = false;
};

/// Local dependence of one sample on one joint's free parameters: at most 4 control
/// points are non-zero, i.e. at most 4 free parameters (fewer near the ends, where
/// control points share q_start / q_end).
struct LocalParameterWeights {
  int count = 0;
  std::array<int, 4> parameter{};   ///< free-parameter index within the joint
  std::array<double, 4> value{};    ///< ∂q/∂x
  std::array<double, 4> d1{};       ///< ∂(dq/du)/∂x: divide by T for ∂q̇/∂x
  std::array<double, 4> d2{};       ///< ∂(d²q/du²)/∂x: divide by T² for ∂q̈/∂x
};

/// The fixed normalised sample times u_s = s / (N − 1) with their basis values, computed
/// once: T only scales derivatives (q̇ = (1/T) dq/du, q̈ = (1/T²) d²q/du²).
class SampledTrajectory {
 public:
  SampledTrajectory(const MotionParametrization& parametrization, int sampleCount);
  /// Samples at given normalised times u = t / T ∈ [0, 1] (task instants, fine resampling).
  SampledTrajectory(const MotionParametrization& parametrization, const std::vector<double>& normalisedTimes);
  int sampleCount() const { return static_cast<int>(bases_.size()); }
  const MotionParametrization& parametrization() const { return parametrization_; }
  double time(int sample, double duration) const { return duration * u_[sample]; }
  const LocalBasis& basis(int sample) const { return bases_[sample]; }
  const LocalParameterWeights& weights(int sample) const { return weights_[sample]; }

  /// Chain rule through the splines for any per-sample output y(q, q̇, q̈) (rows m):
  ///   ∂y/∂x_{j,l} = ∂y/∂q_j w_l + ∂y/∂q̇_j w'_l / T + ∂y/∂q̈_j w''_l / T²
  /// over the k ≤ 4 local parameters of every joint. dyDx: m × (jointCount · k), written;
  /// parameters: jointCount · k global indices, written. Either input may be empty (zero).
  void chainRule(int sample, double duration, const Eigen::Ref<const Eigen::MatrixXd>& dyDq,
                 const Eigen::Ref<const Eigen::MatrixXd>& dyDv, const Eigen::Ref<const Eigen::MatrixXd>& dyDa,
                 Eigen::MatrixXd& dyDx, Eigen::VectorXi& parameters) const;

  /// ∂y/∂T = −(∂y/∂q̇ q̇ + 2 ∂y/∂q̈ q̈) / T (q fixed: it depends on t/T only). dyDT: m, written.
  static void durationDerivative(double duration, const Eigen::Ref<const Eigen::MatrixXd>& dyDv,
                                 const Eigen::Ref<const Eigen::MatrixXd>& dyDa, const Eigen::Ref<const Eigen::VectorXd>& v,
                                 const Eigen::Ref<const Eigen::VectorXd>& a, Eigen::VectorXd& dyDT);

  /// q, v, a of every joint at one sample (jointCount each, written; no allocation).
  void evaluate(int sample, const Eigen::MatrixXd& controlPoints, double duration, Eigen::Ref<Eigen::VectorXd> q,
                Eigen::Ref<Eigen::VectorXd> v, Eigen::Ref<Eigen::VectorXd> a) const;

 private:
  MotionParametrization parametrization_;
  std::vector<double> u_;
  std::vector<LocalBasis> bases_;
  std::vector<LocalParameterWeights> weights_;
};

}  // namespace mcopt
