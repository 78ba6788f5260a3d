#pragma once
// Two optimisers one after the other on one budget: a global one that explores (e.g. DIRECT_L),
// then a local one from the best point it found (e.g. COBYLA), the classic "DIRECT then COBYLA".
//
//   TwoStageOptions t;
//   t.first.algorithm = "DIRECT_L";
//   t.then.algorithm = "COBYLA";
//   t.first_fraction = 0.3;                     // 30 % of max_evaluations for DIRECT
//   OptimizationResult r = minimize_two_stage(problem, t, 200, x0);
//
// The first stage gets floor(first_fraction * max_evaluations) evaluations (at least 1). When its
// algorithm handles bounds only and the problem has constraints, it runs on the exact-L1 penalty
// form f + w (sum max(0, g) + sum |h|) (penalty_problem.hpp, w = penalty_weight); the values it saw
// are still recorded as the problem's own (objective and constraints, feasibility judged with the
// first stage's constraint_tolerance). The second stage starts from the first stage's best point
// (of the form it optimised) with the rest of the budget (its first evaluation repeats that point:
// the stages keep separate caches). The result is one run: both histories in order (indices
// continued), counts and simulations added, reason and message of the second stage, the best point
// over both (feasible first, then lowest objective; else the smallest violation), algorithm
// "FIRST->THEN".
#include <vector>

#include "abuopt/optimizer/minimize.hpp"

namespace abuopt::opt {

struct TwoStageOptions {
  OptimizerOptions first;          // max_evaluations is set from the total
  OptimizerOptions then;           // likewise
  double first_fraction = 0.3;     // in (0, 1)
  double penalty_weight = 100.0;   // > 0; first stage on a constrained problem with a bound-only algorithm
};

// Throws abuopt::ConfigError for invalid settings (as minimize() does, and first_fraction outside
// (0, 1), penalty_weight not > 0, max_evaluations < 2).
OptimizationResult minimize_two_stage(Problem& problem, const TwoStageOptions& options, long max_evaluations,
                                      std::vector<double> x0 = {});

}  // namespace abuopt::opt
