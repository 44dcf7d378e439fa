// SPDX-License-Identifier: BSD-3-Clause
#include "tests/fuzz/fuzz_support.hpp"

#include <unistd.h>

#include <fstream>

#include "core/errors.hpp"

namespace mcopt::fuzz {

namespace {
/// The folder, removed when the process exits normally (libFuzzer's end of -max_total_time,
/// -runs, a replay), so that runs do not pile folders up in /tmp. After a finding libFuzzer
/// leaves without static destructors, and the folder stays beside the finding.
struct OwnFolder {
  std::filesystem::path path;
  OwnFolder() : path(std::filesystem::temp_directory_path() / ("mcopt-fuzz-" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(path / "scenarios");
    std::error_code ignored;
    std::filesystem::create_directory_symlink(std::filesystem::path(MCOPT_SOURCE_DIR) / "robots", path / "robots", ignored);
  }
  ~OwnFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);  // removes the robots link, not what it names
  }
  OwnFolder(const OwnFolder&) = delete;
  OwnFolder& operator=(const OwnFolder&) = delete;
};
}  // namespace

const std::filesystem::path& workDir() {
  static const OwnFolder folder;
  return folder.path;
}

void writeFile(const std::filesystem::path& path, const std::uint8_t* data, std::size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

void writeFile(const std::filesystem::path& path, const std::string& text) {
  writeFile(path, reinterpret_cast<const std::uint8_t*>(text.data()), text.size());
}

namespace {
int refusals = 0;
std::string lastMessage;
}  // namespace

void refused(const std::exception& error) {
  ++refusals;
  lastMessage = error.what();
}
int refusalCount() { return refusals; }
const std::string& lastRefusal() { return lastMessage; }

void runCommand(const std::function<cli::Runner(CLI::App&)>& add, const std::vector<std::string>& argv) {
  CLI::App app;
  CLI::App* command = app.add_subcommand(argv.front());
  const cli::Runner run = add(*command);
  std::vector<std::string> reversed(argv.rbegin(), argv.rend());  // CLI11 parses a vector back to front
  try {
    app.parse(reversed);
    run();
  } catch (const CLI::ParseError& e) {
    refused(e);
  } catch (const InputError& e) {
    refused(e);
  }
}

std::filesystem::path hrp2File(const std::string& name) { return std::filesystem::path(MCOPT_SOURCE_DIR) / "robots/hrp2" / name; }

}  // namespace mcopt::fuzz
