// The startup-profile design problem (see startup_profile_problem.hpp).
#include "abuopt/problems/startup_profile_problem.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "abuopt/common/config_error.hpp"
#include "abuopt/core/batch_runner.hpp"
#include "abuopt/core/monte_carlo_stats.hpp"
#include "abuopt/core/simulation_config.hpp"
#include "abuopt/optimizer/penalty_problem.hpp"

namespace abuopt::problems {

namespace {

using opt::format_number;

constexpr double kUnit = 1e-7;  // I_r metrics and objectives in units of 1e-7 kg m (the report's)

std::string list_text(const std::vector<double>& v) {
  std::string t = "[";
  for (std::size_t i = 0; i < v.size(); ++i) t += (i ? ", " : "") + format_number(v[i]);
  return t + "]";
}

std::string segment_path(std::size_t i) { return "design.segments[" + std::to_string(i) + "]"; }

void check_value(const DesignValue& v, const std::string& path, bool duration) {
  const std::string kind = duration ? "a duration" : "a frequency";
  if (!v.free) {
    if (duration && !(std::isfinite(v.value) && v.value > 0))
      throw ConfigError(path, format_number(v.value), "must be > 0 (a profile with a duration <= 0 is never simulated)");
    if (!duration && !(std::isfinite(v.value) && v.value >= 0))
      throw ConfigError(path, format_number(v.value), "must be >= 0 (" + kind + ")");
    if (v.value > (duration ? kMaxSegmentDurationS : kMaxFrequencyHz))
      throw ConfigError(path, format_number(v.value),
                        "must be <= " + format_number(duration ? kMaxSegmentDurationS : kMaxFrequencyHz) +
                            (duration ? " s" : " Hz") + " (the largest value a profile may have)");
    return;
  }
  if (!std::isfinite(v.lower)) throw ConfigError(path + ".min", format_number(v.lower), "must be finite");
  if (!std::isfinite(v.upper)) throw ConfigError(path + ".max", format_number(v.upper), "must be finite");
  if (!(v.lower < v.upper))
    throw ConfigError(path + ".min", format_number(v.lower),
                      "must be below " + path + ".max = " + format_number(v.upper) + " (bounds reversed or equal)");
  if (duration && !(v.lower > 0))
    throw ConfigError(path + ".min", format_number(v.lower),
                      "must be > 0 (a profile with a duration <= 0 is never simulated)");
  if (!duration && v.lower < 0)
    throw ConfigError(path + ".min", format_number(v.lower), "must be >= 0 (" + kind + ")");
  const double limit = duration ? kMaxSegmentDurationS : kMaxFrequencyHz;
  if (v.upper > limit)
    throw ConfigError(path + ".max", format_number(v.upper),
                      "must be <= " + format_number(limit) + (duration ? " s" : " Hz") +
                          " (the largest " + (duration ? "segment duration" : "frequency") + " a profile may have)");
  if (!(v.value >= v.lower && v.value <= v.upper))
    throw ConfigError(path + ".x0", format_number(v.value),
                      "must be in [" + format_number(v.lower) + ", " + format_number(v.upper) + "] (the bounds)");
  if (v.scale < 0 || !std::isfinite(v.scale)) throw ConfigError(path + ".scale", format_number(v.scale), "must be > 0");
}

}  // namespace

const EnumNames<ObjectiveKind> kObjectiveKindNames = {
    {ObjectiveKind::Mean, "mean"},
    {ObjectiveKind::PctMi, "pct_mi"},
    {ObjectiveKind::Weighted, "weighted"},
    {ObjectiveKind::SmoothPctMi, "smooth_pct_mi"},
    {ObjectiveKind::Quantile, "quantile"},
    {ObjectiveKind::Cvar, "cvar"}};
const EnumNames<PctMiStatistic> kPctMiStatisticNames = {{PctMiStatistic::Exact, "exact"},
                                                        {PctMiStatistic::Smooth, "smooth"}};
const EnumNames<ImbalanceDefinition> kImbalanceDefinitionNames = {{ImbalanceDefinition::Magnitude, "magnitude"},
                                                                  {ImbalanceDefinition::ReportX, "report_x"}};
const EnumNames<AmplitudeStatistic> kAmplitudeStatisticNames = {{AmplitudeStatistic::Max, "max"},
                                                                {AmplitudeStatistic::Mean, "mean"}};

std::string to_string(ObjectiveKind k) { return enum_name(kObjectiveKindNames, k); }
std::string to_string(ImbalanceDefinition d) { return enum_name(kImbalanceDefinitionNames, d); }
std::string to_string(AmplitudeStatistic a) { return enum_name(kAmplitudeStatisticNames, a); }

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

// ---- The field lists --------------------------------------------------------------------------

namespace {

// A segment value: a number (fixed), a mapping {min, max, x0, scale} (free), or absent (the
// template's value, pre-filled by the list's resize; NaN when the template has no such segment).
void describe_design_value(FieldArchive& a, const char* key, DesignValue& v, std::size_t index) {
  a.number_or_section(key, v.free, v.value, Rule::any(), [&] {
    a.field("min", v.lower, Rule::any(), FieldOptions::required_key().without_identity());
    a.field("max", v.upper, Rule::any(), FieldOptions::required_key().without_identity());
    if (a.reading() && !a.has("x0")) {  // default start: the template's value if inside the bounds
      const double t = v.value;
      v.value = (std::isfinite(t) && t >= v.lower && t <= v.upper) ? t : 0.5 * (v.lower + v.upper);
    }
    a.field("x0", v.value, Rule::any(), FieldOptions::not_identity());
    FieldOptions scale = FieldOptions::not_identity();
    scale.enabled = a.reading() || v.scale > 0;  // 0: upper - lower (never written)
    a.field("scale", v.scale, Rule::positive(), scale);
  });
  if (a.reading() && !v.free && std::isnan(v.value))
    throw ConfigError(a.path(key), "<missing>",
                      "is required (the profile template has no segment " + std::to_string(index) + ")");
}

}  // namespace

void describe_design_fields(FieldArchive& a, ProfileDesign& d, const StartupProfile& tmpl) {
  a.field("start_frequency_hz", d.start_frequency_hz, Rule::non_negative());
  const auto fill = [&](std::size_t n) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const std::size_t old_size = d.segments.size();
    d.segments.resize(n);
    for (std::size_t i = old_size; i < n; ++i) {
      const bool in_template = i < tmpl.segments().size();
      d.segments[i].end_frequency_hz.value = in_template ? tmpl.segments()[i].end_frequency_hz : nan;
      d.segments[i].duration_s.value = in_template ? tmpl.segments()[i].duration_s : nan;
    }
  };
  a.list("segments", d.segments.size(), fill,
         [&](std::size_t i) {
           // hold: true replaces end_frequency_hz (a dwell at the previous end frequency).
           FieldOptions hold = FieldOptions::only_if(true, "");
           hold.enabled = a.reading() || d.segments[i].hold;
           a.field("hold", d.segments[i].hold, hold);
           if (!d.segments[i].hold) describe_design_value(a, "end_frequency_hz", d.segments[i].end_frequency_hz, i);
           describe_design_value(a, "duration_s", d.segments[i].duration_s, i);
         },
         FieldOptions::required_key("(one entry per profile segment: {end_frequency_hz, duration_s})"));
  if (a.reading() && d.segments.empty()) throw ConfigError(a.path("segments"), "[]", "must have at least one segment");
}

