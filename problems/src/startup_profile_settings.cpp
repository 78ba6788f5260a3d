// The startup-profile problem's settings: the field lists of its config sections, reading and
// validation (see startup_profile_problem.hpp).
#include "abuopt/problems/startup_profile_problem.hpp"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "abuopt/common/config_error.hpp"
#include "abuopt/core/simulation_config.hpp"

namespace abuopt::problems {

namespace {

using opt::format_number;

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
    {ObjectiveKind::Cvar, "cvar"},
    {ObjectiveKind::StartupTime, "startup_time"}};
const EnumNames<PctMiStatistic> kPctMiStatisticNames = {{PctMiStatistic::Exact, "exact"},
                                                        {PctMiStatistic::Smooth, "smooth"}};
const EnumNames<ImbalanceDefinition> kImbalanceDefinitionNames = {{ImbalanceDefinition::Magnitude, "magnitude"},
                                                                  {ImbalanceDefinition::ReportX, "report_x"}};
const EnumNames<AmplitudeStatistic> kAmplitudeStatisticNames = {{AmplitudeStatistic::Max, "max"},
                                                                {AmplitudeStatistic::Mean, "mean"}};

std::string to_string(ObjectiveKind k) { return enum_name(kObjectiveKindNames, k); }
std::string to_string(ImbalanceDefinition d) { return enum_name(kImbalanceDefinitionNames, d); }
std::string to_string(AmplitudeStatistic a) { return enum_name(kAmplitudeStatisticNames, a); }

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
  // The ball count as a variable (written, and in the identity, only when given: other problems keep their ids).
  FieldOptions balls;
  balls.enabled = a.reading() || d.ball_count.free;
  BallCountDesign& b = d.ball_count;
  a.section("ball_count", [&] {
    if (a.reading()) b.free = true;
    a.field("min", b.lower, Rule::in_range(1, kMaxBallCount), FieldOptions::required_key().without_identity());
    a.field("max", b.upper, Rule::in_range(1, kMaxBallCount), FieldOptions::required_key().without_identity());
    if (a.reading() && !a.has("x0")) b.value = b.lower;
    a.field("x0", b.value, Rule::any(), FieldOptions::not_identity());
    a.field("total_mass_kg", b.total_mass_kg, Rule::positive_at_most(AbuLimits::kMassKg), FieldOptions::required_key());
    a.field("density_kg_m3", b.density_kg_m3, Rule::positive_at_most(1e5),
            FieldOptions::only_if(!a.reading() || !a.has("diameter_m") || !a.has("density_kg_m3"),
                                  "cannot be combined with design.ball_count.diameter_m (the diameter is given)"));
    a.field("diameter_m", b.diameter_m, Rule::positive_at_most(AbuLimits::kLengthM));
  }, balls);
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
  FieldOptions mean_bound;  // written (and in the identity) only when set: older problems keep their ids
  mean_bound.enabled = a.reading() || c.max_mean_abs_ir.has_value();
  a.field("max_mean_abs_ir", c.max_mean_abs_ir, Rule::positive(), mean_bound);
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
  // The envelope of uncertain parameters: drawn per run like the montecarlo keys (envelope.hpp).
  FieldOptions envelope;
  envelope.enabled = a.reading() || !s.study.uncertain.envelope.empty();
  a.section("envelope", [&] { describe_fields(a, s.study.uncertain.envelope); }, envelope);
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
  if (a.reading() && !s.objective.robust_friction_mu.empty() && s.study.uncertain.envelope.friction_mu.given())
    throw ConfigError("objective.robust.friction_mu", list_text(s.objective.robust_friction_mu),
                      "cannot be combined with envelope.friction_mu (give the friction values in one place)");
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
  if (d.ball_count.free) {
    const BallCountDesign& b = d.ball_count;
    const auto whole = [](double v, const char* key) {
      if (v != std::floor(v)) throw ConfigError(std::string("design.ball_count.") + key, format_number(v), "must be a whole number of balls");
    };
    whole(b.lower, "min");
    whole(b.upper, "max");
    whole(b.value, "x0");
    if (!(b.lower < b.upper))
      throw ConfigError("design.ball_count.min", format_number(b.lower),
                        "must be below design.ball_count.max = " + format_number(b.upper) + " (one count: give abu.balls)");
    if (!(b.value >= b.lower && b.value <= b.upper))
      throw ConfigError("design.ball_count.x0", format_number(b.value),
                        "must be in [" + format_number(b.lower) + ", " + format_number(b.upper) + "] (the bounds)");
    if (s.study.design.kind == InitialConditionKind::Grid)
      throw ConfigError("montecarlo.design", "grid",
                        "cannot be used with design.ball_count (a grid's runs = grid^balls change with the count); use "
                        "lhs, random, halton or sobol");
    // every count must make a valid ABU (balls that fit on the track, a valid Monte Carlo)
    for (double n : {b.lower, b.upper}) {
      MonteCarloStudy st = s.study;
      st.setup.abu = abu_with_ball_count(st.setup.abu, static_cast<std::size_t>(n), b);
      try {
        validate(st.setup.abu);
        validate(st);
      } catch (const ConfigError& e) {
        throw ConfigError(std::string("design.ball_count: with ") + format_number(n) + " balls: " + e.what());
      }
    }
  }
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
  positive(c.max_mean_abs_ir, "constraints.max_mean_abs_ir");
  if (!(std::isfinite(c.penalty_weight) && c.penalty_weight >= 0))
    throw ConfigError("constraints.penalty_weight", format_number(c.penalty_weight), "must be >= 0");
  if (s.validation.runs < 1) throw ConfigError("validation.runs", "0", "must be >= 1");
  validate(s.study);
}

}  // namespace abuopt::problems
