#pragma once
// Pareto front of two objectives of the startup-profile problem, startup time T (sum of the
// durations: exact, linear in x) against the problem's objective (mean |I_r| by default), by the
// epsilon-constraint method (docs/sweep.md, "Pareto front"): for each bound eps_k of a list,
//
//     minimise f(x)   subject to   T(x) <= eps_k   and the config's other constraints,
//
// solved by the config's optimiser (abuopt::opt::minimize) through the evaluation archive, each
// bound a problem of its own (T's bound is part of the problem identity). The bounds are solved in
// increasing order; each bound is solved from the design's x0 and (warm_start) once more from the
// previous bound's best point (feasible for the looser bound), and the better feasible run is
// kept, so the front's objective can only fall as eps grows while a warm start alone cannot trap
// the series in the first bound's basin (measured in docs/sweep.md). Each front point is then
// evaluated out of sample (the validation section's fresh initial conditions), as is the report's
// final profile, which the plot marks.
//
//   pareto:
//     max_startup_time_s: [10, 12, 14, 16, 18, 20, 22]   # the eps_k, > 0, sorted here
//     warm_start: true                                   # false: only the run from x0
//
// pareto.method nsga2 or moead instead: one run of pagmo's NSGA-II or MOEA/D on both objectives at
// once (compare's fronts machinery, front_comparison.hpp: pareto_front_problem), no bounds:
//
//   pareto:
//     method: nsga2                     # epsilon_constraint (default) | nsga2 | moead
//     max_evaluations: 600              # the whole front's budget (required)
//     population: 20                    # NSGA-II: a multiple of 4, >= 8; MOEA/D: >= 4
//     reference: {objective: 18, second: 23}   # hypervolume reference point (required)
#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "abuopt/common/yaml_reader.hpp"
#include "abuopt/optimizer/minimize.hpp"
#include "abuopt/optimizer/optimization_result.hpp"
#include "abuopt/optimizer/optimizer_options.hpp"
#include "abuopt/problems/startup_profile_problem.hpp"

namespace abuopt {

struct ParetoSettings {
  enum class Method { EpsilonConstraint, Nsga2, Moead };
  Method method = Method::EpsilonConstraint;
  // epsilon_constraint
  std::vector<double> max_startup_time_s;  // sorted ascending, distinct
  bool warm_start = true;
  // nsga2, moead
  long max_evaluations = 0;                // the front's budget
  long population = 20;
  std::pair<double, double> reference{0, 0};  // (objective, startup time)
};
std::string to_string(ParetoSettings::Method m);  // "epsilon_constraint", "nsga2", "moead"

// Reads the `pareto` section (strict; finish() is called). ConfigError naming key, value and rule:
// an unknown method; for epsilon_constraint, fewer than 2 bounds, a repeated one, or a key of the
// population methods; for nsga2/moead, bounds or warm_start given (they mean nothing without a
// series), max_evaluations or reference missing, a population that does not suit the method or
// exceeds the budget.
ParetoSettings read_pareto_settings(YamlReader section);

struct ParetoPoint {
  double epsilon = 0;                   // the bound on T
  std::string problem_id;               // of the bounded problem (archive key)
  opt::OptimizationResult result;       // the kept run
  long evaluations = 0;                 // of every run of this bound
  int starts = 1;                       // runs made (2 with a warm start)
  bool warm_start_won = false;          // the kept run is the warm-started one
  std::vector<double> x;                // its best point (empty: none)
  double startup_time_s = 0;            // T(x)
  opt::Evaluation out_of_sample;        // x on the validation set (ok = false when not run)
  bool dominated = false;               // another front point is no worse in both and better in one
};

// The optimiser's best point of a bound as an Evaluation (objective, inequality, metrics).
opt::Evaluation in_sample_evaluation(const ParetoPoint& p);

struct ParetoResult {
  std::vector<ParetoPoint> points;       // in order of eps
  opt::Evaluation report_in_sample;      // the report's final profile
  opt::Evaluation report_out_of_sample;
  double report_startup_time_s = 0;
  bool interrupted = false;              // Ctrl-C / request_stop / the progress callback stopped it
};

// Called after every evaluation of every run: the bound being solved (index, count) and the
// optimiser's progress. Return false to stop the series (as an EvaluationCallback; no further
// bound is solved, no validation, `interrupted` is set).
using ParetoProgress = std::function<bool(std::size_t, std::size_t, const opt::Progress&)>;

// The epsilon-constraint series (pareto.method must be epsilon_constraint, else ConfigError).
// Solves every bound (archive at archive_path, shared by all of them; problem ids differ), then,
// unless interrupted or `validate` is false, the out-of-sample evaluations. `base` must not bound
// the startup time itself (ConfigError: constraints.max_startup_time_s is set by the series).
// `x0`: where every bound's first run starts (empty: the design's x0; `abuopt compare`'s fronts give
// each run of the series a start of its own).
ParetoResult run_pareto(const problems::StartupProfileSettings& base, const opt::OptimizerOptions& options,
                        const ParetoSettings& pareto, const std::string& archive_path,
                        const std::string& command_config, const std::string& config_hash,
                        const ParetoProgress& progress = {}, bool validate = true,
                        const std::vector<double>& x0 = {});

// Marks `dominated` among the points with a feasible best (minimising both T and the objective).
void mark_dominated(std::vector<ParetoPoint>& points);

// pareto.csv: one line per bound: epsilon_s, startup_time_s, feasible, dominated, objective,
// objective_hw95, out_of_sample_objective, out_of_sample_hw95, pct_mi, out_of_sample_pct_mi,
// evaluations, archive_hits, reason, the variables. Then pareto.png/.pdf (gnuplot; scripts run from
// `dir`): the front in and out of sample with 95 % error bars and the report's profile marked.
// Returns the plot's message.
std::string write_pareto_outputs(const std::filesystem::path& dir, const problems::StartupProfileProblem& shape,
                                 const ParetoResult& r);

}  // namespace abuopt
