#pragma once
// Statistics of a Monte Carlo study (spec section 5; formulas in docs/montecarlo.md).
//
// Failed runs (outcome status != Ok) are COUNTED (failed, per status) but EXCLUDED from every other
// statistic: residual imbalance, %MI, %LC, settling time and amplitude are over the n_ok runs that
// reached the end time. A failed run has no trustworthy final state; counting it as balanced or as
// unbalanced would bias the figures either way, so the failure rate is reported next to them.
// With n_ok = 0 the statistics are NaN (null in JSON) and the counts are 0.
//
// For each definition of the residual imbalance I_r (magnitude |I_r|, and the report's I_r,x):
//   mean = (1/n) sum I_r, max, min, median and quantiles p10, p90, p95 with linear interpolation
//   between order statistics (Hyndman & Fan type 7, the default of R and NumPy): for sorted
//   x_0 <= ... <= x_{n-1} and probability p, h = (n - 1) p, Q(p) = x_{floor h} + (h - floor h)
//   (x_{floor h + 1} - x_{floor h}).
//   %MI = 100 k / n, k = #runs with I_r >= I, I = m_I e of that run (the imbalance without balls,
//   AbuParameters::imbalance_kgm(), or the run's own m_I when the imbalance mass is uncertain),
//   with its 95 % Wilson score interval (z = 1.959963984540054):
//     centre = (p + z^2/(2n)) / (1 + z^2/n),  half = z / (1 + z^2/n) sqrt(p (1 - p)/n + z^2/(4 n^2))
//   (in percent). When some runs reuse the simulation of an exchanged one (identical balls,
//   MonteCarloStudy::reuse_exchangeable), p is still over all runs but n is the number of distinct
//   (simulated) ok runs: the duplicates add no information.
// %LC = 100 (#ok runs not settled at the end time) / n_ok.
// Settling time: mean, median, max over the settled ok runs. Amplitude: max and mean of
// max_amplitude_mm over the ok runs.
#include <array>
#include <cstddef>
#include <iosfwd>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "abuopt/core/monte_carlo.hpp"
#include "abuopt/core/outcome.hpp"

