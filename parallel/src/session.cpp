// The MPI session, the serving ranks and the runner over ranks (parallel.hpp describes the model;
// rank 0's pool of runs is dispatcher.cpp). Without MPI (ABUOPT_HAVE_MPI undefined) the same
// functions run one process.
#include "abuopt/parallel/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <map>
#include <stdexcept>
#include <thread>
#include <vector>

#include "abuopt/core/monte_carlo.hpp"
#include "abuopt/optimizer/evaluation_scheduler.hpp"

#ifdef ABUOPT_HAVE_MPI
#include <mpi.h>

#include "codec.hpp"
#include "dispatcher.hpp"
#include "wire.hpp"
#endif

namespace abuopt::parallel {

namespace {
Session* g_session = nullptr;
std::atomic<bool> g_interrupted{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the SIGTERM handler sets an atomic<bool>");
}  // namespace

bool interrupted() noexcept { return g_interrupted.load(); }

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

std::shared_ptr<opt::EvaluationScheduler> make_evaluation_scheduler() {
  const Session* s = session();
  const bool spread = s && s->concurrent_studies();
  return std::make_shared<opt::ThreadScheduler>(spread ? kEvaluationsAtOnce : 1);
}

#ifndef ABUOPT_HAVE_MPI

Session::Session(int&, char**&) { g_session = this; }
Session::~Session() { g_session = nullptr; }
int Session::serve() { return 0; }
int Session::finish(int status) {
  finished_ = true;
  return status_ = status;
}
bool Session::concurrent_studies() const { return false; }
void Session::abort(int status) { std::exit(status); }
std::shared_ptr<BatchRunner> make_runner(std::size_t threads) { return std::make_shared<ThreadPoolRunner>(threads); }

#else

namespace detail {

// Sets the flag and calls the SIGINT handler in place (the optimiser's sets its own stop flag), if
// it is a function: SIG_DFL would end the process, which is not what SIGTERM under MPI asks for.
void note_interrupt() noexcept {
  if (g_interrupted.exchange(true)) return;
  struct sigaction current {};
  if (sigaction(SIGINT, nullptr, &current) != 0) return;
  if ((current.sa_flags & SA_SIGINFO) == 0 && current.sa_handler != SIG_DFL && current.sa_handler != SIG_IGN)
    current.sa_handler(SIGINT);
}

}  // namespace detail

namespace {

using detail::Reader;
using detail::Writer;

std::unique_ptr<detail::Dispatcher> g_dispatcher;  // rank 0 of a session of several ranks

int g_ranks = 1;  // the session's size, for the signal handler

// SIGTERM: the command is interrupted. With one rank and no SIGINT handler to call (a command that
// does not stop early, e.g. montecarlo) the process ends as SIGINT would end it.
extern "C" void on_sigterm(int) {
  struct sigaction current {};
  if (g_ranks == 1 && sigaction(SIGINT, nullptr, &current) == 0 && (current.sa_flags & SA_SIGINFO) == 0 &&
      current.sa_handler == SIG_DFL)
    std::raise(SIGINT);
  detail::note_interrupt();
}

// Fault injection for the tests of faults (tests/app/mpi_cli_test.cpp): ABUOPT_TEST_FAULT =
// "throw:R[:K]" makes serving rank R throw in its K-th chunk (default 1), "die:R[:K]" kills it
// there (SIGKILL); "die_job:R:J" (below) kills it when its J-th study arrives.
void injected_fault(int rank) {
  static const char* v = std::getenv("ABUOPT_TEST_FAULT");
  static long chunks = 0;
  if (!v) return;
  const std::string spec(v);
  const auto colon = spec.find(':');
  if (colon == std::string::npos) return;
  if (std::atoi(spec.c_str() + colon + 1) != rank) return;
  const auto second = spec.find(':', colon + 1);
  const long at = second == std::string::npos ? 1 : std::atol(spec.c_str() + second + 1);
  if (++chunks != at) return;
  if (spec.compare(0, colon, "die") == 0) std::raise(SIGKILL);
  if (spec.compare(0, colon, "throw") == 0)
    throw std::runtime_error("fault injected by ABUOPT_TEST_FAULT=" + spec);
}

// "die_job:R:J" kills serving rank R when the setup of its J-th study arrives (deterministic,
// unlike a chunk count, which depends on how the dynamic scheduling shares the runs out).
void injected_job_fault(int rank) {
  static const char* v = std::getenv("ABUOPT_TEST_FAULT");
  static long jobs = 0;
  if (!v) return;
  const std::string spec(v);
  if (spec.rfind("die_job:", 0) != 0) return;
  const auto second = spec.find(':', 8);
  if (second == std::string::npos) return;
  if (std::atoi(spec.c_str() + 8) != rank) return;
  if (++jobs == std::atol(spec.c_str() + second + 1)) std::raise(SIGKILL);
}

// A run abandoned because of SIGTERM.
struct Abandoned {};

// Rank 0's side of the studies: a handle on the session's one pool (dispatcher.hpp).
class MpiStudyRunner final : public StudyRunner {
 public:
  MpiStudyRunner(std::size_t threads, int ranks) : threads_(threads), ranks_(ranks) {}

  std::size_t concurrency() const override {
    return (threads_ == 0 ? hardware_threads() : threads_) * static_cast<std::size_t>(ranks_);
  }
  // A task closure cannot travel: plain batches run on this rank's threads.
  void run(std::size_t count, const std::function<void(std::size_t)>& task, const ProgressCallback& progress) override {
    ThreadPoolRunner(threads_).run(count, task, progress);
  }
  void run_study(const MonteCarloStudy& s, PreparedStudy& p, const ProgressCallback& progress) override {
    if (!g_dispatcher) throw std::logic_error("a Monte Carlo over ranks after the MPI session finished");
    g_dispatcher->run_study(s, p, progress, threads_);
  }

