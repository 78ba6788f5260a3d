#pragma once
// abuopt::parallel: the one place that knows MPI (issue 11). Everything below it sees only the
// abstract runners: core's StudyRunner/BatchRunner (monte_carlo.hpp, batch_runner.hpp). This
// header includes no MPI header; a build without MPI (ABUOPT_MPI=OFF or no MPI found) has the same
// functions with one process.
//
// Model: rank 0 runs the command (reads the config, runs the optimiser, writes every file, the
// archive and stdout); the other ranks serve: for each Monte Carlo study of rank 0 they get the
// setup (YAML, rebuilt and checked on the rank), then chunks of runs on request, each with its
// inputs (initial angles, uncertain parameters: prepared once, on rank 0) — dynamic balancing: a
// rank that is done asks for more — with threads inside every rank. Outcomes come back as bytes
// and land in slot i, so the result is bit-identical to one process for any ranks x threads.
//
//   int main(int argc, char** argv) {
//     abuopt::parallel::Session mpi(argc, argv);   // MPI only when launched by mpirun
//     if (!mpi.is_root()) return mpi.serve();       // the other ranks
//     ... the command, with make_runner(threads) for its Monte Carlo ...
//     return mpi.finish(status);                    // releases the serving ranks
//   }
#include <cstddef>
#include <memory>
#include <string>

#include "abuopt/core/batch_runner.hpp"

namespace abuopt::parallel {

// True when this binary was built with MPI.
bool built_with_mpi();

// True when the process was started by an MPI launcher (mpirun/mpiexec/srun): Open MPI's
// OMPI_COMM_WORLD_SIZE, PMI_SIZE or PMIX_RANK in the environment. Without it MPI is never
// initialised and the binary runs as a plain program.
bool launched_by_mpi();

class Session {
 public:
  // Initialises MPI (threads: funneled) when built with it and launched_by_mpi(); otherwise a
  // one-process session. Installs handlers so that SIGINT/SIGTERM on a serving rank only stops it
  // serving (the command on rank 0 decides when to stop).
  Session(int& argc, char**& argv);
  ~Session();  // MPI_Finalize (after finish())
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool is_root() const { return rank_ == 0; }

  // Serving ranks: run the studies rank 0 sends until it says it is done; the exit status.
  int serve();
  // Rank 0: tell the serving ranks that the command ended with `status`; returns status.
  int finish(int status);
  // Ends every rank at once with `status` (MPI_Abort; plain exit without MPI): for a fault with
  // no way back (a rank stuck in a study). The message is printed first by the caller.
  [[noreturn]] void abort(int status);

 private:
  int rank_ = 0;
  int size_ = 1;
  bool mpi_ = false;
  bool finished_ = false;
};

// The session of this process (nullptr before a Session exists).
Session* session();

// The runner of a Monte Carlo with `threads` threads per rank (0: all cores): a StudyRunner over
// every rank when the session has more than one, else a ThreadPoolRunner. Rank 0 only.
std::shared_ptr<BatchRunner> make_runner(std::size_t threads);

}  // namespace abuopt::parallel
