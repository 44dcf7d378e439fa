// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A study's cases on this machine (docs/reference/studies.md, "Local pool"): `jobs` case runners at a
// time, each a process `mcopt study case DIR K` (Ipopt with MUMPS is not safe twice in one
// process), each dying with the pool.

#include <csignal>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <vector>

#include "study/study_folder.hpp"

namespace mcopt::study {

struct PoolEvents {
  std::function<void(std::size_t)> onStart;
  std::function<void(std::size_t, const CaseReport&)> onEnd;
};

/// Runs the cases in order, `jobs` at a time. When `stop` becomes non-zero no case starts any
/// more and the running ones get SIGTERM (each writes its last iterate and its record);
/// returns false then, true when every case ran.
bool runLocalPool(const StudyFolder& folder, const std::vector<std::size_t>& cases, int jobs,
                  const std::filesystem::path& mcopt, const PoolEvents& events, const volatile std::sig_atomic_t& stop);

}  // namespace mcopt::study
