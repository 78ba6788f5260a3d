#pragma once
// Internal (MPI builds only): the messages between rank 0 and the serving ranks, and the calls that
// move them. The protocol (parallel.hpp has the model):
//
//   serving rank -> rank 0, tag kTagRequest: [int32 kind][uint64 job]...
//       kRequestResults: [uint64 count][uint64 first][count outcomes]  (count 0: nothing yet)
//       kRequestError:   [string message]        (the job failed on this rank)
//       kRequestInterrupted: [string message]    (this rank got SIGTERM: the job was abandoned)
//     Every serving rank has exactly one request outstanding at any time: one right after it
//     starts, then one after each chunk it was given.
//   rank 0 -> serving rank, tag kTagAssign: [int32 kind]...
//       kAssignChunk: [uint64 n_forget][n_forget uint64 job ids the rank may drop]
//                     [uint64 job][uint64 threads][uint8 has_setup][string setup if has_setup]
//                     [uint64 first][uint64 count][count run inputs]
//       kAssignEnd:   [int32 exit status]        (the command is over: leave serve())
//     Rank 0 answers a request when it has work for the rank (a chunk of any active study);
//     until then the request waits ("parked"), so a rank idles without messages.
#include <mpi.h>

#include <chrono>
#include <cstdint>
#include <thread>
#include <vector>

namespace abuopt::parallel::detail {

constexpr int kTagRequest = 2;
constexpr int kTagAssign = 3;
constexpr std::int32_t kRequestResults = 1, kRequestError = 2, kRequestInterrupted = 3;
constexpr std::int32_t kAssignChunk = 1, kAssignEnd = 2;

inline void send(const std::vector<char>& bytes, int to, int tag) {
  MPI_Send(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, to, tag, MPI_COMM_WORLD);
}

// Receives the next message with `tag` from `from` (MPI_ANY_SOURCE: any rank); its sender in
// *source. Blocks (MPI_Probe) until one is there: call it once one has been seen (wait_for).
inline std::vector<char> receive(int from, int tag, int* source = nullptr) {
  MPI_Status st;
  MPI_Probe(from, tag, MPI_COMM_WORLD, &st);
  int n = 0;
  MPI_Get_count(&st, MPI_BYTE, &n);
  std::vector<char> bytes(static_cast<std::size_t>(n));
  MPI_Recv(bytes.data(), n, MPI_BYTE, st.MPI_SOURCE, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  if (source) *source = st.MPI_SOURCE;
  return bytes;
}

// Waits for a message without spinning a core (Open MPI's blocking calls busy-poll, and a serving
// rank may wait minutes while rank 0 runs an optimiser step): naps of `first`, doubling up to 1 ms.
inline void wait_for(int from, int tag, std::chrono::microseconds first) {
  std::chrono::microseconds nap = first;
  int flag = 0;
  while (true) {
    MPI_Iprobe(from, tag, MPI_COMM_WORLD, &flag, MPI_STATUS_IGNORE);
    if (flag) return;
    std::this_thread::sleep_for(nap);
    nap = std::min(2 * nap, std::chrono::microseconds(1000));
  }
}

}  // namespace abuopt::parallel::detail
