// The startup-profile design problem (see startup_profile_problem.hpp).
#include "abuopt/problems/startup_profile_problem.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "abuopt/common/config_error.hpp"
#include "abuopt/core/batch_runner.hpp"
#include "abuopt/core/model_version.hpp"
#include "abuopt/core/monte_carlo_stats.hpp"
#include "abuopt/core/simulation_config.hpp"
#include "abuopt/optimizer/penalty_problem.hpp"

namespace abuopt::problems {

namespace {

using opt::format_number;

constexpr double kUnit = 1e-7;  // I_r metrics and objectives in units of 1e-7 kg m (the report's)

}  // namespace

double peak_angular_acceleration_rad_s2(const StartupProfile& profile) {
  double peak = 0, f0 = profile.start_frequency_hz();
  for (const auto& g : profile.segments()) {
    peak = std::max(peak, 2 * M_PI * 2 * std::abs(g.end_frequency_hz - f0) / g.duration_s);
    f0 = g.end_frequency_hz;
  }
  return peak;
}

std::uint64_t fnv1a64(std::string_view text) {
  std::uint64_t h = 14695981039346656037ull;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

// ---- The problem -----------------------------------------------------------------------------

StartupProfileProblem::StartupProfileProblem(StartupProfileSettings settings) : settings_(std::move(settings)) {
  validate(settings_);
  const auto& segs = settings_.design.segments;
  for (std::size_t i = 0; i < segs.size(); ++i) {
    for (int which = 0; which < 2; ++which) {
      const DesignValue& v = which == 0 ? segs[i].end_frequency_hz : segs[i].duration_s;
      if (!v.free || (which == 0 && segs[i].hold)) continue;
      opt::Variable var;
      var.name = (which == 0 ? "f" : "dt") + std::to_string(i + 1);
      var.lower = v.lower;
      var.upper = v.upper;
      var.scale = v.scale > 0 ? v.scale : v.upper - v.lower;
      variables_.push_back(var);
      x0_.push_back(v.value);
      slots_.push_back({i, which == 1});
    }
  }
  const BallCountDesign& bc = settings_.design.ball_count;
  if (bc.free) {
    opt::Variable var;
    var.name = "balls";
    var.lower = bc.lower - 0.5;
    var.upper = bc.upper + 0.5;
    var.scale = var.upper - var.lower;
    ball_variable_ = variables_.size();
    variables_.push_back(var);
    x0_.push_back(bc.value);
  }
  const ConstraintSettings& c = settings_.constraints;
  if (c.max_startup_time_s) constraint_names_.push_back("startup_time");
  if (c.max_amplitude_mm) constraint_names_.push_back("amplitude");
  if (c.max_pct_mi) constraint_names_.push_back("pct_mi");
  if (c.max_angular_acceleration_rad_s2) constraint_names_.push_back("angular_acceleration");
  if (c.max_mean_abs_ir) constraint_names_.push_back("mean_abs_ir");
}

std::vector<std::string> StartupProfileProblem::inequality_names() const { return constraint_names_; }

std::unique_ptr<opt::Problem> make_startup_profile_problem(const StartupProfileSettings& settings,
                                                           std::shared_ptr<BatchRunner> runner,
                                                           bool concurrent_studies) {
  auto problem = std::make_unique<StartupProfileProblem>(settings);
  if (runner) problem->set_monte_carlo_runner(std::move(runner), concurrent_studies);
  const double w = settings.constraints.penalty_weight;
  if (w > 0) return std::make_unique<opt::PenaltyProblem>(std::move(problem), w);
  return problem;
}

std::vector<double> StartupProfileProblem::initial_point() const { return x0_; }

StartupProfile StartupProfileProblem::profile_at(const std::vector<double>& x) const {
  if (x.size() != variables_.size())
    throw std::invalid_argument("startup profile problem: the problem has " + std::to_string(variables_.size()) +
                                " variables, the design vector has " + std::to_string(x.size()));
  std::vector<InclinedSineSegment> segs;
  for (const auto& s : settings_.design.segments) segs.push_back({s.end_frequency_hz.value, s.duration_s.value});
  for (std::size_t k = 0; k < slots_.size(); ++k) {
    InclinedSineSegment& g = segs[slots_[k].segment];
    (slots_[k].duration ? g.duration_s : g.end_frequency_hz) = x[k];
  }
  // Holds take the previous end frequency (the start frequency for the first segment).
  for (std::size_t i = 0; i < segs.size(); ++i)
    if (settings_.design.segments[i].hold)
      segs[i].end_frequency_hz = i == 0 ? settings_.design.start_frequency_hz : segs[i - 1].end_frequency_hz;
  return StartupProfile(std::move(segs), settings_.design.start_frequency_hz);
}

std::size_t ball_count_at(const BallCountDesign& b, double x) {
  const double n = std::isfinite(x) ? std::round(x) : b.lower;
  return static_cast<std::size_t>(std::clamp(n, b.lower, b.upper));
}

AbuParameters abu_with_ball_count(const AbuParameters& abu, std::size_t n, const BallCountDesign& b) {
  AbuParameters p = abu;
  Ball ball;
  ball.mass_kg = b.total_mass_kg / static_cast<double>(n);
  ball.diameter_m = b.diameter_m ? *b.diameter_m : std::cbrt(6.0 * ball.mass_kg / (M_PI * b.density_kg_m3));
  p.balls.assign(n, ball);
  return p;
}

std::size_t StartupProfileProblem::balls_at(const std::vector<double>& x) const {
  if (!ball_variable_) return settings_.study.setup.abu.balls.size();
  if (x.size() != variables_.size())
    throw std::invalid_argument("startup profile problem: the problem has " + std::to_string(variables_.size()) +
                                " variables, the design vector has " + std::to_string(x.size()));
  return ball_count_at(settings_.design.ball_count, x[*ball_variable_]);
}

AbuParameters StartupProfileProblem::abu_at(const std::vector<double>& x) const {
  if (!ball_variable_) return settings_.study.setup.abu;
  return abu_with_ball_count(settings_.study.setup.abu, balls_at(x), settings_.design.ball_count);
}

double StartupProfileProblem::startup_time_s(const std::vector<double>& x) const {
  const StartupProfile p = profile_at(x);
  double t = 0;
  for (const auto& g : p.segments()) t += g.duration_s;
  return t;
}

opt::Evaluation StartupProfileProblem::evaluate(const std::vector<double>& x) {
  if (x.size() != variables_.size())
    return opt::Evaluation::failed("the problem has " + std::to_string(variables_.size()) +
                                   " variables, the design vector has " + std::to_string(x.size()));
  const StartupProfile p = profile_at(x);
  if (!ball_variable_) return evaluate_profile(p);
  return evaluate_with_threads(p, settings_.study.design, settings_.study.runs, settings_.study.seed, settings_.threads,
                               balls_at(x));
}

// The study's initial-condition design with the validation's kind, grid, run count and seed.
InitialConditionDesign StartupProfileProblem::validation_design() const {
  const ValidationSettings& v = settings_.validation;
  InitialConditionDesign d = settings_.study.design;
  d.kind = v.design;
  d.grid_points_per_axis = v.grid;
  d.count = v.runs;
  d.seed = v.seed;
  return d;
}

opt::Evaluation StartupProfileProblem::evaluate_out_of_sample_at(const std::vector<double>& x) const {
  const ValidationSettings& v = settings_.validation;
  const InitialConditionDesign d = validation_design();
  return evaluate_with_threads(profile_at(x), d, v.runs, v.seed, settings_.threads,
                               ball_variable_ ? balls_at(x) : 0);
}

opt::Evaluation StartupProfileProblem::evaluate_shared(const std::vector<double>& x, std::size_t concurrent) {
  if (x.size() != variables_.size() || concurrent <= 1) return evaluate(x);
  const std::size_t all = settings_.threads == 0 ? hardware_threads() : settings_.threads;
  const std::size_t share = std::max<std::size_t>(1, all / concurrent);
  return evaluate_with_threads(profile_at(x), settings_.study.design, settings_.study.runs, settings_.study.seed,
                               share, ball_variable_ ? balls_at(x) : 0);
}

std::size_t StartupProfileProblem::max_sample_size() const {
  switch (settings_.study.design.kind) {
    case InitialConditionKind::Random:
    case InitialConditionKind::Halton:
    case InitialConditionKind::Sobol: return settings_.study.runs;
    case InitialConditionKind::Grid:
    case InitialConditionKind::LatinHypercube: return 0;
  }
  return 0;
}

opt::Evaluation StartupProfileProblem::evaluate_sampled(const std::vector<double>& x, std::size_t n,
                                                        std::size_t concurrent) {
  if (n == settings_.study.runs) return concurrent > 1 ? evaluate_shared(x, concurrent) : evaluate(x);
  if (n < 1 || n > max_sample_size())
    throw std::invalid_argument("StartupProfileProblem::evaluate_sampled: n = " + std::to_string(n) +
                                " is outside [1, " + std::to_string(max_sample_size()) + "] (montecarlo.design " +
                                to_string(settings_.study.design.kind) + ", runs " +
                                std::to_string(settings_.study.runs) + ")");
  if (x.size() != variables_.size())
    return opt::Evaluation::failed("the problem has " + std::to_string(variables_.size()) +
                                   " variables, the design vector has " + std::to_string(x.size()));
  const std::size_t all = settings_.threads == 0 ? hardware_threads() : settings_.threads;
  const std::size_t threads =
      concurrent > 1 ? std::max<std::size_t>(1, all / concurrent) : settings_.threads;
  return evaluate_with_threads(profile_at(x), settings_.study.design, n, settings_.study.seed, threads,
                               ball_variable_ ? balls_at(x) : 0);
}

opt::Evaluation StartupProfileProblem::evaluate_profile(const StartupProfile& profile) const {
  return evaluate_profile(profile, settings_.study.design, settings_.study.runs, settings_.study.seed);
}

opt::Evaluation StartupProfileProblem::evaluate_out_of_sample(const StartupProfile& profile) const {
  const ValidationSettings& v = settings_.validation;
  const InitialConditionDesign d = validation_design();
  return evaluate_profile(profile, d, v.runs, v.seed);
}

opt::Evaluation StartupProfileProblem::evaluate_profile(const StartupProfile& profile,
                                                        const InitialConditionDesign& design, std::size_t runs,
                                                        std::uint64_t seed) const {
  return evaluate_with_threads(profile, design, runs, seed, settings_.threads);
}

opt::Evaluation StartupProfileProblem::evaluate_with_threads(const StartupProfile& profile,
                                                            const InitialConditionDesign& design, std::size_t runs,
                                                            std::uint64_t seed, std::size_t threads,
                                                            std::size_t balls) const {
  // Guard: a profile whose durations are not > 0 (or values not finite) is never simulated.
  const auto& segs = profile.segments();
  for (std::size_t i = 0; i < segs.size(); ++i) {
    if (!(std::isfinite(segs[i].duration_s) && segs[i].duration_s > 0))
      return opt::Evaluation::failed("segment " + std::to_string(i + 1) + " duration " +
                                     format_number(segs[i].duration_s) + " s is not > 0: not simulated");
    if (!std::isfinite(segs[i].end_frequency_hz))
      return opt::Evaluation::failed("segment " + std::to_string(i + 1) + " end frequency is not finite: not simulated");
  }

  const ObjectiveSettings& os = settings_.objective;
  const bool x_def = os.definition == ImbalanceDefinition::ReportX;
  auto ir = [x_def](const MonteCarloStats& st) -> const ResidualImbalanceStats& {
    return x_def ? st.report_x : st.magnitude;
  };
  const bool smooth_objective = os.kind == ObjectiveKind::SmoothPctMi || os.kind == ObjectiveKind::Quantile ||
                                os.kind == ObjectiveKind::Cvar;
  const bool smooth_constraint = settings_.constraints.pct_mi_statistic == PctMiStatistic::Smooth;
  const bool smooth_wanted = smooth_objective || smooth_constraint;
  auto objective_of = [&](const MonteCarloStats& st, const std::vector<MonteCarloSample>& samples) {
    const double mean = ir(st).mean / kUnit, pct = ir(st).pct_mi;
    switch (os.kind) {
      case ObjectiveKind::Mean: return mean;
      case ObjectiveKind::PctMi: return pct;
      case ObjectiveKind::Weighted: return os.weight_mean * mean + os.weight_pct_mi * pct;
      case ObjectiveKind::StartupTime: return profile.duration_s();
      case ObjectiveKind::SmoothPctMi:
      case ObjectiveKind::Quantile:
      case ObjectiveKind::Cvar: {
        const SmoothImbalanceStats sm = compute_smooth_statistics(samples, x_def, os.level);
        return os.kind == ObjectiveKind::SmoothPctMi ? sm.pct_mi
               : os.kind == ObjectiveKind::Quantile  ? sm.quantile / kUnit
                                                     : sm.cvar / kUnit;
      }
    }
    return mean;
  };

  MonteCarloStudy st = settings_.study;
  st.setup.profile = profile;
  st.design = design;
  if (balls > 0) st.setup.abu = abu_with_ball_count(st.setup.abu, balls, settings_.design.ball_count);
  st.runs = runs;
  st.seed = seed;
  std::vector<std::optional<double>> passes;
  if (os.robust_friction_mu.empty())
    passes.push_back(std::nullopt);
  else
    for (double mu : os.robust_friction_mu) passes.push_back(mu);

  ThreadPoolRunner own_runner(threads);
  BatchRunner& runner = runner_ ? *runner_ : own_runner;
  std::vector<MonteCarloSample> pooled;
  std::vector<double> objectives, pass_pct_mi;
  std::vector<std::array<double, 2>> pass_hw;  // per pass: 95 % half-widths of mean |I_r|, I_r,x [kg m]
  double wall = 0;
  for (const auto& mu : passes) {
    if (mu) {
      st.uncertain.friction = FrictionUncertainty{};
      st.uncertain.friction.sampling = FrictionSampling::Fixed;
      st.uncertain.friction.value = *mu;
    }
    MonteCarloResult r;
    try {
      r = run_monte_carlo(st, runner);
    } catch (const ConfigError& e) {
      return opt::Evaluation::failed(std::string("profile not simulated: ") + e.what());
    }
    const MonteCarloStats ps = compute_statistics(r);
    wall += r.wall_time_s;
    if (ps.ok == 0)
      return opt::Evaluation::failed("every run failed" +
                                     (mu ? " at friction mu = " + format_number(*mu) : std::string()));
    objectives.push_back(objective_of(ps, r.samples));
    pass_pct_mi.push_back(ir(ps).pct_mi);
    const IntervalLayout layout = interval_layout(st);
    pass_hw.push_back({mean_half_width95(r.samples, layout, false), mean_half_width95(r.samples, layout, true)});
    for (auto& s : r.samples) pooled.push_back(std::move(s));
  }
  const MonteCarloStats all = compute_statistics(pooled);
  SmoothImbalanceStats smooth;
  if (smooth_wanted) smooth = compute_smooth_statistics(pooled, x_def, os.level);

  opt::Evaluation e;
  auto& m = e.metrics;
  m["ir_magnitude_mean"] = all.magnitude.mean / kUnit;
  m["ir_magnitude_median"] = all.magnitude.median / kUnit;
  m["ir_magnitude_max"] = all.magnitude.max / kUnit;
  m["ir_x_mean"] = all.report_x.mean / kUnit;
  m["ir_x_median"] = all.report_x.median / kUnit;
  m["ir_x_max"] = all.report_x.max / kUnit;
  // 95 % half-widths of the two means (the sampling error of this design's figure; docs/sweep.md):
  // core's mean_half_width95 with each pass's sampling layout (independent runs, the envelope's
  // strata or the Sobol' replicates: interval_layout), the passes combined as independent equal-
  // weight means, sqrt(sum hw_p^2) / P; and the Wilson interval of the %MI in use.
  auto half_width_95 = [&pass_hw](bool x_definition) {
    double ss = 0;
    for (const auto& hw : pass_hw) ss += hw[x_definition ? 1 : 0] * hw[x_definition ? 1 : 0];
    return pass_hw.empty() ? std::numeric_limits<double>::quiet_NaN()
                           : std::sqrt(ss) / static_cast<double>(pass_hw.size()) / kUnit;
  };
  m["ir_magnitude_mean_hw95"] = half_width_95(false);
  m["ir_x_mean_hw95"] = half_width_95(true);
  m["pct_mi_ci95_lo"] = ir(all).pct_mi_ci95[0];
  m["pct_mi_ci95_hi"] = ir(all).pct_mi_ci95[1];
  m["pct_mi_magnitude"] = all.magnitude.pct_mi;
  m["pct_mi_x"] = all.report_x.pct_mi;
  m["pct_mi"] = ir(all).pct_mi;
  m["pct_lc"] = all.pct_lc;
  m["amplitude_max_mm"] = all.amplitude_max_mm;
  m["amplitude_mean_mm"] = all.amplitude_mean_mm;
  m["startup_time_s"] = profile.duration_s();
  m["end_time_s"] = pooled.empty() ? 0.0 : pooled.front().outcome.end_time_s;
  m["runs"] = static_cast<double>(all.runs);
  m["failed_runs"] = static_cast<double>(all.failed);
  m["mc_wall_time_s"] = wall;
  if (smooth_wanted) {
    m["pct_mi_smooth"] = smooth.pct_mi;
    m["ir_quantile"] = smooth.quantile / kUnit;
    m["ir_cvar"] = smooth.cvar / kUnit;
    m["smoothing_bandwidth"] = smooth.bandwidth;
  }
  m["peak_angular_acceleration_rad_s2"] = peak_angular_acceleration_rad_s2(profile);
  if (balls > 0) m["balls"] = static_cast<double>(balls);
  if (passes.size() > 1 || passes.front()) {
    for (std::size_t k = 0; k < passes.size(); ++k) {
      const std::string tag = std::to_string(k + 1);
      m["mu" + tag] = *passes[k];
      m["objective_mu" + tag] = objectives[k];
      m["pct_mi_mu" + tag] = pass_pct_mi[k];
    }
  }

  if (static_cast<double>(all.failed) > os.max_failed_fraction * static_cast<double>(all.runs)) {
    opt::Evaluation f = opt::Evaluation::failed(
        std::to_string(all.failed) + " of " + std::to_string(all.runs) + " runs failed (more than objective.max_failed_fraction = " +
        format_number(os.max_failed_fraction) + ")");
    f.metrics = std::move(m);
    return f;
  }

  double obj = 0;
  for (double v : objectives) obj += v;
  e.objective = obj / static_cast<double>(objectives.size());
  if (os.kind == ObjectiveKind::StartupTime) e.objective = profile.duration_s();  // exact, not an average

  const ConstraintSettings& c = settings_.constraints;
  std::vector<double> g;
  if (c.max_startup_time_s) g.push_back(profile.duration_s() / *c.max_startup_time_s - 1.0);
  if (c.max_amplitude_mm) {
    const double a = c.amplitude == AmplitudeStatistic::Max ? all.amplitude_max_mm : all.amplitude_mean_mm;
    g.push_back(a / *c.max_amplitude_mm - 1.0);
  }
  if (c.max_pct_mi) g.push_back((smooth_constraint ? smooth.pct_mi : ir(all).pct_mi) / *c.max_pct_mi - 1.0);
  if (c.max_angular_acceleration_rad_s2)
    g.push_back(peak_angular_acceleration_rad_s2(profile) / *c.max_angular_acceleration_rad_s2 - 1.0);
  if (c.max_mean_abs_ir) g.push_back(all.magnitude.mean / kUnit / *c.max_mean_abs_ir - 1.0);
  e.inequality = std::move(g);
  return e;
}

std::string StartupProfileProblem::identity_text() const {
  // Every identity field of the field lists (bounds, x0, scales, threads and the validation
  // section are marked out of it): a new key is in the identity as soon as it is described.
  // With hard contact the contact model's version too (core/model_version.hpp): archives of an
  // older contact model do not answer; the identities of runs without contact stay as they were.
  std::string text = "# abuopt startup_profile problem, evaluation v2\n";
  if (settings_.study.setup.abu.ball_contact == BallContact::Hard)
    text += "# contact model v" + std::to_string(kContactModelVersion) + "\n";
  return text + identity_fields(settings_);
}

std::string StartupProfileProblem::validation_identity() const {
  const ValidationSettings& v = settings_.validation;
  std::string text = to_string(v.design);
  if (v.design == InitialConditionKind::Grid) text += "/grid" + std::to_string(v.grid);
  return text + "/runs" + std::to_string(v.runs) + "/seed" + std::to_string(v.seed);
}

std::string StartupProfileProblem::identity() const {
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(fnv1a64(identity_text())));
  return std::string("startup_profile-") + hex;
}

}  // namespace abuopt::problems