void describe_fields(FieldArchive& a, ObjectiveSettings& o) {
  a.field("kind", o.kind, kObjectiveKindNames);
  a.field("definition", o.definition, kImbalanceDefinitionNames);
  a.field("level", o.level, Rule::in_range(1e-9, 0.999999),
          FieldOptions::only_if(o.kind == ObjectiveKind::Quantile || o.kind == ObjectiveKind::Cvar,
                                "is only used with objective.kind: quantile or cvar"));
  const bool weighted = o.kind == ObjectiveKind::Weighted;
  if (a.reading() && weighted && !a.has("weights"))
    throw ConfigError(a.path("weights"), "<missing>", "is required with objective.kind: weighted ({mean: w1, pct_mi: w2})");
  a.section("weights", [&] {
    a.field("mean", o.weight_mean, Rule::non_negative());
    a.field("pct_mi", o.weight_pct_mi, Rule::non_negative());
  }, FieldOptions::only_if(weighted, "is only used with objective.kind: weighted"));
  FieldOptions robust;
  robust.enabled = a.reading() || !o.robust_friction_mu.empty();
  a.section("robust", [&] {
    a.field("friction_mu", o.robust_friction_mu, Rule::in_range(0.0, 0.999), FieldOptions::required_key());
  }, robust);
  a.field("max_failed_fraction", o.max_failed_fraction, Rule::in_range(0.0, 1.0));
}

