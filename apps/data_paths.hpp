// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Where the command finds its own files — the plotting scripts and the replay page's template —
// whether it runs from its build tree or from an install prefix (docs/getting-started/install.md):
//   installed   <prefix>/bin/mcopt reads <prefix>/share/mcopt/{scripts,replay}
//   build tree  the source tree it was built from: scripts/, apps/replay/
// Nothing else is searched: a command that finds neither says where it looked.

#include <filesystem>
#include <string>

namespace mcopt::cli {

/// scripts/NAME (a Python script of the command: plot_result.py, plot_study.py, report.py).
std::filesystem::path scriptFile(const std::string& name);

/// The folder of the replay page's template (viewer.html, viewer.js).
std::filesystem::path replayViewerDirectory();

}  // namespace mcopt::cli
