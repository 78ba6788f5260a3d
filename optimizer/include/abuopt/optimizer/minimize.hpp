#pragma once
// One entry point for every optimiser:
//
//   abuopt::opt::OptimizerOptions o;  o.algorithm = "slsqp";
//   abuopt::opt::OptimizationResult r = abuopt::opt::minimize(problem, o);
//   std::cout << r.full_report();
//
// Every adapter (NLopt, Ipopt) evaluates the problem through one wrapper that
//   * clips each requested point into the bounds (no evaluation is ever outside them),
//   * answers a point already evaluated in this run from memory,
//   * enforces max_evaluations and max_time_s itself (no evaluation beyond the budget),
//   * turns an exception thrown by evaluate() into the reason `evaluation_error`,
//   * checks the SIGINT flag and the callback after each evaluation,
//   * records the history and the best feasible point,
//   * computes finite-difference gradients (forward or central, step h * max(|x_i|, scale_i),
//     one-sided at a bound).
// so the best point so far is returned whatever stops the run.
#include <functional>
#include <vector>

#include "abuopt/optimizer/algorithms.hpp"
#include "abuopt/optimizer/optimization_result.hpp"
#include "abuopt/optimizer/optimizer_options.hpp"
#include "abuopt/optimizer/problem.hpp"

namespace abuopt::opt {

// What the per-evaluation callback sees.
struct Progress {
  const EvaluationRecord& last;  // the evaluation just made
  long evaluations;              // so far, including archive hits
  long archive_hits;
  double elapsed_s;
  bool have_feasible;            // a feasible point has been found
  double best_objective;         // its objective (+inf if none)
};
// Called after every evaluation; return false to stop the run (reason stopped_by_callback).
using EvaluationCallback = std::function<bool(const Progress&)>;

// Minimises `problem` from x0 (empty: problem.initial_point()).
// Throws abuopt::ConfigError before any evaluation for invalid options, an invalid problem
// (bounds reversed, ...), a starting point of the wrong size / outside the bounds / NaN, an
// unknown algorithm, or an algorithm that cannot handle the problem's constraints (global
// bound-only algorithms; local bound-only algorithms are wrapped in AUGLAG instead).
// Once evaluations start it never throws: everything else is a TerminationReason.
OptimizationResult minimize(Problem& problem, const OptimizerOptions& options, std::vector<double> x0 = {},
                            const EvaluationCallback& callback = {});

// Asks the running minimize() calls to stop after their current evaluation, with reason
// `interrupted` (what the SIGINT handler does). Async-signal-safe.
void request_stop() noexcept;

}  // namespace abuopt::opt
