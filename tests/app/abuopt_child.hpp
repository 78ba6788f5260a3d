#pragma once
// Runs the built `abuopt` binary (ABUOPT_EXE) as a child this test waits for by its pid: its exit
// status or the signal that ended it, its own peak memory (wait4's rusage, not the test's other
// children), its wall time, and what it printed. Optionally sends it a signal after a delay (what
// Ctrl-C or `kill` does) and measures how long it took to end after that.
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace abuopt::test {

struct ChildResult {
  int status = -1;          // exit status, -1 when ended by a signal
  int signal = 0;           // the signal that ended it, 0 when it exited
  long max_rss_kb = 0;      // the child's peak resident memory
  double wall_s = 0;        // start to end
  double after_signal_s = -1;  // from sending `sig` to the end (-1: no signal sent)
  std::string output;       // stdout and stderr
};

// When to send a signal: `at_s` seconds after the start, and not before `after_text` has appeared
// in the output (then as soon as it has; the wait is at most `wait_s`: a loaded machine).
struct SignalPlan {
  int sig = 0;  // 0: none
  double at_s = 0;
  std::string after_text;
  double wait_s = 120;
};

inline std::string file_text(const char* path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// args: the arguments after the program name.
inline ChildResult run_child(const std::vector<std::string>& args, const SignalPlan& plan = {},
                             const std::string& stdin_path = "/dev/null") {
  const int sig = plan.sig;
  ChildResult r;
  char tmpl[] = "/tmp/abuopt_child_XXXXXX";
  const int out_fd = ::mkstemp(tmpl);
  if (out_fd < 0) return r;
  const auto t0 = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int in_fd = ::open(stdin_path.c_str(), O_RDONLY);
    if (in_fd >= 0) ::dup2(in_fd, 0);
    ::dup2(out_fd, 1);
    ::dup2(out_fd, 2);
    // a test runner may have SIGINT ignored (background job): the child starts with defaults
    ::signal(SIGINT, SIG_DFL);
    ::signal(SIGTERM, SIG_DFL);
    std::vector<char*> argv;
    std::string exe = ABUOPT_EXE;
    argv.push_back(exe.data());
    std::vector<std::string> copy = args;
    for (std::string& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(exe.c_str(), argv.data());
    ::_exit(127);
  }
  ::close(out_fd);
  int st = 0;
  struct rusage ru {};
  std::chrono::steady_clock::time_point t_sig{};
  if (sig != 0) {
    // poll until the delay has passed or the child ended by itself
    while (true) {
      const pid_t w = ::wait4(pid, &st, WNOHANG, &ru);
      if (w == pid) goto done;
      const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (t >= plan.at_s && (plan.after_text.empty() || t >= plan.wait_s ||
                             file_text(tmpl).find(plan.after_text) != std::string::npos))
        break;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    t_sig = std::chrono::steady_clock::now();
    ::kill(pid, sig);
  }
  ::wait4(pid, &st, 0, &ru);
  if (sig != 0) r.after_signal_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_sig).count();
done:
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.max_rss_kb = ru.ru_maxrss;
  if (WIFEXITED(st)) r.status = WEXITSTATUS(st);
  if (WIFSIGNALED(st)) r.signal = WTERMSIG(st);
  r.output = file_text(tmpl);
  ::unlink(tmpl);
  return r;
}

}  // namespace abuopt::test
