#pragma once
// EvaluationArchive: every evaluation of a study stored in an SQLite file (the idea of OpenMDAO's
// SqliteRecorder), so that a study never evaluates the same design twice and a killed study
// resumes where it stopped.
//
// * Problem identity: a string given by the caller (e.g. a hash of the resolved config). One file
//   may hold several problems; lookups only ever match the same problem id.
// * Exact matching: the design vector is stored as the hex of each double's bits (plus a readable
//   JSON copy), so find(x) answers only a bitwise-identical repeat. Objective and constraint
//   values are stored the same way and come back bit for bit; metrics are JSON (doubles
//   round-trip exactly; inf/nan are stored as the strings "inf", "-inf", "nan").
// * Durability: WAL journal, each store() is its own committed transaction. Killing the process
//   (even SIGKILL) loses nothing that store() returned from (synchronous=NORMAL: an OS crash or
//   power loss may lose the last few commits).
// * Thread-safe: every method takes a mutex.
// * Integrity: every stored evaluation carries a checksum (FNV-1a 64 of everything read back:
//   problem id, x, run count, values, inequality count, metrics, status, message), verified on
//   every read. A row that fails it is damaged: it is deleted, never answered (find() misses, so
//   ArchivedProblem recomputes and stores it again; entries() leaves it out), and said through the
//   warning handler (default: a line on stderr). A file that SQLite itself finds damaged
//   (PRAGMA quick_check on opening, or a corruption error later) is a ConfigError naming the file.
// * Schema version: PRAGMA user_version = schema_version() (2: checksums and run counts); an
//   archive of another version is a ConfigError that says so (it is not migrated).
// * Run count: a value is stored with the Monte Carlo run count it was computed with, which is
//   part of the key: a request at another run count never gets it. 0: the problem's own sample
//   size (a problem that is not sampled, or a sampled one at its configured size, which its
//   problem id fixes); n > 0: a value at another sample size n (adaptive sampling, problem.hpp
//   evaluate_sampled: the first n samples of the problem's fixed sequence).
//
// * Metadata (provenance): the table `metadata` holds one row per command that opened the archive
//   for a problem (record_metadata): time, abuopt version, git commit, command, config file and
//   the config's hash, so every evaluation can be traced (by its timestamp) to the abuopt that
//   computed it. Added without a schema change: older archives get the table when next opened.
// * Export: archive_export.hpp writes every stored evaluation as CSV and JSON (docs/archive.md).
//
// ArchivedProblem decorates any Problem: evaluate(x) first asks the archive; a hit is returned
// with Evaluation::from_archive = true (and counted by minimize() in archive_hits), a miss is
// evaluated by the wrapped problem and stored. Failed evaluations (ok == false) are stored too
// (a rerun would fail the same way); evaluations that throw are not stored.
#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "abuopt/optimizer/problem.hpp"

struct sqlite3;

namespace abuopt::opt {

class EvaluationArchive {
 public:
  struct Entry {
    long id = 0;
    std::vector<double> x;
    long runs = 0;  // Monte Carlo runs of the value (0: not a sampled problem)
    Evaluation evaluation;
    double wall_time_s = 0.0;
    std::string timestamp;  // ISO 8601, UTC
  };

  // One row of the metadata table.
  struct Metadata {
    long id = 0;
    std::string problem_id;
    std::string timestamp;  // ISO 8601, UTC
    std::string abuopt_version;
    std::string git_commit;
    std::string command;      // "optimize", "sweep", ...
    std::string config;       // the config file as given
    std::string config_hash;  // provenance.hpp's config_hash
  };
  // One row of the problems table (check_signature).
  struct ProblemRecord {
    std::string problem_id;
    std::string name;
    std::vector<std::string> variables;
    std::vector<std::string> inequality;
    std::vector<std::string> equality;
    std::string created;
  };

  // ReadOnly (the archive readers: list, show, best, history, Python abuopt.Archive): the file must
  // exist and be an archive; nothing is written (no schema, no journal mode, damaged rows are left
  // out but not deleted), so a read-only file or directory can be read and is left byte-identical.
  enum class OpenMode { ReadWrite, ReadOnly };

  // Opens or creates (ReadWrite) the archive file; throws abuopt::ConfigError naming the file if it
  // cannot, if SQLite finds it damaged, if it has another schema version, or (ReadOnly) if it is
  // missing or not an archive.
  EvaluationArchive(const std::string& path, std::string problem_id, OpenMode mode = OpenMode::ReadWrite);
  ~EvaluationArchive();
  EvaluationArchive(const EvaluationArchive&) = delete;
  EvaluationArchive& operator=(const EvaluationArchive&) = delete;

