#pragma once
// Out-of-sample check of an optimised startup profile (docs/optimize.md): the best design and the
// report's final profile, each on the optimiser's own Monte Carlo sample (in-sample) and on the
// fresh, larger set of initial conditions of the settings' `validation` section (out-of-sample).
// An optimiser picks the design that did best on its sample, so its in-sample figure is biased
// low; the out-of-sample rows are what a user should compare.
#include <string>
#include <vector>

#include "abuopt/core/profile.hpp"
#include "abuopt/optimizer/optimization_result.hpp"
#include "abuopt/optimizer/penalty_problem.hpp"
#include "abuopt/problems/startup_profile_problem.hpp"

namespace abuopt {

struct ComparisonRow {
  std::string label;  // "best, out-of-sample (1024)"
  opt::Evaluation e;
};

struct OutOfSampleComparison {
  StartupProfile best;    // the optimiser's best design
  StartupProfile report;  // the report's final profile
  // best in-sample, best out-of-sample, report in-sample, report out-of-sample (in this order)
  std::vector<ComparisonRow> rows;
};

// Evaluates the four rows (the best design's in-sample row is taken from `r`, not recomputed).
// `r` must have a best point (r.x not empty). When the optimiser saw the penalty form of the
// problem (`penalty` not null), the recomputed rows are penalised the same way, so that every
// row's objective is the one the optimiser minimised.
OutOfSampleComparison compare_out_of_sample(const problems::StartupProfileProblem& problem,
                                            const opt::OptimizationResult& r,
                                            const opt::PenaltyProblem* penalty = nullptr);

// The rows as a fixed-width table for the terminal (objective, mean |I_r| and I_r,x, %MI, %LC,
// amplitude, startup time, failed runs).
std::string comparison_table(const std::vector<ComparisonRow>& rows);

// The best design against the report's profile, both out-of-sample, on each definition of the
// residual imbalance (mean |I_r|, mean I_r,x, %MI of each): an optimiser that improved one
// definition may have made the other worse, and a summary that names one would hide it.
struct OutOfSampleVerdict {
  std::string text;                // "  best vs report profile, out-of-sample: mean |I_r| 7.1 vs 8.0 better; ..."
  std::vector<std::string> worse;  // the quantities that got worse ("mean I_r,x"), empty when none
};
// `rows` as compare_out_of_sample returns them (rows[1]: best out-of-sample, rows[3]: the report's).
OutOfSampleVerdict out_of_sample_verdict(const std::vector<ComparisonRow>& rows);

}  // namespace abuopt
