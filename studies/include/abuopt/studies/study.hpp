#pragma once
// `abuopt study STUDY.yaml`: a whole design study as one declarative file (docs/study.md).
//
//   StudyFile f = read_study_file("configs/studies/quick.yaml");   // strict YAML, ConfigError
//   StudyResult r = run_study(f, {.out = "results/quick"});          // stages, archive, resume
//   write_study_report(f, r, "results/quick");                       // report.html/.md, summary.json, designs/
//
// The file says everything: the ABU (`abu`, `motor`, `simulation`), the envelope of uncertain
// parameters (`envelope`), the initial-angle sampling (`sampling`), the `baseline` profile, the
// profile `family` (free values with bounds, frequencies optionally in units of the ABU's natural
// frequency), discrete `choices` (ball counts at a total ball mass, enumerated or as one more
// variable of the global stages, or ball sets), the `objective` and
// `constraints` (absolute, or relative to the baseline), the `stages` and one `budget`.
// Stage kinds (one file each, studies/src/study_stage_*.cpp):
//   global     an optimiser of the registry from the family's starting point
//   local      an optimiser from the best design so far (a polish)
//   replicate  the best design of every choice on fresh samples (other seeds): the recommended
//              design is the best mean objective among those feasible on every replication
//   validate   the recommended design and the baseline on fresh, larger samples (intervals over
//              the seeds), and their ratio over a (mu, imbalance) map of the envelope
//   pareto     the front of the objective against the startup time T by epsilon-constraint: one
//              constrained optimisation per bound on T (ascending, each from the previous bound's
//              best, the first from the best so far), each bound its own archived problem; the
//              front's points optionally on fresh samples (seeds, runs)
// Every Monte Carlo goes through one SQLite evaluation archive (OUT/archive.sqlite): a rerun after
// Ctrl-C or kill -9 recomputes nothing it stored and ends with the same results; results do not
// depend on the thread count (common random numbers, seeded optimisers).
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "abuopt/core/batch_runner.hpp"
#include "abuopt/core/monte_carlo.hpp"
#include "abuopt/optimizer/optimization_result.hpp"
#include "abuopt/optimizer/optimizer_options.hpp"
#include "abuopt/problems/startup_profile_problem.hpp"

