// SPDX-License-Identifier: BSD-3-Clause
#include "study/child_process.hpp"

#include <fcntl.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

namespace mcopt::study {

pid_t spawnProcess(const std::vector<std::string>& argv, const SpawnOptions& options) {
  // Everything the child needs is prepared before fork: after it, only async-signal-safe calls.
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  int outputFd = -1;
  if (!options.output.empty()) {
    outputFd = ::open(options.output.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (outputFd < 0) throw std::runtime_error(options.output.string() + ": cannot write (" + std::strerror(errno) + ")");
  }
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    if (outputFd >= 0) ::close(outputFd);
    throw std::runtime_error(std::string("fork failed: ") + std::strerror(errno));
  }
  if (pid == 0) {
    if (options.dieWithParent) {
      ::prctl(PR_SET_PDEATHSIG, SIGTERM);
      if (::getppid() != parent) ::_exit(127);  // the parent died before prctl
    }
    // The parent's handlers are not the child's: default dispositions, nothing blocked.
    ::signal(SIGINT, SIG_DFL);
    ::signal(SIGTERM, SIG_DFL);
    sigset_t none;
    sigemptyset(&none);
    ::sigprocmask(SIG_SETMASK, &none, nullptr);
    if (outputFd >= 0) {
      ::dup2(outputFd, STDOUT_FILENO);
      ::dup2(outputFd, STDERR_FILENO);
    }
    for (const auto& [name, value] : options.environment) ::setenv(name.c_str(), value.c_str(), 1);
    ::execv(args[0], args.data());
    const char message[] = "mcopt: cannot start a child process\n";
    (void)!::write(STDERR_FILENO, message, sizeof message - 1);
    ::_exit(127);
  }
  if (outputFd >= 0) ::close(outputFd);
  return pid;
}

ChildExit childExit(int waitStatus) {
  ChildExit e;
  if (WIFEXITED(waitStatus)) {
    e.exited = true;
    e.code = WEXITSTATUS(waitStatus);
  } else if (WIFSIGNALED(waitStatus)) {
    e.signal = WTERMSIG(waitStatus);
  }
  return e;
}

std::pair<ChildExit, std::string> runAndCapture(const std::vector<std::string>& argv) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error(std::string("pipe failed: ") + std::strerror(errno));
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error(std::string("fork failed: ") + std::strerror(errno));
  if (pid == 0) {
    ::dup2(fds[1], STDOUT_FILENO);
    ::execvp(args[0], args.data());
    const char message[] = "mcopt: cannot start the command\n";
    (void)!::write(STDERR_FILENO, message, sizeof message - 1);
    ::_exit(127);
  }
  ::close(fds[1]);
  std::string output;
  std::array<char, 4096> buffer{};
  for (;;) {
    const ssize_t n = ::read(fds[0], buffer.data(), buffer.size());
    if (n > 0) output.append(buffer.data(), static_cast<std::size_t>(n));
    else if (n == 0 || errno != EINTR) break;
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return {childExit(status), output};
}

std::filesystem::path currentExecutable() { return std::filesystem::read_symlink("/proc/self/exe"); }

}  // namespace mcopt::study
