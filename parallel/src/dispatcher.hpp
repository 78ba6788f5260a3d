#pragma once
// Internal (MPI builds only): rank 0's side of the Monte Carlo over ranks. One Dispatcher per
// process hands out the runs of every study in flight (several at once when an optimiser
// evaluates a batch of independent designs: docs/cluster.md, "Batches of evaluations") to rank 0's
// own worker threads and, in chunks on request, to the serving ranks (the messages: wire.hpp).
//
// Threads: any thread may call run_study, several at once. Exactly one of them at a time (the
// "pumper") makes MPI calls (MPI_THREAD_SERIALIZED); the others sleep until their study is done or
// the pumper's study is, and then one of them takes over. The worker threads make no MPI call.
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "abuopt/core/monte_carlo.hpp"

namespace abuopt::parallel::detail {

// Rank 0 and the serving ranks alike: the command is interrupted (sets the flag of interrupted()
// and calls the SIGINT handler in place, e.g. the optimiser's, which then stops). Defined in
// session.cpp; async-signal-safe.
void note_interrupt() noexcept;

class Dispatcher {
 public:
  // `ranks`: the size of MPI_COMM_WORLD; `serialized`: MPI provides MPI_THREAD_SERIALIZED (else
  // only the thread that constructed the dispatcher may run studies).
  Dispatcher(int ranks, bool serialized);
  ~Dispatcher();  // stops the worker threads
  Dispatcher(const Dispatcher&) = delete;
  Dispatcher& operator=(const Dispatcher&) = delete;

  // p.samples[k].outcome for every k in p.simulate, computed on every rank with `threads` threads
  // per rank. Throws Interrupted after SIGTERM (or a rank's report of it), std::runtime_error
  // "rank R: <message>" when a run threw on rank R.
  void run_study(const MonteCarloStudy& s, PreparedStudy& p, const ProgressCallback& progress, std::size_t threads);

  // The command is over: receives each serving rank's outstanding request and sends it the end
  // with `status`. No study may run any more.
  void finish(int status);

  // Studies may run from several threads at once.
  bool concurrent() const { return serialized_; }

 private:
  struct Job {
    std::uint64_t id = 0;
    std::string setup;  // as it travels (encode_setup)
    std::shared_ptr<const Simulator> sim;
    PreparedStudy* prepared = nullptr;
    std::size_t threads = 1;  // per serving rank
    std::size_t total = 0, next = 0, done = 0, in_flight = 0;  // runs; chunks out
    std::string error;
    bool interrupted = false;
    bool finished() const { return (next >= total || !error.empty()) && in_flight == 0; }
    bool open() const { return error.empty() && next < total; }
  };
  struct RankState {
    bool parked = false;               // its request is received and waits for work
    std::vector<std::uint64_t> known;  // jobs whose setup it holds
    std::vector<std::uint64_t> forget; // finished jobs to tell it to drop
  };

  // One round of MPI work: receive every pending request, apply its results, give parked ranks
  // chunks. True when a message came or went. Caller holds pump_.
  bool pump();
  // A chunk of the oldest open job for a taker with `threads` threads (mutex_ held): the job (null
  // when none is open), its first run and count.
  std::shared_ptr<Job> take(std::size_t threads, std::size_t& first, std::size_t& count);
  void worker();
  void ensure_workers(std::size_t n);
  void fail_all_interrupted();  // mutex_ held

  const int ranks_;
  const bool serialized_;
  const std::thread::id owner_;

  std::mutex mutex_;  // guards everything below but the threads vector
  std::condition_variable work_;     // workers: a job opened, or stop
  std::condition_variable changed_;  // study owners: a job finished, or the pumper left
  std::list<std::shared_ptr<Job>> jobs_;
  std::uint64_t last_id_ = 0;
  std::vector<RankState> rank_state_;
  std::size_t ranks_threads_ = 1;  // threads per rank of the latest study (chunk sizing)
  std::string broken_;  // the exchange failed (a defect): every study fails with this
  bool pumping_ = false;  // a study owner is the pumper
  bool interrupt_seen_ = false;
  bool stop_ = false;
  bool finished_ = false;

  std::mutex pump_;  // held by the one thread making MPI calls
  std::mutex threads_mutex_;
  std::vector<std::thread> workers_;
};

}  // namespace abuopt::parallel::detail
