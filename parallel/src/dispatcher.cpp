// Rank 0's side of the Monte Carlo over ranks (dispatcher.hpp). MPI builds only.
#ifdef ABUOPT_HAVE_MPI

#include "dispatcher.hpp"

#include <algorithm>
#include <chrono>
#include <exception>
#include <stdexcept>

#include "abuopt/parallel/parallel.hpp"
#include "codec.hpp"
#include "wire.hpp"

namespace abuopt::parallel::detail {

namespace {

// The size of the next chunk of runs per thread: guided (a quarter of what is left in every open
// study, per thread of all ranks, so the last chunks are small and the ranks finish together), at
// least 1, at most 64 runs.
std::size_t chunk_size(std::size_t left, std::size_t all_threads) {
  return std::clamp<std::size_t>(left / (4 * std::max<std::size_t>(all_threads, 1)), 1, 64);
}

}  // namespace

Dispatcher::Dispatcher(int ranks, bool serialized)
    : ranks_(ranks), serialized_(serialized), owner_(std::this_thread::get_id()), rank_state_(ranks) {}

Dispatcher::~Dispatcher() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  work_.notify_all();
  std::lock_guard<std::mutex> lock(threads_mutex_);
  for (std::thread& t : workers_) t.join();
}

void Dispatcher::ensure_workers(std::size_t n) {
  std::lock_guard<std::mutex> lock(threads_mutex_);
  while (workers_.size() < n) workers_.emplace_back([this] { worker(); });
}

std::shared_ptr<Dispatcher::Job> Dispatcher::take(std::size_t threads, std::size_t& first, std::size_t& count) {
  std::size_t left = 0;
  std::shared_ptr<Job> oldest;
  for (const auto& j : jobs_)
    if (j->open()) {
      left += j->total - j->next;
      if (!oldest) oldest = j;
    }
  if (!oldest) return nullptr;
  const std::size_t all_threads = ranks_threads_ * static_cast<std::size_t>(ranks_);
  count = std::min(chunk_size(left, all_threads) * threads, oldest->total - oldest->next);
  first = oldest->next;
  oldest->next += count;
  ++oldest->in_flight;
  return oldest;
}

// Rank 0's own threads take chunks (one thread's worth each) like any rank.
void Dispatcher::worker() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    work_.wait(lock, [&] {
      if (stop_) return true;
      for (const auto& j : jobs_)
        if (j->open()) return true;
      return false;
    });
    if (stop_) return;
    std::size_t first = 0, count = 0;
    const std::shared_ptr<Job> job = take(1, first, count);
    if (!job) continue;
    lock.unlock();
    std::string error;
    bool interrupted_here = false;
    try {
      for (std::size_t i = first; i < first + count; ++i) {
        if (interrupted()) {
          interrupted_here = true;
          break;
        }
        MonteCarloSample& smp = job->prepared->samples[job->prepared->simulate[i]];
        smp.outcome = job->sim->run(smp.beta0, smp.overrides);
      }
    } catch (const std::exception& e) {
      error = std::string("rank 0: ") + e.what();
    }
    lock.lock();
    --job->in_flight;
    if (interrupted_here) {
      job->interrupted = true;
      if (job->error.empty()) job->error = "interrupted";
    } else if (!error.empty()) {
      if (job->error.empty()) job->error = error;
    } else {
      job->done += count;
    }
    if (job->finished()) changed_.notify_all();
  }
}

void Dispatcher::fail_all_interrupted() {
  for (const auto& j : jobs_) {
    j->interrupted = true;
    if (j->error.empty()) j->error = "interrupted";
  }
}

bool Dispatcher::pump() {
  bool busy = false;
  bool rank_interrupted = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (interrupted() && !interrupt_seen_) {
      interrupt_seen_ = true;
      fail_all_interrupted();
    }
  }
  // every request that has come
  while (true) {
    int flag = 0;
    MPI_Status st;
    MPI_Iprobe(MPI_ANY_SOURCE, kTagRequest, MPI_COMM_WORLD, &flag, &st);
    if (!flag) break;
    busy = true;
    int from = 0;
    const std::vector<char> bytes = receive(st.MPI_SOURCE, kTagRequest, &from);
    Reader in(bytes.data(), bytes.size());
    const auto kind = in.get<std::int32_t>();
    const auto id = in.get<std::uint64_t>();
    std::lock_guard<std::mutex> lock(mutex_);
    rank_state_[static_cast<std::size_t>(from)].parked = true;
    if (id == 0) continue;  // a rank's first request: nothing to report
    const auto it = std::find_if(jobs_.begin(), jobs_.end(), [&](const auto& j) { return j->id == id; });
    if (it == jobs_.end()) throw std::logic_error("rank " + std::to_string(from) + " answered for a study that is not running");
    Job& job = **it;
    --job.in_flight;
    if (kind == kRequestResults) {
      const auto n = in.get<std::uint64_t>();
      const auto first = in.get<std::uint64_t>();
      if (first + n > job.total) throw std::logic_error("rank " + std::to_string(from) + " returned runs out of range");
      for (std::uint64_t i = 0; i < n; ++i)
        job.prepared->samples[job.prepared->simulate[first + i]].outcome = get_outcome(in);
      job.done += n;
    } else {
      const std::string message = in.get_string();
      if (kind == kRequestInterrupted) {
        job.interrupted = true;
        rank_interrupted = true;
      }
      if (job.error.empty()) job.error = "rank " + std::to_string(from) + ": " + message;
    }
  }
  // a serving rank got the job's SIGTERM first: the whole command stops (as for rank 0's own)
  if (rank_interrupted) {
    note_interrupt();
    std::lock_guard<std::mutex> lock(mutex_);
    interrupt_seen_ = true;
    fail_all_interrupted();
  }
  // work for the parked ranks
  for (int r = 1; r < ranks_; ++r) {
    RankState& rs = rank_state_[static_cast<std::size_t>(r)];
    std::shared_ptr<Job> job;
    std::size_t first = 0, count = 0;
    Writer w;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!rs.parked) continue;
      for (const auto& j : jobs_)
        if (j->open()) {
          job = j;
          break;
        }
      if (!job) break;  // nothing open: every parked rank waits
      job = take(job->threads, first, count);
      w.put(kAssignChunk);
      w.put<std::uint64_t>(rs.forget.size());
      for (std::uint64_t f : rs.forget) w.put(f);
      rs.forget.clear();
      w.put(job->id);
      w.put<std::uint64_t>(job->threads);
      const bool has_setup = std::find(rs.known.begin(), rs.known.end(), job->id) == rs.known.end();
      w.put<std::uint8_t>(has_setup ? 1 : 0);
      if (has_setup) {
        w.put(job->setup);
        rs.known.push_back(job->id);
      }
      w.put<std::uint64_t>(first);
      w.put<std::uint64_t>(count);
      rs.parked = false;
    }
    // the inputs do not change during the study (the workers write outcomes only)
    for (std::size_t i = first; i < first + count; ++i)
      put_inputs(w, job->prepared->samples[job->prepared->simulate[i]]);
    send(w.bytes(), r, kTagAssign);
    busy = true;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& j : jobs_)
      if (j->finished()) {
        changed_.notify_all();
        break;
      }
  }
  return busy;
}

