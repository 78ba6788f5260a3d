#pragma once
// Two-objective problems of `abuopt compare` (the `fronts:` section; issue 33 item 4): the
// startup-profile problem with its objective (mean |I_r|) and a metric (startup time T) both
// minimised, solved by pagmo's NSGA-II or MOEA/D (opt::minimize_two_objectives) and by `abuopt pareto`'s
// epsilon-constraint series (run_pareto) at equal evaluations, every front point validated out of
// sample, compared by hypervolume against one reference point per problem.
//
//   fronts:
//     - label: time_vs_imbalance_19s
//       second_objective: startup_time_s     # a metric, minimised beside the objective
//       max_evaluations: 240                 # every run's budget (equal evaluations)
//       seeds: 4                             # runs per method: run k starts at start k (k = 0: the
//       seed: 304                            #   design's x0, then seeded random designs) with seed + k
//       reference: {objective: 25, second: 23}   # hypervolume reference point
//       startup_profile: {...}               # an `abuopt optimize` config's sections; no bound on T
//       methods:
//         - {label: NSGA-II, algorithm: pagmo_nsga2, population: 20}
//         - {label: MOEA/D, algorithm: pagmo_moead, population: 20}   # any population >= 4
//         - {label: eps-constraint, algorithm: epsilon_constraint, bounds_s: [8, 11, 14, 17, 19, 23],
//            warm_start: true, inner: {algorithm: cobyla, options: {initial_step: 0.1}}}
//
// Equal evaluations: NSGA-II and MOEA/D get max_evaluations; the epsilon-constraint series makes one run per
// bound plus (warm_start) one more per bound after the first, each with
// epsilon_constraint_inner_budget() = floor(max_evaluations / runs), so its total never exceeds
// the budget and falls short of it by less than one inner run when every run uses its budget.
// A front point is a feasible in-sample point (NSGA-II, MOEA/D: the non-dominated feasible evaluations of
// the run; epsilon-constraint: each bound's kept best point). Out of sample: the problem's
// validation section at the point's x; a point infeasible there drops out of the out-of-sample
// front. hv_in / hv_out = opt::hypervolume_2d of the in-sample / validated points against the
// reference (points not better than it in both coordinates add nothing).
// Resumable: every run keeps its evaluations in <archive>/<label>/run<k>-<method>.sqlite and the
// validations in <archive>/<label>/validation.sqlite (as the single-objective problems).
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "abuopt/common/yaml_reader.hpp"
#include "abuopt/optimizer/benchmarking.hpp"
#include "abuopt/optimizer/optimizer_options.hpp"
#include "abuopt/problems/startup_profile_problem.hpp"
#include "abuopt/studies/pareto.hpp"

namespace abuopt {

struct FrontMethod {
  enum class Kind { Nsga2, EpsilonConstraint, Moead };
  std::string label;
  Kind kind = Kind::Nsga2;
  opt::OptimizerOptions options;  // NSGA-II's / MOEA/D's (population), or the epsilon-constraint's inner optimiser
  std::vector<double> bounds_s;   // epsilon-constraint: the bounds on the second objective, ascending
  bool warm_start = true;         // epsilon-constraint: each bound also from the previous bound's best
};

struct FrontProblem {
  std::string label;
  problems::StartupProfileSettings settings;  // without a bound on the second objective
  std::string second_objective = "startup_time_s";
  long max_evaluations = 200;
  int seeds = 1;
  std::uint64_t seed = 1;
  double constraint_tolerance = 1e-6;
  std::pair<double, double> reference{0, 0};  // (objective, second)
  std::vector<FrontMethod> methods;
};

// One `fronts:` entry (strict; finish() called). ConfigError naming key, value and rule: an
// unknown algorithm, a second objective other than startup_time_s for the epsilon-constraint, a
// bound on the startup time in the problem, fewer than 2 bounds or a repeated one, a reference
// missing, not > 0 or not beyond the loosest bound, a budget below one NSGA-II population or one
// that leaves an inner run fewer than dimension + 2 evaluations, duplicate method labels.
FrontProblem read_front_problem(YamlReader& entry);

// `abuopt pareto` with pareto.method nsga2 or moead: the front as a FrontProblem of one run
// (label `label`, method "NSGA-II" or "MOEA/D" with pareto.population, budget pareto.max_evaluations,
// reference pareto.reference, seed and constraint_tolerance from `options`, the run from the
// design's x0) for run_front_comparison, so its outputs are compare's (fronts.csv, hypervolume.csv,
// front_<label>.png, every point validated out of sample, archived and resumable). ConfigError: a
// bound on the startup time or a penalty_weight in `base` (both objectives are the method's own).
FrontProblem pareto_front_problem(const problems::StartupProfileSettings& base, const opt::OptimizerOptions& options,
                                  const ParetoSettings& pareto, const std::string& label);

// Runs of the epsilon-constraint series and the budget of each: floor(budget / runs).
std::size_t epsilon_constraint_runs(std::size_t bounds, bool warm_start);
long epsilon_constraint_inner_budget(long budget, std::size_t bounds, bool warm_start);

struct FrontPoint {
  double objective = 0, second = 0;   // in sample
  bool non_dominated = true;          // among the run's in-sample points
  std::vector<double> x;
  std::optional<opt::Evaluation> validation;  // out of sample (unset: validation off)
  double validated_second = 0;        // the metric out of sample (T is exact: equal to `second`)
  bool validated_feasible = false;
};

struct FrontRun {
  std::string problem, method;
  int run = 0;
  long evaluations = 0;               // every evaluation of the run (all bounds for the series)
  long budget = 0;                    // the problem's max_evaluations
  long inner_budget = 0;              // epsilon-constraint: per inner run (0 for pagmo's)
  std::vector<FrontPoint> points;     // the in-sample front points, by objective
  double hv_in = 0, hv_out = 0;
  std::size_t points_out = 0;         // points feasible out of sample
  bool validated = false;
  std::string reason;                 // pagmo's termination, or the series' last bound's
  double wall_time_s = 0;
};

struct FrontComparison {
  std::vector<FrontProblem> problems;
  std::vector<FrontRun> runs;         // problem-major, then run, then method
};

// Every method's runs on every problem (`threads` runs at once; the results do not depend on it),
// archived under archive_directory/<label>/ when it is not empty. on_run_ended: called as each run
// ends (one call at a time) with the runs ended so far and the total. A run stopped by
// stop_requested() is recorded as it stopped (the caller reports the interruption).
FrontComparison run_front_comparison(
    const std::vector<FrontProblem>& problems, const std::string& archive_directory, int threads,
    const std::function<void(const FrontRun&, std::size_t ended, std::size_t total)>& on_run_ended = {});

// Per problem and method: runs, median evaluations, median and range of hv in and out of sample,
// points feasible out of sample / in sample.
std::string format_front_table(const FrontComparison& c);

// fronts.csv (problem, method, run, point, objective, second, non_dominated, validated_objective,
// validated_second, validated_feasible, x), hypervolume.csv (problem, method, run, evaluations,
// budget, inner_budget, hv_in, hv_out, points_in, points_out, reference_objective, reference_second,
// reason, wall_time_s), and per problem front_<label>.dat/.gp and, with gnuplot, .png/.pdf.
// Adds the written paths to files and the PNGs not made to skipped_plots.
void write_front_outputs(const FrontComparison& c, const std::string& directory, opt::WrittenFiles& written,
                         bool make_plots = true);

}  // namespace abuopt
