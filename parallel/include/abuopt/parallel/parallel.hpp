#pragma once
// abuopt::parallel: the one place that knows MPI (issue 11). Everything below it sees only the
// abstract runners: core's StudyRunner/BatchRunner (monte_carlo.hpp, batch_runner.hpp). This
// header includes no MPI header; a build without MPI (ABUOPT_MPI=OFF or no MPI found) has the same
// functions with one process.
//
// Model: rank 0 runs the command (reads the config, runs the optimiser, writes every file, the
// archive and stdout); the other ranks serve. Every Monte Carlo study of rank 0 goes into one pool
// of runs, dealt out in chunks on request (dynamic balancing: a rank that is done asks for more),
// each chunk with its inputs (initial angles, uncertain parameters: prepared once, on rank 0) and,
// the first time a rank meets the study, its setup (YAML, rebuilt and checked on the rank). Several
// studies may be in the pool at once: an optimiser's batch of independent evaluations (design
// points, finite-difference neighbours) runs as concurrent studies (make_evaluation_scheduler), so
// the whole batch is spread over every rank and its tail is paid once (docs/cluster.md, "Batches of
// evaluations"). Threads inside every rank. Outcomes come back as bytes and land in slot i, so the
// result is bit-identical to one process for any ranks x threads.
//
// Ctrl-C: mpirun sends SIGTERM to every rank (and SIGKILL a second later, Open MPI's
// odls_base_sigkill_timeout); a rank that gets it abandons its chunk, every study in flight ends
// with Interrupted, the optimiser stops (its SIGINT handler is called), rank 0 writes what is done
// and the command returns 130; the serving ranks leave with 130 too.
//
#include <cstddef>
#include <memory>
#include <stdexcept>
#include <string>

#include "abuopt/common/stop.hpp"
#include "abuopt/core/batch_runner.hpp"

namespace abuopt::opt {
class EvaluationScheduler;  // abuopt/optimizer/evaluation_scheduler.hpp
}

namespace abuopt::parallel {

// Thrown by a Monte Carlo over ranks that was interrupted (SIGTERM on a rank: Ctrl-C to mpirun,
// scancel); a command reports it and ends with status 130.
class Interrupted : public abuopt::Interrupted {  // the one stop of abuopt/common/stop.hpp
 public:
  using abuopt::Interrupted::Interrupted;
};

// True once this process (or, on rank 0, a serving rank) got SIGTERM under MPI.
bool interrupted() noexcept;

// True when this binary was built with MPI.
bool built_with_mpi();

// True when the process was started by an MPI launcher (mpirun/mpiexec/srun): Open MPI's
// OMPI_COMM_WORLD_SIZE, PMI_SIZE or PMIX_RANK in the environment. Without it MPI is never
// initialised and the binary runs as a plain program.
bool launched_by_mpi();

class Session {
 public:
  // Initialises MPI (threads: serialized, any thread may make MPI calls, one at a time) when built
  // with it and launched_by_mpi(); otherwise a one-process session. Under MPI, SIGTERM interrupts
  // (see the model above) and a serving rank ignores SIGINT (Ctrl-C is rank 0's).
  Session(int& argc, char**& argv);
  ~Session();  // MPI_Finalize (after finish())
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool is_root() const { return rank_ == 0; }

  // Serving ranks: run the chunks rank 0 sends until it says the command is over; its exit status.
  int serve();
  // Rank 0: tell the serving ranks that the command ended with `status`; returns status.
  int finish(int status);
  // More than one rank, and Monte Carlo studies may run from several threads at once (MPI gave
  // MPI_THREAD_SERIALIZED): batches of evaluations can be spread (make_evaluation_scheduler).
  bool concurrent_studies() const;
  // Ends every rank at once with `status` (MPI_Abort; plain exit without MPI): for a fault with
  // no way back (a rank stuck in a study). The message is printed first by the caller.
  [[noreturn]] void abort(int status);

 private:
  int rank_ = 0;
  int size_ = 1;
  bool mpi_ = false;
  bool serialized_ = false;
  bool finished_ = false;
  int status_ = 0;  // the command's exit status (serving ranks: rank 0's)
};

// The session of this process (nullptr before a Session exists).
Session* session();

// The runner of a Monte Carlo with `threads` threads per rank (0: all cores): a StudyRunner over
// every rank when the session has more than one, else a ThreadPoolRunner. Rank 0 only. Every
// runner of a session shares its one pool of runs; run_study may be called from several threads
// at once when concurrent_studies().
std::shared_ptr<BatchRunner> make_runner(std::size_t threads);

// The evaluation scheduler (optimizer/evaluation_scheduler.hpp) of an optimiser whose problem runs
// its Monte Carlo on make_runner(): kEvaluationsAtOnce evaluations of a batch at once, each on a
// thread of rank 0 that only waits for its study while the studies' runs share the pool (one
// evaluation at a time without concurrent_studies()). For a problem that declares thread_safe().
constexpr std::size_t kEvaluationsAtOnce = 64;
std::shared_ptr<opt::EvaluationScheduler> make_evaluation_scheduler();

}  // namespace abuopt::parallel
