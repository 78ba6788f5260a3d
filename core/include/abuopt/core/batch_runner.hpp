#pragma once
// Running a batch of independent, indexed tasks: the seam between the Monte Carlo engine and the
// hardware. The engine hands over "do task i for i in [0, count)"; each task writes its result
// into slot i of a pre-sized vector, so the results never depend on which worker ran which index,
// nor in what order. A backend only decides where the tasks run: ThreadPoolRunner uses the cores
// of this machine; an MPI backend would split the index range across ranks and gather the slots.
//
// Contract for every backend:
//  - task(i) is called exactly once for every i in [0, count) (unless a task throws);
//  - tasks may run concurrently, so task must be safe to call from several threads at once;
//  - the progress callback (if set) is called with (done, total, elapsed_s), done increasing,
//    never concurrently with itself, and a last time with done == total; it runs on a worker
//    thread while the other workers wait for it, so keep it cheap (throttle any drawing); it may
//    throw to cancel the batch (handled like a throwing task);
//  - if a task throws, the remaining tasks are skipped (those running finish) and the first
//    exception is rethrown from run() after all workers have stopped.
#include <cstddef>
#include <functional>

namespace abuopt {

// (runs done, total runs, seconds since run() started)
using ProgressCallback = std::function<void(std::size_t done, std::size_t total, double elapsed_s)>;

class BatchRunner {
 public:
  virtual ~BatchRunner() = default;
  virtual void run(std::size_t count, const std::function<void(std::size_t index)>& task,
                   const ProgressCallback& progress = {}) = 0;
  // Number of concurrent workers this runner uses (for reports).
  virtual std::size_t concurrency() const = 0;
};

// std::thread pool: `threads` workers (0 = std::thread::hardware_concurrency(), at least 1; never
// more workers than tasks) pull the next index from a shared atomic counter (self-balancing: a
// fast worker simply takes more indices). threads == 1 runs on the calling thread.
class ThreadPoolRunner final : public BatchRunner {
 public:
  explicit ThreadPoolRunner(std::size_t threads = 0);
  void run(std::size_t count, const std::function<void(std::size_t index)>& task,
           const ProgressCallback& progress = {}) override;
  std::size_t concurrency() const override { return threads_; }

 private:
  std::size_t threads_;
};

// Number of hardware threads (>= 1).
std::size_t hardware_threads();

}  // namespace abuopt
