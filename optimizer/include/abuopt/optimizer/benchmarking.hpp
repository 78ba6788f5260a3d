#pragma once
// Comparison of optimisers on a set of problems (Moré & Wild 2009, "Benchmarking derivative-free
// optimization algorithms"; Dolan & Moré 2002, "Benchmarking optimization software with
// performance profiles").
//
//   ComparisonSetup setup;
//   setup.problems.push_back({"hs071", [] { return make_benchmark("hs071"); }, 200, 3});
//   setup.solvers.push_back(solver_spec("SAO", "sao"));
//   setup.solvers.push_back(solver_spec("COBYLA", "cobyla"));
//   ComparisonResult r = run_comparison(setup);
//   std::cout << format_table(r);
//   write_comparison(r, "results/compare-x");   // CSVs, gnuplot script, PNGs if gnuplot exists
//
// An *instance* is a (problem, starting point) pair; every solver runs on every instance with the
// problem's evaluation budget, and every run keeps its history.
//
// Solved: instance p is solved by a run at the first evaluation that is feasible and has
//   f - f* <= tau * max(|f*|, 1)
// (f the true objective: the metric `true_objective_metric` when an evaluation reports it, as the
// noisy benchmarks do, else the objective). t_{p,s} = that evaluation count (1-based), +inf if
// never. f* = ProblemSpec::f_star, else the problem's best_known(), else the lowest feasible true
// objective found by any run on that problem.
//   data profile        d_s(alpha) = |{p : t_{p,s} <= alpha (n_p + 1)}| / |P|
//   performance profile rho_s(tau) = |{p : r_{p,s} <= tau}| / |P|,
//                       r_{p,s} = t_{p,s} / min_s' t_{p,s'}  (+inf if s did not solve p; if no
//                       solver solved p, p counts in |P| but never as solved)
// Problems from elsewhere (the startup-profile design problem built from its config) join
// through the ProblemFactory callback.
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "abuopt/common/yaml_reader.hpp"
#include "abuopt/optimizer/optimization_result.hpp"
#include "abuopt/optimizer/optimizer_options.hpp"
#include "abuopt/optimizer/problem.hpp"
#include "abuopt/optimizer/sao.hpp"

