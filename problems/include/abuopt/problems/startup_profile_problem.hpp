#pragma once
// The startup-profile design problem (spec section 8, report section 4.6): where the optimiser and
// the ABU model meet.
//
//   design vector x  ->  StartupProfile (inclined-sine segments, some values free, some fixed)
//                    ->  Monte Carlo over initial ball angles (the core engine), once per friction
//                        value of the robust set (one pass at the nominal friction otherwise)
//                    ->  objective, inequality constraints g(x) <= 0, metrics.
//
// Common random numbers: every design is evaluated on the SAME initial conditions (the
// `montecarlo` design and seed are fixed), so differences between designs are not masked by
// sampling noise, and the same x always gives bit-identical values (an archive can answer repeats).
//
// Objective (minimised), with I_r in units of 1e-7 kg m (as the report's tables) and %MI in percent,
// for the chosen definition of I_r (magnitude |I_r| by default, or the report's I_r,x):
//   mean:      mean I_r
//   pct_mi:    %MI (piecewise constant in x: a step of 100/runs; prefer mean or weighted)
//   weighted:  w_mean * mean I_r + w_pct_mi * %MI
//   smooth_pct_mi, quantile, cvar: the smooth statistics of core (compute_smooth_statistics: the
//              smoothed exceedance in percent, the |I_r| quantile and CVaR at objective.level), for
//              optimisers; validation and reports stay on the exact ones. With them (and with
//              constraints.pct_mi_statistic: smooth) the metrics add pct_mi_smooth, ir_quantile,
//              ir_cvar and smoothing_bandwidth.
//   startup_time: T = the sum of the durations [s] (exact, no noise; the Monte Carlo still runs for
//              the constraints and metrics): "the least startup time with a given quality", with
//              constraints.max_mean_abs_ir and max_pct_mi.
// Robust (objective.robust.friction_mu = [mu_1..mu_K]): the objective is the average over k of the
// objective of the Monte Carlo run with friction fixed to mu_k (same initial conditions for every
// k); constraints and metrics use the pooled statistics of all K x runs runs (pooled %MI = average
// %MI; pooled amplitude max = max over every run).
//
// Constraints (each optional), in relative form so that one tolerance suits all:
//   startup_time:  T_profile / max_startup_time_s - 1 <= 0      (T_profile = sum of durations)
//   amplitude:     A / max_amplitude_mm - 1 <= 0, A = max over runs of the peak amplitude
//                  (amplitude: max, default) or the mean over runs of it (amplitude: mean)
//   pct_mi:        %MI / max_pct_mi - 1 <= 0                    (definition of the objective; the
//                  smoothed exceedance with constraints.pct_mi_statistic: smooth)
//   mean_abs_ir:   mean |I_r| / max_mean_abs_ir - 1 <= 0        (always |I_r|, pooled over the robust set;
//                  the Monte Carlo's mean, in 1e-7 kg m)
//   angular_acceleration: a / max_angular_acceleration_rad_s2 - 1 <= 0, a = peak_angular_acceleration_rad_s2
// The problem always declares its constraints. With constraints.penalty_weight = w > 0 the
// optimisers see its penalty form instead (make_startup_profile_problem, opt::PenaltyProblem): no
// declared constraints (for bound-only optimisers), objective + w * sum_i max(0, g_i) (exact L1).
//
// A failed evaluation (opt::Evaluation::failed, never an exception): a profile with a duration
// that is not > 0 (never simulated), every run of a pass failing, or more failed runs than
// objective.max_failed_fraction.
//
// Metrics of every evaluation (pooled over the robust set; I_r in 1e-7 kg m):
//   ir_magnitude_{mean,median,max}, ir_x_{mean,median,max}, pct_mi_magnitude, pct_mi_x, pct_mi
//   (the constrained/optimised definition), pct_lc, amplitude_max_mm, amplitude_mean_mm,
//   startup_time_s, end_time_s, runs, failed_runs, mc_wall_time_s; with a robust set also
//   objective_mu<k>, mu<k> and pct_mi_mu<k> for k = 1..K (the penalty form adds g_<name> per
//   constraint and objective_without_penalty).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "abuopt/common/config_fields.hpp"
#include "abuopt/common/yaml_reader.hpp"
#include "abuopt/core/initial_conditions.hpp"
#include "abuopt/core/monte_carlo.hpp"
#include "abuopt/core/profile.hpp"
#include "abuopt/core/simulator.hpp"
#include "abuopt/optimizer/problem.hpp"

