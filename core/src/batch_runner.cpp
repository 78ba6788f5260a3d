#include "abuopt/core/batch_runner.hpp"

#include "abuopt/common/stop.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

namespace abuopt {

std::size_t hardware_threads() {
  const unsigned n = std::thread::hardware_concurrency();
  return n == 0 ? 1 : n;
}

ThreadPoolRunner::ThreadPoolRunner(std::size_t threads) : threads_(threads == 0 ? hardware_threads() : threads) {}

void ThreadPoolRunner::run(std::size_t count, const std::function<void(std::size_t index)>& task,
                           const ProgressCallback& progress) {
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  if (count == 0) {
    if (progress) progress(0, 0, elapsed());
    return;
  }

  std::atomic<std::size_t> next{0};
  std::atomic<bool> stop{false};
  std::mutex mutex;  // guards done, first_error and the progress callback
  std::size_t done = 0;
  std::exception_ptr first_error;

  std::atomic<bool> interrupted{false};
  auto worker = [&] {
    while (!stop.load(std::memory_order_relaxed)) {
      // the stop request (SIGINT / SIGTERM, abuopt/common/stop.hpp): no new task; those running finish
      if (stop_requested()) {
        interrupted.store(true);
        stop.store(true, std::memory_order_relaxed);
        return;
      }
      const std::size_t i = next.fetch_add(1, std::memory_order_relaxed);
      if (i >= count) return;
      try {
        task(i);
        std::lock_guard<std::mutex> lock(mutex);
        ++done;
        if (progress && !first_error) progress(done, count, elapsed());  // may throw to cancel
      } catch (const Interrupted&) {  // a run that polled the stop request itself (simulator.cpp)
        interrupted.store(true);
        stop.store(true, std::memory_order_relaxed);
        return;
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!first_error) first_error = std::current_exception();
        stop.store(true, std::memory_order_relaxed);
        return;
      }
    }
  };

  const std::size_t workers = std::min(threads_, count);
  if (workers <= 1) {
    worker();
  } else {
    std::vector<std::thread> pool;
    pool.reserve(workers - 1);
    // The system may refuse a thread (process or memory limits): go on with the ones it gave,
    // and say so, instead of leaving joinable threads to std::terminate.
    for (std::size_t w = 1; w < workers; ++w) {
      try {
        pool.emplace_back(worker);
      } catch (const std::system_error& e) {
        std::fprintf(stderr, "abuopt: warning: the system started only %zu of the %zu worker threads asked for (%s); "
                     "going on with %zu\n", pool.size() + 1, workers, e.what(), pool.size() + 1);
        break;
      }
    }
    worker();  // the calling thread works too
    for (auto& t : pool) t.join();
  }
  if (first_error) std::rethrow_exception(first_error);
  if (interrupted.load() && done < count)
    throw Interrupted("interrupted by " + stop_signal_name() + " after " + std::to_string(done) + " of " +
                      std::to_string(count) + " runs");
}

}  // namespace abuopt