namespace abuopt::studies {

enum class StageKind { Global, Local, Replicate, Validate, Pareto };
extern const EnumNames<StageKind> kStageKindNames;  // global, local, replicate, validate, pareto
std::string to_string(StageKind k);

struct StageSpec {
  StageKind kind = StageKind::Global;
  std::string name;                 // default: the kind (made unique: "local_2")
  opt::OptimizerOptions optimizer;  // global, local
  double penalty_weight = 10.0;     // global/local with an optimiser that takes bounds only
  std::vector<std::uint64_t> seeds; // replicate, validate: one fresh sample per seed
  std::size_t runs = 0;             // replicate, validate: runs per sample (0: the sampling's runs)
  // validate: the ratio map over the envelope (empty: no map)
  std::vector<double> map_friction_mu;
  std::vector<double> map_imbalance_factor;  // x abu.imbalance_mass_kg
  std::size_t map_runs = 0;         // runs per map point (0: the stage's runs)
  // pareto: the bounds on the startup time T [s], ascending (key `bounds`; `over: startup_time`)
  std::vector<double> pareto_bounds;
  // pareto `method`: "epsilon_constraint" (the bounds), "nsga2" or "moead" (one pagmo run per
  // choice on the objective and T at once, budget optimizer.max_evaluations, no bounds), with the
  // population and the most front points kept (spread over T; each a design, checked on the seeds)
  std::string pareto_method = "epsilon_constraint";
  long pareto_population = 20;
  std::size_t pareto_points = 12;
};

struct RelativeConstraints {
  std::optional<double> amplitude_vs_baseline;             // A <= factor x the baseline's A
  std::optional<double> angular_acceleration_vs_baseline;  // peak a <= factor x the baseline's
  std::optional<double> startup_time_vs_baseline;          // T <= factor x the baseline's T
};

// One discrete choice of balls: a count at the total mass (choices.balls.counts) or a ball set
// (choices.balls.sets).
struct BallChoice {
  std::string label;        // "balls3" (a count) or the set's name (default "set<i+1>")
  std::vector<Ball> balls;
};

// "3 balls" for a count, the set's name for a set (logs, notes, the report).
std::string choice_name(const BallChoice& c);
// The balls' distinct diameters in mm, "3" or "2.5/3".
std::string diameters_mm(const std::vector<Ball>& balls);

struct StudyFile {
  std::string path;                  // the file as given
  std::string title;
  MonteCarloStudy base;              // abu, motor, simulation, baseline profile, sampling, envelope
  std::size_t threads = 0;           // Monte Carlo workers (0: all cores); results do not depend on it
  bool frequencies_natural = false;  // family: free frequency values in units of f_n = sqrt(k/M)/2pi
  problems::ProfileDesign family;    // as written (natural units not yet applied)
  std::vector<BallChoice> choices;   // one entry (label "balls<n>"): the abu's balls
  std::optional<double> total_ball_mass_kg;  // choices.balls.counts
  // choices.balls.mode: variable (counts only): the global stages see the count as one more variable
  // (problems::BallCountDesign, the abu's ball diameter), the later stages polish the chosen count(s)
  bool ball_count_variable = false;
  problems::ObjectiveSettings objective;
  problems::ConstraintSettings constraints;
  RelativeConstraints relative;
  std::vector<StageSpec> stages;
  long max_evaluations = 1000;       // budget: optimiser evaluations over every stage and choice
};

// Reads and validates a study file. Throws ConfigError naming the key, the value and the rule.
StudyFile read_study_file(const std::string& path);

// The ABU of one choice (index into f.choices) and the problem settings of that choice:
// family frequencies in Hz, relative constraints resolved against `baseline` metrics.
AbuParameters abu_of_choice(const StudyFile& f, std::size_t choice);
problems::StartupProfileSettings settings_of_choice(const StudyFile& f, std::size_t choice,
                                                    const std::map<std::string, double>& baseline_metrics);
// choices.balls.mode: variable: the settings of the first choice with the ball count free over the
// counts (the global stages' problem).
problems::StartupProfileSettings settings_of_variable_count(const StudyFile& f,
                                                            const std::map<std::string, double>& baseline_metrics);
// Which free end frequencies can reach f_n (Hz); empty message when one can.
std::string resonance_reach_text(const problems::ProfileDesign& d, double natural_frequency_hz);

// The plan of a study (`abuopt study FILE --check`): counts from the file alone, nothing simulated.
struct StudyPlan {
  long long runs_per_evaluation = 0;    // sampling.runs x the robust friction values (if any)
  long long optimiser_evaluations = 0;  // min(the optimiser stages' budgets x choices, budget.max_evaluations)
  long long other_evaluations = 0;      // the baseline and the evaluations on fresh samples (Monte Carlos)
  long long simulations = 0;            // an upper estimate of the simulations of the whole study
  std::vector<std::string> warnings;    // the family cannot reach the resonance, ...
};
StudyPlan plan_of(const StudyFile& f);
// The plan as text for a person: f_n, the free variables with bounds in Hz (after natural units),
// the choices, each stage with its optimiser and budget, runs per evaluation, the estimate, warnings.
std::string plan_text(const StudyFile& f);

// One evaluated design (a point of one stage).
struct StudyDesign {
  std::string label;          // "balls2_local" ...
  std::size_t choice = 0;     // index into StudyFile::choices
  std::size_t balls = 0;      // the ball count of that choice
  std::string stage;
  std::vector<std::string> variable_names;
  std::vector<double> x;
  StartupProfile profile;
  opt::Evaluation in_sample;
  std::vector<opt::Evaluation> replications;  // replicate stage
  bool robust_feasible = false;               // feasible on every replication (or in sample without them)
  double replicated_objective = 0.0;          // mean over replications (in-sample objective without them)
};

struct StageTrace {
  std::string stage;
  std::string choice;                  // the choice's label ("variable count" for a global stage over the count)
  std::size_t balls = 0;               // its ball count (0: the count is a variable)
  std::string algorithm;
  std::string reason;
  long evaluations = 0, archive_hits = 0;
  std::vector<double> objective;       // every evaluation (NaN: failed)
  std::vector<double> best_feasible;   // best feasible so far (NaN: none yet)
};

// A metric over fresh samples: mean and a 95 % t-interval over the seeds.
struct Interval {
  double mean = 0.0, lo = 0.0, hi = 0.0;
  std::size_t samples = 0;
};
Interval interval_of(const std::vector<double>& values);

// One point of the Pareto front (pareto stage): the best design with T <= bound.
struct FrontPoint {
  double bound_s = 0.0;          // the bound on the startup time
  StudyDesign design;            // label pareto_T<bound> (balls<n>_pareto_T<bound> with several choices)
  bool feasible = false;         // in sample, under T <= bound and the study's other constraints
  bool dominated = false;        // another feasible point of the same choice is no worse in T and mean |I_r|, better in one
  long evaluations = 0, archive_hits = 0;
  Interval out_of_sample_ir;     // mean |I_r| on the stage's fresh samples (samples = 0: none)
  bool feasible_out_of_sample = false;  // on every fresh sample
};
struct ParetoFront {
  std::string stage;             // the stage's name (empty: no pareto stage ran)
  std::string method = "epsilon_constraint";  // or nsga2, moead (bound_s is then the point's own T)
  std::size_t runs = 0;          // runs per fresh sample
  std::vector<std::uint64_t> seeds;
  std::vector<FrontPoint> points;  // per choice, in order of the bounds
  Interval baseline_out_of_sample_ir;  // the baseline on the same fresh samples
};

// The settled runs of one profile on one sample as `abuopt eqset --runs` measures them.
struct FinalPositions {
  std::vector<std::pair<double, double>> angles_deg;  // final (beta_1, beta_2) of each settled run
  std::vector<char> early;                            // 1: settled below the band edge (split by speed)
  std::vector<double> depth;                          // |U| / r_lock of the run's own parameters
  std::size_t not_settled = 0;
  double early_share = 0, depth_mean = 0, depth_lo = 0, depth_hi = 0;  // mean depth and its 95 % interval
  double early_depth_mean = 0, late_depth_mean = 0;
};

struct ValidationResult {
  bool done = false;
  std::size_t runs = 0;
  std::vector<std::uint64_t> seeds;
  std::map<std::string, Interval> design, baseline;  // per metric
  Interval ratio_mean_ir;                            // design / baseline mean |I_r|, per seed
  std::vector<double> map_mu, map_imbalance;
  std::vector<std::vector<double>> map_ratio;        // [imbalance factor][mu]: design / baseline mean |I_r|
  std::size_t map_runs = 0;
  // Where the balls of the recommended design and of the baseline stopped on the first fresh sample
  // (two balls only), over the lock set of the nominal ABU (lock gauge <= 1: held at every constant
  // speed; core/include/abuopt/core/final_states.hpp).
  FinalPositions final_design, final_baseline;
  std::size_t lock_n = 0;          // the lock set's grid: lock_n x lock_n over [0, 360)^2 deg
  std::vector<char> lock_in_set;   // row-major: index i * lock_n + j = (beta_1 = i, beta_2 = j)
  double lock_mu = 0, lock_band_lo_hz = 0, lock_band_hi_hz = 0;
  double early_edge_hz = 0;        // early: settled below this speed (r_in = 2 r_lock, nominal ABU)
};

struct StudyResult {
  bool interrupted = false;
  double wall_time_s = 0.0;
  long evaluations = 0, archive_hits = 0;
  opt::Evaluation baseline;                    // baseline profile, in sample
  double baseline_peak_acceleration = 0.0;
  std::vector<std::string> constraint_names;
  std::vector<std::string> notes;              // resonance reach, unmet constraints, ...
  std::vector<StudyDesign> designs;            // every stage's best, per choice
  std::optional<std::size_t> recommended;      // index into designs (the best design found; see verdict)
  bool candidate = false;  // a replicate stage ran and no design met the constraints on every fresh sample
  std::vector<StageTrace> traces;
  ValidationResult validation;
  ParetoFront front;
  // How each ball choice did: with choices.balls.mode: variable, per count the global stages'
  // evaluations there and the best feasible objective; otherwise each choice's final design.
  struct ChoiceSummary {
    std::string label;
    std::size_t balls = 0;
    long evaluations = 0;          // variable mode: the global stages' evaluations at this count
    double best_feasible = 0;      // in sample (NaN: none feasible)
    bool chosen = false;           // variable mode: polished by the later stages
  };
  std::vector<ChoiceSummary> choice_summary;
};

struct StudyRunOptions {
  std::string out;                                 // directory (archive.sqlite goes there)
  std::optional<std::size_t> threads;              // overrides the file's
  std::function<void(const std::string&)> log;     // one line at a time
  std::function<void(long done, long total)> progress;  // evaluations of the budget
  std::function<bool()> stop_requested;            // polled between evaluations
  // Where every Monte Carlo runs (e.g. over MPI ranks: parallel::make_runner); null: a thread pool
  // of the file's (or `threads`) workers. Results do not depend on it.
  std::shared_ptr<BatchRunner> runner;
};

StudyResult run_study(const StudyFile& f, const StudyRunOptions& o);

// What the study can say of its best design, for the headline of every report and the command's
// last line: recommended (feasible on every fresh sample and, validated, better than the baseline
// on fresh samples), no_better (validated: no difference the samples can tell), worse (validated:
// worse than the baseline), candidate (not feasible on every fresh sample), unvalidated (no
// validate stage), none (no design).
enum class Verdict { Recommended, NoBetter, Worse, Candidate, Unvalidated, None };
Verdict verdict_of(const StudyResult& r);
std::string to_string(Verdict v);  // recommended, no_better, worse, candidate, unvalidated, none
// The headline's first words: "Recommended design", "Candidate design", "Best design found", ...
std::string headline_of(Verdict v);

// report.html, report.md, summary.json and designs/<label>.yaml (ready for `abuopt montecarlo`).
// Returns the files written.
std::vector<std::string> write_study_report(const StudyFile& f, const StudyResult& r, const std::string& out_dir);

}  // namespace abuopt::studies
