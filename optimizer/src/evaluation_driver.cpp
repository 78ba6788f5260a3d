#include "evaluation_driver.hpp"

#include "abuopt/common/output_file.hpp"
#include "abuopt/common/stop.hpp"

#include <algorithm>
#include <csignal>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
#include <stdexcept>

namespace abuopt::opt::detail {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
}

std::atomic<bool>& interrupt_flag() noexcept {
  static std::atomic<bool> flag{false};
  return flag;
}

namespace {
extern "C" void abuopt_sigint_handler(int) { abuopt::opt::detail::interrupt_flag().store(true); }

std::mutex& sigint_mutex() {
  static std::mutex m;
  return m;
}
int sigint_users = 0;                 // guarded by sigint_mutex()
struct sigaction sigint_previous {};  // the handler before the first guard
}  // namespace

SigintGuard::SigintGuard(bool enable) : enabled_(enable && !abuopt::stop_handlers_installed()) {
  // the program's own handlers (abuopt/common/stop.hpp, app/main.cpp) already stop the run
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(sigint_mutex());
  if (sigint_users++ == 0) {
    struct sigaction sa {};
    sa.sa_handler = abuopt_sigint_handler;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0;
    sigaction(SIGINT, &sa, &sigint_previous);
  }
}

SigintGuard::~SigintGuard() {
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(sigint_mutex());
  if (--sigint_users == 0) sigaction(SIGINT, &sigint_previous, nullptr);
}

EvaluationDriver::EvaluationDriver(Problem& problem, const OptimizerOptions& options,
                                   const EvaluationCallback& callback)
    : problem_(problem),
      options_(options),
      callback_(callback),
      variables_(problem.variables()),
      n_ineq_(problem.inequality_names().size()),
      n_eq_(problem.equality_names().size()),
      start_(std::chrono::steady_clock::now()) {
  default_sample_size_ = sample_size_ = problem.sample_size();
  scheduler_ = options.scheduler ? options.scheduler : std::make_shared<ThreadScheduler>(options.evaluation_threads);
  for (const Variable& v : variables_) {
    lower_y_.push_back(v.lower / v.scale);
    upper_y_.push_back(v.upper / v.scale);
  }
  const double eps = std::numeric_limits<double>::epsilon();
  fd_step_ = options.fd_relative_step > 0 ? options.fd_relative_step
             : options.finite_difference == FiniteDifference::Central ? std::cbrt(eps)
                                                                        : std::sqrt(eps);
}

void EvaluationDriver::set_sample_size(std::size_t n) {
  if (n == 0) n = default_sample_size_;
  if (n != default_sample_size_ && (n < 1 || n > problem_.max_sample_size()))
    throw std::invalid_argument("EvaluationDriver::set_sample_size: " + std::to_string(n) + " is outside [1, " +
                                std::to_string(problem_.max_sample_size()) + "] for problem '" + problem_.name() + "'");
  sample_size_ = n;
}

std::vector<double> EvaluationDriver::to_scaled(const std::vector<double>& x) const {
  return to_unit_scale(variables_, x);
}

double EvaluationDriver::elapsed_s() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void EvaluationDriver::stop(TerminationReason reason, std::string message) {
  if (stop_reason_) return;  // the first reason wins
  stop_reason_ = reason;
  stop_message_ = std::move(message);
}

bool EvaluationDriver::check_limits() {
  if (stop_reason_) return true;
  if (interrupt_flag().load() || abuopt::stop_requested()) {
    stop(TerminationReason::Interrupted, "interrupted (SIGINT or request_stop) after " +
                                             std::to_string(evaluations_) + " evaluations");
  } else if (evaluations_ >= options_.max_evaluations) {
    stop(TerminationReason::MaxEvaluations,
         "evaluation budget of " + std::to_string(options_.max_evaluations) + " used up");
  } else if (options_.max_time_s > 0 && elapsed_s() >= options_.max_time_s) {
    stop(TerminationReason::MaxTime, "time limit of " + format_number(options_.max_time_s) + " s reached");
  }
  return stop_reason_.has_value();
}

