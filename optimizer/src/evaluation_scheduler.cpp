#include "abuopt/optimizer/evaluation_scheduler.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

namespace abuopt::opt {

ThreadScheduler::ThreadScheduler(std::size_t threads) {
  const unsigned hw = std::thread::hardware_concurrency();
  threads_ = threads > 0 ? threads : (hw == 0 ? 1 : hw);
}

void ThreadScheduler::run(std::size_t count, const std::function<void(std::size_t index)>& task) {
  const std::size_t workers = std::min(threads_, count);
  if (workers <= 1) {
    for (std::size_t i = 0; i < count; ++i) task(i);
    return;
  }
  std::atomic<std::size_t> next{0};
  std::mutex mutex;
  std::exception_ptr first_error;
  auto worker = [&] {
    for (std::size_t i = next++; i < count; i = next++) {
      try {
        task(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!first_error) first_error = std::current_exception();
        next = count;
        return;
      }
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(workers - 1);
  for (std::size_t w = 1; w < workers; ++w) {
    try {
      pool.emplace_back(worker);
    } catch (const std::system_error&) {
      break;  // the system refused a thread: the ones we have (and this one) do the work
    }
  }
  worker();
  for (std::thread& t : pool) t.join();
  if (first_error) std::rethrow_exception(first_error);
}

}  // namespace abuopt::opt
