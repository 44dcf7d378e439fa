// SPDX-License-Identifier: BSD-3-Clause
#include "core/motion_derivatives.hpp"

#include "core/spatial_algebra.hpp"

namespace mcopt {

void bodyMotionDerivatives(const DynamicsModel& model, const DynamicsData& d, int b, MotionDerivative& dTwistDq,
                           MotionDerivative& dTwistDv, MotionDerivative& dAccelerationDq,
                           MotionDerivative& dAccelerationDv, MotionDerivative& dAccelerationDa) {
  const int n = model.jointCount();
  for (MotionDerivative* m : {&dTwistDq, &dTwistDv, &dAccelerationDq, &dAccelerationDv, &dAccelerationDa}) m->setZero(6, n);
  auto twist = [&d](int i) { return (Vector6() << d.linearVelocity[i], d.angularVelocity[i]).finished(); };
  auto acceleration = [&d](int i) {
    return (Vector6() << d.linearAcceleration[i], d.angularAcceleration[i]).finished();
  };
  const Vector6 vb = twist(b), ab = acceleration(b);
  const auto& edges = model.treeJoints();
  for (int j = b; j > 0; j = edges[j].parent) {
    Vector6 s;
    s << d.jointMoment[j], (edges[j].prismatic ? Vector3::Zero() : d.jointAxis[j]);
    const Vector6 vj = twist(j);
    const int column = edges[j].joint;
    dTwistDq.col(column) = motionCross(s, vb - vj);
    dTwistDv.col(column) = s;
    dAccelerationDq.col(column) = motionCross(s, ab - acceleration(j)) + motionCross(vb - vj, motionCross(s, vj));
    dAccelerationDv.col(column) = motionCross(s, vb - vj - twist(edges[j].parent));
    dAccelerationDa.col(column) = s;
  }
}

}  // namespace mcopt
