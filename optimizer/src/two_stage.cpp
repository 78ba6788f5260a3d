// Two optimisers on one budget (two_stage.hpp): the first explores, the second refines.
#include "abuopt/optimizer/two_stage.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>

#include "abuopt/common/config_error.hpp"
#include "abuopt/optimizer/algorithms.hpp"
#include "abuopt/optimizer/penalty_problem.hpp"

namespace abuopt::opt {

namespace {

// The problem as the first stage sees it (its penalty form, or itself), recording every
// evaluation of the problem itself in order, so that the first stage's history can be told in the
// problem's own values.
class RecordingProblem : public Problem {
 public:
  RecordingProblem(Problem& inner, std::optional<double> penalty) : inner_(inner) {
    if (penalty) penalty_ = std::make_unique<PenaltyProblem>(inner, *penalty);
  }
  std::string name() const override { return inner_.name(); }
  std::vector<Variable> variables() const override { return inner_.variables(); }
  std::vector<std::string> inequality_names() const override {
    return penalty_ ? std::vector<std::string>{} : inner_.inequality_names();
  }
  std::vector<std::string> equality_names() const override {
    return penalty_ ? std::vector<std::string>{} : inner_.equality_names();
  }
  std::vector<double> initial_point() const override { return inner_.initial_point(); }
  std::size_t sample_size() const override { return inner_.sample_size(); }
  bool stochastic() const override { return inner_.stochastic(); }
  Evaluation evaluate(const std::vector<double>& x) override {
    Evaluation e;
    try {
      e = inner_.evaluate(x);
    } catch (const std::exception& ex) {
      log(x, Evaluation::failed(std::string("evaluation threw: ") + ex.what()));
      throw;
    }
    log(x, e);
    return penalty_ ? penalty_->penalise(std::move(e)) : e;
  }
  std::vector<std::pair<std::vector<double>, Evaluation>> take_log() { return std::move(log_); }

 private:
  void log(const std::vector<double>& x, Evaluation e) {
    std::lock_guard<std::mutex> lock(mutex_);
    log_.emplace_back(x, std::move(e));
  }
  Problem& inner_;
  std::unique_ptr<PenaltyProblem> penalty_;
  std::mutex mutex_;
  std::vector<std::pair<std::vector<double>, Evaluation>> log_;
};

}  // namespace

OptimizationResult minimize_two_stage(Problem& problem, const TwoStageOptions& t, long max_evaluations,
                                      std::vector<double> x0) {
  if (!(t.first_fraction > 0 && t.first_fraction < 1))
    throw ConfigError("first_fraction", format_number(t.first_fraction), "must be in (0, 1)");
  if (!(std::isfinite(t.penalty_weight) && t.penalty_weight > 0))
    throw ConfigError("penalty_weight", format_number(t.penalty_weight), "must be > 0");
  if (max_evaluations < 2)
    throw ConfigError("max_evaluations", std::to_string(max_evaluations), "must be >= 2 for two stages");
  const AlgorithmInfo& first = find_algorithm(t.first.algorithm, "optimizer.algorithm");
  const bool penalise = (!problem.inequality_names().empty() && !first.inequality_constraints) ||
                        (!problem.equality_names().empty() && !first.equality_constraints);
  const long first_budget = std::max(1L, static_cast<long>(std::floor(t.first_fraction * static_cast<double>(max_evaluations))));

  RecordingProblem recorder(problem, penalise ? std::optional<double>(t.penalty_weight) : std::nullopt);
  OptimizerOptions o1 = t.first;
  o1.max_evaluations = first_budget;
  o1.keep_history = true;
  const OptimizationResult r1 = minimize(recorder, o1, x0);
  const auto log = recorder.take_log();

  OptimizerOptions o2 = t.then;
  o2.max_evaluations = std::max(1L, max_evaluations - r1.evaluations);
  o2.keep_history = true;
  OptimizationResult r = minimize(problem, o2, r1.x.empty() ? x0 : r1.x);

  // the first stage's history in the problem's own values, then the second's, indices continued
  std::vector<EvaluationRecord> history;
  for (std::size_t i = 0; i < r1.history.size(); ++i) {
    EvaluationRecord h = r1.history[i];
    if (i < log.size()) {
      const Evaluation& e = log[i].second;
      h.x = log[i].first;
      h.objective = e.ok ? e.objective : std::numeric_limits<double>::infinity();
      h.inequality = e.inequality;
      h.equality = e.equality;
      h.metrics = e.metrics;
      h.ok = e.ok;
      h.max_violation = max_constraint_violation(e);
      h.feasible = is_feasible(e, o1.constraint_tolerance);
      h.message = e.message;
    }
    history.push_back(std::move(h));
  }
  const long offset = static_cast<long>(history.size());
  for (EvaluationRecord h : r.history) {
    h.index += offset;
    history.push_back(std::move(h));
  }
  r.evaluations += r1.evaluations;
  r.archive_hits += r1.archive_hits;
  r.failed_evaluations += r1.failed_evaluations;
  r.gradient_evaluations += r1.gradient_evaluations;
  r.samples += r1.samples;
  r.iterations += r1.iterations;
  r.wall_time_s += r1.wall_time_s;
  r.algorithm = r1.algorithm + "->" + r.algorithm;
  r.message = "first stage (" + r1.algorithm + ", " + std::to_string(r1.evaluations) + " evaluations" +
              (penalise ? ", penalty form" : "") + "): " + r1.message + "; second stage: " + r.message;
  // the best point over both stages
  const EvaluationRecord* best = nullptr;
  auto better = [](const EvaluationRecord& a, const EvaluationRecord& b) {
    if (a.feasible != b.feasible) return a.feasible;
    if (a.feasible) return a.objective < b.objective;
    if (a.ok != b.ok) return a.ok;
    return a.max_violation < b.max_violation;
  };
  for (const EvaluationRecord& h : history)
    if (!best || better(h, *best)) best = &h;
  if (best) {
    r.x = best->x;
    r.objective = best->objective;
    r.inequality = best->inequality;
    r.equality = best->equality;
    r.metrics = best->metrics;
    r.feasible = best->feasible;
    r.max_violation = best->max_violation;
  }
  r.history = std::move(history);
  return r;
}

}  // namespace abuopt::opt
