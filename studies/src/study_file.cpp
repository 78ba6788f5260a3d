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
#include "abuopt/optimizer/multi_objective.hpp"
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
  if (s.kind == StageKind::Pareto)
    s.pareto_method = r.get_choice_or("method", "epsilon_constraint", {"epsilon_constraint", "nsga2", "moead"});
  const bool population_front = s.kind == StageKind::Pareto && s.pareto_method != "epsilon_constraint";
  if (s.kind != StageKind::Pareto || !population_front)
    for (const char* k : {"population", "points"})
      if (r.has(k))
        throw ConfigError(r.key_path(k), yaml_value_text(r.node()[k]),
                          "is only used by a pareto stage with method nsga2 or moead");
  if (population_front) {
    r.get_choice_or("over", "startup_time", {"startup_time"});
    if (r.has("bounds"))
      throw ConfigError(r.key_path("bounds"), yaml_value_text(r.node()["bounds"]),
                        "means nothing for method " + s.pareto_method +
                            ": its front spans every startup time the family allows (bounds belong to "
                            "method epsilon_constraint)");
    if (r.has("optimizer") && r.child("optimizer").has("algorithm"))
      throw ConfigError(r.key_path("optimizer") + ".algorithm",
                        yaml_value_text(r.node()["optimizer"]["algorithm"]),
                        "must be absent with method " + s.pareto_method +
                            " (the method is the stage's method; optimizer gives max_evaluations, the front's "
                            "budget per choice, and seed)");
    s.pareto_population = r.get_int_or("population", 20, Rule::in_range(1, 100000));
    s.pareto_points = static_cast<std::size_t>(r.get_int_or("points", 12, Rule::in_range(2, 1000)));
  } else if (s.kind == StageKind::Pareto) {
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
    if (population_front)
      opt::check_two_objective_population(
          s.pareto_method == "moead" ? opt::TwoObjectiveMethod::Moead : opt::TwoObjectiveMethod::Nsga2,
          s.pareto_population, s.optimizer.max_evaluations, r.key_path("population"),
          r.key_path("optimizer") + ".max_evaluations");
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
    if (n > 1) {
      stages[i].name += '_';
      stages[i].name += std::to_string(n);
    }
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
  {  // discrete choices: ball counts at one total ball mass, or ball sets
    YamlReader c = root.child("choices");
    YamlReader b = c.child("balls");
    double total = 0;
    for (const Ball& ball : setup.abu.balls) total += ball.mass_kg;
    if (b.present()) {
      if (b.has("counts") && b.has("sets"))
        throw ConfigError(b.key_path("sets"), "<list>", "give either counts (at total_mass_kg) or sets, not both");
      if (!b.has("counts") && !b.has("sets"))
        throw ConfigError(b.key_path("counts"), "<missing>",
                          "choices.balls needs counts: [2, 3, ...] (at total_mass_kg) or sets: [{ball_count, "
                          "ball_mass_kg, ball_diameter_m} or {balls: [...]}, ...]");
      if (b.has("counts")) {
        if (setup.abu.balls.empty())
          throw ConfigError("abu.balls", "[]", "choices.balls needs one ball in abu to take its diameter from");
        const std::vector<double> counts = b.get_double_list("counts", Rule::in_range(1, problems::kMaxBallCount));
        if (counts.empty()) throw ConfigError(b.key_path("counts"), "[]", "must hold at least one count");
        if (b.has("total_mass_kg")) total = b.get_double("total_mass_kg", Rule::positive_at_most(AbuLimits::kMassKg));
        f.total_ball_mass_kg = total;
        for (double v : counts) {
          if (v != std::floor(v)) throw ConfigError(b.key_path("counts"), format_number(v), "must be whole numbers");
          const auto n = static_cast<std::size_t>(v);
          for (const BallChoice& other : f.choices)
            if (other.balls.size() == n)
              throw ConfigError(b.key_path("counts"), format_number(v), "each count may appear once");
          Ball ball = setup.abu.balls.front();
          // the first ball's material (density): the diameter follows the mass
          ball.diameter_m *= std::cbrt((total / v) / ball.mass_kg);
          ball.mass_kg = total / v;
          f.choices.push_back({"balls" + std::to_string(n), std::vector<Ball>(n, ball)});
        }
        const std::string mode = b.get_choice_or("mode", "enumerate", {"enumerate", "variable"});
        f.ball_count_variable = mode == "variable";
        if (f.ball_count_variable) {
          std::vector<std::size_t> sorted;
          for (const BallChoice& ch : f.choices) sorted.push_back(ch.balls.size());
          std::sort(sorted.begin(), sorted.end());
          if (sorted.size() < 2 || sorted.back() - sorted.front() + 1 != sorted.size())
            throw ConfigError(b.key_path("mode"), "variable",
                              "needs two or more consecutive counts (the variable takes every whole count between the "
                              "least and the largest)");
        }
      } else {
        for (const char* k : {"total_mass_kg", "mode"})
          if (b.has(k)) throw ConfigError(b.key_path(k), "<given>", "is only used with counts");
        std::size_t i = 0;
        for (YamlReader& set : b.children("sets")) {
          BallChoice ch;
          ch.label = set.get_string_or("name", "set" + std::to_string(i + 1));
          if (set.has("balls")) {
            for (const char* k : {"ball_count", "ball_mass_kg", "ball_diameter_m"})
              if (set.has(k))
                throw ConfigError(set.key_path(k), "<given>", "give either a balls list or ball_count/ball_mass_kg/"
                                                              "ball_diameter_m, not both (as in the abu section)");
            for (YamlReader& item : set.children("balls")) {
              Ball ball;
              YamlReadArchive a(item);
              describe_fields(a, ball);
              item.finish();
              ch.balls.push_back(ball);
            }
          } else {
            if (!set.has("ball_count"))
              throw ConfigError(set.key_path("ball_count"), "<missing>",
                                "a ball set needs ball_count (with ball_mass_kg, ball_diameter_m) or a balls list");
            Ball ball;
            const long n = set.get_int("ball_count", Rule::in_range(1, problems::kMaxBallCount));
            ball.mass_kg = set.get_double_or("ball_mass_kg", ball.mass_kg, Rule::positive_at_most(AbuLimits::kMassKg));
            ball.diameter_m =
                set.get_double_or("ball_diameter_m", ball.diameter_m, Rule::positive_at_most(AbuLimits::kLengthM));
            ch.balls.assign(static_cast<std::size_t>(n), ball);
          }
          set.finish();
          if (ch.balls.empty()) throw ConfigError(set.key_path("balls"), "[]", "must hold at least one ball");
          for (const BallChoice& other : f.choices)
            if (other.label == ch.label)
              throw ConfigError(set.key_path("name"), ch.label, "each set needs its own name");
          AbuParameters p = setup.abu;
          p.balls = ch.balls;
          const std::string path = "choices.balls.sets[" + std::to_string(i) + "]";
          validate(p, path.c_str());
          f.choices.push_back(ch);
          ++i;
        }
        if (f.choices.empty()) throw ConfigError(b.key_path("sets"), "[]", "must hold at least one set");
      }
      b.finish();
    }
    c.finish();
    if (f.choices.empty())
      f.choices.push_back({"balls" + std::to_string(setup.abu.balls.size()), setup.abu.balls});
    if (f.family.ball_count.free)
      throw ConfigError("family.ball_count", "<given>",
                        "give the ball count as a study choice: choices.balls: {counts: [...], total_mass_kg: ..., "
                        "mode: variable}");
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
  if (f.ball_count_variable)
    for (std::size_t i = 0; i < f.stages.size(); ++i) {
      if (f.stages[i].kind == StageKind::Global) break;
      if (f.stages[i].kind == StageKind::Local)
        throw ConfigError("stages[" + std::to_string(i) + "].kind", "local",
                          "with choices.balls.mode: variable the first optimiser stage must be global (it chooses "
                          "the ball count the local stages polish)");
    }
  {
    YamlReader b = root.child("budget");
    f.max_evaluations = b.get_int_or("max_evaluations", f.max_evaluations, Rule::in_range(1, 1e9));
    b.finish();
  }
  root.finish();
  // every choice must make a valid problem (bounds inside the simulator's range, balls that fit)
  for (std::size_t i = 0; i < f.choices.size(); ++i) {
    std::map<std::string, double> placeholder = {{"amplitude_max_mm", 1.0}, {"amplitude_mean_mm", 1.0}};
    try {
      problems::validate(settings_of_choice(f, i, placeholder));
      if (f.ball_count_variable && i == 0) problems::validate(settings_of_variable_count(f, placeholder));
    } catch (const ConfigError& e) {  // the problem's keys are the study's family keys
      std::string m = e.what();
      if (m.rfind("design.", 0) == 0) m.replace(0, 7, "family.");
      if (f.frequencies_natural && m.find("frequency") != std::string::npos)
        m += " (in Hz: family.frequency_unit is natural, f_n = " +
             format_number(abu_of_choice(f, i).natural_frequency_hz()) + " Hz)";
      throw ConfigError(m);
    }
  }
  return f;
}

std::string choice_name(const BallChoice& c) {
  const std::string n = std::to_string(c.balls.size());
  return c.label == "balls" + n ? n + " balls" : c.label;
}

AbuParameters abu_of_choice(const StudyFile& f, std::size_t choice) {
  AbuParameters p = f.base.setup.abu;
  p.balls = f.choices.at(choice).balls;
  return p;
}

problems::StartupProfileSettings settings_of_variable_count(const StudyFile& f,
                                                            const std::map<std::string, double>& baseline) {
  problems::StartupProfileSettings s = settings_of_choice(f, 0, baseline);
  problems::BallCountDesign& b = s.design.ball_count;
  b.free = true;
  b.lower = b.upper = static_cast<double>(f.choices.front().balls.size());
  for (const BallChoice& ch : f.choices) {
    b.lower = std::min(b.lower, static_cast<double>(ch.balls.size()));
    b.upper = std::max(b.upper, static_cast<double>(ch.balls.size()));
  }
  b.value = static_cast<double>(f.choices.front().balls.size());  // the first count listed
  b.total_mass_kg = f.total_ball_mass_kg.value_or(0.0);
  const Ball& first = f.base.setup.abu.balls.front();  // as the enumerated counts: the first ball's density
  b.diameter_m.reset();
  b.density_kg_m3 = first.mass_kg / (M_PI / 6.0 * first.diameter_m * first.diameter_m * first.diameter_m);
  return s;
}

problems::StartupProfileSettings settings_of_choice(const StudyFile& f, std::size_t choice,
                                                    const std::map<std::string, double>& baseline) {
  problems::StartupProfileSettings s;
  s.study = f.base;
  s.study.setup.abu = abu_of_choice(f, choice);
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
    if (seg.hold) continue;
    const auto& v = seg.end_frequency_hz;
    // a fixed end frequency within 2 % of f_n: the family already dwells or passes slowly there
    if (!v.free && std::abs(v.value - fn) <= 0.02 * fn) return "";
    if (!v.free) continue;
    if (v.lower <= fn && fn <= v.upper) return "";
    ranges << (any_free ? ", " : "") << "f" << i + 1 << " in [" << format_number(v.lower) << ", "
           << format_number(v.upper) << "] Hz";
    any_free = true;
  }
  if (!any_free) return "";  // only durations are free: the family passes the resonance at fixed frequencies
  return "the family cannot reach the resonance: no free end frequency can be placed at the natural frequency " +
         format_number(std::round(fn * 100) / 100) + " Hz (" + ranges.str() +
         "); give the bounds relative to it (family.frequency_unit: natural) or widen them";
}

}  // namespace abuopt::studies
