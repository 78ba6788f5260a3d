#include "abuopt/common/stop.hpp"

#include <unistd.h>

#include <csignal>
#include <cstring>

namespace abuopt {

namespace {

std::atomic<bool> g_stop{false};
std::atomic<int> g_signal{0};
std::atomic<int> g_scopes{0};
std::atomic<bool> g_installed{false};
static_assert(std::atomic<int>::is_always_lock_free && std::atomic<bool>::is_always_lock_free,
              "the signal handler uses lock-free atomics only");

void say(const char* text) {
  const ssize_t r = ::write(STDERR_FILENO, text, std::strlen(text));
  (void)r;
}

extern "C" void abuopt_on_stop_signal(int sig) {
  // a second signal, or one where nothing polls the request: end now (async-signal-safe only)
  if (g_scopes.load() == 0 || g_stop.load()) {
    say(sig == SIGTERM ? "\nabuopt: terminated (SIGTERM)\n" : "\nabuopt: interrupted (SIGINT)\n");
    ::_exit(128 + sig);
  }
  request_stop(sig);
}

}  // namespace

void install_stop_handlers() {
  if (g_installed.exchange(true)) return;
  struct sigaction sa {};
  sa.sa_handler = abuopt_on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, nullptr);
  struct sigaction term {};
  if (sigaction(SIGTERM, nullptr, &term) == 0 && (term.sa_flags & SA_SIGINFO) == 0 && term.sa_handler == SIG_DFL)
    sigaction(SIGTERM, &sa, nullptr);
}

bool stop_handlers_installed() noexcept { return g_installed.load(); }
bool stop_requested() noexcept { return g_stop.load(std::memory_order_relaxed); }
const std::atomic<bool>& stop_flag() noexcept { return g_stop; }
int stop_signal() noexcept { return g_signal.load(); }
int stop_exit_status() noexcept { return 128 + (g_signal.load() == SIGTERM ? SIGTERM : SIGINT); }

std::string stop_signal_name() {
  return g_signal.load() == SIGTERM ? "SIGTERM" : "SIGINT (Ctrl-C)";
}

void request_stop(int signal) noexcept {
  int none = 0;
  g_signal.compare_exchange_strong(none, signal);
  g_stop.store(true);
}

void clear_stop() noexcept {
  g_stop.store(false);
  g_signal.store(0);
}

StopScope::StopScope() noexcept { g_scopes.fetch_add(1); }
StopScope::~StopScope() { g_scopes.fetch_sub(1); }

void throw_if_stop_requested(const std::string& where) {
  if (stop_requested()) throw Interrupted("interrupted by " + stop_signal_name() + where);
}

}  // namespace abuopt
