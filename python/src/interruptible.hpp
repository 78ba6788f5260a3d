#pragma once
// Long calls of the Python module: the work (no Python inside) runs on a worker thread while the
// calling thread, the GIL released between polls, checks Python's signals every 50 ms. On a signal
// (Ctrl-C: KeyboardInterrupt is set) the process's stop request (abuopt/common/stop.hpp) and the
// caller's own `stop` flag, if given, are set; the library stops at its next safe point (a Monte
// Carlo between runs; an evaluation cut short is not recorded), and the Python exception is raised
// here within about a second instead of after the whole call. The stop request is process-wide:
// calls running at the same time in other Python threads stop too.
#include <Python.h>
#include <pybind11/pybind11.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <exception>
#include <mutex>
#include <thread>

#include "abuopt/common/stop.hpp"

namespace abuopt::python {

template <class Work>
void run_interruptible(Work&& work, std::atomic<bool>* stop = nullptr) {
  namespace py = pybind11;
  std::mutex m;
  std::condition_variable cv;
  bool done = false;
  std::exception_ptr error;
  std::thread worker([&] {
    try {
      work();
    } catch (...) {
      error = std::current_exception();
    }
    const std::lock_guard<std::mutex> lock(m);
    done = true;
    cv.notify_one();
  });
  bool interrupted = false;
  while (true) {
    {
      py::gil_scoped_release release;
      std::unique_lock<std::mutex> lock(m);
      if (cv.wait_for(lock, std::chrono::milliseconds(50), [&] { return done; })) break;
    }
    if (!interrupted && PyErr_CheckSignals() != 0) {  // the Python error (KeyboardInterrupt) is set
      interrupted = true;
      if (stop) stop->store(true);
      request_stop(SIGINT);
    }
  }
  {
    py::gil_scoped_release release;
    worker.join();
  }
  if (interrupted) {
    clear_stop();  // the next call starts afresh
    throw py::error_already_set();
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace abuopt::python
