// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The debug preset's MCOPT_CHECK_MALLOC (CMakeLists.txt, CMakePresets.json): Eigen's run-time
// no-malloc check (EIGEN_RUNTIME_NO_MALLOC), armed around a per-sample path once its buffers
// are sized, so that an Eigen allocation there stops a debug build at once (eigen_assert).
// Eigen's flag is one process-wide boolean, so a scope is opened by the thread that starts a
// parallel region, around the whole region — never per thread, where one thread's exit would
// disarm another's check. Without MCOPT_CHECK_MALLOC a scope does nothing and costs nothing.
// (Allocation of every kind, Eigen's or not, is counted by tests/core/test_no_allocation.cpp.)
#include <Eigen/Core>

namespace mcopt {

#ifdef MCOPT_CHECK_MALLOC
/// Called by every scope as it arms, with the name of its path, on the thread that armed it:
/// tests record which per-sample paths are guarded and allocate under a guard on purpose
/// (tests/core/test_no_malloc_scope.cpp). Null otherwise; debug builds only.
inline void (*noMallocProbe)(const char* path) = nullptr;
#endif

class NoMallocScope {
 public:
#ifdef MCOPT_CHECK_MALLOC
  /// `path` names the per-sample path guarded (a literal). `armed` false: the path is not warm
  /// yet (its buffers are sized inside), nothing is checked.
  explicit NoMallocScope(const char* path, bool armed = true) : armed_(armed) {
    if (!armed_) return;
    previous_ = Eigen::internal::is_malloc_allowed();  // (set_is_malloc_allowed returns the new value)
    Eigen::internal::set_is_malloc_allowed(false);
    if (noMallocProbe != nullptr) noMallocProbe(path);
  }
  ~NoMallocScope() {
    if (armed_) Eigen::internal::set_is_malloc_allowed(previous_);
  }
#else
  explicit NoMallocScope(const char*, bool = true) {}
#endif
  NoMallocScope(const NoMallocScope&) = delete;
  NoMallocScope& operator=(const NoMallocScope&) = delete;

#ifdef MCOPT_CHECK_MALLOC
 private:
  bool armed_ = false, previous_ = true;
#endif
};

}  // namespace mcopt