namespace abuopt {

// Sample quantile, linear interpolation (type 7). `sorted` ascending and non-empty; 0 <= p <= 1.
double quantile_type7(const std::vector<double>& sorted, double p);

// 95 % (or other z) Wilson score interval of a proportion k/n, as fractions in [0, 1].
// n = 0 gives {NaN, NaN}.
std::pair<double, double> wilson_interval(std::size_t k, std::size_t n, double z = 1.959963984540054);
// The same for a proportion p observed on an effective sample size n (not necessarily whole).
std::pair<double, double> wilson_interval_p(double p, double n, double z = 1.959963984540054);

struct ResidualImbalanceStats {
  std::size_t count = 0;     // ok runs
  std::size_t distinct = 0;  // of which simulated for themselves (the rest reuse an exchanged run)
  double mean = 0, min = 0, max = 0, median = 0, p10 = 0, p90 = 0, p95 = 0;  // kg m
  std::size_t mi_count = 0;                   // runs with I_r >= I
  double pct_mi = 0;                          // 100 mi_count / count
  std::array<double, 2> pct_mi_ci95{0, 0};    // Wilson score interval, percent
};

// Number of RunStatus values, and a stable snake_case key for each ("ok", "solver_failure",
// "chatter_limit", "step_limit", "event_limit") used in JSON and CSV.
inline constexpr std::size_t kRunStatusCount = 5;
std::string status_key(RunStatus s);

struct MonteCarloStats {
  std::size_t runs = 0;
  std::size_t ok = 0;
  std::size_t distinct = 0;  // ok runs simulated for themselves (MonteCarloStudy::reuse_exchangeable)
  std::size_t failed = 0;                                  // status != Ok
  std::array<std::size_t, kRunStatusCount> status_counts{};  // indexed by RunStatus
  ResidualImbalanceStats magnitude;  // |I_r| (RunOutcome::residual_imbalance_kgm)
  ResidualImbalanceStats report_x;   // I_r,x (RunOutcome::residual_imbalance_x_kgm), report eq 4.2
  std::size_t not_settled = 0;       // ok runs not settled at the end time
  double pct_lc = 0;                 // 100 not_settled / ok
  std::size_t settled = 0;
  double settling_mean_s = 0, settling_median_s = 0, settling_max_s = 0;
  double amplitude_max_mm = 0, amplitude_mean_mm = 0;
  double wall_time_s = 0;            // of the study (0 when computed from bare samples)
  std::size_t concurrency = 0;
};

MonteCarloStats compute_statistics(const std::vector<MonteCarloSample>& samples);
MonteCarloStats compute_statistics(const MonteCarloResult& result);  // adds wall time, concurrency

// Half-width of the 95 % interval of the mean |I_r| (report_x: I_r,x, in kg m) over the ok runs,
// for the study's sampling (mean_interval_groups): independent runs: 1.96 s / sqrt(n); strata
// (the envelope's stratified draws, run i in cell i mod H, weights 1/H): 1.96 sqrt(sum s_h^2 /
// (H^2 n_h)); replicates (scrambled Sobol', run i in replicate i mod R): t_{R-1} sd(replicate
// means) / sqrt(R). NaN when there are too few ok runs.
enum class IntervalKind { Independent, Strata, Replicates };
struct IntervalLayout {
  IntervalKind kind = IntervalKind::Independent;
  std::size_t groups = 1;
};
IntervalLayout interval_layout(const MonteCarloStudy& s);
double mean_half_width95(const std::vector<MonteCarloSample>& samples, const IntervalLayout& layout,
                         bool report_x = false);

// The summary as one JSON object: runs, ok, failed, status_counts {key: n}, pct_lc, not_settled,
// wall_time_s, concurrency, magnitude {...}, report_x {...} (count, mean, min, max, median, p10,
// p90, p95, mi_count, pct_mi, pct_mi_ci95 [lo, hi]), settling_time_s {settled, mean, median, max},
// max_amplitude_mm {max, mean}, quantile_definition. NaN becomes null.
nlohmann::json to_json(const MonteCarloStats& s);
// The same with the 95 % half-width of each mean from the study's sampling layout
// (magnitude.mean_ci95_half_width, report_x.mean_ci95_half_width): what `abuopt montecarlo --json`
// and the Python module's summary print.
nlohmann::json to_json(const MonteCarloStats& s, const MonteCarloResult& result, const MonteCarloStudy& study);

// Human-readable multi-line summary (both definitions, kg m in units of 1e-7 as in the report).
std::string format_summary(const MonteCarloStats& s);

// ---- Smooth statistics (docs/montecarlo.md, "Smooth statistics"): for optimisation only ----
// Under common random numbers the count %MI is piecewise constant in the design (it moves in steps
// of 100/n when one run's I_r crosses its threshold). These are continuous in the runs' values:
//   smoothed exceedance  p_h = (1/n) sum_i Phi((r_i - 1) / h),  r_i = I_r,i / I_i (I_i the run's
//     threshold, as for %MI), Phi the standard normal CDF (a Gaussian-kernel smoothed indicator),
//     h = 0.9 sd(r) n^(-1/5) (Silverman's rule on the sample: shrinks with n, so p_h tends to the
//     count); h = 0 (all r equal) gives the count itself.
//   quantile             Q(level) of I_r, type 7 (continuous in the values).
//   CVaR                 Q + (1 / (n (1 - level))) sum_i max(0, I_r,i - Q)  (Rockafellar-Uryasev:
//     the mean of the worst (1 - level) fraction; level 0 gives the mean).
// Failed runs are excluded, as everywhere. Validation and every reported figure use the exact
// statistics (compute_statistics).
struct SmoothImbalanceStats {
  std::size_t count = 0;     // ok runs
  double bandwidth = 0;      // h (ratio units)
  double pct_mi = 0;         // 100 p_h, percent
  double level = 0.9;
  double quantile = 0;       // kg m
  double cvar = 0;           // kg m
};
// Silverman's bandwidth 0.9 sd n^(-1/5) of a sample (0 for fewer than 2 values).
double smoothing_bandwidth(const std::vector<double>& values);
// `report_x`: the report's I_r,x instead of |I_r|. level in [0, 1) (std::invalid_argument
// otherwise). No ok run: NaN statistics, count 0.
SmoothImbalanceStats compute_smooth_statistics(const std::vector<MonteCarloSample>& samples, bool report_x,
                                               double level);

// Per-run CSV: header, then one line per sample in index order. Columns:
// index, beta0_1..beta0_N, mu, imbalance_mass_kg (empty when nominal), imbalance_angle_rad,
// stiffness_N_per_m, restitution (this run's effective values: the envelope's draws), beta_final_1..beta_final_N, ir_magnitude_kgm, ir_x_kgm, settled, settling_time_s,
// max_amplitude_mm, events, rhs_evaluations, status. Numbers round-trip exactly (shortest form).
void write_runs_csv(std::ostream& os, const std::vector<MonteCarloSample>& samples);

}  // namespace abuopt
