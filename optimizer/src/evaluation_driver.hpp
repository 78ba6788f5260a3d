#pragma once
// Internal: the one wrapper through which every adapter evaluates the problem (see minimize.hpp).
// Adapters work in scaled coordinates y = x / scale; the driver maps back, clips into the bounds,
// caches, counts, enforces the budget and records the best point.
#include <atomic>
#include <chrono>
#include <deque>
#include <exception>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <utility>
#include <string>
#include <vector>

#include "abuopt/optimizer/evaluation_scheduler.hpp"
#include "abuopt/optimizer/minimize.hpp"

namespace abuopt::opt::detail {

// Set by the SIGINT handler and request_stop().
std::atomic<bool>& interrupt_flag() noexcept;

// Installs the SIGINT handler (it only sets interrupt_flag()) while at least one run that wants
// it is alive, and restores the previous handler when the last one ends. The one Ctrl-C mechanism
// of every algorithm minimize() runs (NLopt, Ipopt, SAO).
class SigintGuard {
 public:
  explicit SigintGuard(bool enable);
  ~SigintGuard();
  SigintGuard(const SigintGuard&) = delete;
  SigintGuard& operator=(const SigintGuard&) = delete;

 private:
  bool enabled_;
};

struct EvaluatedPoint {
  std::vector<double> x;  // real units, inside the bounds
  std::size_t samples = 0;  // the sample size it was evaluated at (0: not a sampled problem)
  Evaluation e;
  double violation = 0.0;
  bool feasible = false;
};

class EvaluationDriver {
 public:
  EvaluationDriver(Problem& problem, const OptimizerOptions& options, const EvaluationCallback& callback);

  std::size_t n() const { return variables_.size(); }
  std::size_t n_inequality() const { return n_ineq_; }
  std::size_t n_equality() const { return n_eq_; }
  const std::vector<double>& lower_scaled() const { return lower_y_; }
  const std::vector<double>& upper_scaled() const { return upper_y_; }
  std::vector<double> to_scaled(const std::vector<double>& x) const;
  // The point (real units) that evaluate(y) evaluates: y * scale clipped into the bounds.
  std::vector<double> evaluated_x(const std::vector<double>& y) const {
    bool clipped = false;
    return clip(y.data(), clipped);
  }

  // Evaluates at scaled point y (length n). Returns nullptr, without evaluating, once the run is
  // stopped (budget, time, interrupt, callback, error). The pointer stays valid for the run.
  const EvaluatedPoint* evaluate(const double* y, bool for_gradient = false);

  // Evaluates independent scaled points at once (evaluation_scheduler.hpp); out[i] is what
  // evaluate(ys[i]) would have returned had the points been evaluated one after another in input
  // order: repeats are answered from memory, the budget admits the first new points only, the
  // records, counts, callback and stop checks follow input order, and everything after the point
  // at which the run stopped is nullptr (and not recorded). Only wall times depend on the
  // scheduler. Points evaluated after a stop (target, callback, exception) are discarded here;
  // an ArchivedProblem has stored them.
  std::vector<const EvaluatedPoint*> evaluate_batch(const std::vector<std::vector<double>>& ys,
                                                    bool for_gradient = false);

  // Finite-difference derivatives in scaled coordinates at y, whose evaluation is `base`:
  // grad_f (n), jac_ineq (n_inequality x n, row-major), jac_eq (n_equality x n); any may be null.
  // Returns false if the run stopped meanwhile (the outputs are then partial).
  bool derivatives(const double* y, const EvaluatedPoint& base, double* grad_f, double* jac_ineq, double* jac_eq);

  // Sample size of the evaluations from now on (problem.hpp evaluate_sampled; docs/sao.md
  // "Adaptive sample size"): 0 or the problem's own sample_size() evaluate as evaluate() does;
  // another n in [1, max_sample_size()] by evaluate_sampled(x, n) (std::invalid_argument
  // otherwise). A point is known per (x, sample size): the same x at another n is a new evaluation.
  void set_sample_size(std::size_t n);
  // The sample size evaluations use now: the problem's own sample_size() unless set.
  std::size_t sample_size() const { return sample_size_; }
  std::size_t max_sample_size() const { return problem_.max_sample_size(); }
  std::size_t default_sample_size() const { return default_sample_size_; }
  // Sum of the sample sizes of the evaluations counted so far (Monte Carlo runs).
  long samples() const { return samples_; }

  bool stopped() const { return stop_reason_.has_value(); }
  // An evaluation that could not store its result (OutputError: the archive cannot be written)
  // ends the run; minimize() rethrows it after the result is filled (exit status 4, not 3).
  std::exception_ptr fatal_error() const { return fatal_; }
  std::optional<TerminationReason> stop_reason() const { return stop_reason_; }
  const std::string& stop_message() const { return stop_message_; }
  void stop(TerminationReason reason, std::string message);

  long evaluations() const { return evaluations_; }

  // What an optimiser is told for a failed evaluation (the result and history keep +inf):
  // model-based methods (COBYLA, BOBYQA, ...) break on inf, so they get a finite penalty,
  // the largest finite objective seen so far plus its magnitude plus 1 (1e10 before any), and
  // for each constraint the largest |constraint value| seen so far plus 1 (violated).
  double failure_objective() const;
  double failure_constraint() const;
  double elapsed_s() const;

  // Fills the counts, best point and history of `r` (reason and message are the caller's).
  void fill(OptimizationResult& r) const;

 private:
  bool check_limits();  // sets the stop reason when a limit is reached; true if stopped
  // y (scaled) -> x (real units) clipped into the bounds; `clipped` when it moved.
  std::vector<double> clip(const double* y, bool& clipped) const;
  // Counts and records a computed point (the bookkeeping of evaluate()).
  const EvaluatedPoint* record(std::vector<double> x, bool clipped, BatchEvaluation b, bool for_gradient);

  Problem& problem_;
  const OptimizerOptions& options_;
  const EvaluationCallback& callback_;
  std::vector<Variable> variables_;
  std::size_t n_ineq_ = 0, n_eq_ = 0;
  std::vector<double> lower_y_, upper_y_;
  double fd_step_;
  std::shared_ptr<EvaluationScheduler> scheduler_;
  std::chrono::steady_clock::time_point start_;

  std::deque<EvaluatedPoint> points_;
  using Key = std::pair<std::size_t, std::vector<double>>;  // (sample size, x in real units)
  std::map<Key, std::size_t> index_;                          // -> points_
  std::size_t default_sample_size_ = 0, sample_size_ = 0;
  long samples_ = 0;
  std::optional<std::size_t> best_;
  std::vector<EvaluationRecord> history_;

  double max_finite_objective_ = -std::numeric_limits<double>::infinity();
  double max_abs_constraint_ = 0.0;
  long evaluations_ = 0, archive_hits_ = 0, failed_ = 0, gradient_evals_ = 0, repeats_ = 0, clipped_ = 0;
  std::optional<TerminationReason> stop_reason_;
  std::exception_ptr fatal_;
  std::string stop_message_;
};

}  // namespace abuopt::opt::detail