void describe_fields(FieldArchive& a, ConstraintSettings& c) {
  a.field("max_startup_time_s", c.max_startup_time_s, Rule::positive());
  a.field("max_amplitude_mm", c.max_amplitude_mm, Rule::positive());
  a.field("max_pct_mi", c.max_pct_mi, Rule::in_range(1e-9, 100.0));
  a.field("max_angular_acceleration_rad_s2", c.max_angular_acceleration_rad_s2, Rule::positive());
  a.field("amplitude", c.amplitude, kAmplitudeStatisticNames);
  a.field("penalty_weight", c.penalty_weight, Rule::non_negative());
  FieldOptions statistic;  // written (and in the identity) only when not the default exact count
  statistic.enabled = a.reading() || c.pct_mi_statistic != PctMiStatistic::Exact;
  a.field("pct_mi_statistic", c.pct_mi_statistic, kPctMiStatisticNames, statistic);
}

// The validation section; its defaults follow the Monte Carlo section (seed + 1) and the balls.
void describe_validation_fields(FieldArchive& a, ValidationSettings& v, const MonteCarloStudy& study) {
  const bool runs_given = a.has("runs");
  if (a.reading()) v.seed = study.seed + 1;
  a.field("enabled", v.enabled);
  a.field("design", v.design, kInitialConditionKindNames);
  a.field("grid", v.grid, Rule::at_least(1));
  double grid_runs = 1;
  for (std::size_t b = 0; b < study.setup.abu.balls.size(); ++b) grid_runs *= static_cast<double>(v.grid);
  a.field("runs", v.runs, Rule::at_least(1));
  if (a.reading()) {
    if (!runs_given)
      v.runs = v.design == InitialConditionKind::Grid ? static_cast<std::size_t>(grid_runs) : 1024;
    else if (v.design == InitialConditionKind::Grid && static_cast<double>(v.runs) != grid_runs)
      throw ConfigError(a.path("runs"), std::to_string(v.runs),
                        "must equal validation.grid^balls = " + format_number(grid_runs) + " with the grid design");
  }
  a.field("seed", v.seed, Rule::in_range(0, 9007199254740992.0));
}

void describe_fields(FieldArchive& a, StartupProfileSettings& s) {
  describe_fields(a, s.study.setup);  // abu, profile, motor, simulation
  a.section("montecarlo", [&] { describe_montecarlo_fields(a, s.study, s.threads); },
            FieldOptions::derived_defaults());
  if (a.reading()) validate(s.study, "montecarlo");
  FieldOptions design = FieldOptions::required_key(
      "(design: {segments: [...]} with at least one free {min, max} value)");
  if (a.reading()) s.design.start_frequency_hz = s.study.setup.profile.start_frequency_hz();
  a.section("design", [&] { describe_design_fields(a, s.design, s.study.setup.profile); }, design);
  a.nested("objective", s.objective);
  if (a.reading() && !s.objective.robust_friction_mu.empty() &&
      s.study.uncertain.friction.sampling != FrictionSampling::Nominal)
    throw ConfigError("objective.robust.friction_mu", list_text(s.objective.robust_friction_mu),
                      "cannot be combined with montecarlo.friction (give the friction values in one place)");
  a.nested("constraints", s.constraints);
  FieldOptions validation = FieldOptions::derived_defaults();
  validation.identity = false;  // the out-of-sample check does not decide evaluate(x)
  a.section("validation", [&] { describe_validation_fields(a, s.validation, s.study); }, validation);
}

