// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The outputs one evaluation of a sample computes (motion_problem.cpp, sampleOutputs), in the
// order of its output vector y: what the constraint terms read (constraint_term.hpp).

#include <vector>

namespace mcopt {

/// Output index of each per-sample quantity (rows of a sample's evaluation).
struct SampleOutputs {
  int joints = 0, contacts = 0;  ///< n, environment contacts
  /// Admissibility rows (contact_admissibility.hpp): the reference contact's from 0, environment
  /// contact i's from contactRowStart[1 + i], each as many as its contact model has; contacts + 2 values.
  std::vector<int> contactRowStart{0, 6};
  int contactRowCount(int c) const {  ///< c = 0: the reference contact; 1 + i: environment contact i
    return contactRowStart[static_cast<std::size_t>(c) + 1] - contactRowStart[static_cast<std::size_t>(c)];
  }
  int torque(int j) const { return j; }
  int referenceRow(int c) const { return joints + c; }
  int contactRow(int contact, int c) const { return joints + contactRowStart[static_cast<std::size_t>(contact) + 1] + c; }
  int infeasibility() const { return joints + contactRowStart.back(); }
  int power(int j) const { return infeasibility() + 1 + j; }
  int closing = 0;  ///< joints that close an environment contact (closed_chains.hpp)
  int closingPosition(int k) const { return power(joints) + k; }
  int closingVelocity(int k) const { return power(joints) + closing + k; }
  int reaches = 0;  ///< held contacts whose loop's reach is bounded (closure_reach_margin > 0), else 0
  int loopReach(int i) const { return power(joints) + 2 * closing + i; }
  int size() const { return power(joints) + 2 * closing + reaches; }
};

}  // namespace mcopt