std::vector<double> EvaluationDriver::clip(const double* y, bool& clipped) const {
  const std::size_t n = variables_.size();
  std::vector<double> x(n);
  clipped = false;
  for (std::size_t i = 0; i < n; ++i) {
    const Variable& v = variables_[i];
    double xi = std::isnan(y[i]) ? 0.5 * (v.lower + v.upper) : y[i] * v.scale;
    const double slack = 1e-12 * (v.upper - v.lower);
    if (xi < v.lower) {
      clipped |= xi < v.lower - slack || std::isnan(y[i]);
      xi = v.lower;
    } else if (xi > v.upper) {
      clipped |= xi > v.upper + slack || std::isnan(y[i]);
      xi = v.upper;
    } else if (std::isnan(y[i])) {
      clipped = true;
    }
    x[i] = xi;
  }
  return x;
}

const EvaluatedPoint* EvaluationDriver::evaluate(const double* y, bool for_gradient) {
  const std::size_t n = variables_.size();
  return evaluate_batch({std::vector<double>(y, y + n)}, for_gradient).front();
}

std::vector<const EvaluatedPoint*> EvaluationDriver::evaluate_batch(const std::vector<std::vector<double>>& ys,
                                                                    bool for_gradient) {
  // ---- plan, in input order: repeats, new points, and how many of those the budget admits ----
  enum class Kind { Repeat, New, Refused };
  struct Item {
    Kind kind = Kind::Refused;
    std::vector<double> x;
    bool clipped = false;
    std::size_t slot = 0;  // New: index into `fresh`
  };
  std::vector<Item> items(ys.size());
  std::vector<std::vector<double>> fresh;
  std::map<std::vector<double>, std::size_t> in_batch;  // x -> slot of its first occurrence
  const std::size_t n_samples = sample_size_;
  const bool own_size = n_samples == default_sample_size_;  // evaluate() as without sampling
  bool refused = check_limits();
  for (std::size_t i = 0; i < ys.size(); ++i) {
    if (ys[i].size() != variables_.size())
      throw std::invalid_argument("EvaluationDriver::evaluate_batch: a point of the wrong size");
    Item& it = items[i];
    it.x = clip(ys[i].data(), it.clipped);
    if (index_.count(Key(n_samples, it.x)) || in_batch.count(it.x)) {
      it.kind = Kind::Repeat;
      continue;
    }
    // what check_limits() would say before this evaluation (the time limit and an interrupt are
    // checked once per batch, above)
    if (refused || evaluations_ + static_cast<long>(fresh.size()) >= options_.max_evaluations) {
      refused = true;
      it.kind = Kind::Refused;
      continue;
    }
    it.kind = Kind::New;
    it.slot = fresh.size();
    in_batch.emplace(it.x, it.slot);
    fresh.push_back(it.x);
  }

  // ---- evaluate the new points (at once where the problem and the scheduler allow) ----
  std::vector<BatchEvaluation> computed;
  if (!fresh.empty()) {
    if (fresh.size() == 1) {  // one point: on this thread, as a plain evaluate()
      computed.resize(1);
      const auto t0 = std::chrono::steady_clock::now();
      try {
        computed[0].evaluation = own_size ? problem_.evaluate(fresh[0]) : problem_.evaluate_sampled(fresh[0], n_samples);
      } catch (...) {
        computed[0].error = std::current_exception();
      }
      computed[0].wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    } else {
      computed = own_size ? problem_.evaluate_batch(fresh, *scheduler_)
                          : problem_.evaluate_batch_sampled(fresh, n_samples, *scheduler_);
      if (computed.size() != fresh.size())
        throw std::logic_error("Problem::evaluate_batch returned " + std::to_string(computed.size()) +
                               " results for " + std::to_string(fresh.size()) + " points");
    }
  }

  // ---- record in input order, as one evaluation after another would have ----
  std::vector<const EvaluatedPoint*> out(ys.size(), nullptr);
  for (std::size_t i = 0; i < items.size(); ++i) {
    Item& it = items[i];
    if (auto found = index_.find(Key(n_samples, it.x)); found != index_.end()) {
      ++repeats_;
      out[i] = &points_[found->second];
      continue;
    }
    if (check_limits()) continue;  // stopped (by an earlier point of the batch, or a limit)
    if (it.kind != Kind::New) continue;  // cannot happen: refused points come after a limit
    out[i] = record(std::move(it.x), it.clipped, std::move(computed[it.slot]), for_gradient);
  }
  return out;
}

