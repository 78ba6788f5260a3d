// The startup-profile design problem (see startup_profile_problem.hpp).
#include "abuopt/problems/startup_profile_problem.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "abuopt/common/config_error.hpp"
#include "abuopt/core/batch_runner.hpp"
#include "abuopt/core/monte_carlo_stats.hpp"
#include "abuopt/core/simulation_config.hpp"

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

// A segment value: a number (fixed), a mapping {min, max, x0, scale} (free), or absent (fixed at
// the template's value when the template has this segment).
DesignValue read_design_value(YamlReader& seg, const std::string& key, std::optional<double> template_value,
                              std::size_t index) {
  DesignValue v;
  if (!seg.has(key)) {
    if (!template_value)
      throw ConfigError(seg.key_path(key), "<missing>",
                        "is required (the profile template has no segment " + std::to_string(index) + ")");
    v.value = *template_value;
    return v;
  }
  const YAML::Node& n = seg.node();
  if (key == "end_frequency_hz" && n[key].IsScalar() && n[key].Scalar() == "hold") {
    v.hold = true;
    seg.get_string(key);  // marks the key as used
    return v;
  }
  if (n[key].IsMap()) {
    YamlReader m = seg.child(key);
    v.free = true;
    v.lower = m.get_double("min");
    v.upper = m.get_double("max");
    const double fallback = (template_value && *template_value >= v.lower && *template_value <= v.upper)
                                ? *template_value
                                : 0.5 * (v.lower + v.upper);
    v.value = m.get_double_or("x0", fallback);
    v.scale = m.get_double_or("scale", 0.0, Rule::positive());
    m.finish();
    return v;
  }
  v.value = seg.get_double(key);
  return v;
}

void check_value(const DesignValue& v, const std::string& path, bool duration) {
  const std::string kind = duration ? "a duration" : "a frequency";
  if (!v.free) {
    if (duration && !(std::isfinite(v.value) && v.value > 0))
      throw ConfigError(path, format_number(v.value), "must be > 0 (a profile with a duration <= 0 is never simulated)");
    if (!duration && !(std::isfinite(v.value) && v.value >= 0))
      throw ConfigError(path, format_number(v.value), "must be >= 0 (" + kind + ")");
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
  if (!(v.value >= v.lower && v.value <= v.upper))
    throw ConfigError(path + ".x0", format_number(v.value),
                      "must be in [" + format_number(v.lower) + ", " + format_number(v.upper) + "] (the bounds)");
  if (v.scale < 0 || !std::isfinite(v.scale)) throw ConfigError(path + ".scale", format_number(v.scale), "must be > 0");
}

InitialConditionKind kind_of(const std::string& s, const std::string& path) {
  return initial_condition_kind_from_string(s, path);
}

void append_value(std::ostringstream& os, const std::string& name, const DesignValue& v) {
  if (v.hold)
    os << "  " << name << ": hold\n";
  else if (v.free)
    os << "  " << name << ": free\n";
  else
    os << "  " << name << ": " << format_number(v.value) << "\n";
}

std::string uncertain_text(const UncertainParameters& u) {
  std::ostringstream os;
  os << "friction: " << to_string(u.friction.sampling);
  switch (u.friction.sampling) {
    case FrictionSampling::Nominal: break;
    case FrictionSampling::Fixed: os << " " << format_number(u.friction.value); break;
    case FrictionSampling::List: os << " " << list_text(u.friction.values); break;
    case FrictionSampling::Range:
      os << " [" << format_number(u.friction.lo) << ", " << format_number(u.friction.hi) << "]";
      break;
  }
  os << "\nimbalance_mass: " << to_string(u.imbalance_mass.sampling);
  if (u.imbalance_mass.sampling == ImbalanceMassSampling::RelativeRange)
    os << " [" << format_number(u.imbalance_mass.relative_lo) << ", " << format_number(u.imbalance_mass.relative_hi)
       << "]";
  os << "\nimbalance_angle: " << to_string(u.imbalance_angle.sampling);
  if (u.imbalance_angle.sampling == ImbalanceAngleSampling::Fixed) os << " " << format_number(u.imbalance_angle.angle_rad);
  os << "\n";
  return os.str();
}

}  // namespace

std::string to_string(ObjectiveKind k) {
  switch (k) {
    case ObjectiveKind::mean: return "mean";
    case ObjectiveKind::pct_mi: return "pct_mi";
    case ObjectiveKind::weighted: return "weighted";
  }
  return "?";
}
std::string to_string(ImbalanceDefinition d) { return d == ImbalanceDefinition::magnitude ? "magnitude" : "report_x"; }
std::string to_string(AmplitudeStatistic a) { return a == AmplitudeStatistic::max ? "max" : "mean"; }

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

