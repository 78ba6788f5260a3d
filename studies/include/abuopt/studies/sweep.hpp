#pragma once
// Design sweeps of the startup-profile problem (docs/sweep.md): the design's free variables (or a
// subset; the others stay at their x0) over a full-factorial grid, a Latin hypercube or a Sobol'
// sequence, every point evaluated by the problem's Monte Carlo (its threads) through the
// evaluation archive, so a rerun after a kill evaluates only the points not stored yet, and an
// optimize run on the same config and output folder reuses them (same problem id, same full x).
//
//   sweep:
//     method: grid            # grid | lhs | sobol
//     variables: [dt2, dt3]   # default: every free variable of `design`
//     points: 12              # grid: levels per variable; lhs, sobol: number of points
//     levels: {dt2: 12}       # grid only: levels of one variable (overrides points)
//     seed: 1                 # lhs only
//
// Points in the unit box u in [0,1]^k are mapped to x_i = lower_i + u_i (upper_i - lower_i) of the
// swept variables (exactly lower/upper at u = 0/1); grid level j of n is u = j / (n - 1), the first
// variable varying slowest. Sobol': points 0..N-1 of the plain Joe-Kuo sequence (core's), the
// first point the lower corner; N a power of two keeps its balance. LHS: surrogate's maximin
// Latin hypercube (50 candidates) from the seed.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "abuopt/common/yaml_reader.hpp"
#include "abuopt/optimizer/evaluation_archive.hpp"
#include "abuopt/problems/startup_profile_problem.hpp"

namespace abuopt {

enum class SweepMethod { Grid, Lhs, Sobol };
std::string to_string(SweepMethod m);

struct SweepSettings {
  SweepMethod method = SweepMethod::Grid;
  std::vector<std::string> variables;  // names; empty: every free variable
  std::size_t points = 0;              // grid: per variable; lhs, sobol: in all (0: not given)
  std::vector<std::pair<std::string, std::size_t>> levels;  // grid: per-variable levels
  std::uint64_t seed = 1;
};

// Reads the `sweep` section (strict: unknown keys are errors; finish() is called). `free` are the
// problem's variables (to check names). ConfigError naming the key, value and rule.
SweepSettings read_sweep_settings(YamlReader section, const std::vector<opt::Variable>& free);

// The plan resolved against the problem: which variables, how many levels, the unit-box points.
struct SweepPlan {
  SweepMethod method = SweepMethod::Grid;
  std::vector<std::size_t> swept;   // indices into the problem's variables
  std::vector<std::size_t> levels;  // grid: levels per swept variable
  std::vector<std::vector<double>> unit;  // one row per point, one column per swept variable
  std::vector<std::vector<double>> x;     // the full design vectors (non-swept at x0)
};
// Largest sweep accepted (guards levels^k against typos).
inline constexpr std::size_t kMaxSweepPoints = 1'000'000;
// ConfigError for an impossible plan (no points, too many, a grid level < 2, Sobol' beyond its
// dimensions, LHS with fewer than 2 points).
SweepPlan plan_sweep(const SweepSettings& s, const std::vector<opt::Variable>& vars, const std::vector<double>& x0);

// The unit-box designs alone (rows = points).
std::vector<std::vector<double>> grid_unit_design(const std::vector<std::size_t>& levels);
std::vector<std::vector<double>> sobol_unit_design(std::size_t points, std::size_t dims);
std::vector<std::vector<double>> lhs_unit_design(std::size_t points, std::size_t dims, std::uint64_t seed);

struct SweepPoint {
  std::size_t index = 0;
  std::vector<double> x;
  opt::Evaluation e;
  bool from_archive = false;
  double wall_time_s = 0;  // of this evaluation (0 from the archive)
  double max_violation = 0;
  bool feasible = false;
};

struct SweepResult {
  SweepPlan plan;
  std::vector<SweepPoint> points;  // in plan order; fewer than planned when interrupted
  bool interrupted = false;
  long computed = 0, archive_hits = 0, failed = 0;
  double wall_time_s = 0;
};

// The feasible point with the lowest objective (the first of equals), or null when none is feasible.
const SweepPoint* best_feasible_point(const SweepResult& r);

// Called after every point: the point, points done, points planned, elapsed seconds.
using SweepProgress = std::function<void(const SweepPoint&, std::size_t, std::size_t, double)>;

// Evaluates every point of the plan through `archive` (find, else problem.evaluate and store),
// in order. Stops after the current point when `stop` becomes true (the SIGINT flag of the app).
// A failed evaluation is a counted point, never an exception. constraint_tolerance decides
// `feasible`.
SweepResult run_sweep(opt::Problem& problem, opt::EvaluationArchive& archive, const SweepPlan& plan,
                      const SweepProgress& progress = {}, const std::atomic<bool>* stop = nullptr,
                      double constraint_tolerance = 1e-6);

// r_lock of the sweep's ABU (core/final_states.hpp) when every run has the same parameters (no
// uncertain friction or imbalance, no envelope); nullopt otherwise.
std::optional<double> sweep_lock_radius_kgm(const problems::StartupProfileSettings& s);

// sweep.csv: one line per point: point, from_archive, ok, feasible, objective, objective_hw95,
// every variable, g_<constraint>, every metric (sorted), wall_time_s, message, depth_mean (the mean
// |I_r| over r_lock; empty when sweep_lock_radius_kgm is nullopt). Numbers shortest
// round-trip; absent values empty.
void write_sweep_csv(const std::filesystem::path& path, const problems::StartupProfileProblem& problem,
                     const SweepResult& r);

// The plots (PNG and PDF through gnuplot, scripts runnable from `dir`): 1 variable: objective
// against it with 95 % error bars; a 2-variable grid: maps of the objective and of %MI with
// contours, infeasible points marked; otherwise one panel per swept variable. Returns one message
// per plot ("wrote ...", "skipped: ...", "failed: ...").
std::vector<std::string> write_sweep_plots(const std::filesystem::path& dir,
                                           const problems::StartupProfileProblem& problem, const SweepResult& r);

// Label of the objective with units ("mean |I_r| [1e-7 kg m]") and of a variable ("dt2 [s]").
std::string objective_label(const problems::StartupProfileSettings& s);
std::string variable_label(const std::string& name);
// Half-width of the objective's 95 % interval from the metrics (objective kind mean only; NaN else).
double objective_half_width(const problems::StartupProfileSettings& s, const opt::Evaluation& e);

}  // namespace abuopt