namespace abuopt::opt {

// One optimiser of a comparison: any algorithm name of minimize() (NLopt names, IPOPT, SAO).
struct SolverSpec {
  std::string label;         // its name in tables and plots (unique)
  OptimizerOptions options;  // algorithm and settings (SAO's in options.sao); max_evaluations,
                             // constraint_tolerance and seed are set per run from the ProblemSpec
  // A second stage (two_stage.hpp), e.g. DIRECT_L then COBYLA: `options` runs first with
  // first_fraction of the budget (on the penalty form of weight penalty_weight when it handles
  // bounds only and the problem has constraints), `then` from its best point with the rest.
  std::optional<OptimizerOptions> then;
  double first_fraction = 0.3;
  double penalty_weight = 100.0;
  // Runs made outside abuopt (e.g. examples/python/optuna_study.py): when not empty, nothing is run;
  // run k on problem P is read from external_run_path(external_runs, P, k) (read_external_run).
  std::string external_runs;
};
// <directory>/<problem label, file-safe>/start<k>.csv
std::string external_run_path(const std::string& directory, const std::string& problem_label, int start);
// An external run's history (external_runs.cpp: evaluation,ok,objective,max_violation,<variables>)
// as an OptimizationResult: feasible per constraint_tolerance, the best point as minimize() picks
// it. ConfigError naming the file (and line) for a missing file, a wrong header, a bad number, a
// point outside the bounds, or more evaluations than max_evaluations (> 0).
OptimizationResult read_external_run(const std::string& path, const Problem& problem, double constraint_tolerance,
                                     long max_evaluations);
// A solver with default settings; `algorithm` is checked (ConfigError listing the valid names).
SolverSpec solver_spec(const std::string& label, const std::string& algorithm);
// Reads one solver entry: label, algorithm (any minimize() name or sao), optional `options:`
// (the keys of an optimizer: section except algorithm) and `sao:` sections, and optionally a second
// stage: `then: {algorithm: cobyla, options: {...}}`, `first_fraction: 0.3`, `penalty_weight: 100`.
// Or an external solver: `{label: Optuna-TPE, external: DIR}` (no algorithm; SolverSpec::external_runs).
SolverSpec read_solver_spec(YamlReader& entry);

// Makes a fresh instance of a problem (called once per run).
using ProblemFactory = std::function<std::unique_ptr<Problem>()>;

struct ProblemSpec {
  std::string label;                   // unique
  ProblemFactory make;
  long max_evaluations = 200;          // budget of every run (> 0)
  int starts = 1;                      // the problem's initial_point(), then starts-1 seeded
                                       // uniform random points in the bounds (>= 1)
  std::uint64_t seed = 1;              // of the random starts; run k of a solver gets seed + k
  double constraint_tolerance = 1e-6;  // feasibility tolerance of every run on it
  std::optional<double> f_star;        // reference value (else best_known(), else best found)
  // Out-of-sample check of every run's result (e.g. the startup problem on its validation set:
  // fresh runs of a seed no optimiser saw); empty: none. Called once per run on the result's x
  // (thread-safe: runs may go at once), never for a run without a point.
  std::function<Evaluation(const std::vector<double>& x)> validate;
  // What the evaluation archive keys this problem's values by (ComparisonSetup::archive_directory):
  // a value stored under one identity never answers another. Give a hash of everything that fixes
  // the values (the startup problem: its archive id); empty: the label.
  std::string identity;
  // What keys the stored out-of-sample values beside the identity: everything that fixes
  // validate()'s values but not the problem's (the startup problem: its validation section's
  // design, runs and seed), so a changed validation never answers from values stored for another.
  // Empty: the identity alone keys them (a validate() that the identity fixes).
  std::string validation_identity;
  // Checkpoints of the out-of-sample trajectory (needs validate; 0: none): at evaluations
  // ceil(j max_evaluations / C), j = 1..C, the run's incumbent so far (its best feasible value that
  // counts, as the convergence curve) is validated too (RunRecord::validated_convergence), so the
  // evaluations a method needs to come within x % of the best design OUT of sample can be read off
  // (a sampled problem's in-sample values fit its own runs: their best is no reference).
  int validation_checkpoints = 0;
};

struct RunRecord;

struct ComparisonSetup {
  std::vector<ProblemSpec> problems;
  std::vector<SolverSpec> solvers;
  double tau = 1e-2;  // accuracy of "solved" (relative, see above), in (0, 1)
  std::string true_objective_metric = "noise_free_objective";
  // Called after each run (e.g. to print progress), in run order; may be empty.
  std::function<void(const RunRecord&)> on_run;
  // Called as each run ends (a progress line), from the thread that ran it, one call at a time,
  // with the runs ended so far and the total of the comparison; f* is not known yet, so
  // evaluations_to_solve is -1. May be empty.
  std::function<void(const RunRecord&, std::size_t ended, std::size_t total)> on_run_ended;
  // Resumable comparison: when not empty, every run keeps its evaluations in an evaluation archive
  // of its own (evaluation_archive.hpp), <archive_directory>/<problem>/start<k>-<solver>.sqlite,
  // and the out-of-sample checks go into <archive_directory>/<problem>/validation.sqlite. A rerun
  // answers what is stored bit for bit; the optimisers are deterministic, so an interrupted run
  // retraces its path from the archive and goes on from where it stopped, and a finished run is
  // replayed without computing anything (RunRecord::result.archive_hits counts the answers). The
  // problems' identities key the values (ProblemSpec::identity). No run handles SIGINT itself then:
  // Ctrl-C ends the comparison at once, and every evaluation stored so far stays.
  std::string archive_directory;
  // Runs of one problem at once (its starts x solvers are independent); the results do not
  // depend on it (only wall times do). 1: one after another. Each run's own Monte Carlo threads
  // come on top, so for the startup problem keep threads x montecarlo.threads near the cores.
  int threads = 1;
};

// One point of a convergence curve: after `evaluation` evaluations the best feasible true
// objective so far is `best` (recorded when it improves).
struct ConvergencePoint {
  long evaluation = 0;
  double best = 0.0;
};

// The run's incumbent after `evaluation` evaluations, validated (ProblemSpec::validation_checkpoints).
struct ValidatedCheckpoint {
  long evaluation = 0;
  double objective = 0.0;      // out of sample
  double max_violation = 0.0;  // out of sample
  bool feasible = false;       // out of sample, within the run's tolerance
};

struct RunRecord {
  std::string problem;
  std::string solver;
  int start = 0;                   // index of the starting point
  std::size_t dimension = 0;       // n_p
  std::size_t sample_size = 0;     // the problem's own Monte Carlo size (Problem::sample_size())
  std::vector<double> x0;
  OptimizationResult result;       // with its history
  double best_true_objective = std::numeric_limits<double>::infinity();  // best feasible (true f)
  bool feasible = false;
  long evaluations_to_solve = -1;  // t_{p,s}; -1: not solved
  std::vector<ConvergencePoint> convergence;
  // ProblemSpec::validate of result.x (unset without one); feasible within the run's tolerance
  std::optional<Evaluation> validation;
  bool validation_feasible = false;
  bool validation_from_archive = false;  // the validation was answered by the archive
  std::vector<ValidatedCheckpoint> validated_convergence;  // ProblemSpec::validation_checkpoints; in order
};

struct ComparisonResult {
  std::vector<std::string> problems;  // labels, in setup order
  std::vector<std::string> solvers;   // labels, in setup order
  std::vector<double> f_star;         // per problem
  std::vector<std::string> f_star_source;  // "given", "best_known", "best_found", "none"
  double tau = 1e-2;
  std::vector<RunRecord> runs;        // problem-major, then start, then solver

