// SPDX-License-Identifier: BSD-3-Clause
#include "apps/python_script.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>

#include "apps/data_paths.hpp"

namespace mcopt::cli {

std::string pythonInterpreter() {
  if (const char* chosen = std::getenv("MCOPT_PYTHON"); chosen && *chosen) return chosen;
  if (::access("/usr/bin/python3", X_OK) == 0) return "/usr/bin/python3";
  return "python3";
}

std::pair<study::ChildExit, std::string> runPythonScript(const std::string& name, const std::vector<std::string>& arguments) {
  std::vector<std::string> command = {pythonInterpreter(), scriptFile(name).string()};
  command.insert(command.end(), arguments.begin(), arguments.end());
  return study::runAndCapture(command);
}

study::ChildExit runPythonScriptAttached(const std::string& name, const std::vector<std::string>& arguments) {
  std::vector<std::string> command = {pythonInterpreter(), scriptFile(name).string()};
  command.insert(command.end(), arguments.begin(), arguments.end());
  study::SpawnOptions options;
  options.dieWithParent = true;
  const pid_t child = study::spawnProcess(command, options);
  int status = 0;
  while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  return study::childExit(status);
}

std::string pythonFailure(const std::string& name, const study::ChildExit& exit) {
  return pythonInterpreter() + " scripts/" + name + (exit.exited ? " ended with code " + std::to_string(exit.code) : " died of signal " + std::to_string(exit.signal)) +
         "; it needs matplotlib: Debian's python3-matplotlib, or Python with matplotlib in $MCOPT_PYTHON";
}

}  // namespace mcopt::cli
