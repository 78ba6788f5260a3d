#pragma once
// Runs the built `abuopt` binary (ABUOPT_EXE, set by tests/app/CMakeLists.txt) for the end-to-end
// tests of the command line: exit status and what it printed.
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace abuopt::test {

struct CliResult {
  int status;          // exit status (-1: did not exit normally)
  std::string output;  // stdout, and stderr unless with_stderr is false
};

// `env` is prepended to the command (e.g. "ABUOPT_GNUPLOT=/nonexistent").
inline CliResult run_abuopt(const std::string& args, const std::string& env = "", bool with_stderr = true) {
  const std::string cmd = env + (env.empty() ? "" : " ") + std::string(ABUOPT_EXE) + " " + args +
                          (with_stderr ? " 2>&1" : " 2>/dev/null");
  std::array<char, 4096> buf{};
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return {-1, ""};
  while (fgets(buf.data(), buf.size(), p)) out += buf.data();
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

}  // namespace abuopt::test
