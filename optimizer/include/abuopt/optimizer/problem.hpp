#pragma once
// The problem contract every optimiser in abuopt::opt works on (the idea of pagmo's `problem`:
// "fitness + bounds + counts of constraints", with benchmark problems carrying best_known()).
//
//   minimise   f(x)
//   subject to g_i(x) <= 0      (inequality constraints, named)
//              h_j(x)  = 0      (equality constraints, named)
//              lower_k <= x_k <= upper_k   (every design variable is bounded and named)
//
// An evaluation may fail (a simulation that did not finish, a model outside its range): it then
// returns ok = false and is treated by every optimiser as a point with objective +inf that is not
// feasible. It never ends a run. An exception thrown from evaluate() is different: it is taken as
// a defect and ends the run with reason `evaluation_error` (the best point so far is still
// returned).
//
// The optimiser layer knows nothing of ABUs: metrics are plain named numbers.
#include <cstddef>
#include <exception>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace abuopt::opt {

class EvaluationScheduler;  // evaluation_scheduler.hpp

// One bounded design variable.
struct Variable {
  std::string name;
  double lower = 0.0;
  double upper = 1.0;
  // Typical magnitude of the variable (> 0). Optimisers work on x / scale, and finite-difference
  // steps are h * max(|x|, scale), so variables of very different size are treated alike.
  double scale = 1.0;
};

// What one evaluation of the problem returns.
struct Evaluation {
  double objective = 0.0;                 // minimised
  std::vector<double> inequality;         // g(x), feasible when <= 0; one per inequality name
  std::vector<double> equality;           // h(x), feasible when == 0; one per equality name
  std::map<std::string, double> metrics;  // any extra named outputs (for reports and archives)
  bool ok = true;                         // false: the evaluation failed (see `message`)
  std::string message;                    // why it failed, or a note
  bool from_archive = false;              // answered from an evaluation archive, not computed

  // A failed evaluation: objective +inf, no constraint values, the reason in `message`.
  static Evaluation failed(std::string why);
};

// One point of a batch (Problem::evaluate_batch): its evaluation, or the exception evaluate()
// threw (then `evaluation` is unset), and the wall time it took.
struct BatchEvaluation {
  Evaluation evaluation;
  std::exception_ptr error;
  double wall_time_s = 0.0;
};

// Best known solution of a benchmark problem.
struct BestKnown {
  std::vector<double> x;
  double objective = 0.0;
};

class Problem {
 public:
  virtual ~Problem() = default;

  virtual std::string name() const = 0;
  virtual std::vector<Variable> variables() const = 0;
  virtual std::vector<std::string> inequality_names() const { return {}; }
  virtual std::vector<std::string> equality_names() const { return {}; }

  // Evaluates the objective, the constraints and the metrics at x (x is inside the bounds and has
  // one entry per variable: every optimiser checks this before calling).
  virtual Evaluation evaluate(const std::vector<double>& x) = 0;

  // ---- Evaluation concurrency (evaluation_scheduler.hpp) ----
  // True when evaluate() may run on several threads at once (pagmo's thread_safety). Default
  // false: a batch is evaluated one point after another on the calling thread.
  virtual bool thread_safe() const { return false; }
  // evaluate(x) as one of `concurrent` evaluations running at once: a problem with threads of its
  // own (a Monte Carlo) uses about 1/concurrent of them. Same value as evaluate(x). Default:
  // evaluate(x).
  virtual Evaluation evaluate_shared(const std::vector<double>& x, std::size_t concurrent);
  // Evaluates independent points; out[i] belongs to xs[i] whatever ran where. Every point is
  // evaluated (an exception of one is stored in its slot, the others go on). Default: on
  // `scheduler` through evaluate_shared when thread_safe() and there is more than one point, else
  // evaluate() one after another.
  virtual std::vector<BatchEvaluation> evaluate_batch(const std::vector<std::vector<double>>& xs,
                                                      EvaluationScheduler& scheduler);

  // ---- Sample size (a Monte Carlo estimate per evaluation; docs/sao.md "Adaptive sample size") ----
  // The number of samples (Monte Carlo runs) evaluate(x) uses; 0: not a sampled problem (default).
  virtual std::size_t sample_size() const { return 0; }
  // Largest n evaluate_sampled() accepts: the length of the problem's one fixed sequence of
  // samples; 0 (default): the sample size cannot be chosen.
  virtual std::size_t max_sample_size() const { return 0; }
  // evaluate(x) on the first n samples of that fixed sequence (1 <= n <= max_sample_size()), as
  // one of `concurrent` evaluations running at once (see evaluate_shared). Common random numbers:
  // the value at 2n shares its first n samples with the value at n, and n = sample_size() gives
  // exactly evaluate(x). Default: n == sample_size() is evaluate_shared(x, concurrent), any other n
  // is std::invalid_argument.
  virtual Evaluation evaluate_sampled(const std::vector<double>& x, std::size_t n, std::size_t concurrent = 1);
  // evaluate_batch at sample size n: the same scheduling, each point by evaluate_sampled. Default:
  // n == sample_size() is evaluate_batch(xs, scheduler).
  virtual std::vector<BatchEvaluation> evaluate_batch_sampled(const std::vector<std::vector<double>>& xs,
                                                              std::size_t n, EvaluationScheduler& scheduler);

