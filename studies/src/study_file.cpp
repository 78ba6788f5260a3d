// The study file (studies/include/abuopt/studies/study.hpp, docs/study.md): reading, validation and
// what one choice (a ball count) makes of it. The sections that other commands share (abu, motor,
// simulation, the profile, the Monte Carlo sampling, the uncertain parameters, the design family,
// the objective and constraints) are read through their own field lists; only the study's own keys
// (choices, relative constraints, stages, budget) are read here.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/text.hpp"
#include "abuopt/core/simulation_config.hpp"
#include "abuopt/studies/study.hpp"

namespace abuopt::studies {

const EnumNames<StageKind> kStageKindNames = {{StageKind::Global, "global"},
                                              {StageKind::Local, "local"},
                                              {StageKind::Replicate, "replicate"},
                                              {StageKind::Validate, "validate"},
                                              {StageKind::Pareto, "pareto"}};

std::string to_string(StageKind k) { return enum_name(kStageKindNames, k); }

namespace {

constexpr double kMaxSeed = 9007199254740992.0;  // 2^53: seeds are exact in YAML numbers

std::vector<std::uint64_t> read_seeds(YamlReader& r, const std::string& key) {
  std::vector<std::uint64_t> out;
  for (double v : r.get_double_list(key, Rule::in_range(0, kMaxSeed))) {
    if (v != std::floor(v)) throw ConfigError(r.key_path(key), format_number(v), "seeds must be whole numbers");
    out.push_back(static_cast<std::uint64_t>(v));
  }
  if (out.empty()) throw ConfigError(r.key_path(key), "[]", "must hold at least one seed");
  return out;
}

StageSpec read_stage(YamlReader& r) {
  StageSpec s;
  if (!r.has("kind"))
    throw ConfigError(r.key_path("kind"), "<missing>", "is required (global, local, pareto, replicate or validate)");
  const std::string kind = r.get_choice_or("kind", "", {"global", "local", "pareto", "replicate", "validate"});
  for (const auto& [k, name] : kStageKindNames)
    if (name == kind) s.kind = k;
  s.name = r.get_string_or("name", kind);
  const bool optimiser = s.kind == StageKind::Global || s.kind == StageKind::Local || s.kind == StageKind::Pareto;
  if (s.kind == StageKind::Pareto) {
    r.get_choice_or("over", "startup_time", {"startup_time"});
    if (!r.has("bounds"))
      throw ConfigError(r.key_path("bounds"), "<missing>",
                        "is required for a pareto stage (the bounds on the startup time [s], e.g. [8, 11, 15, 19])");
    s.pareto_bounds = r.get_double_list("bounds", Rule::positive_at_most(1e4));
    if (s.pareto_bounds.empty()) throw ConfigError(r.key_path("bounds"), "[]", "must hold at least one bound");
    std::sort(s.pareto_bounds.begin(), s.pareto_bounds.end());
    for (std::size_t i = 1; i < s.pareto_bounds.size(); ++i)
      if (s.pareto_bounds[i] == s.pareto_bounds[i - 1])
        throw ConfigError(r.key_path("bounds"), format_number(s.pareto_bounds[i]), "each bound may appear once");
  }
  if (optimiser) {
    if (!r.has("optimizer"))
      throw ConfigError(r.key_path("optimizer"), "<missing>",
                        "is required for a " + kind + " stage ({algorithm: ..., max_evaluations: ...})");
    YamlReader o = r.child("optimizer");
    s.optimizer = opt::read_optimizer_options(o);
    s.optimizer.validate();
    s.penalty_weight = r.get_double_or("penalty_weight", s.penalty_weight, Rule::positive());
    if (s.kind == StageKind::Pareto) {  // optional: the front's points on fresh samples
      if (r.has("seeds")) s.seeds = read_seeds(r, "seeds");
      s.runs = static_cast<std::size_t>(r.get_int_or("runs", 0, Rule::in_range(0, 1e7)));
      if (r.has("map")) throw ConfigError(r.key_path("map"), "<given>", "is only used by the validate stage");
    } else {
      for (const char* k : {"seeds", "runs", "map"})
        if (r.has(k)) throw ConfigError(r.key_path(k), "<given>", "is only used by replicate, validate and pareto stages");
    }
  } else {
    if (r.has("optimizer"))
      throw ConfigError(r.key_path("optimizer"), "<given>", "is only used by global, local and pareto stages");
    if (!r.has("seeds"))
      throw ConfigError(r.key_path("seeds"), "<missing>",
                        "is required for a " + kind + " stage (one fresh sample per seed, e.g. [101, 102])");
    s.seeds = read_seeds(r, "seeds");
    s.runs = static_cast<std::size_t>(r.get_int_or("runs", 0, Rule::in_range(0, 1e7)));
    if (r.has("map")) {
      if (s.kind != StageKind::Validate)
        throw ConfigError(r.key_path("map"), "<given>", "is only used by the validate stage");
      YamlReader m = r.child("map");
      s.map_friction_mu = m.get_double_list("friction_mu", Rule::in_range(0.0, 0.999));
      s.map_imbalance_factor = m.get_double_list("imbalance_mass_factor", Rule::in_range(0.01, 10.0));
      s.map_runs = static_cast<std::size_t>(m.get_int_or("runs", 0, Rule::in_range(0, 1e7)));
      if (s.map_friction_mu.empty() || s.map_imbalance_factor.empty())
        throw ConfigError(m.key_path("friction_mu"), "[]", "the map needs at least one friction and one imbalance value");
      m.finish();
    }
  }
  r.finish();
  return s;
}

void check_stage_order(std::vector<StageSpec>& stages, const std::string& path) {
  if (stages.empty()) throw ConfigError(path, "[]", "must hold at least one stage (global, local, replicate, validate)");
  bool optimiser_seen = false, replicate_seen = false, validate_seen = false;
  for (std::size_t i = 0; i < stages.size(); ++i) {
    const std::string key = path + "[" + std::to_string(i) + "].kind";
    const StageKind k = stages[i].kind;
    if (validate_seen) throw ConfigError(key, to_string(k), "no stage may follow the validate stage");
    if ((k == StageKind::Global || k == StageKind::Local) && replicate_seen)
      throw ConfigError(key, to_string(k), "optimiser stages must come before the replicate stage");
    if (k == StageKind::Replicate && replicate_seen) throw ConfigError(key, "replicate", "only one replicate stage");
    if ((k == StageKind::Replicate || k == StageKind::Validate) && !optimiser_seen)
      throw ConfigError(key, to_string(k), "needs a global or local stage before it (a design to check)");
    if (k == StageKind::Pareto && !optimiser_seen)
      throw ConfigError(key, "pareto", "needs a global or local stage before it (the front starts from its best design)");
    optimiser_seen |= k == StageKind::Global || k == StageKind::Local;
    replicate_seen |= k == StageKind::Replicate;
    validate_seen |= k == StageKind::Validate;
  }
  // unique names: "local", "local_2", ...
  for (std::size_t i = 0; i < stages.size(); ++i) {
    int n = 1;
    for (std::size_t j = 0; j < i; ++j) n += stages[j].name == stages[i].name;
    if (n > 1) stages[i].name += "_" + std::to_string(n);
  }
}

std::optional<double> optional_positive(YamlReader& r, const char* key) {
  if (!r.has(key)) return std::nullopt;
  return r.get_double(key, Rule::positive());
}

}  // namespace

StudyFile read_study_file(const std::string& path) {
  StudyFile f;
  f.path = path;
  YamlReader root = YamlReader::load_file(path);
  f.title = root.get_string_or("title", std::filesystem::path(path).stem().string());
  SimulationSetup& setup = f.base.setup;
  setup.abu = read_abu_parameters(root.child("abu"));
  setup.motor = read_motor(root.child("motor"));
  setup.options = read_simulation_options(root.child("simulation"));
  if (!root.has("baseline"))
    throw ConfigError("baseline", "<missing>", "is required (the profile the designs are compared with)");
  setup.profile = read_profile(root.child("baseline"));

  {  // the initial ball angles: the same for every design (common random numbers)
    YamlReader s = root.child("sampling");
    for (const char* k : {"friction", "imbalance"})
      if (s.has(k))
        throw ConfigError(s.key_path(k), "<given>", "give the uncertain parameters in the `envelope` section");
    YamlReadArchive a(s);
    describe_montecarlo_fields(a, f.base, f.threads);
    s.finish();
  }
  // the envelope: uncertain parameters drawn per run (core/envelope.hpp; objective and constraints
  // hold over it)
  f.base.uncertain.envelope = read_envelope(root);

  {  // the profile family
    if (!root.has("family"))
      throw ConfigError("family", "<missing>", "is required (family: {segments: [...]} with free {min, max} values)");
    YamlReader fam = root.child("family");
    const std::string unit = fam.get_choice_or("frequency_unit", "hz", {"hz", "natural"});
    f.frequencies_natural = unit == "natural";
    f.family.start_frequency_hz = setup.profile.start_frequency_hz();
    YamlReadArchive a(fam);
    problems::describe_design_fields(a, f.family, setup.profile);
    fam.finish();
  }
  {  // discrete choices: ball counts at one total ball mass
    YamlReader c = root.child("choices");
    YamlReader b = c.child("balls");
    double total = 0;
    for (const Ball& ball : setup.abu.balls) total += ball.mass_kg;
    if (b.present()) {
      for (double v : b.get_double_list("counts", Rule::in_range(1, 12))) {
        if (v != std::floor(v)) throw ConfigError(b.key_path("counts"), format_number(v), "must be whole numbers");
        f.ball_counts.push_back(static_cast<std::size_t>(v));
      }
      if (b.has("total_mass_kg")) total = b.get_double("total_mass_kg", Rule::positive_at_most(AbuLimits::kMassKg));
      b.finish();
      if (setup.abu.balls.empty())
        throw ConfigError("abu.balls", "[]", "choices.balls needs one ball in abu to take its diameter from");
      f.total_ball_mass_kg = total;
    }
    c.finish();
    if (f.ball_counts.empty()) f.ball_counts.push_back(setup.abu.balls.size());
  }
  {
    YamlReader o = root.child("objective");
    read_fields(o, f.objective);
    if (!f.objective.robust_friction_mu.empty() && f.base.uncertain.envelope.friction_mu.given())
      throw ConfigError("objective.robust.friction_mu", format_number(f.objective.robust_friction_mu.front()),
                        "cannot be combined with envelope.friction_mu (give the friction values in one place)");
  }
  {
    YamlReader c = root.child("constraints");
    f.relative.amplitude_vs_baseline = optional_positive(c, "amplitude_vs_baseline");
    f.relative.angular_acceleration_vs_baseline = optional_positive(c, "angular_acceleration_vs_baseline");
    f.relative.startup_time_vs_baseline = optional_positive(c, "startup_time_vs_baseline");
    YamlReadArchive a(c);
    describe_fields(a, f.constraints);
    c.finish();
    const auto both = [&](const std::optional<double>& rel, const std::optional<double>& abs, const char* rk,
                          const char* ak) {
      if (rel && abs)
        throw ConfigError(std::string("constraints.") + rk, format_number(*rel),
                          std::string("give either ") + rk + " or " + ak + ", not both");
    };
    both(f.relative.amplitude_vs_baseline, f.constraints.max_amplitude_mm, "amplitude_vs_baseline", "max_amplitude_mm");
    both(f.relative.angular_acceleration_vs_baseline, f.constraints.max_angular_acceleration_rad_s2,
         "angular_acceleration_vs_baseline", "max_angular_acceleration_rad_s2");
    both(f.relative.startup_time_vs_baseline, f.constraints.max_startup_time_s, "startup_time_vs_baseline",
         "max_startup_time_s");
  }
  if (!root.has("stages"))
    throw ConfigError("stages", "<missing>", "is required (a list: global, local, replicate, validate)");
  for (YamlReader& s : root.children("stages")) f.stages.push_back(read_stage(s));
  check_stage_order(f.stages, "stages");
  {
    YamlReader b = root.child("budget");
    f.max_evaluations = b.get_int_or("max_evaluations", f.max_evaluations, Rule::in_range(1, 1e9));
    b.finish();
  }
  root.finish();
  // every choice must make a valid problem (bounds inside the simulator's range, balls that fit)
  for (std::size_t n : f.ball_counts) {
    std::map<std::string, double> placeholder = {{"amplitude_max_mm", 1.0}, {"amplitude_mean_mm", 1.0}};
    try {
      problems::validate(settings_of_choice(f, n, placeholder));
    } catch (const ConfigError& e) {  // the problem's keys are the study's family keys
      std::string m = e.what();
      if (m.rfind("design.", 0) == 0) m.replace(0, 7, "family.");
      if (f.frequencies_natural && m.find("frequency") != std::string::npos)
        m += " (in Hz: family.frequency_unit is natural, f_n = " +
             format_number(abu_of_choice(f, n).natural_frequency_hz()) + " Hz)";
      throw ConfigError(m);
    }
  }
  return f;
}

AbuParameters abu_of_choice(const StudyFile& f, std::size_t balls) {
  AbuParameters p = f.base.setup.abu;
  if (!f.total_ball_mass_kg) return p;
  Ball b = p.balls.front();
  b.mass_kg = *f.total_ball_mass_kg / static_cast<double>(balls);
  p.balls.assign(balls, b);
  return p;
}

problems::StartupProfileSettings settings_of_choice(const StudyFile& f, std::size_t balls,
                                                    const std::map<std::string, double>& baseline) {
  problems::StartupProfileSettings s;
  s.study = f.base;
  s.study.setup.abu = abu_of_choice(f, balls);
  s.study.design.balls = s.study.setup.abu.balls.size();
  s.threads = f.threads;
  s.design = f.family;
  if (f.frequencies_natural) {
    const double fn = s.study.setup.abu.natural_frequency_hz();
    for (auto& seg : s.design.segments) {
      problems::DesignValue& v = seg.end_frequency_hz;
      if (seg.hold || !v.free) continue;  // fixed values stay in Hz (the drive's operating speed)
      v.value *= fn;
      v.lower *= fn;
      v.upper *= fn;
      v.scale *= fn;
    }
  }
  s.objective = f.objective;
  s.constraints = f.constraints;
  const auto metric = [&](const std::string& k) {
    auto it = baseline.find(k);
    return it == baseline.end() ? std::numeric_limits<double>::quiet_NaN() : it->second;
  };
  if (f.relative.amplitude_vs_baseline) {
    const bool mean = f.constraints.amplitude == problems::AmplitudeStatistic::Mean;
    s.constraints.max_amplitude_mm = *f.relative.amplitude_vs_baseline * metric(mean ? "amplitude_mean_mm" : "amplitude_max_mm");
  }
  if (f.relative.angular_acceleration_vs_baseline)
    s.constraints.max_angular_acceleration_rad_s2 = *f.relative.angular_acceleration_vs_baseline *
                                                    problems::peak_angular_acceleration_rad_s2(f.base.setup.profile);
  if (f.relative.startup_time_vs_baseline)
    s.constraints.max_startup_time_s = *f.relative.startup_time_vs_baseline * f.base.setup.profile.duration_s();
  s.validation.enabled = false;
  return s;
}

std::string resonance_reach_text(const problems::ProfileDesign& d, double fn) {
  std::ostringstream ranges;
  bool any_free = false;
  for (std::size_t i = 0; i < d.segments.size(); ++i) {
    const auto& seg = d.segments[i];
    if (seg.hold || !seg.end_frequency_hz.free) continue;
    const auto& v = seg.end_frequency_hz;
    if (v.lower <= fn && fn <= v.upper) return "";
    ranges << (any_free ? ", " : "") << "f" << i + 1 << " in [" << format_number(v.lower) << ", "
           << format_number(v.upper) << "] Hz";
    any_free = true;
  }
  if (!any_free) return "";  // only durations are free: the family passes the resonance at fixed frequencies
  return "the family cannot reach the resonance: no free end frequency can be placed at the natural frequency " +
         format_number(fn) + " Hz (" + ranges.str() +
         "); give the bounds relative to it (family.frequency_unit: natural) or widen them";
}

}  // namespace abuopt::studies