const EvaluatedPoint* EvaluationDriver::record(std::vector<double> x, bool clipped, BatchEvaluation b,
                                               bool for_gradient) {
  if (b.error) {
    // an evaluation stopped by the stop request (its Monte Carlo threw Interrupted between runs)
    // is not an evaluation: nothing is recorded, the run ends as interrupted
    try {
      std::rethrow_exception(b.error);
    } catch (const abuopt::Interrupted&) {
      stop(TerminationReason::Interrupted,
           "interrupted (SIGINT or request_stop) after " + std::to_string(evaluations_) + " evaluations");
      return nullptr;
    } catch (const abuopt::OutputError& e) {
      fatal_ = b.error;
      stop(TerminationReason::EvaluationError, e.what());
      return nullptr;
    } catch (...) {
    }
  }
  if (clipped) ++clipped_;
  EvaluatedPoint p;
  p.x = x;
  p.samples = sample_size_;
  bool threw = false;
  if (b.error) {
    threw = true;
    try {
      std::rethrow_exception(b.error);
    } catch (const std::exception& ex) {
      p.e = Evaluation::failed(std::string("evaluation threw: ") + ex.what());
    } catch (...) {
      p.e = Evaluation::failed("evaluation threw a non-standard exception");
    }
  } else {
    p.e = std::move(b.evaluation);
    try {
      check_evaluation_shape(n_ineq_, n_eq_, p.e);
    } catch (const std::exception& ex) {
      p.e = Evaluation::failed(std::string("evaluation threw: ") + ex.what());
      threw = true;
    }
  }
  const double wall = b.wall_time_s;
  if (!p.e.ok) p.e.objective = kInf;
  if (std::isnan(p.e.objective)) {
    p.e.ok = false;
    p.e.objective = kInf;
    if (p.e.message.empty()) p.e.message = "objective is NaN";
  }
  auto has_nan = [](const std::vector<double>& v) {
    for (double d : v)
      if (std::isnan(d)) return true;
    return false;
  };
  if (p.e.ok && (has_nan(p.e.inequality) || has_nan(p.e.equality))) {
    p.e.ok = false;
    p.e.objective = kInf;
    if (p.e.message.empty()) p.e.message = "a constraint value is NaN";
  }
  p.violation = max_constraint_violation(p.e);
  p.feasible = is_feasible(p.e, options_.constraint_tolerance);

  if (p.e.ok) {
    if (std::isfinite(p.e.objective)) max_finite_objective_ = std::max(max_finite_objective_, p.e.objective);
    for (double g : p.e.inequality)
      if (std::isfinite(g)) max_abs_constraint_ = std::max(max_abs_constraint_, std::fabs(g));
    for (double h : p.e.equality)
      if (std::isfinite(h)) max_abs_constraint_ = std::max(max_abs_constraint_, std::fabs(h));
  }
  ++evaluations_;
  samples_ += static_cast<long>(p.samples);
  if (p.e.from_archive) ++archive_hits_;
  if (!p.e.ok) ++failed_;
  if (for_gradient) ++gradient_evals_;

  points_.push_back(std::move(p));
  const std::size_t idx = points_.size() - 1;
  index_.emplace(Key(points_.back().samples, x), idx);
  const EvaluatedPoint& stored = points_.back();

  // best: feasible with lowest f; else the smallest violation among ok points; else anything.
  // Between feasible points of different sample sizes (adaptive sampling) the larger sample wins:
  // a value on few runs is the noisier estimate, and the result is the estimate on the most runs.
  auto better = [&](const EvaluatedPoint& a, const EvaluatedPoint& b) {
    if (a.feasible != b.feasible) return a.feasible;
    if (a.feasible && a.samples != b.samples) return a.samples > b.samples;
    if (a.feasible) return a.e.objective < b.e.objective;
    if (a.e.ok != b.e.ok) return a.e.ok;
    return a.violation < b.violation;
  };
  if (!best_ || better(stored, points_[*best_])) best_ = idx;

  EvaluationRecord rec;
  rec.index = evaluations_ - 1;
  rec.x = stored.x;
  rec.objective = stored.e.objective;
  rec.inequality = stored.e.inequality;
  rec.equality = stored.e.equality;
  rec.metrics = stored.e.metrics;
  rec.ok = stored.e.ok;
  rec.feasible = stored.feasible;
  rec.max_violation = stored.violation;
  rec.from_archive = stored.e.from_archive;
  rec.for_gradient = for_gradient;
  rec.wall_time_s = wall;
  rec.elapsed_s = elapsed_s();
  rec.message = stored.e.message;

  if (threw) stop(TerminationReason::EvaluationError, stored.e.message + " (at evaluation " +
                                                           std::to_string(rec.index) + ")");
  const EvaluatedPoint& best = points_[*best_];
  if (options_.target && best.feasible && best.e.objective <= *options_.target)
    stop(TerminationReason::TargetReached,
         "a feasible point reached f = " + format_number(best.e.objective) + " <= target " +
             format_number(*options_.target));
  if (callback_) {
    Progress progress{rec, evaluations_, archive_hits_, rec.elapsed_s, best.feasible,
                      best.feasible ? best.e.objective : kInf};
    try {
      if (!callback_(progress)) stop(TerminationReason::StoppedByCallback, "the callback asked to stop");
    } catch (const std::exception& ex) {
      stop(TerminationReason::StoppedByCallback, std::string("the callback threw: ") + ex.what());
    }
  }
  if (interrupt_flag().load() || abuopt::stop_requested())
    stop(TerminationReason::Interrupted,
         "interrupted (SIGINT or request_stop) after " + std::to_string(evaluations_) + " evaluations");
  if (options_.keep_history) history_.push_back(std::move(rec));
  return &stored;
}

