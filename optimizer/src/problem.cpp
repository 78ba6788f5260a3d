#include "abuopt/optimizer/problem.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>

#include "abuopt/common/config_error.hpp"
#include "abuopt/optimizer/evaluation_scheduler.hpp"

namespace abuopt::opt {

std::string format_number(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  auto res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

Evaluation Evaluation::failed(std::string why) {
  Evaluation e;
  e.objective = std::numeric_limits<double>::infinity();
  e.ok = false;
  e.message = std::move(why);
  return e;
}

std::vector<double> Problem::initial_point() const {
  std::vector<double> x;
  for (const Variable& v : variables()) x.push_back(0.5 * (v.lower + v.upper));
  return x;
}

Evaluation Problem::evaluate_shared(const std::vector<double>& x, std::size_t) { return evaluate(x); }

Evaluation Problem::evaluate_sampled(const std::vector<double>& x, std::size_t n, std::size_t concurrent) {
  if (n != sample_size())
    throw std::invalid_argument("Problem::evaluate_sampled: problem '" + name() + "' is evaluated at " +
                                std::to_string(sample_size()) + " samples only, asked for " + std::to_string(n));
  return concurrent > 1 ? evaluate_shared(x, concurrent) : evaluate(x);
}

namespace {
// The scheduling of Problem::evaluate_batch: `one(x, share)` evaluates a point as one of `share`
// evaluations at once (share 1: alone, on the calling thread).
template <class One>
std::vector<BatchEvaluation> run_batch(const Problem& problem, const std::vector<std::vector<double>>& xs,
                                       EvaluationScheduler& scheduler, One one_point) {
  std::vector<BatchEvaluation> out(xs.size());
  const bool concurrent = problem.thread_safe() && xs.size() > 1 && scheduler.concurrency() > 1;
  const std::size_t share = concurrent ? std::min(xs.size(), scheduler.concurrency()) : 1;
  auto one = [&](std::size_t i) {
    const auto t0 = std::chrono::steady_clock::now();
    try {
      out[i].evaluation = one_point(xs[i], share);
    } catch (...) {
      out[i].error = std::current_exception();
    }
    out[i].wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  if (concurrent)
    scheduler.run(xs.size(), one);
  else
    for (std::size_t i = 0; i < xs.size(); ++i) one(i);
  return out;
}
}  // namespace

std::vector<BatchEvaluation> Problem::evaluate_batch(const std::vector<std::vector<double>>& xs,
                                                     EvaluationScheduler& scheduler) {
  return run_batch(*this, xs, scheduler, [this](const std::vector<double>& x, std::size_t share) {
    return share > 1 ? evaluate_shared(x, share) : evaluate(x);
  });
}

std::vector<BatchEvaluation> Problem::evaluate_batch_sampled(const std::vector<std::vector<double>>& xs,
                                                             std::size_t n, EvaluationScheduler& scheduler) {
  if (n == sample_size()) return evaluate_batch(xs, scheduler);
  return run_batch(*this, xs, scheduler, [this, n](const std::vector<double>& x, std::size_t share) {
    return evaluate_sampled(x, n, share);
  });
}

FunctionProblem::FunctionProblem(std::string name, std::vector<Variable> variables, Function function,
                                 std::vector<std::string> inequality_names,
                                 std::vector<std::string> equality_names)
    : name_(std::move(name)),
      variables_(std::move(variables)),
      function_(std::move(function)),
      inequality_names_(std::move(inequality_names)),
      equality_names_(std::move(equality_names)) {}

std::vector<double> FunctionProblem::initial_point() const {
  return initial_point_.empty() ? Problem::initial_point() : initial_point_;
}

FunctionProblem& FunctionProblem::set_initial_point(std::vector<double> x0) {
  initial_point_ = std::move(x0);
  return *this;
}

FunctionProblem& FunctionProblem::set_best_known(BestKnown best) {
  best_known_ = std::move(best);
  return *this;
}

FunctionProblem& FunctionProblem::set_thread_safe(bool safe) {
  thread_safe_ = safe;
  return *this;
}

namespace {
std::string entry(const std::vector<Variable>& vars, std::size_t i) {
  return "x[" + std::to_string(i) + "] (" + vars[i].name + ")";
}
}  // namespace

void check_problem(const Problem& problem) {
  const std::vector<Variable> vars = problem.variables();
  const std::string where = "problem '" + problem.name() + "'";
  if (vars.empty()) throw ConfigError(where + ": has no design variables");
  std::set<std::string> names;
  for (std::size_t i = 0; i < vars.size(); ++i) {
    const Variable& v = vars[i];
    if (v.name.empty()) throw ConfigError(where + ": variable x[" + std::to_string(i) + "] has no name");
    if (!names.insert(v.name).second)
      throw ConfigError(where + ": variable name '" + v.name + "' is used twice");
    if (!std::isfinite(v.lower) || !std::isfinite(v.upper))
      throw ConfigError(where + ": variable " + entry(vars, i) + ": bounds [" + format_number(v.lower) + ", " +
                        format_number(v.upper) + "] must be finite");
    if (!(v.lower < v.upper))
      throw ConfigError(where + ": variable " + entry(vars, i) + ": lower bound " + format_number(v.lower) +
                        " is not below upper bound " + format_number(v.upper));
    if (!(std::isfinite(v.scale) && v.scale > 0))
      throw ConfigError(where + ": variable " + entry(vars, i) + ": scale " + format_number(v.scale) +
                        " must be > 0");
  }
  std::set<std::string> cnames;
  for (const auto& list : {problem.inequality_names(), problem.equality_names()})
    for (const std::string& c : list) {
      if (c.empty()) throw ConfigError(where + ": a constraint has no name");
      if (!cnames.insert(c).second) throw ConfigError(where + ": constraint name '" + c + "' is used twice");
    }
}

void check_design_vector(const std::vector<Variable>& vars, const std::vector<double>& x, const std::string& what) {
  if (x.size() != vars.size())
    throw ConfigError(what + ": the problem has " + std::to_string(vars.size()) + " variables, the design vector has " +
                      std::to_string(x.size()));
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (std::isnan(x[i])) throw ConfigError(what + ": " + entry(vars, i) + " = nan is not a number");
    if (x[i] < vars[i].lower)
      throw ConfigError(what + ": " + entry(vars, i) + " = " + format_number(x[i]) + " is below its lower bound " +
                        format_number(vars[i].lower));
    if (x[i] > vars[i].upper)
      throw ConfigError(what + ": " + entry(vars, i) + " = " + format_number(x[i]) + " is above its upper bound " +
                        format_number(vars[i].upper));
  }
}

void check_design_vector(const Problem& problem, const std::vector<double>& x, const std::string& what) {
  check_design_vector(problem.variables(), x, what);
}

void check_evaluation_shape(std::size_t n_inequality, std::size_t n_equality, const Evaluation& e) {
  if (!e.ok) return;  // a failed evaluation need not carry constraint values
  if (e.inequality.size() != n_inequality)
    throw std::logic_error("the problem declares " + std::to_string(n_inequality) +
                           " inequality constraints, the evaluation returned " + std::to_string(e.inequality.size()));
  if (e.equality.size() != n_equality)
    throw std::logic_error("the problem declares " + std::to_string(n_equality) +
                           " equality constraints, the evaluation returned " + std::to_string(e.equality.size()));
}

std::vector<double> clip_to_bounds(const std::vector<Variable>& vars, std::vector<double> x) {
  for (std::size_t i = 0; i < x.size() && i < vars.size(); ++i) {
    if (x[i] < vars[i].lower) x[i] = vars[i].lower;
    if (x[i] > vars[i].upper) x[i] = vars[i].upper;
  }
  return x;
}

std::vector<double> to_unit_box(const std::vector<Variable>& vars, const std::vector<double>& x) {
  std::vector<double> u(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) u[i] = (x[i] - vars[i].lower) / (vars[i].upper - vars[i].lower);
  return u;
}

std::vector<double> from_unit_box(const std::vector<Variable>& vars, const std::vector<double>& u) {
  std::vector<double> x(u.size());
  for (std::size_t i = 0; i < u.size(); ++i) x[i] = vars[i].lower + u[i] * (vars[i].upper - vars[i].lower);
  return x;
}

std::vector<double> to_unit_scale(const std::vector<Variable>& vars, const std::vector<double>& x) {
  std::vector<double> y(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) y[i] = x[i] / vars[i].scale;
  return y;
}

std::vector<double> from_unit_scale(const std::vector<Variable>& vars, const std::vector<double>& y) {
  std::vector<double> x(y.size());
  for (std::size_t i = 0; i < y.size(); ++i) x[i] = y[i] * vars[i].scale;
  return x;
}

double max_constraint_violation(const Evaluation& e) {
  if (!e.ok) return std::numeric_limits<double>::infinity();
  double v = 0.0;
  for (double g : e.inequality) {
    if (std::isnan(g)) return std::numeric_limits<double>::infinity();
    v = std::max(v, g);
  }
  for (double h : e.equality) {
    if (std::isnan(h)) return std::numeric_limits<double>::infinity();
    v = std::max(v, std::fabs(h));
  }
  return v;
}

bool is_feasible(const Evaluation& e, double tol) {
  return e.ok && std::isfinite(e.objective) && max_constraint_violation(e) <= tol;
}

}  // namespace abuopt::opt