void Dispatcher::run_study(const MonteCarloStudy& s, PreparedStudy& p, const ProgressCallback& progress,
                           std::size_t threads) {
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  if (!serialized_ && std::this_thread::get_id() != owner_)
    throw std::logic_error("MPI without MPI_THREAD_SERIALIZED: Monte Carlo studies must come from the main thread");
  auto job = std::make_shared<Job>();
  job->sim = std::make_shared<const Simulator>(s.setup);  // validates the setup
  job->setup = encode_setup(s.setup);
  job->prepared = &p;
  job->threads = threads == 0 ? hardware_threads() : threads;
  job->total = p.simulate.size();
  ensure_workers(job->threads);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (finished_) throw std::logic_error("a Monte Carlo study after the MPI session finished");
    if (interrupted()) throw Interrupted("interrupted: no new Monte Carlo study is started");
    job->id = ++last_id_;
    ranks_threads_ = job->threads;
    jobs_.push_back(job);
  }
  work_.notify_all();

  // Until the study is done: one waiting thread at a time is the pumper (the MPI calls for every
  // study in flight, naps of 20 us after traffic doubling to 1 ms while none comes); the others
  // sleep until their study is done or the pumper leaves (then one of them takes over).
  std::chrono::microseconds nap(20);
  std::size_t reported = static_cast<std::size_t>(-1);
  bool pumper = false;
  while (true) {
    std::size_t done = 0;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      auto over = [&] { return job->finished() || !broken_.empty(); };
      if (pumper)
        changed_.wait_for(lock, nap, over);
      else
        changed_.wait(lock, [&] { return over() || !pumping_; });
      if (over()) break;
      if (!pumper) pumping_ = pumper = true;
      done = job->done;
    }
    if (progress && done != reported) progress(reported = done, job->total, elapsed());
    bool busy = false;
    std::string pump_error;
    try {
      std::lock_guard<std::mutex> mpi(pump_);
      busy = pump();
    } catch (const std::exception& e) {
      pump_error = std::string("rank 0: ") + e.what();
    }
    if (!pump_error.empty()) {  // a broken exchange: every study fails with the reason
      std::lock_guard<std::mutex> lock(mutex_);
      if (broken_.empty()) broken_ = pump_error;
      changed_.notify_all();
    }
    nap = busy ? std::chrono::microseconds(20) : std::min(2 * nap, std::chrono::microseconds(1000));
  }
  if (pumper) {
    std::lock_guard<std::mutex> lock(mutex_);
    pumping_ = false;
  }
  changed_.notify_all();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    jobs_.remove(job);
    for (RankState& rs : rank_state_) {
      const auto it = std::find(rs.known.begin(), rs.known.end(), job->id);
      if (it == rs.known.end()) continue;
      rs.known.erase(it);
      rs.forget.push_back(job->id);
    }
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!broken_.empty()) throw std::runtime_error(broken_);
  }
  if (job->interrupted) throw Interrupted("interrupted (SIGTERM, e.g. Ctrl-C to mpirun) during a Monte Carlo study");
  if (!job->error.empty()) throw std::runtime_error(job->error);
  if (job->done != job->total)
    throw std::logic_error("the ranks returned " + std::to_string(job->done) + " of " + std::to_string(job->total) +
                           " runs");
  if (progress) progress(job->total, job->total, elapsed());
}

void Dispatcher::finish(int status) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (finished_) return;
    finished_ = true;
    stop_ = true;
  }
  work_.notify_all();
  {
    std::lock_guard<std::mutex> lock(threads_mutex_);
    for (std::thread& t : workers_) t.join();
    workers_.clear();
  }
  std::lock_guard<std::mutex> pump(pump_);
  Writer w;
  w.put(kAssignEnd);
  w.put<std::int32_t>(status);
  for (int r = 1; r < ranks_; ++r) {
    if (!rank_state_[static_cast<std::size_t>(r)].parked) {  // its outstanding request first
      wait_for(r, kTagRequest, std::chrono::microseconds(20));
      receive(r, kTagRequest);
    }
    send(w.bytes(), r, kTagAssign);
  }
}

}  // namespace abuopt::parallel::detail

#endif  // ABUOPT_HAVE_MPI
