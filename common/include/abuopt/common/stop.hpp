#pragma once
// The one stop request of the process: SIGINT (Ctrl-C) and SIGTERM (kill, a batch system's end of
// job) ask every long command to stop at its next safe point, keep what it finished and exit 130
// (SIGINT) or 143 (SIGTERM). docs/security.md ("Interrupting a command") is the user's view.
//
//   app/main.cpp:        install_stop_handlers();            // once, at start
//   a command:           StopScope scope;                    // "I poll": a signal sets the request
//                        ... if (stop_requested()) { write what is complete; throw Interrupted(...); }
//   an engine's loop:    throw_if_stop_requested("...");      // between runs / evaluations
//   main's catch:        Interrupted -> message, stop_exit_status()
//
// Outside every StopScope (a command that cannot stop early, e.g. `simulate`), or at a second
// signal, the handler ends the process at once with 128 + signal after a one-line message. The
// Python module has no handlers: it polls PyErr_CheckSignals() and calls request_stop() itself.
#include <atomic>
#include <stdexcept>
#include <string>

namespace abuopt {

// Installs the SIGINT and SIGTERM handlers (idempotent). A SIGTERM handler that is already there
// (the MPI session's, parallel/) is kept: it calls the SIGINT one.
void install_stop_handlers();
bool stop_handlers_installed() noexcept;

// The request: set by the handlers (inside a StopScope), by request_stop(), read anywhere.
bool stop_requested() noexcept;
const std::atomic<bool>& stop_flag() noexcept;
int stop_signal() noexcept;            // SIGINT, SIGTERM, or 0 (none)
int stop_exit_status() noexcept;       // 128 + signal: 130 (SIGINT) or 143 (SIGTERM)
std::string stop_signal_name();        // "SIGINT (Ctrl-C)", "SIGTERM"
void request_stop(int signal) noexcept;  // async-signal-safe; the first signal wins
void clear_stop() noexcept;            // tests and the Python module (one call after another)

// Code that polls the request lives in a scope; signals outside every scope end the process.
class StopScope {
 public:
  StopScope() noexcept;
  ~StopScope();
  StopScope(const StopScope&) = delete;
  StopScope& operator=(const StopScope&) = delete;
};

// Thrown where a stop request ends work (the batch runner between runs, a command after it has
// written what is complete). main turns it into its message and stop_exit_status().
class Interrupted : public std::runtime_error {
 public:
  explicit Interrupted(const std::string& what) : std::runtime_error(what) {}
};

// Throws Interrupted("interrupted by <signal>" + where) when a stop is requested.
void throw_if_stop_requested(const std::string& where = "");

}  // namespace abuopt