namespace abuopt::problems {

// One value of a segment: fixed, or a free design variable with bounds.
struct DesignValue {
  bool free = false;
  double value = 0.0;   // fixed: the value; free: the starting point x0
  double lower = 0.0;   // free only
  double upper = 0.0;   // free only
  double scale = 0.0;   // free only; 0: upper - lower
};

struct SegmentDesign {
  bool hold = false;             // a dwell: end frequency = the previous end (start) frequency, no variable
  DesignValue end_frequency_hz;  // variable name f<i> (1-based); unused with hold
  DesignValue duration_s;        // variable name dt<i>
};

// The ball count as one more design variable (design.ball_count, docs/optimize.md): identical
// balls sharing a fixed total mass, m = total_mass_kg / n each. The optimiser sees a continuous
// variable `balls` in [min - 0.5, max + 0.5]; the count is the nearest whole number (clamped to
// [min, max]), so every count has an interval of width 1. A ball's diameter is diameter_m when given,
// else that of a solid sphere of the mass and density_kg_m3 (steel by default): d = cbrt(6 m / (pi rho)).
// Each count has its own initial angles (a design over n balls), the same for every design.
inline constexpr double kMaxBallCount = 12;
struct BallCountDesign {
  bool free = false;              // the design.ball_count section is given
  double lower = 0.0, upper = 0.0;  // whole counts, 1 <= min < max <= kMaxBallCount
  double value = 0.0;             // x0, a whole count in [min, max] (default min)
  double total_mass_kg = 0.0;     // > 0
  double density_kg_m3 = 7850.0;  // steel
  std::optional<double> diameter_m;  // every ball this diameter (then the density is not used)
};

struct ProfileDesign {
  double start_frequency_hz = 0.0;
  std::vector<SegmentDesign> segments;
  BallCountDesign ball_count;
};

// The count the ball-count variable x stands for: the nearest whole number, clamped to [min, max].
std::size_t ball_count_at(const BallCountDesign& b, double x);
// The ABU with n identical balls of the ball-count design (mass total / n, its diameter); the
// other parameters as given.
AbuParameters abu_with_ball_count(const AbuParameters& abu, std::size_t n, const BallCountDesign& b);

enum class ObjectiveKind { Mean, PctMi, Weighted, SmoothPctMi, Quantile, Cvar, StartupTime };
enum class ImbalanceDefinition { Magnitude, ReportX };
enum class AmplitudeStatistic { Max, Mean };
// mean, pct_mi, weighted, smooth_pct_mi, quantile, cvar, startup_time
extern const EnumNames<ObjectiveKind> kObjectiveKindNames;
extern const EnumNames<ImbalanceDefinition> kImbalanceDefinitionNames;  // magnitude, report_x
extern const EnumNames<AmplitudeStatistic> kAmplitudeStatisticNames;    // max, mean
// Which %MI the pct_mi constraint bounds: the count, or the smoothed exceedance (core's
// compute_smooth_statistics).
enum class PctMiStatistic { Exact, Smooth };
extern const EnumNames<PctMiStatistic> kPctMiStatisticNames;  // exact, smooth
std::string to_string(ObjectiveKind k);
std::string to_string(ImbalanceDefinition d);
std::string to_string(AmplitudeStatistic a);

struct ObjectiveSettings {
  ObjectiveKind kind = ObjectiveKind::Mean;
  ImbalanceDefinition definition = ImbalanceDefinition::Magnitude;
  double weight_mean = 1.0;    // weighted: per 1e-7 kg m of mean I_r
  double weight_pct_mi = 0.0;  // weighted: per percent of %MI
  double level = 0.9;          // quantile, cvar: the level (in (0, 1))
  // Robust objective: average over these friction coefficients; empty: one pass with the
  // montecarlo section's friction (nominal abu.friction_mu by default).
  std::vector<double> robust_friction_mu;
  // More failed runs than this fraction (pooled) make the evaluation fail.
  double max_failed_fraction = 0.05;
};

struct ConstraintSettings {
  std::optional<double> max_startup_time_s;
  std::optional<double> max_amplitude_mm;
  AmplitudeStatistic amplitude = AmplitudeStatistic::Max;
  std::optional<double> max_pct_mi;
  // Mean |I_r| over the runs (pooled over the robust set) [1e-7 kg m], whatever objective.definition.
  std::optional<double> max_mean_abs_ir;
  PctMiStatistic pct_mi_statistic = PctMiStatistic::Exact;
  // Peak angular acceleration of the profile, max over segments of 2 pi * 2 |H| / dt [rad/s^2]
  // (exact, no noise): what the drive must be able to follow.
  std::optional<double> max_angular_acceleration_rad_s2;
  double penalty_weight = 0.0;  // > 0: optimised in penalty form (make_startup_profile_problem)
};

// The out-of-sample check of the app: a fresh, larger set of initial conditions.
struct ValidationSettings {
  bool enabled = true;
  InitialConditionKind design = InitialConditionKind::Random;
  std::size_t grid = 32;    // grid design: points per axis (runs = grid^balls)
  std::size_t runs = 1024;
  std::uint64_t seed = 1000003;
};

struct StartupProfileSettings {
  // abu, motor, simulation and the profile TEMPLATE (its values fill segment values that the
  // design leaves out), the initial-condition design, runs, seed and uncertain parameters.
  MonteCarloStudy study;
  std::size_t threads = 0;  // Monte Carlo workers (0: all cores); results do not depend on it
  ProfileDesign design;
  ObjectiveSettings objective;
  ConstraintSettings constraints;
  ValidationSettings validation;
};

// The field lists of the sections (common/config_fields.hpp): reading, writing, validation and the
// problem identity all come from them. The design's absent segment values come from the profile
// template; the validation section's defaults from the montecarlo section.
void describe_fields(FieldArchive& a, ObjectiveSettings& o);
void describe_fields(FieldArchive& a, ConstraintSettings& c);
void describe_design_fields(FieldArchive& a, ProfileDesign& d, const StartupProfile& profile_template);
void describe_validation_fields(FieldArchive& a, ValidationSettings& v, const MonteCarloStudy& study);
// Every section of the settings: abu, profile, motor, simulation, montecarlo, design, objective,
// constraints, validation.
void describe_fields(FieldArchive& a, StartupProfileSettings& s);

// Reads the sections abu, profile, motor, simulation, montecarlo, design, objective, constraints
// and validation of `root` (docs/optimize.md lists every key). Leaves the other sections (optimizer,
// sao) to the caller, who calls root.finish(). Throws ConfigError naming key, value and rule.
StartupProfileSettings read_startup_profile_settings(YamlReader& root);

// The design section alone (the profile template fills absent segment values).
ProfileDesign read_profile_design(YamlReader design, const StartupProfile& profile_template);

// Throws ConfigError for an invalid design (no free variable, bounds reversed, x0 outside the
// bounds, durations not > 0, ...), objective or constraint settings.
void validate(const StartupProfileSettings& s);

// Peak angular acceleration of a profile [rad/s^2]: an inclined sine of height H and duration dt
// peaks at f' = 2 |H| / dt (at its middle), so a = max over segments of 2 pi * 2 |H| / dt.
double peak_angular_acceleration_rad_s2(const StartupProfile& profile);

// FNV-1a, 64 bits.
std::uint64_t fnv1a64(std::string_view text);

class StartupProfileProblem : public opt::Problem {
 public:
  explicit StartupProfileProblem(StartupProfileSettings settings);  // validates; throws ConfigError