// ---- Reading ---------------------------------------------------------------------------------

ProfileDesign read_profile_design(YamlReader design, const StartupProfile& tmpl) {
  if (!design.present())
    throw ConfigError("design", "<missing>",
                      "is required (design: {segments: [...]} with at least one free {min, max} value)");
  ProfileDesign d;
  d.start_frequency_hz = tmpl.start_frequency_hz();
  YamlReadArchive a(design);
  describe_design_fields(a, d, tmpl);
  design.finish();
  return d;
}

StartupProfileSettings read_startup_profile_settings(YamlReader& root) {
  StartupProfileSettings s;
  YamlReadArchive a(root);
  describe_fields(a, s);
  validate(s);
  return s;
}

void validate(const StartupProfileSettings& s) {
  validate_fields(s.objective, "objective");
  validate_fields(s.constraints, "constraints");
  const ProfileDesign& d = s.design;
  if (d.segments.empty()) throw ConfigError("design.segments", "[]", "must have at least one segment");
  if (!(std::isfinite(d.start_frequency_hz) && d.start_frequency_hz >= 0 && d.start_frequency_hz <= kMaxFrequencyHz))
    throw ConfigError("design.start_frequency_hz", format_number(d.start_frequency_hz),
                      "must be in [0, " + format_number(kMaxFrequencyHz) + "] Hz");
  std::size_t free = 0;
  for (std::size_t i = 0; i < d.segments.size(); ++i) {
    if (!d.segments[i].hold) check_value(d.segments[i].end_frequency_hz, segment_path(i) + ".end_frequency_hz", false);
    check_value(d.segments[i].duration_s, segment_path(i) + ".duration_s", true);
    free += (!d.segments[i].hold && d.segments[i].end_frequency_hz.free) + d.segments[i].duration_s.free;
  }
  if (free == 0)
    throw ConfigError("design.segments", std::to_string(d.segments.size()) + " segments, all values fixed",
                      "no free variable: give at least one value as {min: ..., max: ...}");
  const ObjectiveSettings& o = s.objective;
  if (o.kind == ObjectiveKind::Weighted && !(o.weight_mean > 0 || o.weight_pct_mi > 0))
    throw ConfigError("objective.weights", "{mean: " + format_number(o.weight_mean) + ", pct_mi: " +
                                               format_number(o.weight_pct_mi) + "}",
                      "at least one weight must be > 0");
  for (std::size_t k = 0; k < o.robust_friction_mu.size(); ++k) {
    const double mu = o.robust_friction_mu[k];
    if (!(std::isfinite(mu) && mu >= 0 && mu < 1))
      throw ConfigError("objective.robust.friction_mu[" + std::to_string(k) + "]", format_number(mu), "must be in [0, 1)");
  }
  if (!(o.max_failed_fraction >= 0 && o.max_failed_fraction <= 1))
    throw ConfigError("objective.max_failed_fraction", format_number(o.max_failed_fraction), "must be in [0, 1]");
  const ConstraintSettings& c = s.constraints;
  auto positive = [](const std::optional<double>& v, const char* key) {
    if (v && !(std::isfinite(*v) && *v > 0)) throw ConfigError(key, format_number(*v), "must be > 0");
  };
  positive(c.max_startup_time_s, "constraints.max_startup_time_s");
  positive(c.max_amplitude_mm, "constraints.max_amplitude_mm");
  positive(c.max_pct_mi, "constraints.max_pct_mi");
  positive(c.max_angular_acceleration_rad_s2, "constraints.max_angular_acceleration_rad_s2");
  if (!(std::isfinite(c.penalty_weight) && c.penalty_weight >= 0))
    throw ConfigError("constraints.penalty_weight", format_number(c.penalty_weight), "must be >= 0");
  if (s.validation.runs < 1) throw ConfigError("validation.runs", "0", "must be >= 1");
  validate(s.study);
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
  const ConstraintSettings& c = settings_.constraints;
  if (c.max_startup_time_s) constraint_names_.push_back("startup_time");
  if (c.max_amplitude_mm) constraint_names_.push_back("amplitude");
  if (c.max_pct_mi) constraint_names_.push_back("pct_mi");
  if (c.max_angular_acceleration_rad_s2) constraint_names_.push_back("angular_acceleration");
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
  return evaluate_profile(profile_at(x));
}

