// SPDX-License-Identifier: BSD-3-Clause
#include "core/bspline.hpp"

#include <algorithm>
#include <cmath>

#include "core/errors.hpp"

namespace mcopt {

namespace {
constexpr int kDegree = 3;
}

BSplineBasis::BSplineBasis(int controlPointCount) : n_(controlPointCount) {
  if (n_ < 4) throw InputError("a clamped cubic B-spline needs at least 4 control points, got " + std::to_string(n_));
  const int spans = n_ - kDegree;
  knots_.resize(static_cast<std::size_t>(n_ + kDegree + 1));
  for (int i = 0; i < static_cast<int>(knots_.size()); ++i)
    knots_[i] = std::clamp(static_cast<double>(i - kDegree) / spans, 0.0, 1.0);
}

LocalBasis BSplineBasis::evaluate(double u) const {
  u = std::clamp(u, 0.0, 1.0);
  // Knot span i with knots[i] ≤ u < knots[i+1], the last span closed at u = 1.
  const int spans = n_ - kDegree;
  const int span = kDegree + std::min(static_cast<int>(u * spans), spans - 1);

  // Basis functions and derivatives (Piegl & Tiller, The NURBS Book, algorithm A2.3).
  double ndu[kDegree + 1][kDegree + 1];
  double left[kDegree + 1], right[kDegree + 1];
  ndu[0][0] = 1.0;
  for (int j = 1; j <= kDegree; ++j) {
    left[j] = u - knots_[span + 1 - j];
    right[j] = knots_[span + j] - u;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      ndu[j][r] = right[r + 1] + left[j - r];
      const double temp = ndu[r][j - 1] / ndu[j][r];
      ndu[r][j] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    ndu[j][j] = saved;
  }
  double ders[3][kDegree + 1];
  for (int j = 0; j <= kDegree; ++j) ders[0][j] = ndu[j][kDegree];
  double a[2][kDegree + 1];
  for (int r = 0; r <= kDegree; ++r) {
    int s1 = 0, s2 = 1;
    a[0][0] = 1.0;
    for (int k = 1; k <= 2; ++k) {
      double d = 0.0;
      const int rk = r - k, pk = kDegree - k;
      if (r >= k) {
        a[s2][0] = a[s1][0] / ndu[pk + 1][rk];
        d = a[s2][0] * ndu[rk][pk];
      }
      const int j1 = rk >= -1 ? 1 : -rk;
      const int j2 = (r - 1 <= pk) ? k - 1 : kDegree - r;
      for (int j = j1; j <= j2; ++j) {
        a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][rk + j];
        d += a[s2][j] * ndu[rk + j][pk];
      }
      if (r <= pk) {
        a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
        d += a[s2][k] * ndu[r][pk];
      }
      ders[k][r] = d;
      std::swap(s1, s2);
    }
  }
  LocalBasis local;
  local.first = span - kDegree;
  for (int j = 0; j <= kDegree; ++j) {
    local.value[j] = ders[0][j];
    local.d1[j] = ders[1][j] * kDegree;
    local.d2[j] = ders[2][j] * kDegree * (kDegree - 1);
  }
  return local;
}

MotionParametrization::MotionParametrization(int jointCount, int controlPointCount, bool periodic)
    : joints_(jointCount), basis_(controlPointCount), periodic_(periodic) {
  if (controlPointCount < 7)
    throw InputError("clamped trajectories with rest at both ends need at least 7 control points, got " +
                     std::to_string(controlPointCount));
}

int MotionParametrization::parameterOfControlPoint(int k) const {
  const int n = controlPointCount();
  if (k <= 2) return 0;
  if (k >= n - 3) return endParameter();
  return k - 2;
}

void MotionParametrization::controlPoints(const Eigen::Ref<const Eigen::VectorXd>& parameters,
                                          Eigen::MatrixXd& points) const {
  const int n = controlPointCount(), m = parametersPerJoint();
  points.resize(joints_, n);
  for (int j = 0; j < joints_; ++j)
    for (int k = 0; k < n; ++k) points(j, k) = parameters[j * m + parameterOfControlPoint(k)];
}

Eigen::VectorXd MotionParametrization::constantMotion(const Eigen::Ref<const Eigen::VectorXd>& posture) const {
  return interpolatedMotion(posture, posture);
}

Eigen::VectorXd MotionParametrization::interpolatedMotion(const Eigen::Ref<const Eigen::VectorXd>& start,
                                                          const Eigen::Ref<const Eigen::VectorXd>& end) const {
  const int m = parametersPerJoint();
  Eigen::VectorXd x(parameterCount());
  for (int j = 0; j < joints_; ++j) {
    if (!periodic_) {
      for (int k = 0; k < m; ++k) x[j * m + k] = start[j] + (end[j] - start[j]) * k / (m - 1);
      continue;
    }
    // The inner control points 1 … m − 1 of a periodic motion: out to `end` and back, a tent.
    x[j * m] = start[j];
    for (int k = 1; k < m; ++k) {
      const double s = static_cast<double>(k) / m;
      x[j * m + k] = start[j] + (end[j] - start[j]) * (1.0 - std::abs(2.0 * s - 1.0));
    }
  }
  return x;
}

