#pragma once
// Reading an evaluation archive afterwards (what OpenMDAO's CaseReader offers): the problems a file
// holds and the runs (commands) that wrote them, every evaluation in storing order, the best
// feasible design, its history, and filters on constraints, metrics and variables. The command
// line's `abuopt archive list|show|best|history` and the Python `abuopt.Archive` are built on it
// (docs/archive.md).
//
//   ArchiveReader r("results/cobyla/archive.sqlite");
//   const ArchiveProblem& p = r.problem("");              // the only problem, or a unique id prefix
//   auto best = r.best(p, {parse_archive_filter("pct_mi<=5")});
//
// Feasible: ok, every inequality g <= tolerance and every |h| <= tolerance (the optimisers'
// default constraint tolerance, 1e-6, unless given).
#include <optional>
#include <string>
#include <vector>

#include "abuopt/optimizer/evaluation_archive.hpp"

namespace abuopt::opt {

// "name OP value" with OP one of <=, <, >=, >, ==: name is a variable, an inequality constraint
// (its name, or g_<name>), an equality constraint (h_<name>), a metric, or "objective".
struct ArchiveFilter {
  enum class Op { Le, Lt, Ge, Gt, Eq };
  std::string name;
  Op op = Op::Le;
  double value = 0.0;
  std::string text;  // as given
};
// ConfigError naming `key` (the option or argument it came from) for text that is not a filter.
ArchiveFilter parse_archive_filter(const std::string& text, const std::string& key = "filter");

struct ArchiveProblem {
  EvaluationArchive::ProblemRecord record;
  std::vector<EvaluationArchive::Metadata> runs;  // one per command that opened it, oldest first
  std::vector<EvaluationArchive::Entry> evaluations;  // intact ones, in storing order
  long damaged_rows_left_out = 0;
};

// One point of the history: the evaluation and the best feasible objective up to and including it.
struct ArchiveHistoryPoint {
  const EvaluationArchive::Entry* entry = nullptr;
  bool feasible = false;
  double max_violation = 0.0;      // max(0, g..., |h|...); inf for a failed evaluation
  double best_feasible = 0.0;      // NaN until the first feasible evaluation
};

class ArchiveReader {
 public:
  // Reads the whole file (ConfigError when it does not exist, is damaged or has another schema version).
  explicit ArchiveReader(const std::string& path);

  const std::string& path() const { return path_; }
  const std::vector<ArchiveProblem>& problems() const { return problems_; }
  // The problem whose id is `id_or_prefix` or starts with it; "" picks the only problem. ConfigError
  // (naming `key`) when none or several match, listing the ids.
  const ArchiveProblem& problem(const std::string& id_or_prefix, const std::string& key = "problem") const;

  double tolerance() const { return tolerance_; }
  void set_tolerance(double t) { tolerance_ = t; }

  bool feasible(const ArchiveProblem& p, const EvaluationArchive::Entry& e) const;
  static double max_violation(const EvaluationArchive::Entry& e);
  // Whether `e` passes every filter (a filter on a name the evaluation lacks fails it). ConfigError
  // when a filter names nothing the problem has (with "did you mean").
  static bool passes(const ArchiveProblem& p, const EvaluationArchive::Entry& e, const std::vector<ArchiveFilter>& f);
  // The value a filter name refers to, NaN when this evaluation lacks it.
  static double value_of(const ArchiveProblem& p, const EvaluationArchive::Entry& e, const std::string& name);
  // Throws ConfigError for a filter whose name the problem does not have.
  static void check_filters(const ArchiveProblem& p, const std::vector<ArchiveFilter>& f);

  // The feasible evaluation with the lowest objective among those passing `filters` (ties: the first
  // stored); nullptr when none.
  const EvaluationArchive::Entry* best(const ArchiveProblem& p, const std::vector<ArchiveFilter>& filters = {}) const;
  // The evaluations passing `filters`, in storing order, with the best feasible objective so far.
  std::vector<ArchiveHistoryPoint> history(const ArchiveProblem& p, const std::vector<ArchiveFilter>& filters = {}) const;
  // The evaluation with archive row id `id`; nullptr when the problem has none.
  static const EvaluationArchive::Entry* find(const ArchiveProblem& p, long id);

 private:
  std::string path_;
  std::vector<ArchiveProblem> problems_;
  double tolerance_ = 1e-6;
};

}  // namespace abuopt::opt
