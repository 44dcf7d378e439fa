// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// What the fuzz targets share (docs/developers/fuzzing.md): each input is written where the command line
// would read it, and read through the command's own code. A bad input may end in InputError —
// the CLI's clear "file: field:" message, exit code 2 — or in a refused command line; anything
// else (a crash, a sanitizer report, another exception, which the CLI would print as an
// internal error) escapes to libFuzzer as a finding.
#include <CLI/CLI.hpp>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "apps/commands.hpp"

namespace mcopt::fuzz {

/// A folder of this process's own, with `robots` linked to the source tree's robots/, so that
/// side files named as the bundled scenarios name them (../robots/hrp2/…) resolve from
/// scenarios/ inside it. Removed when the process exits normally.
const std::filesystem::path& workDir();

/// The bytes as a file (created or truncated).
void writeFile(const std::filesystem::path& path, const std::uint8_t* data, std::size_t size);
void writeFile(const std::filesystem::path& path, const std::string& text);

/// Registers one subcommand as main.cpp does, parses `argv` (the subcommand first) and runs it.
/// InputError and CLI11's parse errors are outcomes; other exceptions propagate.
void runCommand(const std::function<cli::Runner(CLI::App&)>& add, const std::vector<std::string>& argv);

/// Records a refusal (an InputError) and its message: the seed corpora must be accepted, so
/// that the fuzzing starts from inputs that reach the deep paths (tests/fuzz/replay_main.cpp).
void refused(const std::exception& error);
int refusalCount();
const std::string& lastRefusal();

/// The HRP-2 model of the source tree.
std::filesystem::path hrp2File(const std::string& name);

}  // namespace mcopt::fuzz
