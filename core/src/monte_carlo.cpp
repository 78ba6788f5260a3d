#include "abuopt/core/monte_carlo.hpp"

#include <chrono>
#include <cmath>

#include "abuopt/common/config_error.hpp"

namespace abuopt {

namespace {

MonteCarloSample make_sample(const MonteCarloStudy& s, std::size_t index, std::vector<double> beta0) {
  MonteCarloSample out;
  out.index = index;
  out.beta0 = std::move(beta0);
  out.overrides = sample_overrides(s.uncertain, s.setup.abu, s.seed, index);
  out.friction_mu = out.overrides.friction_mu.value_or(s.setup.abu.friction_mu);
  out.imbalance_kgm =
      out.overrides.imbalance_mass_kg.value_or(s.setup.abu.imbalance_mass_kg) * s.setup.abu.eccentricity_m;
  return out;
}

}  // namespace

InitialConditionDesign study_design(const MonteCarloStudy& s) {
  InitialConditionDesign d = s.design;
  d.balls = s.setup.abu.balls.size();
  if (d.kind != InitialConditionKind::Grid) d.count = s.runs;
  return d;
}

void validate(const MonteCarloStudy& s, const std::string& path) {
  const std::string p = path.empty() ? "" : path + ".";
  if (s.setup.abu.balls.empty()) throw ConfigError("abu.balls", "[]", "must hold at least one ball for a Monte Carlo");
  if (s.runs < 1) throw ConfigError(p + "runs", std::to_string(s.runs), "must be >= 1");
  const InitialConditionDesign d = study_design(s);
  validate(d, path);
  if (d.kind == InitialConditionKind::Grid && d.size() != s.runs)
    throw ConfigError(p + "runs", std::to_string(s.runs),
                      "must equal grid^balls = " + std::to_string(d.grid_points_per_axis) + "^" +
                          std::to_string(d.balls) + " = " + std::to_string(d.size()) +
                          " with the grid design (change grid, or use design random, lhs, halton or sobol)");
  validate(s.uncertain, path);
}

MonteCarloSample prepare_sample(const MonteCarloStudy& s, std::size_t index) {
  validate(s);
  if (index >= s.runs)
    throw ConfigError("run index", std::to_string(index), "must be < runs = " + std::to_string(s.runs));
  return make_sample(s, index, initial_condition_at(study_design(s), index));
}

MonteCarloSample run_one(const MonteCarloStudy& s, std::size_t index, const SampleFunction& sample) {
  MonteCarloSample out = prepare_sample(s, index);
  out.outcome = sample(out.beta0, out.overrides);
  return out;
}

MonteCarloResult run_monte_carlo(const MonteCarloStudy& s, const SampleFunction& sample, BatchRunner& runner,
                                 const ProgressCallback& progress) {
  validate(s);
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::vector<double>> points = generate_initial_conditions(study_design(s));

  MonteCarloResult result;
  result.samples.resize(s.runs);
  result.concurrency = runner.concurrency();
  runner.run(
      s.runs,
      [&](std::size_t i) {
        MonteCarloSample smp = make_sample(s, i, std::move(points[i]));
        smp.outcome = sample(smp.beta0, smp.overrides);
        result.samples[i] = std::move(smp);
      },
      progress);
  result.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

MonteCarloConfig read_monte_carlo_config(YamlReader& root, SimulationSetup setup) {
  MonteCarloConfig cfg;
  MonteCarloStudy& st = cfg.study;
  st.setup = std::move(setup);
  YamlReader mc = root.child("montecarlo");
  const std::string path = mc.path();

  st.design.kind = initial_condition_kind_from_string(
      mc.get_choice_or("design", "grid", {"grid", "random", "lhs", "halton", "sobol"}), mc.key_path("design"));
  st.design.grid_points_per_axis = static_cast<std::size_t>(mc.get_int_or("grid", 32, Rule::at_least(1)));
  st.design.balls = st.setup.abu.balls.size();
  if (mc.has("runs")) {
    st.runs = static_cast<std::size_t>(mc.get_int("runs", Rule::at_least(1)));
  } else {
    mc.get_int_or("runs", 0);  // marks the key as read
    st.runs = st.design.kind == InitialConditionKind::Grid ? st.design.size() : 1024;
  }
  const long seed = mc.get_int_or("seed", 0, Rule::in_range(0, 9007199254740992.0));
  st.seed = static_cast<std::uint64_t>(seed);
  st.design.seed = st.seed;
  st.design.random_shift = mc.get_bool_or("shift", true);
  cfg.threads = static_cast<std::size_t>(mc.get_int_or("threads", 0, Rule::non_negative()));
  st.uncertain = read_uncertain_parameters(mc);
  mc.finish();
  validate(st, path);
  return cfg;
}

}  // namespace abuopt