  const std::string& path() const { return path_; }
  const std::string& problem_id() const { return problem_id_; }

  // The stored evaluation of exactly x (bitwise) at this run count for this problem id, if any and
  // intact (a damaged row is deleted, said, and not returned).
  std::optional<Evaluation> find(const std::vector<double>& x, long runs = 0) const;
  // Stores one evaluation with its checksum and commits. A repeat of an (x, runs) already stored is
  // ignored (first wins).
  void store(const std::vector<double>& x, const Evaluation& evaluation, double wall_time_s, long runs = 0);
  // Number of evaluations stored for this problem id.
  long count() const;
  // All intact evaluations of this problem id, in the order they were stored.
  std::vector<Entry> entries() const;

  // Adds a metadata row for this problem id with this abuopt's version and git commit.
  void record_metadata(const std::string& command, const std::string& config, const std::string& config_hash);
  // The metadata rows of this problem id, oldest first.
  std::vector<Metadata> metadata() const;
  // Every problem recorded in the file (any problem id), in the order they were first recorded.
  std::vector<ProblemRecord> problems() const;

  // Where warnings about damaged rows go (default: "warning: ..." on stderr).
  void set_warning_handler(std::function<void(const std::string&)> handler);
  // Rows found damaged (and deleted) since this archive was opened.
  long damaged_rows() const { return damaged_.load(); }
  // The PRAGMA user_version this code writes and reads.
  static int schema_version();

  // Records the problem's variable and constraint names under this problem id, or, if already
  // recorded, throws abuopt::ConfigError when they differ (an id reused for another problem).
  void check_signature(const Problem& problem);

  // The exact key of a design vector: 16 hex digits per double, of its IEEE-754 bits.
  static std::string key_of(const std::vector<double>& x);

 private:
  void exec(const char* sql) const;
  // A row whose checksum fails: deleted, counted, said (mutex held by the caller).
  void discard_damaged(long id, const std::string& what) const;
  std::string path_;
  std::string problem_id_;
  bool read_only_ = false;
  sqlite3* db_ = nullptr;
  mutable std::mutex mutex_;
  std::function<void(const std::string&)> warn_;
  mutable std::atomic<long> damaged_{0};
};

class ArchivedProblem : public Problem {
 public:
  // Both must outlive this object. Calls archive.check_signature(inner).
  ArchivedProblem(Problem& inner, EvaluationArchive& archive);

  std::string name() const override { return inner_.name(); }
  std::vector<Variable> variables() const override { return inner_.variables(); }
  std::vector<std::string> inequality_names() const override { return inner_.inequality_names(); }
  std::vector<std::string> equality_names() const override { return inner_.equality_names(); }
  std::vector<double> initial_point() const override { return inner_.initial_point(); }
  std::optional<BestKnown> best_known() const override { return inner_.best_known(); }

  Evaluation evaluate(const std::vector<double>& x) override;
  bool thread_safe() const override { return inner_.thread_safe(); }
  Evaluation evaluate_shared(const std::vector<double>& x, std::size_t concurrent) override;
  // Hits are answered from the archive; the misses go to the wrapped problem's evaluate_batch and
  // are stored in input order once all are done (the archive's rows never depend on the threads).
  std::vector<BatchEvaluation> evaluate_batch(const std::vector<std::vector<double>>& xs,
                                              EvaluationScheduler& scheduler) override;

  // Sample sizes (problem.hpp): forwarded; a value at n is stored under run count 0 when n is the
  // wrapped problem's own sample_size() (so archives written before adaptive sampling still
  // answer), else under n.
  std::size_t sample_size() const override { return inner_.sample_size(); }
  std::size_t max_sample_size() const override { return inner_.max_sample_size(); }
  bool stochastic() const override { return inner_.stochastic(); }
  Evaluation evaluate_sampled(const std::vector<double>& x, std::size_t n, std::size_t concurrent = 1) override;
  std::vector<BatchEvaluation> evaluate_batch_sampled(const std::vector<std::vector<double>>& xs, std::size_t n,
                                                      EvaluationScheduler& scheduler) override;
  // The archive's run count of a value at sample size n: 0 for n == sample_size(), else n.
  long runs_key(std::size_t n) const;

  long hits() const { return hits_.load(); }      // answered from the archive
  long misses() const { return misses_.load(); }  // evaluated by the wrapped problem and stored

 private:
  Problem& inner_;
  EvaluationArchive& archive_;
  std::atomic<long> hits_{0};
  std::atomic<long> misses_{0};
};

}  // namespace abuopt::opt