  std::string name() const override { return "startup_profile"; }
  std::vector<opt::Variable> variables() const override { return variables_; }
  std::vector<std::string> inequality_names() const override;
  opt::Evaluation evaluate(const std::vector<double>& x) override;
  std::vector<double> initial_point() const override;

  // Evaluation concurrency (optimizer/evaluation_scheduler.hpp): evaluations are independent and
  // may run at once, each with its share of the Monte Carlo threads: one of `concurrent` gets
  // max(1, T / concurrent) of montecarlo.threads = T (0: all cores). With a Monte Carlo runner set
  // (set_monte_carlo_runner) evaluations go one at a time, each spread by that runner, unless the
  // runner takes studies from several threads at once (MPI ranks: abuopt::parallel).
  bool thread_safe() const override { return !runner_ || runner_concurrent_; }
  opt::Evaluation evaluate_shared(const std::vector<double>& x, std::size_t concurrent) override;
  // Sample size (opt::Problem, docs/sao.md "Adaptive sample size"): montecarlo.runs = N. With a
  // nested design (random, halton, sobol: point i does not depend on the design's size, and the
  // uncertain parameters of run i come from hash(seed, i)) the first n runs of the N are the
  // sample at size n, so max_sample_size() = N and evaluate_sampled(x, n) is evaluate(x) on runs
  // 0..n-1 (n = N: exactly evaluate(x)); lhs and grid designs are not nested (max 0).
  std::size_t sample_size() const override { return settings_.study.runs; }
  std::size_t max_sample_size() const override;
  opt::Evaluation evaluate_sampled(const std::vector<double>& x, std::size_t n, std::size_t concurrent = 1) override;