opt::Evaluation StartupProfileProblem::evaluate_shared(const std::vector<double>& x, std::size_t concurrent) {
  if (x.size() != variables_.size() || concurrent <= 1) return evaluate(x);
  const std::size_t all = settings_.threads == 0 ? hardware_threads() : settings_.threads;
  const std::size_t share = std::max<std::size_t>(1, all / concurrent);
  return evaluate_with_threads(profile_at(x), settings_.study.design, settings_.study.runs, settings_.study.seed,
                               share);
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
  return evaluate_with_threads(profile_at(x), settings_.study.design, n, settings_.study.seed, threads);
}

opt::Evaluation StartupProfileProblem::evaluate_profile(const StartupProfile& profile) const {
  return evaluate_profile(profile, settings_.study.design, settings_.study.runs, settings_.study.seed);
}

opt::Evaluation StartupProfileProblem::evaluate_out_of_sample(const StartupProfile& profile) const {
  const ValidationSettings& v = settings_.validation;
  InitialConditionDesign d = settings_.study.design;
  d.kind = v.design;
  d.grid_points_per_axis = v.grid;
  d.count = v.runs;
  d.seed = v.seed;
  return evaluate_profile(profile, d, v.runs, v.seed);
}

opt::Evaluation StartupProfileProblem::evaluate_profile(const StartupProfile& profile,
                                                        const InitialConditionDesign& design, std::size_t runs,
                                                        std::uint64_t seed) const {
  return evaluate_with_threads(profile, design, runs, seed, settings_.threads);
}

opt::Evaluation StartupProfileProblem::evaluate_with_threads(const StartupProfile& profile,
                                                            const InitialConditionDesign& design, std::size_t runs,
                                                            std::uint64_t seed, std::size_t threads) const {
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
  // 95 % half-widths of the two means, 1.96 s / sqrt(n) over the ok runs (the sampling error of
  // this design's figure; docs/sweep.md), and the Wilson interval of the %MI in use.
  auto half_width_95 = [&pooled](bool x_definition) {
    std::vector<double> v;
    for (const auto& smp : pooled)
      if (smp.outcome.ok())
        v.push_back((x_definition ? smp.outcome.residual_imbalance_x_kgm : smp.outcome.residual_imbalance_kgm) / kUnit);
    const double n = static_cast<double>(v.size());
    if (v.size() < 2) return std::numeric_limits<double>::quiet_NaN();
    double mean = 0, ss = 0;
    for (double a : v) mean += a / n;
    for (double a : v) ss += (a - mean) * (a - mean);
    return 1.959963984540054 * std::sqrt(ss / (n - 1) / n);
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
  e.inequality = std::move(g);
  return e;
}

std::string StartupProfileProblem::identity_text() const {
  // Every identity field of the field lists (bounds, x0, scales, threads and the validation
  // section are marked out of it): a new key is in the identity as soon as it is described.
  return "# abuopt startup_profile problem, evaluation v2\n" + identity_fields(settings_);
}

std::string StartupProfileProblem::identity() const {
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(fnv1a64(identity_text())));
  return std::string("startup_profile-") + hex;
}

}  // namespace abuopt::problems