void MotionParametrization::velocityControlPoints(const Eigen::MatrixXd& points, double duration,
                                                  Eigen::MatrixXd& velocity) const {
  const int n = controlPointCount();
  const auto& u = basis_.knots();
  velocity.resize(joints_, n - 1);
  for (int k = 0; k < n - 1; ++k)
    velocity.col(k) = 3.0 * (points.col(k + 1) - points.col(k)) / (duration * (u[k + 4] - u[k + 1]));
}

namespace {
std::vector<double> uniformTimes(int sampleCount) {
  if (sampleCount < 2) throw InputError("a trajectory needs at least 2 samples, got " + std::to_string(sampleCount));
  std::vector<double> u;
  for (int s = 0; s < sampleCount; ++s) u.push_back(static_cast<double>(s) / (sampleCount - 1));
  return u;
}
}  // namespace

SampledTrajectory::SampledTrajectory(const MotionParametrization& parametrization, int sampleCount)
    : SampledTrajectory(parametrization, uniformTimes(sampleCount)) {}

SampledTrajectory::SampledTrajectory(const MotionParametrization& parametrization,
                                     const std::vector<double>& normalisedTimes)
    : parametrization_(parametrization) {
  for (const double u : normalisedTimes) {
    if (!(u >= 0.0 && u <= 1.0))
      throw InputError("normalised sample time must lie in [0, 1], got " + std::to_string(u));
    u_.push_back(u);
    const LocalBasis local = parametrization.basis().evaluate(u);
    bases_.push_back(local);
    // Fold control points that share a free parameter (the clamped ends).
    LocalParameterWeights w;
    for (int i = 0; i < 4; ++i) {
      const int parameter = parametrization.parameterOfControlPoint(local.first + i);
      int slot = 0;
      while (slot < w.count && w.parameter[slot] != parameter) ++slot;
      if (slot == w.count) {
        w.parameter[slot] = parameter;
        ++w.count;
      }
      w.value[slot] += local.value[i];
      w.d1[slot] += local.d1[i];
      w.d2[slot] += local.d2[i];
    }
    weights_.push_back(w);
  }
}

void SampledTrajectory::evaluate(int sample, const Eigen::MatrixXd& points, double duration,
                                 Eigen::Ref<Eigen::VectorXd> q, Eigen::Ref<Eigen::VectorXd> v,
                                 Eigen::Ref<Eigen::VectorXd> a) const {
  const LocalBasis& b = bases_[sample];
  const auto block = points.middleCols<4>(b.first);
  const Eigen::Map<const Eigen::Vector4d> value(b.value.data()), d1(b.d1.data()), d2(b.d2.data());
  q.noalias() = block * value;
  v.noalias() = block * d1;
  v /= duration;
  a.noalias() = block * d2;
  a /= duration * duration;
}

void SampledTrajectory::chainRule(int sample, double duration, const Eigen::Ref<const Eigen::MatrixXd>& dyDq,
                                  const Eigen::Ref<const Eigen::MatrixXd>& dyDv,
                                  const Eigen::Ref<const Eigen::MatrixXd>& dyDa, Eigen::MatrixXd& dyDx,
                                  Eigen::VectorXi& parameters) const {
  const LocalParameterWeights& w = weights_[sample];
  const int n = parametrization_.jointCount(), m = parametrization_.parametersPerJoint(), k = w.count;
  const Eigen::Index rows = std::max({dyDq.rows(), dyDv.rows(), dyDa.rows()});
  dyDx.resize(rows, n * k);
  parameters.resize(n * k);
  const double t1 = 1.0 / duration, t2 = t1 * t1;
  for (int j = 0; j < n; ++j)
    for (int l = 0; l < k; ++l) parameters[j * k + l] = j * m + w.parameter[l];
  // The weights are shared by every joint: slot l of all joints is one whole-matrix
  // expression over the columns l, l + k, l + 2k, … (a strided view), which vectorises.
  using Strided = Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>>;
  for (int l = 0; l < k; ++l) {
    Strided slot(dyDx.data() + l * rows, rows, n, Eigen::OuterStride<>(k * rows));
    if (dyDq.size() > 0)
      slot.noalias() = w.value[l] * dyDq;
    else
      slot.setZero();
    if (dyDv.size() > 0) slot.noalias() += (w.d1[l] * t1) * dyDv;
    if (dyDa.size() > 0) slot.noalias() += (w.d2[l] * t2) * dyDa;
  }
}

void SampledTrajectory::durationDerivative(double duration, const Eigen::Ref<const Eigen::MatrixXd>& dyDv,
                                           const Eigen::Ref<const Eigen::MatrixXd>& dyDa,
                                           const Eigen::Ref<const Eigen::VectorXd>& v,
                                           const Eigen::Ref<const Eigen::VectorXd>& a, Eigen::VectorXd& dyDT) {
  dyDT.noalias() = dyDv * v;
  dyDT.noalias() += 2.0 * dyDa * a;
  dyDT /= -duration;
}

}  // namespace mcopt
