#include "abuopt/core/monte_carlo.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <numeric>

#include "abuopt/common/stop.hpp"
#include "abuopt/common/text.hpp"
#include "abuopt/common/config_error.hpp"
#include "abuopt/core/ball_contact.hpp"

namespace abuopt {

namespace {

MonteCarloSample make_sample(const MonteCarloStudy& s, std::size_t index, std::vector<double> beta0) {
  MonteCarloSample out;
  out.index = index;
  if (joint_sampling(s)) {  // the start angles from the joint scrambled Sobol' point
    for (std::size_t b = 0; b < beta0.size(); ++b)
      beta0[b] = 2.0 * M_PI * joint_sobol_coordinate(s.seed, index, Envelope::kParameters + b);
  }
  // With hard ball contact every design point is mapped onto the feasible set (no overlapping
  // start; docs/model.md 11.6): a deterministic map, so a run stays replayable from (seed, index).
  out.beta0 = s.setup.abu.ball_contact == BallContact::Hard && beta0.size() >= 2
                  ? map_onto_contact_feasible_set(s.setup.abu, beta0)
                  : std::move(beta0);
  out.overrides = sample_overrides(s.uncertain, s.setup.abu, s.seed, index);
  out.friction_mu = out.overrides.friction_mu.value_or(s.setup.abu.friction_mu);
  out.imbalance_kgm =
      out.overrides.imbalance_mass_kg.value_or(s.setup.abu.imbalance_mass_kg) * s.setup.abu.eccentricity_m;
  out.stiffness_N_per_m = out.overrides.stiffness_N_per_m.value_or(s.setup.abu.stiffness_N_per_m);
  out.restitution = out.overrides.ball_restitution.value_or(s.setup.abu.ball_restitution);
  return out;
}

// Key of a sample for the exchange symmetry: the sorted initial angles and the uncertain
// parameters. Equal keys: the same physical start with the balls relabelled.
std::vector<double> exchange_key(const MonteCarloSample& smp) {
  std::vector<double> k(smp.beta0);
  std::sort(k.begin(), k.end());
  k.push_back(smp.friction_mu);
  k.push_back(smp.imbalance_kgm);
  k.push_back(smp.overrides.imbalance_angle_rad);
  k.push_back(smp.stiffness_N_per_m);
  k.push_back(smp.restitution);
  return k;
}

// same_as for every sample (identity when reuse is off or the balls differ).
std::vector<std::size_t> reuse_map(const MonteCarloStudy& s, const std::vector<MonteCarloSample>& samples) {
  std::vector<std::size_t> same(samples.size());
  std::iota(same.begin(), same.end(), std::size_t{0});
  if (!s.reuse_exchangeable || !balls_exchangeable(s.setup) || s.setup.abu.balls.size() < 2) return same;
  std::map<std::vector<double>, std::size_t> first;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const auto [it, inserted] = first.emplace(exchange_key(samples[i]), i);
    if (!inserted) same[i] = it->second;
  }
  return same;
}

// The outcome of `from` carried over to `to` (whose initial angles are a permutation of from's):
// ball k of `to` started where ball p(k) of `from` did, so it ends where that one ended.
RunOutcome permuted_outcome(const MonteCarloSample& from, const MonteCarloSample& to) {
  RunOutcome o = from.outcome;
  const std::size_t n = to.beta0.size();
  std::vector<char> used(n, 0);
  for (std::size_t k = 0; k < n; ++k) {
    for (std::size_t q = 0; q < n; ++q) {
      if (!used[q] && from.beta0[q] == to.beta0[k]) {
        used[q] = 1;
        if (q < from.outcome.beta_final.size()) o.beta_final[k] = from.outcome.beta_final[q];
        break;
      }
    }
  }
  o.wall_time_s = 0;  // not paid again
  return o;
}

}  // namespace

bool joint_sampling(const MonteCarloStudy& s) {
  const Envelope& e = s.uncertain.envelope;
  return e.sampling == EnvelopeSampling::Sobol && !e.deterministic() &&
         (s.design.kind == InitialConditionKind::Random || s.design.kind == InitialConditionKind::Sobol);
}

bool balls_exchangeable(const SimulationSetup& setup) {
  const auto& b = setup.abu.balls;
  for (const auto& x : b)
    if (x.mass_kg != b.front().mass_kg || x.diameter_m != b.front().diameter_m) return false;
  return true;
}

InitialConditionDesign study_design(const MonteCarloStudy& s) {
  InitialConditionDesign d = s.design;
  d.balls = s.setup.abu.balls.size();
  if (d.kind != InitialConditionKind::Grid) d.count = s.runs;
  return d;
}

