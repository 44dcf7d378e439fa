// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The wrenches of the non-reference contacts as linear functions of NLP variables z, for the
// single-level formulations (formulation.md §9, methods 2 and 3):
//   variables  F_i(t_s) = z_{i,s}: six variables per contact and sample of its window;
//   splines    F_i(t) = Σ_k b_k(u') z_{i,k}, a clamped cubic B-spline per wrench component
//              over the contact's window, u' = (u − u0)/(u1 − u0), every control point free.
// At a sample, F_i = Σ_l weight_l z[variable_l … variable_l + 5] over at most 4 terms
// (B-spline local support). The reference contact's wrench is not parametrised: it follows
// from the balance (4.10), (4.12), so the balance holds exactly at every sample.
// Normalised times make the map independent of a free duration.

#include <Eigen/Core>
#include <vector>

#include "outer_nlp/scenario.hpp"

namespace mcopt {

/// One parametrisation term among a sample's local force columns: its contact, its weight and
/// its first local column (the wrench's six components follow).
struct LocalForceTerm {
  int contact = 0;
  double weight = 0.0;
  int firstColumn = 0;
};

class ContactForceParametrization {
 public:
  struct Term {
    int variable = 0;  ///< global index of the term's f_x (f_y … m_z follow)
    double weight = 0.0;
  };
  /// windows: per contact, the normalised window [u0, u1]; u: the normalised sample times;
  /// active: per contact and sample, in contact there (inside the window; at an instant sampled
  /// twice, the twin on the window's side). firstVariable: global index of z's first entry.
  /// How a contact's wrench is laid out in z.
  enum class Layout {
    Splines,    ///< a clamped cubic B-spline per component over the contact's window, `controlPoints` each
    PerSample,  ///< six variables per sample in contact
  };
  ContactForceParametrization(Layout layout, const std::vector<std::array<double, 2>>& windows,
                              const std::vector<double>& u, const std::vector<std::vector<bool>>& active,
                              int controlPoints, int firstVariable);

  int contactCount() const { return static_cast<int>(windows_.size()); }
  int variableCount() const { return variableCount_; }
  int sampleCount() const { return terms_.empty() ? 0 : static_cast<int>(terms_.front().size()); }
  bool active(int contact, int sample) const { return !terms(contact, sample).empty(); }
  /// Empty when the contact is not in contact at that sample.
  const std::vector<Term>& terms(int contact, int sample) const {
    return terms_[static_cast<std::size_t>(contact)][static_cast<std::size_t>(sample)];
  }
  /// Variables that reproduce given wrenches at the samples (least squares for splines).
  /// wrenches: per contact a 6 × sampleCount matrix (columns outside the window ignored).
  /// Writes z's entries in `x`.
  void fit(const std::vector<Eigen::MatrixXd>& wrenches, Eigen::Ref<Eigen::VectorXd> x) const;

 private:
  std::vector<std::array<double, 2>> windows_;
  std::vector<std::vector<std::vector<Term>>> terms_;  ///< [contact][sample]
  int firstVariable_ = 0, variableCount_ = 0;
};

/// Whether normalised time u lies in the closed window [u0, u1] (with round-off slack).
inline bool insideWindow(double u, const std::array<double, 2>& window) {
  return u >= window[0] - 1e-9 && u <= window[1] + 1e-9;
}

/// The same on one side of u, where an instant is sampled twice: −1 just before it (u in
/// (u0, u1]), +1 just after it (u in [u0, u1)), 0 at u itself (the closed window).
inline bool insideWindow(double u, const std::array<double, 2>& window, int side) {
  if (side < 0) return u > window[0] + 1e-9 && u <= window[1] + 1e-9;
  if (side > 0) return u >= window[0] - 1e-9 && u < window[1] - 1e-9;
  return insideWindow(u, window);
}

}  // namespace mcopt