// ---- Reading ---------------------------------------------------------------------------------

ProfileDesign read_profile_design(YamlReader design, const StartupProfile& tmpl) {
  ProfileDesign d;
  if (!design.present())
    throw ConfigError("design", "<missing>",
                      "is required (design: {segments: [...]} with at least one free {min, max} value)");
  d.start_frequency_hz = design.get_double_or("start_frequency_hz", tmpl.start_frequency_hz(), Rule::non_negative());
  if (!design.has("segments"))
    throw ConfigError(design.key_path("segments"), "<missing>",
                      "is required (one entry per profile segment: {end_frequency_hz, duration_s})");
  auto segs = design.children("segments");
  if (segs.empty()) throw ConfigError(design.key_path("segments"), "[]", "must have at least one segment");
  for (std::size_t i = 0; i < segs.size(); ++i) {
    YamlReader& s = segs[i];
    const bool in_template = i < tmpl.segments().size();
    SegmentDesign sd;
    sd.end_frequency_hz = read_design_value(
        s, "end_frequency_hz", in_template ? std::optional<double>(tmpl.segments()[i].end_frequency_hz) : std::nullopt, i);
    sd.duration_s = read_design_value(
        s, "duration_s", in_template ? std::optional<double>(tmpl.segments()[i].duration_s) : std::nullopt, i);
    s.finish();
    d.segments.push_back(sd);
  }
  design.finish();
  return d;
}

StartupProfileSettings read_startup_profile_settings(YamlReader& root) {
  StartupProfileSettings s;
  SimulationSetup setup = read_simulation_setup(root);
  MonteCarloConfig mc = read_monte_carlo_config(root, std::move(setup));
  s.study = std::move(mc.study);
  s.threads = mc.threads;
  s.design = read_profile_design(root.child("design"), s.study.setup.profile);

  YamlReader o = root.child("objective");
  const std::string kind = o.get_choice_or("kind", "mean", {"mean", "pct_mi", "weighted"});
  s.objective.kind = kind == "mean" ? ObjectiveKind::mean : kind == "pct_mi" ? ObjectiveKind::pct_mi : ObjectiveKind::weighted;
  s.objective.definition = o.get_choice_or("definition", "magnitude", {"magnitude", "report_x"}) == "magnitude"
                               ? ImbalanceDefinition::magnitude
                               : ImbalanceDefinition::report_x;
  if (o.has("weights")) {
    YamlReader w = o.child("weights");
    if (s.objective.kind != ObjectiveKind::weighted)
      throw ConfigError(o.key_path("weights"), yaml_value_text(w.node()), "is only used with objective.kind: weighted");
    s.objective.weight_mean = w.get_double_or("mean", 1.0, Rule::non_negative());
    s.objective.weight_pct_mi = w.get_double_or("pct_mi", 0.0, Rule::non_negative());
    w.finish();
  } else {
    o.child("weights");
    if (s.objective.kind == ObjectiveKind::weighted)
      throw ConfigError(o.key_path("weights"), "<missing>", "is required with objective.kind: weighted ({mean: w1, pct_mi: w2})");
  }
  YamlReader robust = o.child("robust");
  if (robust.present()) {
    s.objective.robust_friction_mu = robust.get_double_list("friction_mu", Rule::in_range(0.0, 0.999));
    robust.finish();
  }
  s.objective.max_failed_fraction = o.get_double_or("max_failed_fraction", 0.05, Rule::in_range(0.0, 1.0));
  o.finish();
  if (!s.objective.robust_friction_mu.empty() && s.study.uncertain.friction.sampling != FrictionSampling::Nominal)
    throw ConfigError("objective.robust.friction_mu", list_text(s.objective.robust_friction_mu),
                      "cannot be combined with montecarlo.friction (give the friction values in one place)");

  YamlReader c = root.child("constraints");
  if (c.has("max_startup_time_s")) s.constraints.max_startup_time_s = c.get_double("max_startup_time_s", Rule::positive());
  if (c.has("max_amplitude_mm")) s.constraints.max_amplitude_mm = c.get_double("max_amplitude_mm", Rule::positive());
  if (c.has("max_pct_mi")) s.constraints.max_pct_mi = c.get_double("max_pct_mi", Rule::in_range(1e-9, 100.0));
  if (c.has("max_angular_acceleration_rad_s2"))
    s.constraints.max_angular_acceleration_rad_s2 = c.get_double("max_angular_acceleration_rad_s2", Rule::positive());
  s.constraints.amplitude =
      c.get_choice_or("amplitude", "max", {"max", "mean"}) == "max" ? AmplitudeStatistic::max : AmplitudeStatistic::mean;
  s.constraints.penalty_weight = c.get_double_or("penalty_weight", 0.0, Rule::non_negative());
  c.finish();

  YamlReader v = root.child("validation");
  s.validation.enabled = v.get_bool_or("enabled", true);
  s.validation.design = kind_of(v.get_choice_or("design", "random", {"grid", "random", "lhs", "halton", "sobol"}),
                                v.key_path("design"));
  s.validation.grid = static_cast<std::size_t>(v.get_int_or("grid", 32, Rule::at_least(1)));
  const std::size_t balls = s.study.setup.abu.balls.size();
  double grid_runs = 1;
  for (std::size_t b = 0; b < balls; ++b) grid_runs *= static_cast<double>(s.validation.grid);
  if (v.has("runs")) {
    s.validation.runs = static_cast<std::size_t>(v.get_int("runs", Rule::at_least(1)));
    if (s.validation.design == InitialConditionKind::Grid && static_cast<double>(s.validation.runs) != grid_runs)
      throw ConfigError(v.key_path("runs"), std::to_string(s.validation.runs),
                        "must equal validation.grid^balls = " + format_number(grid_runs) + " with the grid design");
  } else {
    v.get_int_or("runs", 0);
    s.validation.runs = s.validation.design == InitialConditionKind::Grid ? static_cast<std::size_t>(grid_runs) : 1024;
  }
  s.validation.seed = static_cast<std::uint64_t>(
      v.get_int_or("seed", static_cast<long>(s.study.seed + 1), Rule::in_range(0, 9007199254740992.0)));
  v.finish();

  validate(s);
  return s;
}