namespace {

// The values a study's factors give, nominal x [lo, hi], must obey the abu section's own rules
// (stiffness in (0, kStiffnessNPerM], imbalance mass in [0, kMassKg]): Simulator::run rejects an
// override outside them with std::invalid_argument, which would abort the study part-way.
void validate_override_ranges(const MonteCarloStudy& s, const std::string& path) {
  const AbuParameters& abu = s.setup.abu;
  auto check = [](const std::string& key, const std::string& value, double nominal, double lo, double hi,
                  bool zero_ok, double limit, const std::string& what) {
    const double a = nominal * lo, b = nominal * hi;
    const bool ok = std::isfinite(a) && std::isfinite(b) && (zero_ok ? a >= 0 : a > 0) && b <= limit;
    if (!ok)
      throw ConfigError(key, value,
                        "gives " + what + " in [" + format_number(a) + ", " + format_number(b) + "] (nominal " + format_number(nominal) +
                            "), which must lie in " + (zero_ok ? "[0, " : "(0, ") + format_number(limit) +
                            "] as the abu section requires");
  };
  const Envelope& e = s.uncertain.envelope;
  if (e.stiffness_factor.given())
    check("envelope.stiffness_factor", e.stiffness_factor.text(), abu.stiffness_N_per_m, e.stiffness_factor.lo,
          e.stiffness_factor.hi, false, AbuLimits::kStiffnessNPerM, "a stiffness (N/m)");
  if (e.imbalance_mass_factor.given())
    check("envelope.imbalance_mass_factor", e.imbalance_mass_factor.text(), abu.imbalance_mass_kg,
          e.imbalance_mass_factor.lo, e.imbalance_mass_factor.hi, true, AbuLimits::kMassKg, "an imbalance mass (kg)");
  const ImbalanceMassUncertainty& m = s.uncertain.imbalance_mass;
  if (m.sampling == ImbalanceMassSampling::RelativeRange)
    check((path.empty() ? "" : path + ".") + "imbalance.mass_relative_range",
          "[" + format_number(m.relative_lo) + ", " + format_number(m.relative_hi) + "]", abu.imbalance_mass_kg, 1.0 + m.relative_lo,
          1.0 + m.relative_hi, true, AbuLimits::kMassKg, "an imbalance mass (kg)");
}

}  // namespace

void validate(const MonteCarloStudy& s, const std::string& path) {
  const std::string p = path.empty() ? "" : path + ".";
  if (s.setup.abu.balls.empty()) throw ConfigError("abu.balls", "[]", "must hold at least one ball for a Monte Carlo");
  if (s.runs < 1) throw ConfigError(p + "runs", std::to_string(s.runs), "must be >= 1");
  // Every run's outcome is kept in memory (about 0.5 kB each): cap what one request may allocate.
  constexpr std::size_t kMaxRuns = 10'000'000;
  if (s.runs > kMaxRuns)
    throw ConfigError(p + "runs", std::to_string(s.runs),
                      "must be <= 10000000 (the per-request memory limit, about 5 GB of outcomes; run several studies "
                      "with different seeds for more, or raise kMaxRuns in core/src/monte_carlo.cpp)");
  const InitialConditionDesign d = study_design(s);
  validate(d, path);
  if (d.kind == InitialConditionKind::Grid && d.size() != s.runs)
    throw ConfigError(p + "runs", std::to_string(s.runs),
                      "must equal grid^balls = " + std::to_string(d.grid_points_per_axis) + "^" +
                          std::to_string(d.balls) + " = " + std::to_string(d.size()) +
                          " with the grid design (change grid, or use design random, lhs, halton or sobol)");
  validate(s.uncertain, path);
  if (joint_sampling(s) && s.setup.abu.balls.size() > Envelope::kMaxJointBalls)
    throw ConfigError("envelope.sampling", "sobol",
                      "draws the start angles of at most 6 balls (the Sobol' directions cover 10 dimensions); "
                      "use sampling: random, or a montecarlo.design other than random/sobol");
  validate_override_ranges(s, path);
  if (s.uncertain.envelope.restitution.given() && s.setup.abu.ball_contact != BallContact::Hard)
    throw ConfigError("envelope.restitution", s.uncertain.envelope.restitution.text(),
                      "needs abu.ball_contact: hard (restitution is the ball-ball impacts' coefficient)");
}

MonteCarloSample prepare_sample(const MonteCarloStudy& s, std::size_t index) {
  validate(s);
  if (index >= s.runs)
    throw ConfigError("run index", std::to_string(index), "must be < runs = " + std::to_string(s.runs));
  MonteCarloSample smp = make_sample(s, index, initial_condition_at(study_design(s), index));
  if (s.reuse_exchangeable && balls_exchangeable(s.setup) && s.setup.abu.balls.size() >= 2) {
    const std::vector<double> key = exchange_key(smp);
    const InitialConditionDesign d = study_design(s);
    for (std::size_t j = 0; j < index; ++j) {
      if (exchange_key(make_sample(s, j, initial_condition_at(d, j))) == key) {
        smp.reused = true;
        smp.reused_from = j;
        break;
      }
    }
  }
  return smp;
}

MonteCarloSample run_one(const MonteCarloStudy& s, std::size_t index, const SampleFunction& sample) {
  MonteCarloSample out = prepare_sample(s, index);
  if (out.reused) {
    // replay exactly what the study did: simulate the reused run and permute its outcome
    MonteCarloSample from = prepare_sample(s, out.reused_from);
    from.outcome = sample(from.beta0, from.overrides);
    out.outcome = permuted_outcome(from, out);
  } else {
    out.outcome = sample(out.beta0, out.overrides);
  }
  return out;
}