 private:
  std::size_t threads_;
  int ranks_;
};

}  // namespace

Session::Session(int& argc, char**& argv) {
  g_session = this;
  if (!launched_by_mpi()) return;
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_SERIALIZED, &provided);
  mpi_ = true;
  serialized_ = provided >= MPI_THREAD_SERIALIZED;
  // PMPI_ (the MPI standard's profiling names of the same calls) where a name clashes: sequential
  // MUMPS, linked in through Ipopt, exports stubs MPI_Comm_rank, MPI_Finalize, MPI_Init and
  // MPI_Wtime for its own use, and when the linker puts libdmumps_seq before libmpi the dynamic
  // linker binds our calls to them (every rank then was "rank 0": seen when parallel began linking
  // the optimizer). The PMPI_ names exist only in the real MPI library.
  PMPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  g_ranks = size_;
  // mpirun turns Ctrl-C into SIGTERM for every rank (SIGINT cannot be forwarded: Open MPI's
  // ess_base_forward_signals refuses it); a serving rank ignores a SIGINT of its own (srun may
  // forward Ctrl-C to every task: the command on rank 0 decides when to stop)
  struct sigaction sa {};
  sa.sa_handler = on_sigterm;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGTERM, &sa, nullptr);
  if (rank_ != 0) std::signal(SIGINT, SIG_IGN);
  if (rank_ == 0 && size_ > 1) g_dispatcher = std::make_unique<detail::Dispatcher>(size_, serialized_);
}

Session::~Session() {
  if (mpi_) {
    if (rank_ == 0 && !finished_) finish(0);
    if (interrupted()) {
      // mpirun is ending the job (it sent SIGTERM and sends SIGKILL a second later): MPI_Finalize
      // would wait for it in vain (seen: the ranks were killed in MPI_Finalize), so leave now with
      // the command's status, what is written being on disk already
      std::fflush(stdout);
      std::fflush(stderr);
      // a serving rank lets rank 0 leave first: once a process of the aborting job has exited,
      // mpirun kills the others at once, and rank 0's status (130) is the one that tells
      if (rank_ != 0) std::this_thread::sleep_for(std::chrono::milliseconds(300));
      std::_Exit(status_);
    }
    PMPI_Finalize();  // not MPI_Finalize: see PMPI_Comm_rank above
  }
  g_session = nullptr;
}

bool Session::concurrent_studies() const { return size_ > 1 && serialized_; }

int Session::serve() {
  if (!mpi_ || rank_ == 0) return 0;
  std::map<std::uint64_t, std::shared_ptr<const Simulator>> studies;  // by job id
  auto request = [&](std::int32_t kind, std::uint64_t job, const std::function<void(Writer&)>& body) {
    Writer w;
    w.put(kind);
    w.put(job);
    body(w);
    detail::send(w.bytes(), 0, detail::kTagRequest);
  };
  request(detail::kRequestResults, 0, [](Writer&) {});  // ready
  while (true) {
    detail::wait_for(0, detail::kTagAssign, std::chrono::microseconds(50));  // not a spinning blocking receive
    const std::vector<char> bytes = detail::receive(0, detail::kTagAssign);
    Reader a(bytes.data(), bytes.size());
    if (a.get<std::int32_t>() == detail::kAssignEnd) return status_ = a.get<std::int32_t>();
    for (auto n = a.get<std::uint64_t>(); n > 0; --n) studies.erase(a.get<std::uint64_t>());
    const auto job = a.get<std::uint64_t>();
    const auto threads = static_cast<std::size_t>(a.get<std::uint64_t>());
    std::string error;
    if (a.get<std::uint8_t>() != 0) {
      const std::string text = a.get_string();
      injected_job_fault(rank_);
      try {
        studies[job] = std::make_shared<const Simulator>(detail::decode_setup(text));
      } catch (const std::exception& e) {
        error = e.what();
      }
    }
    const auto first = a.get<std::uint64_t>();
    const auto count = a.get<std::uint64_t>();
    std::vector<std::vector<double>> beta0(count);
    std::vector<RunOverrides> overrides(count);
    for (std::uint64_t i = 0; i < count; ++i) detail::get_inputs(a, beta0[i], overrides[i]);
    const auto found = studies.find(job);
    if (error.empty() && found == studies.end()) error = "no setup for study " + std::to_string(job) + " on this rank";
    if (!error.empty()) {
      request(detail::kRequestError, job, [&](Writer& w) { w.put(error); });
      continue;
    }
    const Simulator& sim = *found->second;
    std::vector<RunOutcome> out(count);
    try {
      injected_fault(rank_);
      ThreadPoolRunner(threads).run(count, [&](std::size_t i) {
        if (interrupted()) throw Abandoned{};
        out[i] = sim.run(beta0[i], overrides[i]);
      });
    } catch (const Abandoned&) {
      request(detail::kRequestInterrupted, job, [](Writer& w) { w.put(std::string("interrupted (SIGTERM)")); });
      continue;
    } catch (const std::exception& e) {
      request(detail::kRequestError, job, [&](Writer& w) { w.put(std::string(e.what())); });
      continue;
    }
    request(detail::kRequestResults, job, [&](Writer& w) {
      w.put<std::uint64_t>(count);
      w.put<std::uint64_t>(first);
      for (const RunOutcome& o : out) detail::put_outcome(w, o);
    });
  }
}

int Session::finish(int status) {
  status_ = status;
  if (mpi_ && rank_ == 0 && !finished_ && g_dispatcher) {
    g_dispatcher->finish(status);
    g_dispatcher.reset();
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
