// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Results are written atomically: to a temporary file beside the target, flushed,
// then renamed over it, so an interrupted run never leaves a half-written file.

#include <filesystem>
#include <string>

namespace mcopt {

/// Throws InputError naming the path when the folder is not writable.
void writeFileAtomically(const std::filesystem::path& path, const std::string& content);

}  // namespace mcopt