PreparedStudy prepare_study(const MonteCarloStudy& s) {
  validate(s);
  std::vector<std::vector<double>> points = generate_initial_conditions(study_design(s));
  throw_if_stop_requested();  // a study of 10^6 runs takes seconds to prepare: the stop request ends it too
  PreparedStudy p;
  p.samples.resize(s.runs);
  for (std::size_t i = 0; i < s.runs; ++i) {
    if ((i & 4095) == 0) throw_if_stop_requested();
    p.samples[i] = make_sample(s, i, std::move(points[i]));
  }
  throw_if_stop_requested();
  const std::vector<std::size_t> same = reuse_map(s, p.samples);
  throw_if_stop_requested();
  for (std::size_t i = 0; i < s.runs; ++i) {
    p.samples[i].reused = same[i] != i;
    p.samples[i].reused_from = same[i];
    if (same[i] == i) p.simulate.push_back(i);
  }
  return p;
}

namespace {
// The reused runs take their outcome from the run they exchange balls with.
void fill_reused(std::vector<MonteCarloSample>& samples) {
  for (MonteCarloSample& smp : samples)
    if (smp.reused) smp.outcome = permuted_outcome(samples[smp.reused_from], smp);
}
}  // namespace

MonteCarloResult run_monte_carlo(const MonteCarloStudy& s, const SampleFunction& sample, BatchRunner& runner,
                                 const ProgressCallback& progress) {
  const auto start = std::chrono::steady_clock::now();
  PreparedStudy p = prepare_study(s);
  MonteCarloResult result;
  result.concurrency = runner.concurrency();
  runner.run(
      p.simulate.size(),
      [&](std::size_t k) {
        MonteCarloSample& smp = p.samples[p.simulate[k]];
        smp.outcome = sample(smp.beta0, smp.overrides);
      },
      progress);
  fill_reused(p.samples);
  result.samples = std::move(p.samples);
  result.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

MonteCarloResult run_monte_carlo_study(const MonteCarloStudy& s, StudyRunner& runner,
                                       const ProgressCallback& progress) {
  const auto start = std::chrono::steady_clock::now();
  PreparedStudy p = prepare_study(s);
  MonteCarloResult result;
  result.concurrency = runner.concurrency();
  runner.run_study(s, p, progress);
  fill_reused(p.samples);
  result.samples = std::move(p.samples);
  result.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

const EnumNames<InitialConditionKind> kInitialConditionKindNames = {
    {InitialConditionKind::Grid, "grid"},     {InitialConditionKind::Random, "random"},
    {InitialConditionKind::LatinHypercube, "lhs"}, {InitialConditionKind::Halton, "halton"},
    {InitialConditionKind::Sobol, "sobol"}};

void describe_montecarlo_fields(FieldArchive& a, MonteCarloStudy& st, std::size_t& threads) {
  const bool runs_given = a.has("runs");
  if (a.reading()) st.design.balls = st.setup.abu.balls.size();
  a.field("design", st.design.kind, kInitialConditionKindNames);
  a.field("grid", st.design.grid_points_per_axis, Rule::at_least(1));
  a.field("runs", st.runs, Rule::at_least(1));
  if (a.reading() && !runs_given)
    st.runs = st.design.kind == InitialConditionKind::Grid ? st.design.size() : 1024;
  a.field("seed", st.seed, Rule::in_range(0, 9007199254740992.0));
  if (a.reading()) st.design.seed = st.seed;  // one seed in the config; a study built in code may differ
  a.field("design_seed", st.design.seed, Rule::any(), FieldOptions::identity_only());
  a.field("shift", st.design.random_shift);
  a.field("reuse_exchangeable", st.reuse_exchangeable);
  a.field("threads", threads, Rule::non_negative(), FieldOptions::not_identity());
  describe_fields(a, st.uncertain);
}

void describe_fields(FieldArchive& a, MonteCarloConfig& c) { describe_montecarlo_fields(a, c.study, c.threads); }

namespace {

MonteCarloConfig read_section(YamlReader& mc, SimulationSetup setup) {
  MonteCarloConfig cfg;
  cfg.study.setup = std::move(setup);
  read_fields(mc, cfg);
  return cfg;
}

}  // namespace

MonteCarloConfig read_monte_carlo_config_unchecked(YamlReader& root, SimulationSetup setup) {
  YamlReader mc = root.child("montecarlo");
  MonteCarloConfig cfg = read_section(mc, std::move(setup));
  cfg.study.uncertain.envelope = read_envelope(root);
  return cfg;
}

MonteCarloConfig read_monte_carlo_config(YamlReader& root, SimulationSetup setup) {
  YamlReader mc = root.child("montecarlo");
  MonteCarloConfig cfg = read_section(mc, std::move(setup));
  cfg.study.uncertain.envelope = read_envelope(root);
  validate(cfg.study, mc.path());
  return cfg;
}

}  // namespace abuopt