void validate(const StartupProfileSettings& s) {
  const ProfileDesign& d = s.design;
  if (d.segments.empty()) throw ConfigError("design.segments", "[]", "must have at least one segment");
  if (!(std::isfinite(d.start_frequency_hz) && d.start_frequency_hz >= 0))
    throw ConfigError("design.start_frequency_hz", format_number(d.start_frequency_hz), "must be >= 0");
  std::size_t free = 0;
  for (std::size_t i = 0; i < d.segments.size(); ++i) {
    if (d.segments[i].end_frequency_hz.hold && d.segments[i].end_frequency_hz.free)
      throw ConfigError(segment_path(i) + ".end_frequency_hz", "hold", "a hold segment has no free end frequency");
    if (!d.segments[i].end_frequency_hz.hold)
      check_value(d.segments[i].end_frequency_hz, segment_path(i) + ".end_frequency_hz", false);
    check_value(d.segments[i].duration_s, segment_path(i) + ".duration_s", true);
    free += d.segments[i].end_frequency_hz.free + d.segments[i].duration_s.free;
  }
  if (free == 0)
    throw ConfigError("design.segments", std::to_string(d.segments.size()) + " segments, all values fixed",
                      "no free variable: give at least one value as {min: ..., max: ...}");
  const ObjectiveSettings& o = s.objective;
  if (o.kind == ObjectiveKind::weighted && !(o.weight_mean > 0 || o.weight_pct_mi > 0))
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
      if (!v.free) continue;
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

std::vector<std::string> StartupProfileProblem::inequality_names() const {
  if (settings_.constraints.penalty_weight > 0) return {};
  return constraint_names_;
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
    if (settings_.design.segments[i].end_frequency_hz.hold)
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
  const bool x_def = os.definition == ImbalanceDefinition::report_x;
  auto ir = [x_def](const MonteCarloStats& st) -> const ResidualImbalanceStats& {
    return x_def ? st.report_x : st.magnitude;
  };
  auto objective_of = [&](const MonteCarloStats& st) {
    const double mean = ir(st).mean / kUnit, pct = ir(st).pct_mi;
    switch (os.kind) {
      case ObjectiveKind::mean: return mean;
      case ObjectiveKind::pct_mi: return pct;
      case ObjectiveKind::weighted: return os.weight_mean * mean + os.weight_pct_mi * pct;
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

  ThreadPoolRunner runner(settings_.threads);
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
    objectives.push_back(objective_of(ps));
    pass_pct_mi.push_back(ir(ps).pct_mi);
    for (auto& s : r.samples) pooled.push_back(std::move(s));
  }
  const MonteCarloStats all = compute_statistics(pooled);

  opt::Evaluation e;
  auto& m = e.metrics;
  m["ir_magnitude_mean"] = all.magnitude.mean / kUnit;
  m["ir_magnitude_median"] = all.magnitude.median / kUnit;
  m["ir_magnitude_max"] = all.magnitude.max / kUnit;
  m["ir_x_mean"] = all.report_x.mean / kUnit;
  m["ir_x_median"] = all.report_x.median / kUnit;
  m["ir_x_max"] = all.report_x.max / kUnit;
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
    const double a = c.amplitude == AmplitudeStatistic::max ? all.amplitude_max_mm : all.amplitude_mean_mm;
    g.push_back(a / *c.max_amplitude_mm - 1.0);
  }
  if (c.max_pct_mi) g.push_back(ir(all).pct_mi / *c.max_pct_mi - 1.0);
  if (c.max_angular_acceleration_rad_s2)
    g.push_back(peak_angular_acceleration_rad_s2(profile) / *c.max_angular_acceleration_rad_s2 - 1.0);
  if (c.penalty_weight > 0) {
    m["objective_without_penalty"] = e.objective;
    double pen = 0;
    for (std::size_t i = 0; i < g.size(); ++i) {
      m["g_" + constraint_names_[i]] = g[i];
      pen += std::max(0.0, g[i]);
    }
    e.objective += c.penalty_weight * pen;
  } else {
    e.inequality = std::move(g);
  }
  return e;
}

std::string StartupProfileProblem::identity_text() const {
  const StartupProfileSettings& s = settings_;
  std::ostringstream os;
  os << "# abuopt startup_profile problem, evaluation v1\n";
  os << to_yaml(s.study.setup);
  const SimulationOptions& so = s.study.setup.options;
  os << "simulation_extra: {switch_band: " << format_number(so.switch_band) << ", max_steps: " << so.max_steps
     << ", max_events: " << so.max_events << ", chatter_events: " << so.chatter_events
     << ", chatter_window_s: " << format_number(so.chatter_window_s) << "}\n";
  os << "design:\n  start_frequency_hz: " << format_number(s.design.start_frequency_hz) << "\n";
  for (std::size_t i = 0; i < s.design.segments.size(); ++i) {
    const std::string index = std::to_string(i + 1);
    append_value(os, std::string("f").append(index), s.design.segments[i].end_frequency_hz);
    append_value(os, std::string("dt").append(index), s.design.segments[i].duration_s);
  }
  const InitialConditionDesign d = study_design(s.study);
  os << "montecarlo:\n  design: " << to_string(d.kind) << "\n  grid: " << d.grid_points_per_axis
     << "\n  runs: " << s.study.runs << "\n  seed: " << s.study.seed << "\n  design_seed: " << d.seed
     << "\n  shift: " << d.random_shift << "\n";
  os << uncertain_text(s.study.uncertain);
  const ObjectiveSettings& o = s.objective;
  os << "objective: {kind: " << to_string(o.kind) << ", definition: " << to_string(o.definition)
     << ", weights: [" << format_number(o.weight_mean) << ", " << format_number(o.weight_pct_mi)
     << "], robust_friction_mu: " << list_text(o.robust_friction_mu)
     << ", max_failed_fraction: " << format_number(o.max_failed_fraction) << "}\n";
  const ConstraintSettings& c = s.constraints;
  auto opt_text = [](const std::optional<double>& v) { return v ? format_number(*v) : std::string("none"); };
  os << "constraints: {max_startup_time_s: " << opt_text(c.max_startup_time_s)
     << ", max_amplitude_mm: " << opt_text(c.max_amplitude_mm) << ", amplitude: " << to_string(c.amplitude)
     << ", max_pct_mi: " << opt_text(c.max_pct_mi) << ", penalty_weight: " << format_number(c.penalty_weight);
  // Only when set, so that the identity (archive key) of every earlier config is unchanged.
  if (c.max_angular_acceleration_rad_s2)
    os << ", max_angular_acceleration_rad_s2: " << format_number(*c.max_angular_acceleration_rad_s2);
  os << "}\n";
  return os.str();
}

std::string StartupProfileProblem::identity() const {
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(fnv1a64(identity_text())));
  return std::string("startup_profile-") + hex;
}

}  // namespace abuopt::problems
