#pragma once
// Runs the built `sandbox` binary as a user would and captures what it prints.

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace sandbox::testing {

struct CommandRun {
  int exit_code{-1};
  std::string out;  // stdout and stderr together
};

// A shell command line, stdout and stderr captured together.
inline CommandRun RunCommand(const std::string& command_line) {
  CommandRun run;
  const std::string command = command_line + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  std::array<char, 4096> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr) run.out += buffer.data();
  const int status = pclose(pipe);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return run;
}

// `args` go through the shell (quote as on a command line).
inline CommandRun RunSandbox(const std::string& args) {
  return RunCommand(std::string(SANDBOX_BINARY) + " " + args);
}

}  // namespace sandbox::testing
