// The MPI session and the Monte Carlo over ranks (parallel.hpp describes the model). Without MPI
// (ABUOPT_HAVE_MPI undefined) the same functions run one process.
#include "abuopt/parallel/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include "abuopt/core/monte_carlo.hpp"
#include "codec.hpp"

#ifdef ABUOPT_HAVE_MPI
#include <mpi.h>
#endif

namespace abuopt::parallel {

namespace {
Session* g_session = nullptr;
extern "C" void forward_to_sigint(int) { std::raise(SIGINT); }
}

bool built_with_mpi() {
#ifdef ABUOPT_HAVE_MPI
  return true;
#else
  return false;
#endif
}

bool launched_by_mpi() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"})
    if (std::getenv(v)) return true;
  return false;
}

Session* session() { return g_session; }

#ifndef ABUOPT_HAVE_MPI

Session::Session(int&, char**&) { g_session = this; }
Session::~Session() { g_session = nullptr; }
int Session::serve() { return 0; }
int Session::finish(int status) {
  finished_ = true;
  return status;
}
void Session::abort(int status) { std::exit(status); }
std::shared_ptr<BatchRunner> make_runner(std::size_t threads) { return std::make_shared<ThreadPoolRunner>(threads); }

#else

namespace {

using detail::Reader;
using detail::Writer;

// Tags of the messages.
constexpr int kTagCommand = 1;  // rank 0 -> rank: [int32 command][...]
constexpr int kTagRequest = 2;  // rank -> rank 0: [int32 kind][uint64 job][...]
constexpr int kTagAssign = 3;   // rank 0 -> rank: [uint64 job][uint64 first][uint64 count]
constexpr std::int32_t kCommandJob = 1, kCommandEnd = 2;
constexpr std::int32_t kRequestResults = 1, kRequestError = 2;

void send(const std::vector<char>& bytes, int to, int tag) {
  MPI_Send(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, to, tag, MPI_COMM_WORLD);
}

std::vector<char> receive(int from, int tag, int* source = nullptr) {
  MPI_Status st;
  MPI_Probe(from, tag, MPI_COMM_WORLD, &st);
  int n = 0;
  MPI_Get_count(&st, MPI_BYTE, &n);
  std::vector<char> bytes(static_cast<std::size_t>(n));
  MPI_Recv(bytes.data(), n, MPI_BYTE, st.MPI_SOURCE, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  if (source) *source = st.MPI_SOURCE;
  return bytes;
}

// Waits for a message without spinning a core (Open MPI's blocking calls busy-poll; a serving
// rank may wait minutes while rank 0 runs an optimiser step).
void wait_for(int from, int tag, std::chrono::microseconds nap) {
  int flag = 0;
  while (true) {
    MPI_Iprobe(from, tag, MPI_COMM_WORLD, &flag, MPI_STATUS_IGNORE);
    if (flag) return;
    std::this_thread::sleep_for(nap);
  }
}

std::size_t threads_or_all(std::size_t threads) { return threads == 0 ? hardware_threads() : threads; }

// The size of the next chunk of runs: guided (a share of what is left, so the last chunks are
// small and the ranks finish together), at least 1, at most 64 runs.
std::size_t chunk_size(std::size_t left, std::size_t threads) {
  return std::clamp<std::size_t>(left / (4 * std::max<std::size_t>(threads, 1)), 1, 64);
}

// Fault injection for the tests of faults (tests/app/mpi_cli_test.cpp): ABUOPT_TEST_FAULT =
// "throw:R[:K]" makes serving rank R throw in its K-th chunk (default 1), "die:R[:K]" kills it
// there (SIGKILL); "die_job:R:J" (below) kills it when its J-th study arrives.
void injected_fault() {
  static const char* v = std::getenv("ABUOPT_TEST_FAULT");
  static long chunks = 0;
  if (!v) return;
  const std::string spec(v);
  const auto colon = spec.find(':');
  if (colon == std::string::npos) return;
  int rank = -1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (std::atoi(spec.c_str() + colon + 1) != rank) return;
  const auto second = spec.find(':', colon + 1);
  const long at = second == std::string::npos ? 1 : std::atol(spec.c_str() + second + 1);
  if (++chunks != at) return;
  if (spec.compare(0, colon, "die") == 0) std::raise(SIGKILL);
  if (spec.compare(0, colon, "throw") == 0)
    throw std::runtime_error("fault injected by ABUOPT_TEST_FAULT=" + spec);
}

// "die_job:R:J" kills serving rank R when it receives its J-th study (deterministic, unlike a
// chunk count, which depends on how the dynamic scheduling shares the runs out).
void injected_job_fault() {
  static const char* v = std::getenv("ABUOPT_TEST_FAULT");
  static long jobs = 0;
  if (!v) return;
  const std::string spec(v);
  if (spec.rfind("die_job:", 0) != 0) return;
  const auto second = spec.find(':', 8);
  if (second == std::string::npos) return;
  int rank = -1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (std::atoi(spec.c_str() + 8) != rank) return;
  if (++jobs == std::atol(spec.c_str() + second + 1)) std::raise(SIGKILL);
}

// A serving rank's part of one study: the setup once, then chunks of run inputs until rank 0
// says the study is over.
void serve_job(Reader& in) {
  injected_job_fault();
  const auto job = in.get<std::uint64_t>();
  const auto threads = static_cast<std::size_t>(in.get<std::uint64_t>());
  const std::string text = in.get_string();
  auto reply = [&](std::int32_t kind, const std::function<void(Writer&)>& body) {
    Writer w;
    w.put(kind);
    w.put(job);
    body(w);
    send(w.bytes(), 0, kTagRequest);
  };
  std::shared_ptr<const Simulator> sim;
  try {
    sim = std::make_shared<const Simulator>(detail::decode_setup(text));
  } catch (const std::exception& e) {
    reply(kRequestError, [&](Writer& w) { w.put(std::string(e.what())); });
  }
  if (sim) reply(kRequestResults, [](Writer& w) { w.put<std::uint64_t>(0); });
  ThreadPoolRunner runner(threads);
  while (true) {
    wait_for(0, kTagAssign, std::chrono::microseconds(50));  // not a spinning blocking receive
    std::vector<char> bytes = receive(0, kTagAssign);
    Reader a(bytes.data(), bytes.size());
    const auto assigned_job = a.get<std::uint64_t>();
    const auto first = a.get<std::uint64_t>();
    const auto count = a.get<std::uint64_t>();
    if (assigned_job != job) throw std::logic_error("rank 0 and this rank disagree on the study");
    if (count == 0) return;
    std::vector<std::vector<double>> beta0(count);
    std::vector<RunOverrides> overrides(count);
    for (std::uint64_t i = 0; i < count; ++i) detail::get_inputs(a, beta0[i], overrides[i]);
    std::vector<RunOutcome> out(count);
    try {
      injected_fault();
      runner.run(count, [&](std::size_t i) { out[i] = sim->run(beta0[i], overrides[i]); });
    } catch (const std::exception& e) {
      reply(kRequestError, [&](Writer& w) { w.put(std::string(e.what())); });
      continue;
    }
    reply(kRequestResults, [&](Writer& w) {
      w.put<std::uint64_t>(count);
      w.put<std::uint64_t>(first);
      for (const RunOutcome& o : out) detail::put_outcome(w, o);
    });
  }
}

// Rank 0's side: the study over every rank.
class MpiStudyRunner final : public StudyRunner {
 public:
  MpiStudyRunner(std::size_t threads, int ranks) : threads_(threads), ranks_(ranks) {}

  std::size_t concurrency() const override { return threads_or_all(threads_) * static_cast<std::size_t>(ranks_); }

  // A task closure cannot travel: plain batches run on this rank's threads.
  void run(std::size_t count, const std::function<void(std::size_t)>& task, const ProgressCallback& progress) override {
    ThreadPoolRunner(threads_).run(count, task, progress);
  }

  void run_study(const MonteCarloStudy& s, PreparedStudy& p, const ProgressCallback& progress) override;

 private:
  std::size_t threads_;
  int ranks_;
  std::uint64_t job_ = 0;
};

void MpiStudyRunner::run_study(const MonteCarloStudy& s, PreparedStudy& p, const ProgressCallback& progress) {
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  const std::size_t total = p.simulate.size();
  const std::size_t local_threads = threads_or_all(threads_);
  const std::size_t all_threads = concurrency();
  const std::uint64_t job = ++job_;
  const auto sim = std::make_shared<const Simulator>(s.setup);  // validates the setup

  {  // the study to every serving rank
    Writer w;
    w.put(kCommandJob);
    w.put(job);
    w.put<std::uint64_t>(local_threads);
    w.put(detail::encode_setup(s.setup));
    for (int r = 1; r < ranks_; ++r) send(w.bytes(), r, kTagCommand);
  }

  std::mutex mutex;  // guards next, done, error
  std::size_t next = 0, done = 0;
  std::string error;
  // a chunk for `threads` threads (a serving rank takes one for all its threads)
  auto take = [&](std::size_t threads, std::size_t& first) -> std::size_t {
    std::lock_guard<std::mutex> lock(mutex);
    if (!error.empty() || next >= total) return 0;
    const std::size_t n = std::min(chunk_size(total - next, all_threads) * threads, total - next);
    first = next;
    next += n;
    return n;
  };
  auto fail = [&](const std::string& what) {
    std::lock_guard<std::mutex> lock(mutex);
    if (error.empty()) error = what;
  };

  // this rank's threads take chunks like any rank
  std::vector<std::thread> pool;
  for (std::size_t t = 0; t < local_threads; ++t)
    pool.emplace_back([&] {
      std::size_t first = 0;
      while (const std::size_t n = take(1, first)) {
        try {
          for (std::size_t i = first; i < first + n; ++i) {
            MonteCarloSample& smp = p.samples[p.simulate[i]];
            smp.outcome = sim->run(smp.beta0, smp.overrides);
          }
        } catch (const std::exception& e) {
          fail(std::string("rank 0: ") + e.what());
          return;
        }
        std::lock_guard<std::mutex> lock(mutex);
        done += n;
      }
    });

  // this thread: hands out chunks to the serving ranks and takes their outcomes
  int released = 0;  // serving ranks told that the study is over
  std::size_t reported = static_cast<std::size_t>(-1);
  // nap between polls: 20 us after a request, doubling up to 1 ms while none comes (few wake-ups
  // while the ranks compute, a short answer time while they are asking)
  std::chrono::microseconds nap(20);
  try {
    while (released < ranks_ - 1) {
      int flag = 0;
      MPI_Status st;
      MPI_Iprobe(MPI_ANY_SOURCE, kTagRequest, MPI_COMM_WORLD, &flag, &st);
      if (!flag) {
        std::size_t d;
        {
          std::lock_guard<std::mutex> lock(mutex);
          d = done;
        }
        if (progress && d != reported) progress(reported = d, total, elapsed());
        std::this_thread::sleep_for(nap);
        nap = std::min(2 * nap, std::chrono::microseconds(1000));
        continue;
      }
      nap = std::chrono::microseconds(20);
      int from = 0;
      std::vector<char> bytes = receive(st.MPI_SOURCE, kTagRequest, &from);
      Reader in(bytes.data(), bytes.size());
      const auto kind = in.get<std::int32_t>();
      const auto their_job = in.get<std::uint64_t>();
      if (their_job != job) throw std::logic_error("a rank answered for another study");
      if (kind == kRequestError) {
        fail("rank " + std::to_string(from) + ": " + in.get_string());
      } else {
        const auto n = in.get<std::uint64_t>();
        if (n > 0) {
          const auto first = in.get<std::uint64_t>();
          for (std::uint64_t i = 0; i < n; ++i) p.samples[p.simulate[first + i]].outcome = detail::get_outcome(in);
          std::lock_guard<std::mutex> lock(mutex);
          done += n;
        }
      }
      std::size_t first = 0;
      // a serving rank gets a chunk for all its threads at once (ranks are alike: local_threads each)
      const std::size_t n = kind == kRequestError ? 0 : take(local_threads, first);
      Writer w;
      w.put(job);
      w.put<std::uint64_t>(first);
      w.put<std::uint64_t>(n);
      for (std::size_t i = first; i < first + n; ++i) detail::put_inputs(w, p.samples[p.simulate[i]]);
      send(w.bytes(), from, kTagAssign);
      if (n == 0) ++released;
    }
  } catch (const std::exception& e) {
    fail(std::string("rank 0: ") + e.what());
  }
  for (std::thread& t : pool) t.join();
  if (!error.empty()) throw std::runtime_error(error);
  if (done != total) throw std::logic_error("the ranks returned " + std::to_string(done) + " of " +
                                            std::to_string(total) + " runs");
  if (progress) progress(total, total, elapsed());
}

}  // namespace

Session::Session(int& argc, char**& argv) {
  g_session = this;
  if (!launched_by_mpi()) return;
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  mpi_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  if (rank_ != 0) {
    // a serving rank ends when rank 0 says so (or mpirun kills the job): Ctrl-C is rank 0's
    std::signal(SIGINT, SIG_IGN);
    std::signal(SIGTERM, SIG_IGN);
  } else {
    // mpirun turns Ctrl-C into SIGTERM for every rank: on rank 0 it is Ctrl-C (the optimiser's
    // handler stops after the current evaluation and writes what is done)
    std::signal(SIGTERM, forward_to_sigint);
  }
}

Session::~Session() {
  if (mpi_) {
    if (rank_ == 0 && !finished_) finish(0);
    MPI_Finalize();
  }
  g_session = nullptr;
}

int Session::serve() {
  if (!mpi_ || rank_ == 0) return 0;
  while (true) {
    wait_for(0, kTagCommand, std::chrono::milliseconds(1));
    std::vector<char> bytes = receive(0, kTagCommand);
    Reader in(bytes.data(), bytes.size());
    const auto command = in.get<std::int32_t>();
    if (command == kCommandEnd) return in.get<std::int32_t>();
    if (command == kCommandJob) serve_job(in);
  }
}

int Session::finish(int status) {
  if (mpi_ && rank_ == 0 && !finished_) {
    Writer w;
    w.put(kCommandEnd);
    w.put<std::int32_t>(status);
    for (int r = 1; r < size_; ++r) send(w.bytes(), r, kTagCommand);
  }
  finished_ = true;
  return status;
}

void Session::abort(int status) {
  std::fflush(stdout);
  std::fflush(stderr);
  if (mpi_) MPI_Abort(MPI_COMM_WORLD, status);
  std::exit(status);
}

std::shared_ptr<BatchRunner> make_runner(std::size_t threads) {
  Session* s = session();
  if (!s || s->size() <= 1) return std::make_shared<ThreadPoolRunner>(threads);
  return std::make_shared<MpiStudyRunner>(threads, s->size());
}

#endif

}  // namespace abuopt::parallel