  // ---- Noise (pagmo's problem::is_stochastic) ----
  // True when evaluate(x) is an estimate with noise in it (a Monte Carlo mean, a noisy
  // measurement), even if the same x gives the same value (common random numbers). SAO's global
  // phase and restarts are on by default for such problems (docs/sao.md, "Global phase"). Default:
  // a sampled problem (sample_size() > 0) is stochastic, any other is not.
  virtual bool stochastic() const { return sample_size() > 0; }

  // Starting point when the caller gives none; default: the middle of the bounds.
  virtual std::vector<double> initial_point() const;

  // Best known solution, for benchmarks; empty for real problems.
  virtual std::optional<BestKnown> best_known() const { return std::nullopt; }

  std::size_t dimension() const { return variables().size(); }
};

// A problem made of functions (handy for tests and small studies).
class FunctionProblem : public Problem {
 public:
  using Function = std::function<Evaluation(const std::vector<double>&)>;
  FunctionProblem(std::string name, std::vector<Variable> variables, Function function,
                  std::vector<std::string> inequality_names = {},
                  std::vector<std::string> equality_names = {});
  std::string name() const override { return name_; }
  std::vector<Variable> variables() const override { return variables_; }
  std::vector<std::string> inequality_names() const override { return inequality_names_; }
  std::vector<std::string> equality_names() const override { return equality_names_; }
  Evaluation evaluate(const std::vector<double>& x) override { return function_(x); }
  std::vector<double> initial_point() const override;
  std::optional<BestKnown> best_known() const override { return best_known_; }
  bool thread_safe() const override { return thread_safe_; }

  FunctionProblem& set_initial_point(std::vector<double> x0);
  FunctionProblem& set_best_known(BestKnown best);
  // Declares the function safe to call from several threads at once (default: not).
  FunctionProblem& set_thread_safe(bool safe);

 private:
  std::string name_;
  std::vector<Variable> variables_;
  Function function_;
  std::vector<std::string> inequality_names_;
  std::vector<std::string> equality_names_;
  std::vector<double> initial_point_;
  std::optional<BestKnown> best_known_;
  bool thread_safe_ = false;
};

// ---- The central checks (all throw abuopt::ConfigError with both values in the message) ----

// The problem's own definition: at least one variable; names non-empty and unique; bounds finite
// with lower < upper ("variable x[0] (a): lower bound 3 is not below upper bound 1"); scale > 0.
void check_problem(const Problem& problem);

// Size, NaN and bounds of a design vector:
//   "<what>: the problem has 5 variables, the design vector has 4"
//   "<what>: x[2] (dt2) = 12 is above its upper bound 10"
//   "<what>: x[1] (dt1) = nan is not a number"
// `what` names the vector in messages (e.g. "starting point", "optimizer.x0").
void check_design_vector(const std::vector<Variable>& variables, const std::vector<double>& x,
                         const std::string& what = "design vector");
void check_design_vector(const Problem& problem, const std::vector<double>& x,
                         const std::string& what = "design vector");

// The shape of an evaluation against the problem's declared constraints ("the problem declares 2
// inequality constraints, the evaluation returned 1"); throws std::logic_error (a defect).
void check_evaluation_shape(std::size_t n_inequality, std::size_t n_equality, const Evaluation& e);

// x clipped into the bounds (entries that are NaN are left NaN).
std::vector<double> clip_to_bounds(const std::vector<Variable>& variables, std::vector<double> x);

// ---- Scaling helpers ----
// [lower, upper] <-> [0, 1]
std::vector<double> to_unit_box(const std::vector<Variable>& variables, const std::vector<double>& x);
std::vector<double> from_unit_box(const std::vector<Variable>& variables, const std::vector<double>& u);
// x <-> x / scale
std::vector<double> to_unit_scale(const std::vector<Variable>& variables, const std::vector<double>& x);
std::vector<double> from_unit_scale(const std::vector<Variable>& variables, const std::vector<double>& y);

// Largest constraint violation: max(0, max_i g_i, max_j |h_j|); +inf for a failed evaluation.
double max_constraint_violation(const Evaluation& e);
// ok, finite objective and violation <= tolerance.
bool is_feasible(const Evaluation& e, double constraint_tolerance);

// Shortest text that reads back as the same double ("0.1", "12", "1.0000000000000002").
std::string format_number(double v);

}  // namespace abuopt::opt