  // t_{p,s} per instance (rows: (problem, start) in order; columns: solvers); +inf = not solved.
  std::vector<std::vector<double>> solve_matrix() const;
  // n_p of each instance row.
  std::vector<std::size_t> instance_dimensions() const;
};

// Runs every solver from every start of every problem. Throws abuopt::ConfigError before any
// run for an empty or inconsistent setup (duplicate labels, budget <= 0, starts < 1, tau outside
// (0, 1), a solver's options invalid). A run that fails is recorded, never fatal.
ComparisonResult run_comparison(const ComparisonSetup& setup);

// The starting points of a problem spec (first: initial_point()).
std::vector<std::vector<double>> starting_points(const Problem& problem, int starts, std::uint64_t seed);

// Evaluations until the first feasible point with f - f* <= tau max(|f*|, 1); -1 if none.
long evaluations_to_solve(const OptimizationResult& result, double f_star, double tau,
                          const std::string& true_objective_metric = "noise_free_objective",
                          std::size_t full_sample_size = 0);
// Whether an evaluation counts as a value of the problem (for "solved", the best value and the
// convergence curve): always, unless the problem is sampled (full_sample_size > 0, its own Monte
// Carlo size), the evaluation has no true_objective_metric (a noise-free value) and its metric
// `runs` is below full_sample_size: a value of SAO's adaptive sample size on fewer runs is an
// estimate of another, noisier statistic (its minimum over many designs is biased low), so a
// comparison judges every solver on values at the problem's own size.
bool counts_as_problem_value(const EvaluationRecord& h, std::size_t full_sample_size,
                             const std::string& true_objective_metric);

// ---- profile arithmetic (t: rows = instances, columns = solvers, +inf = not solved) ----
// d_s(alpha) for each alpha: fraction of rows with t[p][s] <= alpha (dims[p] + 1).
std::vector<double> data_profile(const std::vector<std::vector<double>>& t, const std::vector<std::size_t>& dims,
                                 std::size_t solver, const std::vector<double>& alphas);
// r_{p,s} = t[p][s] / min_s' t[p][s'] (+inf when t[p][s] is +inf or no solver solved p).
std::vector<std::vector<double>> performance_ratios(const std::vector<std::vector<double>>& t);
// rho_s(tau) for each tau: fraction of rows with r_{p,s} <= tau.
std::vector<double> performance_profile(const std::vector<std::vector<double>>& t, std::size_t solver,
                                        const std::vector<double>& taus);

// ---- reports ----
// One row per (problem, solver), over the starts: solved/starts, median evaluations to solve,
// best feasible true objective, feasible runs, mean evaluations, mean wall time.
std::string format_table(const ComparisonResult& result);

struct WrittenFiles {
  std::vector<std::string> files;          // written (paths)
  std::vector<std::string> skipped_plots;  // PNGs not made (no gnuplot, or gnuplot failed)
  std::string gnuplot;                     // the gnuplot used ("" if none)
};
// Writes into `directory` (created): runs.csv, convergence.csv, data_profile.csv,
// performance_profile.csv, plots.gp and, when gnuplot is on the PATH and make_plots,
// data_profile.png, performance_profile.png and convergence_<problem>.png. Throws
// abuopt::ConfigError if the directory cannot be created or a file cannot be written.
WrittenFiles write_comparison(const ComparisonResult& result, const std::string& directory, bool make_plots = true);

// The gnuplot executable found on the PATH (or /usr/bin/gnuplot), "" if none is executable.
std::string find_gnuplot();

}  // namespace abuopt::opt