double EvaluationDriver::failure_objective() const {
  if (!std::isfinite(max_finite_objective_)) return 1e10;
  return max_finite_objective_ + std::fabs(max_finite_objective_) + 1.0;
}

double EvaluationDriver::failure_constraint() const { return max_abs_constraint_ + 1.0; }

bool EvaluationDriver::derivatives(const double* y_in, const EvaluatedPoint& base, double* grad_f, double* jac_ineq,
                                   double* jac_eq) {
  const std::size_t n = variables_.size();
  auto zero = [&](std::size_t j) {
    if (grad_f) grad_f[j] = 0.0;
    for (std::size_t i = 0; jac_ineq && i < n_ineq_; ++i) jac_ineq[i * n + j] = 0.0;
    for (std::size_t i = 0; jac_eq && i < n_eq_; ++i) jac_eq[i * n + j] = 0.0;
  };
  if (!base.e.ok) {
    for (std::size_t j = 0; j < n; ++j) zero(j);
    return !stopped();
  }
  // the base point clipped into the (scaled) bounds, as it was evaluated
  std::vector<double> yc(y_in, y_in + n);
  for (std::size_t j = 0; j < n; ++j) yc[j] = std::min(std::max(yc[j], lower_y_[j]), upper_y_[j]);
  const double* y = yc.data();
  std::vector<double> yp(yc);
  // Evaluates the neighbour y + delta * e_j (delta may be negative); nullptr if stopped.
  auto neighbour = [&](std::size_t j, double delta, double& actual) -> const EvaluatedPoint* {
    yp[j] = y[j] + delta;
    actual = yp[j] - y[j];  // the step actually taken in floating point
    const EvaluatedPoint* p = evaluate(yp.data(), true);
    yp[j] = y[j];
    return p;
  };
  auto set = [&](std::size_t j, const EvaluatedPoint& a, const EvaluatedPoint& b, double dy) {
    // derivative = (a - b) / dy
    if (grad_f) grad_f[j] = (a.e.objective - b.e.objective) / dy;
    for (std::size_t i = 0; jac_ineq && i < n_ineq_; ++i)
      jac_ineq[i * n + j] = (a.e.inequality[i] - b.e.inequality[i]) / dy;
    for (std::size_t i = 0; jac_eq && i < n_eq_; ++i) jac_eq[i * n + j] = (a.e.equality[i] - b.e.equality[i]) / dy;
  };
  // The first neighbour(s) of every coordinate are independent: one batch (evaluate_batch keeps
  // the order j = 0, 1, ... of one-at-a-time evaluation). Only the fallback of a one-sided
  // difference whose neighbour failed (the other side) is evaluated afterwards, one at a time.
  struct Plan {
    bool central = false;
    double delta = 0;          // one-sided step (0: the box is degenerate: zero derivative)
    std::size_t first = 0;     // index of the first neighbour in the batch
    double up = 0, down = 0;   // the steps actually taken in floating point
  };
  std::vector<Plan> plan(n);
  std::vector<std::vector<double>> batch;
  auto add = [&](std::size_t j, double delta) {
    yp[j] = y[j] + delta;
    const double actual = yp[j] - y[j];
    batch.push_back(yp);
    yp[j] = y[j];
    return actual;
  };
  for (std::size_t j = 0; j < n; ++j) {
    Plan& pl = plan[j];
    const double h = fd_step_ * std::max(std::fabs(y[j]), 1.0);
    const bool room_up = y[j] + h <= upper_y_[j];
    const bool room_down = y[j] - h >= lower_y_[j];
    pl.first = batch.size();
    if (options_.finite_difference == FiniteDifference::Central && room_up && room_down) {
      pl.central = true;
      pl.up = add(j, h);
      pl.down = add(j, -h);
      continue;
    }
    // one-sided: forward if there is room above, else backward
    double delta = h;
    if (!room_up && room_down) delta = -h;
    if (!room_up && !room_down)  // a box narrower than the step: go to the farther bound
      delta = upper_y_[j] - y[j] >= y[j] - lower_y_[j] ? upper_y_[j] - y[j] : lower_y_[j] - y[j];
    pl.delta = delta;
    if (delta != 0.0) pl.up = add(j, delta);
  }
  const std::vector<const EvaluatedPoint*> done = evaluate_batch(batch, true);
  for (const EvaluatedPoint* p : done)
    if (!p) return false;

  for (std::size_t j = 0; j < n; ++j) {
    const Plan& pl = plan[j];
    if (pl.central) {
      const EvaluatedPoint* a = done[pl.first];
      const EvaluatedPoint* b = done[pl.first + 1];
      if (a->e.ok && b->e.ok) {
        set(j, *a, *b, pl.up - pl.down);
        continue;
      }
      if (a->e.ok) set(j, *a, base, pl.up);
      else if (b->e.ok) set(j, base, *b, -pl.down);
      else zero(j);
      continue;
    }
    const double delta = pl.delta;
    if (delta == 0.0) {
      zero(j);
      continue;
    }
    double actual = pl.up;
    const EvaluatedPoint* a = done[pl.first];
    if (a->e.ok && actual != 0.0) {
      if (actual > 0) set(j, *a, base, actual);
      else set(j, base, *a, -actual);
      continue;
    }
    // the neighbour failed: try the other side
    const double other = -delta;
    if ((other > 0 && y[j] + other <= upper_y_[j]) || (other < 0 && y[j] + other >= lower_y_[j])) {
      const EvaluatedPoint* b = neighbour(j, other, actual);
      if (!b) return false;
      if (b->e.ok && actual != 0.0) {
        if (actual > 0) set(j, *b, base, actual);
        else set(j, base, *b, -actual);
        continue;
      }
    }
    zero(j);
  }
  return !stopped();
}

void EvaluationDriver::fill(OptimizationResult& r) const {
  r.evaluations = evaluations_;
  r.samples = samples_;
  r.archive_hits = archive_hits_;
  r.failed_evaluations = failed_;
  r.gradient_evaluations = gradient_evals_;
  r.repeated_requests = repeats_;
  r.clipped_requests = clipped_;
  r.wall_time_s = elapsed_s();
  r.constraint_tolerance = options_.constraint_tolerance;
  if (best_) {
    const EvaluatedPoint& b = points_[*best_];
    r.x = b.x;
    r.objective = b.e.objective;
    r.inequality = b.e.inequality;
    r.equality = b.e.equality;
    r.metrics = b.e.metrics;
    r.feasible = b.feasible;
    r.max_violation = b.violation;
  }
  r.history = history_;
}

}  // namespace abuopt::opt::detail