  // Every Monte Carlo of this problem then runs on `runner` (e.g. MPI ranks, abuopt::parallel),
  // which must outlive the evaluations; null: a ThreadPoolRunner of montecarlo.threads each time.
  // Results do not depend on it. `concurrent_studies`: the runner's run_study may be called from
  // several threads at once (then evaluations may run at once too: thread_safe()).
  void set_monte_carlo_runner(std::shared_ptr<BatchRunner> runner, bool concurrent_studies = false) {
    runner_ = std::move(runner);
    runner_concurrent_ = runner_ && concurrent_studies;
  }

  const StartupProfileSettings& settings() const { return settings_; }

  // The mapping x -> profile (fixed values from the design). x must have one entry per variable
  // (std::invalid_argument otherwise); values are not checked (see evaluate()).
  StartupProfile profile_at(const std::vector<double>& x) const;
  // Sum of the durations at x [s].
  double startup_time_s(const std::vector<double>& x) const;
  // The ball count at x (design.ball_count: the variable `balls`, rounded; otherwise the abu's).
  std::size_t balls_at(const std::vector<double>& x) const;
  // The ABU evaluated at x (the abu section, with design.ball_count's balls at x when given).
  AbuParameters abu_at(const std::vector<double>& x) const;
  // Index of the variable `balls` (design.ball_count given), or none.
  std::optional<std::size_t> ball_count_variable() const { return ball_variable_; }

  // Evaluates any profile exactly as evaluate() does, on the in-sample initial conditions, or on
  // another set (design kind/grid/count/seed; `seed` also seeds the uncertain parameters).
  opt::Evaluation evaluate_profile(const StartupProfile& profile) const;
  opt::Evaluation evaluate_profile(const StartupProfile& profile, const InitialConditionDesign& design,
                                   std::size_t runs, std::uint64_t seed) const;
  // The validation set of the settings as (design, runs, seed) for evaluate_profile.
  opt::Evaluation evaluate_out_of_sample(const StartupProfile& profile) const;
  // The design x (its profile and, with design.ball_count, its balls) on the validation set.
  opt::Evaluation evaluate_out_of_sample_at(const std::vector<double>& x) const;

  // Everything that decides the value of evaluate(x) as canonical text, derived from the field
  // lists (identity_fields of the settings): every key of abu, profile, motor, simulation, the
  // Monte Carlo sampling, the fixed values and the order of the free variables, the objective and
  // the constraints. Not in it (changing them keeps archived evaluations valid): bounds, x0,
  // scales, threads, the validation section, optimizer settings.
  std::string identity_text() const;
  // "startup_profile-<16 hex digits of fnv1a64(identity_text())>": the archive's problem id.
  std::string identity() const;
  // What fixes evaluate_out_of_sample() beside the identity: the validation section's design,
  // grid (grid design only), runs and seed, as "random/runs1024/seed12" (keys stored validations).
  std::string validation_identity() const;

 private:
  InitialConditionDesign validation_design() const;
  StartupProfileSettings settings_;
  std::vector<opt::Variable> variables_;
  std::vector<double> x0_;
  // For each variable: segment index and whether it is the duration.
  struct Slot {
    std::size_t segment;
    bool duration;
  };
  std::vector<Slot> slots_;
  std::vector<std::string> constraint_names_;
  std::optional<std::size_t> ball_variable_;  // index of `balls` in x
  std::shared_ptr<BatchRunner> runner_;
  bool runner_concurrent_ = false;

  // balls = 0: the abu as given; otherwise abu_with_ball_count(balls).
  opt::Evaluation evaluate_with_threads(const StartupProfile& profile, const InitialConditionDesign& design,
                                        std::size_t runs, std::uint64_t seed, std::size_t threads,
                                        std::size_t balls = 0) const;
};

}  // namespace abuopt::problems

namespace abuopt::problems {

// The problem as the optimisers see it: a StartupProfileProblem, or with
// constraints.penalty_weight > 0 its exact-L1-penalty form (opt::PenaltyProblem owning it). Throws
// ConfigError for invalid settings.
// `runner`: where its Monte Carlo studies run (StartupProfileProblem::set_monte_carlo_runner, with
// `concurrent_studies`).
std::unique_ptr<opt::Problem> make_startup_profile_problem(const StartupProfileSettings& settings,
                                                           std::shared_ptr<BatchRunner> runner = nullptr,
                                                           bool concurrent_studies = false);

}  // namespace abuopt::problems
