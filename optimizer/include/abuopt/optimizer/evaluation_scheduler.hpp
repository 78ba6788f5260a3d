#pragma once
// Evaluation concurrency (issue 9 item 4; the idea of pagmo's batch fitness evaluator `bfe` and
// Dakota's evaluation concurrency): the points of a design of experiments, finite-difference
// neighbours and the starts of a multi-start are independent, so they may be evaluated at once.
//
// The seam has two sides:
//  * an EvaluationScheduler decides WHERE the independent tasks of a batch run (ThreadScheduler:
//    threads of this process; an MPI back end lives in abuopt::parallel, above this library);
//  * Problem::evaluate_batch (problem.hpp) decides WHAT a batch is for a problem (ArchivedProblem
//    answers hits from its archive and stores the new values in input order).
// Results are in input order and never depend on the degree of parallelism: a task writes only
// its own slot, and the caller (EvaluationDriver) records, counts and checks the budget in input
// order afterwards.
//
// Threads budget: a batch of k points on a scheduler of W workers runs c = min(k, W) evaluations
// at once, and each is told (Problem::evaluate_shared) that it is one of c, so a problem with
// threads of its own (the Monte Carlo's T threads) uses max(1, T / c) of them: outer x inner <= max(T, c).
#include <cstddef>
#include <functional>
#include <memory>

namespace abuopt::opt {

class EvaluationScheduler {
 public:
  virtual ~EvaluationScheduler() = default;
  // Calls task(i) exactly once for every i in [0, count), possibly concurrently (at most
  // concurrency() at once). An exception thrown by a task is a defect of the scheduler's caller:
  // the remaining tasks are skipped and the first exception is rethrown after all workers stop.
  virtual void run(std::size_t count, const std::function<void(std::size_t index)>& task) = 0;
  // Most tasks running at once (>= 1).
  virtual std::size_t concurrency() const = 0;
};

// Threads of this process: `threads` workers (0: all hardware threads), the calling thread one of
// them; 1 runs every task on the calling thread, in order.
class ThreadScheduler final : public EvaluationScheduler {
 public:
  explicit ThreadScheduler(std::size_t threads = 0);
  void run(std::size_t count, const std::function<void(std::size_t index)>& task) override;
  std::size_t concurrency() const override { return threads_; }

 private:
  std::size_t threads_;
};

}  // namespace abuopt::opt
