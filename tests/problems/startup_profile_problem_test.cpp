// The startup-profile problem: the design vector -> profile mapping (free/fixed values, names,
// bounds, scales), the objective kinds and robust averaging against statistics computed directly
// by the core Monte Carlo engine, the constraint values, the penalty form, the guard against
// durations <= 0, common random numbers, the identity hash, and config errors.
// Tiny Monte Carlo studies (4 runs, profiles of ~0.5 s) keep it fast.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <memory>
#include <string>

#include "abuopt/common/config_error.hpp"
#include "abuopt/core/model_version.hpp"
#include "abuopt/core/monte_carlo.hpp"
#include "abuopt/core/monte_carlo_stats.hpp"
#include "abuopt/core/simulation_config.hpp"
#include "abuopt/problems/startup_profile_problem.hpp"
#include "../common/perturb_archive.hpp"

namespace {

using namespace abuopt;
using problems::StartupProfileProblem;
using problems::StartupProfileSettings;

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "<no error>";
}

StartupProfileSettings settings_from(const std::string& yaml) {
  YamlReader root = YamlReader::load_string(yaml);
  StartupProfileSettings s = problems::read_startup_profile_settings(root);
  root.finish();
  return s;
}

// The report's three-step profile as template; five free variables as in configs/optimize/.
const std::string kThreeStep = R"(
profile:
  segments:
    - {end_frequency_hz: 25.0, duration_s: 1.0}
    - {end_frequency_hz: 29.5, duration_s: 10.0}
    - {end_frequency_hz: 100.0, duration_s: 8.0}
montecarlo: {design: grid, grid: 2, threads: 1}
design:
  segments:
    - end_frequency_hz: {min: 15, max: 28, x0: 25}
      duration_s: {min: 0.3, max: 3, x0: 1, scale: 0.5}
    - end_frequency_hz: {min: 28, max: 32}
      duration_s: {min: 1, max: 12, x0: 10}
    - end_frequency_hz: 100
      duration_s: {min: 1, max: 10, x0: 8}
constraints: {max_startup_time_s: 20, max_pct_mi: 5}
)";

// A short one-segment study: 0 -> f1 Hz in dt1 s (end time 2 dt1), 2 x 2 grid of initial angles.
std::string tiny(const std::string& objective, const std::string& constraints = "",
                 const std::string& montecarlo_extra = "") {
  return "montecarlo: {design: grid, grid: 2, threads: 1" + montecarlo_extra +
         "}\n"
         "design:\n"
         "  segments:\n"
         "    - end_frequency_hz: {min: 20, max: 40, x0: 35}\n"
         "      duration_s: {min: 0.2, max: 1.0, x0: 0.4}\n"
         "objective: " + objective + "\n" +
         (constraints.empty() ? std::string() : "constraints: " + constraints + "\n");
}

// Statistics of the same study computed directly by the engine (independent of the problem).
MonteCarloStats direct_stats(const StartupProfileSettings& s, const StartupProfile& p, std::optional<double> mu = {}) {
  MonteCarloStudy st = s.study;
  st.setup.profile = p;
  if (mu) {
    st.uncertain.friction.sampling = FrictionSampling::Fixed;
    st.uncertain.friction.value = *mu;
  }
  ThreadPoolRunner runner(1);
  return compute_statistics(run_monte_carlo(st, runner));
}

}  // namespace

TEST(StartupProfileProblem, DesignVectorMapsToProfileWithNamesBoundsAndFixedValues) {
  StartupProfileProblem p(settings_from(kThreeStep));
  const auto vars = p.variables();
  ASSERT_EQ(vars.size(), 5u);
  const char* names[] = {"f1", "dt1", "f2", "dt2", "dt3"};
  for (std::size_t i = 0; i < 5; ++i) EXPECT_EQ(vars[i].name, names[i]);
  EXPECT_EQ(vars[0].lower, 15);
  EXPECT_EQ(vars[0].upper, 28);
  EXPECT_EQ(vars[0].scale, 13);   // default: upper - lower
  EXPECT_EQ(vars[1].scale, 0.5);  // given
  EXPECT_EQ(vars[3].lower, 1);
  EXPECT_EQ(vars[3].upper, 12);
  // x0: given, else the template's value when inside the bounds (f2 = 29.5).
  EXPECT_EQ(p.initial_point(), (std::vector<double>{25, 1, 29.5, 10, 8}));
  EXPECT_EQ(p.inequality_names(), (std::vector<std::string>{"startup_time", "pct_mi"}));

  const StartupProfile prof = p.profile_at({20, 0.5, 30, 7, 4});
  ASSERT_EQ(prof.segments().size(), 3u);
  EXPECT_EQ(prof.segments()[0].end_frequency_hz, 20);
  EXPECT_EQ(prof.segments()[0].duration_s, 0.5);
  EXPECT_EQ(prof.segments()[1].end_frequency_hz, 30);
  EXPECT_EQ(prof.segments()[1].duration_s, 7);
  EXPECT_EQ(prof.segments()[2].end_frequency_hz, 100);  // fixed
  EXPECT_EQ(prof.segments()[2].duration_s, 4);
  EXPECT_EQ(prof.start_frequency_hz(), 0);
  EXPECT_DOUBLE_EQ(p.startup_time_s({20, 0.5, 30, 7, 4}), 11.5);
  EXPECT_THROW(p.profile_at({1, 2}), std::invalid_argument);
}

TEST(StartupProfileProblem, AbsentSegmentValuesComeFromTheTemplate) {
  StartupProfileProblem p(settings_from(R"(
profile:
  start_frequency_hz: 2
  segments: [{end_frequency_hz: 25, duration_s: 1}, {end_frequency_hz: 29.5, duration_s: 10}]
design:
  segments:
    - {duration_s: {min: 0.5, max: 2}}
    - {}
)"));
  ASSERT_EQ(p.variables().size(), 1u);
  EXPECT_EQ(p.variables()[0].name, "dt1");
  EXPECT_EQ(p.initial_point(), std::vector<double>{1});  // template value, inside the bounds
  const StartupProfile prof = p.profile_at({1.5});
  EXPECT_EQ(prof.start_frequency_hz(), 2);
  EXPECT_EQ(prof.segments()[0].end_frequency_hz, 25);
  EXPECT_EQ(prof.segments()[1].end_frequency_hz, 29.5);
  EXPECT_EQ(prof.segments()[1].duration_s, 10);
  EXPECT_TRUE(p.inequality_names().empty());
}

TEST(StartupProfileProblem, ObjectiveKindsMatchTheEngineStatistics) {
  const std::vector<double> x = {35, 0.4};
  StartupProfileProblem mean(settings_from(tiny("{kind: mean}")));
  const MonteCarloStats st = direct_stats(mean.settings(), mean.profile_at(x));
  ASSERT_EQ(st.runs, 4u);
  ASSERT_EQ(st.ok, 4u);

  const opt::Evaluation e = mean.evaluate(x);
  ASSERT_TRUE(e.ok) << e.message;
  EXPECT_DOUBLE_EQ(e.objective, st.magnitude.mean / 1e-7);
  EXPECT_DOUBLE_EQ(e.metrics.at("ir_magnitude_mean"), st.magnitude.mean / 1e-7);
  EXPECT_DOUBLE_EQ(e.metrics.at("ir_x_max"), st.report_x.max / 1e-7);
  EXPECT_DOUBLE_EQ(e.metrics.at("pct_mi_x"), st.report_x.pct_mi);
  EXPECT_DOUBLE_EQ(e.metrics.at("amplitude_max_mm"), st.amplitude_max_mm);
  EXPECT_EQ(e.metrics.at("runs"), 4);
  EXPECT_EQ(e.metrics.at("failed_runs"), 0);
  EXPECT_DOUBLE_EQ(e.metrics.at("startup_time_s"), 0.4);
  EXPECT_DOUBLE_EQ(e.metrics.at("end_time_s"), 0.8);  // twice the profile (report's rule)
  // The mean by hand from the per-run outcomes.
  MonteCarloStudy study = mean.settings().study;
  study.setup.profile = mean.profile_at(x);
  ThreadPoolRunner runner(1);
  double sum = 0;
  for (const auto& s : run_monte_carlo(study, runner).samples) sum += s.outcome.residual_imbalance_kgm;
  EXPECT_NEAR(e.objective, sum / 4 / 1e-7, 1e-9);
  // The 95 % half-widths of the means, 1.96 s / sqrt(n) (docs/sweep.md), by hand, and the Wilson
  // interval of the %MI in use.
  for (const bool xdef : {false, true}) {
    std::vector<double> v;
    for (const auto& s : run_monte_carlo(study, runner).samples)
      v.push_back((xdef ? s.outcome.residual_imbalance_x_kgm : s.outcome.residual_imbalance_kgm) / 1e-7);
    double m = 0, ss = 0;
    for (double a : v) m += a / 4;
    for (double a : v) ss += (a - m) * (a - m);
    EXPECT_NEAR(e.metrics.at(xdef ? "ir_x_mean_hw95" : "ir_magnitude_mean_hw95"), 1.96 * std::sqrt(ss / 3 / 4), 1e-3 * std::sqrt(ss / 3 / 4) + 1e-12)
        << xdef;
  }
  EXPECT_DOUBLE_EQ(e.metrics.at("pct_mi_ci95_lo"), st.magnitude.pct_mi_ci95[0]);
  EXPECT_DOUBLE_EQ(e.metrics.at("pct_mi_ci95_hi"), st.magnitude.pct_mi_ci95[1]);

  StartupProfileProblem rx(settings_from(tiny("{kind: mean, definition: report_x}")));
  EXPECT_DOUBLE_EQ(rx.evaluate(x).objective, st.report_x.mean / 1e-7);
  StartupProfileProblem mi(settings_from(tiny("{kind: pct_mi}")));
  EXPECT_DOUBLE_EQ(mi.evaluate(x).objective, st.magnitude.pct_mi);
  StartupProfileProblem w(settings_from(tiny("{kind: weighted, weights: {mean: 2, pct_mi: 0.5}}")));
  EXPECT_DOUBLE_EQ(w.evaluate(x).objective, 2 * st.magnitude.mean / 1e-7 + 0.5 * st.magnitude.pct_mi);
}

TEST(StartupProfileProblem, HalfWidthsFollowTheEnvelopesStrata) {
  // With an envelope (stratified by default: 2 cells per uncertain parameter, here 4 strata) the
  // 95 % half-widths of the means are core's stratified ones (mean_half_width95 with the study's
  // interval_layout), not 1.96 s / sqrt(n) over all runs.
  StartupProfileProblem p(settings_from(
      "montecarlo: {design: random, runs: 12, threads: 1}\n"
      "envelope:\n"
      "  friction_mu: {uniform: [0.05, 0.3]}\n"
      "  stiffness_factor: {uniform: [0.95, 1.05]}\n"
      "design:\n"
      "  segments:\n"
      "    - end_frequency_hz: {min: 20, max: 40, x0: 35}\n"
      "      duration_s: {min: 0.2, max: 1.0, x0: 0.4}\n"
      "objective: {kind: mean}\n"));
  const std::vector<double> x = {35, 0.4};
  const opt::Evaluation e = p.evaluate(x);
  ASSERT_TRUE(e.ok) << e.message;
  MonteCarloStudy study = p.settings().study;
  study.setup.profile = p.profile_at(x);
  const IntervalLayout layout = interval_layout(study);
  ASSERT_EQ(layout.kind, IntervalKind::Strata);
  ASSERT_EQ(layout.groups, 4u);
  ThreadPoolRunner runner(1);
  const MonteCarloResult r = run_monte_carlo(study, runner);
  ASSERT_EQ(r.samples.size(), 12u);
  for (const bool xdef : {false, true}) {
    const double want = mean_half_width95(r.samples, layout, xdef) / 1e-7;
    ASSERT_TRUE(std::isfinite(want));
    EXPECT_NEAR(e.metrics.at(xdef ? "ir_x_mean_hw95" : "ir_magnitude_mean_hw95"), want, 1e-12 * want) << xdef;
  }
}

// The smooth objectives are core's smooth statistics of the same runs; the pct_mi constraint can use
// the smoothed exceedance; the identity changes with them and not for the older keys.
TEST(StartupProfileProblem, SmoothObjectivesAndConstraintAreTheEngineSmoothStatistics) {
  const std::vector<double> x = {35, 0.4};
  StartupProfileProblem base(settings_from(tiny("{kind: mean}")));
  MonteCarloStudy study = base.settings().study;
  study.setup.profile = base.profile_at(x);
  ThreadPoolRunner runner(1);
  const std::vector<MonteCarloSample> samples = run_monte_carlo(study, runner).samples;
  const SmoothImbalanceStats s90 = compute_smooth_statistics(samples, false, 0.9);
  const SmoothImbalanceStats s75 = compute_smooth_statistics(samples, false, 0.75);

  StartupProfileProblem smooth(settings_from(tiny("{kind: smooth_pct_mi}")));
  const opt::Evaluation e = smooth.evaluate(x);
  ASSERT_TRUE(e.ok) << e.message;
  EXPECT_DOUBLE_EQ(e.objective, s90.pct_mi);
  EXPECT_DOUBLE_EQ(e.metrics.at("pct_mi_smooth"), s90.pct_mi);
  EXPECT_DOUBLE_EQ(e.metrics.at("smoothing_bandwidth"), s90.bandwidth);
  StartupProfileProblem q(settings_from(tiny("{kind: quantile, level: 0.75}")));
  EXPECT_DOUBLE_EQ(q.evaluate(x).objective, s75.quantile / 1e-7);
  StartupProfileProblem cv(settings_from(tiny("{kind: cvar}")));
  EXPECT_DOUBLE_EQ(cv.evaluate(x).objective, s90.cvar / 1e-7);
  EXPECT_GE(cv.evaluate(x).objective, q.evaluate(x).objective);

  StartupProfileProblem g(settings_from(tiny("{kind: mean}", "{max_pct_mi: 40, pct_mi_statistic: smooth}")));
  EXPECT_DOUBLE_EQ(g.evaluate(x).inequality.at(0), s90.pct_mi / 40 - 1.0);
  EXPECT_FALSE(base.evaluate(x).metrics.count("pct_mi_smooth"));  // the default outputs are unchanged

  EXPECT_NE(q.identity(), StartupProfileProblem(settings_from(tiny("{kind: quantile, level: 0.8}"))).identity());
  EXPECT_NE(g.identity(), StartupProfileProblem(settings_from(tiny("{kind: mean}", "{max_pct_mi: 40}"))).identity());
  EXPECT_EQ(error_of([] { settings_from(tiny("{kind: mean, level: 0.5}")); }),
            "objective.level = 0.5: is only used with objective.kind: quantile or cvar");
}

TEST(StartupProfileProblem, RobustObjectiveIsTheMeanOverFrictionValues) {
  const std::vector<double> x = {35, 0.4};
  StartupProfileProblem robust(settings_from(tiny("{kind: weighted, weights: {mean: 1, pct_mi: 1}, robust: {friction_mu: [0.02, 0.04]}}")));
  const opt::Evaluation e = robust.evaluate(x);
  ASSERT_TRUE(e.ok) << e.message;
  const MonteCarloStats a = direct_stats(robust.settings(), robust.profile_at(x), 0.02);
  const MonteCarloStats b = direct_stats(robust.settings(), robust.profile_at(x), 0.04);
  const double fa = a.magnitude.mean / 1e-7 + a.magnitude.pct_mi, fb = b.magnitude.mean / 1e-7 + b.magnitude.pct_mi;
  EXPECT_NEAR(e.objective, 0.5 * (fa + fb), 1e-12);
  EXPECT_DOUBLE_EQ(e.metrics.at("objective_mu1"), fa);
  EXPECT_DOUBLE_EQ(e.metrics.at("objective_mu2"), fb);
  EXPECT_EQ(e.metrics.at("mu2"), 0.04);
  // Pooled statistics over both passes: 8 runs, %MI the average of the two.
  EXPECT_EQ(e.metrics.at("runs"), 8);
  EXPECT_NEAR(e.metrics.at("pct_mi"), 0.5 * (a.magnitude.pct_mi + b.magnitude.pct_mi), 1e-12);
  EXPECT_DOUBLE_EQ(e.metrics.at("amplitude_max_mm"), std::max(a.amplitude_max_mm, b.amplitude_max_mm));
  // The friction actually changes the outcome (otherwise the test proves nothing).
  EXPECT_NE(a.magnitude.mean, b.magnitude.mean);
}

TEST(StartupProfileProblem, ConstraintValuesAreRelativeToTheirBounds) {
  const std::vector<double> x = {35, 0.4};
  StartupProfileProblem p(settings_from(tiny("{kind: mean}", "{max_startup_time_s: 0.5, max_amplitude_mm: 2, max_pct_mi: 40}")));
  ASSERT_EQ(p.inequality_names(), (std::vector<std::string>{"startup_time", "amplitude", "pct_mi"}));
  const opt::Evaluation e = p.evaluate(x);
  ASSERT_TRUE(e.ok) << e.message;
  ASSERT_EQ(e.inequality.size(), 3u);
  EXPECT_DOUBLE_EQ(e.inequality[0], 0.4 / 0.5 - 1.0);  // startup time exactly
  EXPECT_DOUBLE_EQ(e.inequality[1], e.metrics.at("amplitude_max_mm") / 2 - 1.0);
  EXPECT_DOUBLE_EQ(e.inequality[2], e.metrics.at("pct_mi_magnitude") / 40 - 1.0);
  // %MI is a multiple of 100/4 with 4 runs.
  EXPECT_DOUBLE_EQ(std::fmod(e.metrics.at("pct_mi"), 25.0), 0.0);

  StartupProfileProblem mean_amp(
      settings_from(tiny("{kind: mean}", "{max_amplitude_mm: 2, amplitude: mean}")));
  const opt::Evaluation m = mean_amp.evaluate(x);
  EXPECT_DOUBLE_EQ(m.inequality[0], m.metrics.at("amplitude_mean_mm") / 2 - 1.0);
  EXPECT_LE(m.metrics.at("amplitude_mean_mm"), m.metrics.at("amplitude_max_mm"));

  // Penalty form: no declared constraints, objective + w * sum max(0, g); the problem itself keeps
  // its constraints.
  const StartupProfileSettings pen_settings =
      settings_from(tiny("{kind: mean}", "{max_startup_time_s: 0.3, max_pct_mi: 40, penalty_weight: 10}"));
  EXPECT_EQ(StartupProfileProblem(pen_settings).inequality_names().size(), 2u);
  const std::unique_ptr<opt::Problem> pen = problems::make_startup_profile_problem(pen_settings);
  EXPECT_TRUE(pen->inequality_names().empty());
  const opt::Evaluation q = pen->evaluate(x);
  EXPECT_TRUE(q.inequality.empty());
  const double g_time = 0.4 / 0.3 - 1.0, g_mi = q.metrics.at("pct_mi") / 40 - 1.0;
  EXPECT_DOUBLE_EQ(q.metrics.at("g_startup_time"), g_time);
  EXPECT_NEAR(q.objective, e.objective + 10 * (std::max(0.0, g_time) + std::max(0.0, g_mi)), 1e-12);
}

TEST(StartupProfileProblem, CommonRandomNumbersGiveIdenticalRepeats) {
  StartupProfileProblem p(settings_from(tiny("{kind: mean}")));
  const opt::Evaluation a = p.evaluate({35, 0.4});
  const opt::Evaluation b = p.evaluate({35, 0.4});
  EXPECT_EQ(a.objective, b.objective);
  // Threads do not matter.
  StartupProfileSettings s = p.settings();
  s.threads = 2;
  StartupProfileProblem q(s);
  EXPECT_EQ(q.evaluate({35, 0.4}).objective, a.objective);
}

TEST(StartupProfileProblem, DurationsNotPositiveAreNeverSimulated) {
  StartupProfileProblem p(settings_from(tiny("{kind: mean}")));
  const opt::Evaluation e = p.evaluate_profile(StartupProfile({{30, 0.0}}));
  EXPECT_FALSE(e.ok);
  EXPECT_NE(e.message.find("not simulated"), std::string::npos) << e.message;
  EXPECT_FALSE(p.evaluate_profile(StartupProfile({{30, 0.5}, {40, -1}})).ok);
  EXPECT_FALSE(p.evaluate_profile(StartupProfile({{30, std::nan("")}})).ok);
}

TEST(StartupProfileProblem, OutOfSampleUsesTheValidationSet) {
  StartupProfileSettings s = settings_from(tiny("{kind: mean}") + "validation: {runs: 6, design: lhs, seed: 3}\n");
  StartupProfileProblem p(s);
  EXPECT_EQ(p.settings().validation.runs, 6u);
  const opt::Evaluation e = p.evaluate_out_of_sample(p.profile_at({35, 0.4}));
  ASSERT_TRUE(e.ok);
  EXPECT_EQ(e.metrics.at("runs"), 6);
  // Default validation: 1024 random runs, seed = montecarlo seed + 1.
  StartupProfileProblem d(settings_from(tiny("{kind: mean}", "", ", seed: 5")));
  EXPECT_EQ(d.settings().validation.runs, 1024u);
  EXPECT_EQ(d.settings().validation.seed, 6u);
  EXPECT_EQ(d.settings().validation.design, InitialConditionKind::Random);
}

TEST(StartupProfileProblem, IdentityChangesWithWhatDecidesTheValues) {
  const std::string base = StartupProfileProblem(settings_from(kThreeStep)).identity();
  EXPECT_EQ(base.rfind("startup_profile-", 0), 0u);
  EXPECT_EQ(base.size(), std::string("startup_profile-").size() + 16);
  EXPECT_EQ(StartupProfileProblem(settings_from(kThreeStep)).identity(), base);  // deterministic

  auto changed = [&](const std::string& from, const std::string& to) {
    std::string y = kThreeStep;
    const auto at = y.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    y.replace(at, from.size(), to);
    return StartupProfileProblem(settings_from(y)).identity();
  };
  // Values that change evaluate(x): a new identity.
  EXPECT_NE(changed("grid: 2,", "grid: 2, seed: 1,"), base);                      // Monte Carlo seed
  EXPECT_NE(changed("design: grid, grid: 2", "design: lhs, runs: 4"), base);      // sampling
  EXPECT_NE(changed("end_frequency_hz: 100\n", "end_frequency_hz: 90\n"), base);  // a fixed value
  EXPECT_NE(changed("max_pct_mi: 5", "max_pct_mi: 4"), base);                     // a constraint
  EXPECT_NE(changed("montecarlo:", "abu: {friction_mu: 0.03}\nmontecarlo:"), base);
  EXPECT_NE(changed("montecarlo:", "objective: {definition: report_x}\nmontecarlo:"), base);
  EXPECT_NE(changed("montecarlo:", "simulation: {rtol: 1e-7}\nmontecarlo:"), base);
  EXPECT_NE(changed("montecarlo:", "envelope: {stiffness_factor: {uniform: [0.95, 1.05]}}\nmontecarlo:"), base);
  {  // the envelope reaches the study the problem evaluates
    std::string y = kThreeStep;
    y.replace(y.find("montecarlo:"), 11, "envelope: {friction_mu: {uniform: [0.02, 0.04]}}\nmontecarlo:");
    EXPECT_EQ(settings_from(y).study.uncertain.envelope.friction_mu, ParameterDistribution::uniform(0.02, 0.04));
    EXPECT_NE(error_of([&] { settings_from(y + "objective: {robust: {friction_mu: [0.02, 0.03]}}\n"); })
                  .find("envelope.friction_mu"),
              std::string::npos);
  }
  // Bounds, x0, threads and validation do not change any value: same identity (archive reused).
  EXPECT_EQ(changed("{min: 15, max: 28, x0: 25}", "{min: 14, max: 28, x0: 20}"), base);
  EXPECT_EQ(changed("threads: 1", "threads: 2"), base);
  EXPECT_EQ(changed("montecarlo:", "validation: {runs: 64}\nmontecarlo:"), base);
  // ... but they key the stored validations (ProblemSpec::validation_identity): a validation of
  // another size, seed or design is never answered by one stored for this one.
  auto validation_id = [&](const std::string& v) {
    return StartupProfileProblem(settings_from(v + kThreeStep)).validation_identity();
  };
  EXPECT_EQ(validation_id(""), "random/runs1024/seed1");  // montecarlo seed 0 + 1
  EXPECT_EQ(validation_id("validation: {runs: 8192}\n"), "random/runs8192/seed1");
  EXPECT_EQ(validation_id("validation: {seed: 7, design: lhs, runs: 10}\n"), "lhs/runs10/seed7");
  EXPECT_EQ(validation_id("validation: {design: grid, grid: 3}\n"), "grid/grid3/runs9/seed1");
  // Hard contact: a new identity, and it names the contact model's version, so that archives of an
  // older contact model (before the pivoting choice of modes) never answer for this one.
  const StartupProfileProblem contact(settings_from("abu: {ball_contact: hard}\n" + kThreeStep));
  EXPECT_NE(contact.identity(), base);
  EXPECT_NE(contact.identity_text().find("# contact model v" + std::to_string(kContactModelVersion) + "\n"),
            std::string::npos);
  EXPECT_EQ(StartupProfileProblem(settings_from(kThreeStep)).identity_text().find("contact model"), std::string::npos);

  EXPECT_NE(problems::fnv1a64("a"), problems::fnv1a64("b"));
  EXPECT_EQ(problems::fnv1a64(""), 14695981039346656037ull);  // FNV-1a offset basis
  EXPECT_EQ(problems::fnv1a64("a"), 0xaf63dc4c8601ec8cull);   // published test vector
}

// Every key of abu, profile, motor and simulation (every leaf of their field lists, so a key added
// later is covered too) changes the problem identity: an archive never answers with evaluations of
// another model.
TEST(StartupProfileProblem, AnySetupKeyChangesTheIdentity) {
  std::string yaml = kThreeStep;  // random initial conditions: a third ball keeps the runs valid
  const std::string grid = "montecarlo: {design: grid, grid: 2, threads: 1}";
  yaml.replace(yaml.find(grid), grid.size(), "montecarlo: {design: random, runs: 4, threads: 1}");
  const StartupProfileSettings base = settings_from(yaml);
  const std::string id = StartupProfileProblem(base).identity();
  std::size_t leaves = 0;
  for (std::size_t k = 0;; ++k) {
    StartupProfileSettings s = base;
    test_support::PerturbArchive a(k);
    describe_fields(a, s.study.setup);
    if (!a.changed()) {
      leaves = a.leaves();
      break;
    }
    std::string changed;
    try {
      changed = StartupProfileProblem(s).identity();
    } catch (const ConfigError& e) {
      ADD_FAILURE() << a.changed_path() << ": " << e.what();
      continue;
    }
    EXPECT_NE(changed, id) << a.changed_path();
  }
  EXPECT_GE(leaves, 8u + 1 + 4 + 1 + 1 + 6 + 8 + 13);  // abu (2 balls), profile (3 segments), motor, simulation
}

// Over every section of the settings: a field is in the identity exactly when it is marked so
// (bounds, x0, scales, threads and the validation section are not), and read -> write -> read
// gives the same settings after any single change.
TEST(StartupProfileProblem, SettingsRoundTripAndIdentityFollowTheFieldLists) {
  StartupProfileSettings base = settings_from(kThreeStep + "objective: {kind: weighted, weights: {mean: 1, pct_mi: 0.5}}\n");
  const std::string id = identity_fields(base);
  auto round_trip = [](const StartupProfileSettings& s) {
    const std::string yaml = write_fields(s);
    return settings_from(yaml);
  };
  EXPECT_EQ(write_fields(round_trip(base)), write_fields(base));
  std::size_t outside = 0;
  for (std::size_t k = 0;; ++k) {
    StartupProfileSettings s = base;
    test_support::PerturbArchive a(k);
    describe_fields(a, s);
    if (!a.changed()) break;
    outside += !a.changed_identity();
    EXPECT_EQ(identity_fields(s) != id, a.changed_identity()) << a.changed_path();
    StartupProfileSettings back;
    try {
      back = round_trip(s);
    } catch (const ConfigError& e) {
      // A single change may break a rule across fields (a grid size against the runs): the
      // reader must say so, never accept it silently.
      EXPECT_NE(std::string(e.what()).find(" = "), std::string::npos) << a.changed_path();
      continue;
    }
    EXPECT_EQ(write_fields(back), write_fields(s)) << a.changed_path();
  }
  // threads; min, max and x0 of the 5 free values and the one scale given; 5 validation keys.
  EXPECT_EQ(outside, 1u + 5 * 3 + 1 + 5);
}

TEST(StartupProfileProblem, ConfigErrorsNameKeyValueAndRule) {
  auto err = [](const std::string& yaml) { return error_of([&] { settings_from(yaml); }); };
  const std::string head = "montecarlo: {design: grid, grid: 2}\n";
  EXPECT_EQ(err(head + "design: {segments: [{end_frequency_hz: {min: 28, max: 15}, duration_s: 1}]}\n"),
            "design.segments[0].end_frequency_hz.min = 28: must be below design.segments[0].end_frequency_hz.max = 15 "
            "(bounds reversed or equal)");
  EXPECT_EQ(err(head + "design: {segments: [{end_frequency_hz: {min: 15, max: 28, x0: 30}, duration_s: 1}]}\n"),
            "design.segments[0].end_frequency_hz.x0 = 30: must be in [15, 28] (the bounds)");
  EXPECT_EQ(err(head + "design: {segments: [{end_frequency_hz: 30, duration_s: {min: 0, max: 2}}]}\n"),
            "design.segments[0].duration_s.min = 0: must be > 0 (a profile with a duration <= 0 is never simulated)");
  EXPECT_EQ(err(head + "design: {segments: [{end_frequency_hz: 30, duration_s: 1}]}\n"),
            "design.segments = 1 segments, all values fixed: no free variable: give at least one value as "
            "{min: ..., max: ...}");
  EXPECT_EQ(err(head + "design: {segments: [{end_frequency_hz: 30, duration_s: -1}, {duration_s: {min: 1, max: 2}}]}\n"),
            "design.segments[0].duration_s = -1: must be > 0 (a profile with a duration <= 0 is never simulated)");
  EXPECT_EQ(err(head + "design: {segments: [{end_frequency_hz: 30, duraton_s: {min: 1, max: 2}}]}\n"),
            "design.segments[0].duraton_s = {min: 1, max: 2}: unknown key (misspelt, or not valid here); did you mean 'duration_s'?");
  EXPECT_EQ(err(head + "profile: {segments: [{end_frequency_hz: 25, duration_s: 1}]}\n"
                       "design: {segments: [{duration_s: {min: 1, max: 2}}, {duration_s: 3}]}\n"),
            "design.segments[1].end_frequency_hz = <missing>: is required (the profile template has no segment 1)");
  EXPECT_EQ(err(head), "design = <missing>: is required (design: {segments: [...]} with at least one free {min, max} value)");
  const std::string design = "design: {segments: [{end_frequency_hz: 30, duration_s: {min: 1, max: 2}}]}\n";
  EXPECT_EQ(err(head + design + "objective: {kind: median}\n"),
            "objective.kind = median: must be one of: mean, pct_mi, weighted, smooth_pct_mi, quantile, cvar, startup_time");
  EXPECT_EQ(err(head + design + "objective: {kind: mean, weights: {mean: 1}}\n"),
            "objective.weights = {mean: 1}: is only used with objective.kind: weighted");
  EXPECT_EQ(err(head + design + "objective: {kind: weighted, weights: {mean: 0, pct_mi: 0}}\n"),
            "objective.weights = {mean: 0, pct_mi: 0}: at least one weight must be > 0");
  EXPECT_EQ(err("montecarlo: {design: grid, grid: 2, friction: {fixed: 0.03}}\n" + design +
                "objective: {robust: {friction_mu: [0.02, 0.04]}}\n"),
            "objective.robust.friction_mu = [0.02, 0.04]: cannot be combined with montecarlo.friction (give the "
            "friction values in one place)");
  EXPECT_EQ(err(head + design + "constraints: {max_pct_mi: -1}\n"), "constraints.max_pct_mi = -1: must be in [1e-09, 100]");
  EXPECT_EQ(err(head + design + "constraints: {max_startup: 20}\n"),
            "constraints.max_startup = 20: unknown key (misspelt, or not valid here); did you mean 'max_startup_time_s'?");
  EXPECT_EQ(err(head + design + "validation: {design: grid, grid: 4, runs: 10}\n"),
            "validation.runs = 10: must equal validation.grid^balls = 16 with the grid design");
}

// A hold segment takes the previous end frequency (a dwell, no variable); frequencies may fall.
TEST(StartupProfileProblem, HoldSegmentsDwellAtThePreviousFrequency) {
  StartupProfileProblem p(settings_from(R"(
montecarlo: {design: grid, grid: 2, threads: 1}
design:
  segments:
    - end_frequency_hz: {min: 20, max: 35, x0: 30}
      duration_s: 1
    - hold: true
      duration_s: {min: 0.5, max: 5, x0: 2}
    - end_frequency_hz: {min: 20, max: 35, x0: 28}
      duration_s: 3
    - {end_frequency_hz: 100, duration_s: 8}
)"));
  ASSERT_EQ(p.variables().size(), 3u);
  EXPECT_EQ(p.variables()[0].name, "f1");
  EXPECT_EQ(p.variables()[1].name, "dt2");
  EXPECT_EQ(p.variables()[2].name, "f3");
  const auto prof = p.profile_at({31.5, 2.5, 27});
  ASSERT_EQ(prof.segments().size(), 4u);
  EXPECT_DOUBLE_EQ(prof.segments()[1].end_frequency_hz, 31.5);
  EXPECT_DOUBLE_EQ(prof.frequency_hz(1.0 + 1.3), 31.5);  // constant through the hold
  EXPECT_DOUBLE_EQ(prof.segments()[2].end_frequency_hz, 27);  // falling segment
  EXPECT_NE(p.identity_text().find("hold: true"), std::string::npos);
  // hold replaces end_frequency_hz: both in one segment is an error naming the key.
  EXPECT_NE(error_of([] {
              settings_from("montecarlo: {design: grid, grid: 2, threads: 1}\ndesign:\n  segments:\n"
                            "    - {hold: true, end_frequency_hz: 30, duration_s: {min: 1, max: 2}}\n");
            }).find("end_frequency_hz"),
            std::string::npos);
  // A hold first segment dwells at the start frequency.
  StartupProfileProblem first(settings_from(R"(
montecarlo: {design: grid, grid: 2, threads: 1}
design:
  start_frequency_hz: 5
  segments:
    - {hold: true, duration_s: 1}
    - end_frequency_hz: {min: 20, max: 35}
      duration_s: 2
)"));
  EXPECT_DOUBLE_EQ(first.profile_at({30}).segments()[0].end_frequency_hz, 5);
}

// The peak angular acceleration of an inclined sine of height H in dt s is 2 pi * 2 |H| / dt (at its
// middle, f' = 2 H / dt); the report's profile peaks in its first segment, 2 pi * 50 = 314.16 rad/s^2.
TEST(StartupProfileProblem, AngularAccelerationConstraintIsExact) {
  const StartupProfile report = StartupProfile::report_final();
  EXPECT_NEAR(problems::peak_angular_acceleration_rad_s2(report), 2 * M_PI * 50, 1e-9);
  // Against the profile's own derivative, sampled finely: the same peak, and a falling segment counts.
  const StartupProfile falling({{30, 1}, {26, 0.5}, {100, 8}});
  double peak = 0;
  for (double t = 0; t < falling.duration_s(); t += 1e-4)
    peak = std::max(peak, 2 * M_PI * std::abs(falling.sample(t).rate_hz_per_s));
  EXPECT_NEAR(problems::peak_angular_acceleration_rad_s2(falling), peak, 1e-3 * peak);
  EXPECT_NEAR(peak, 2 * M_PI * 2 * 30, 1e-3 * peak);  // the first segment: 2 * 30 Hz / 1 s
  const std::vector<double> x = {35, 0.4};
  StartupProfileProblem p(settings_from(tiny("{kind: mean}", "{max_angular_acceleration_rad_s2: 500}")));
  ASSERT_EQ(p.inequality_names(), (std::vector<std::string>{"angular_acceleration"}));
  const opt::Evaluation e = p.evaluate(x);
  ASSERT_TRUE(e.ok) << e.message;
  EXPECT_DOUBLE_EQ(e.inequality[0], 2 * M_PI * 2 * 35 / 0.4 / 500 - 1.0);
  EXPECT_DOUBLE_EQ(e.metrics.at("peak_angular_acceleration_rad_s2"), 2 * M_PI * 2 * 35 / 0.4);
  // The limit decides the constraint values, so it is part of the problem identity (archive key).
  EXPECT_NE(StartupProfileProblem(settings_from(tiny("{kind: mean}"))).identity(), p.identity());
  EXPECT_NE(error_of([] { settings_from(tiny("{kind: mean}", "{max_angular_acceleration_rad_s2: -1}")); })
                .find("constraints.max_angular_acceleration_rad_s2"),
            std::string::npos);
}

// Formulation 2 of the study (docs/studies/startup-profile.md): minimise the startup time subject to
// mean |I_r| and %MI. The objective is the sum of the durations exactly (no noise, no averaging over a
// robust set); the constraint is the Monte Carlo's mean |I_r| over its bound, minus 1, whatever the
// definition of the objective, pooled over the robust set.
TEST(StartupProfileProblem, StartupTimeObjectiveAndMeanConstraint) {
  const std::string three = R"(
montecarlo: {design: grid, grid: 2, threads: 1}
design:
  segments:
    - end_frequency_hz: {min: 10, max: 30, x0: 20}
      duration_s: {min: 0.05, max: 1, x0: 0.1}
    - end_frequency_hz: {min: 20, max: 40, x0: 32}
      duration_s: {min: 0.05, max: 1, x0: 0.2}
    - hold: true
      duration_s: {min: 0.05, max: 1, x0: 0.3}
objective: {kind: startup_time, definition: report_x}
constraints: {max_mean_abs_ir: 12.5, max_pct_mi: 50}
)";
  StartupProfileProblem p(settings_from(three));
  ASSERT_EQ(p.inequality_names(), (std::vector<std::string>{"pct_mi", "mean_abs_ir"}));
  const std::vector<double> x = p.initial_point();  // f1 dt1 f2 dt2 dt3
  ASSERT_EQ(x.size(), 5u);
  const opt::Evaluation e = p.evaluate(x);
  ASSERT_TRUE(e.ok) << e.message;
  const double sum = (0.1 + 0.2) + 0.3;  // 0.6000000000000001: the sum in segment order, bit for bit
  EXPECT_EQ(e.objective, sum);
  EXPECT_EQ(e.objective, e.metrics.at("startup_time_s"));
  const MonteCarloStats st = direct_stats(p.settings(), p.profile_at(x));
  EXPECT_DOUBLE_EQ(e.inequality.at(0), st.report_x.pct_mi / 50 - 1.0);  // %MI of objective.definition
  EXPECT_DOUBLE_EQ(e.inequality.at(1), st.magnitude.mean / 1e-7 / 12.5 - 1.0);  // always |I_r|
  EXPECT_NE(st.magnitude.mean, st.report_x.mean);  // the two definitions differ here (else this proves nothing)
  // Robust: the objective stays the duration (not an average of K copies); the constraint's mean is
  // the pooled mean over the friction values.
  StartupProfileProblem robust(settings_from(
      tiny("{kind: startup_time, robust: {friction_mu: [0.02, 0.04]}}", "{max_mean_abs_ir: 10}")));
  const std::vector<double> y = {35, 0.4};
  const opt::Evaluation r = robust.evaluate(y);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.objective, 0.4);
  const MonteCarloStats a = direct_stats(robust.settings(), robust.profile_at(y), 0.02);
  const MonteCarloStats b = direct_stats(robust.settings(), robust.profile_at(y), 0.04);
  EXPECT_NEAR(r.inequality.at(0), 0.5 * (a.magnitude.mean + b.magnitude.mean) / 1e-7 / 10 - 1.0, 1e-12);
  // The bound decides the constraint values: part of the problem identity; the other problems keep theirs.
  EXPECT_NE(StartupProfileProblem(settings_from(tiny("{kind: startup_time}", "{max_mean_abs_ir: 11}"))).identity(),
            StartupProfileProblem(settings_from(tiny("{kind: startup_time}", "{max_mean_abs_ir: 12}"))).identity());
  // Without the bound the identity text is what it was before the key existed (archives stay valid).
  EXPECT_EQ(StartupProfileProblem(settings_from(tiny("{kind: mean}"))).identity_text().find("max_mean_abs_ir"),
            std::string::npos);
  EXPECT_NE(p.identity_text().find("max_mean_abs_ir: 12.5"), std::string::npos);
  EXPECT_EQ(error_of([] { settings_from(tiny("{kind: startup_time}", "{max_mean_abs_ir: -1}")); }),
            "constraints.max_mean_abs_ir = -1: must be > 0");
  EXPECT_EQ(error_of([] { settings_from(tiny("{kind: startup_time}", "{max_mean_abs_ir: 0}")); }),
            "constraints.max_mean_abs_ir = 0: must be > 0");
  EXPECT_NE(error_of([] { settings_from(tiny("{kind: startuptime}")); }).find("objective.kind = startuptime"),
            std::string::npos);
}

// Adaptive sample size (docs/sao.md): with a nested design (random, halton, sobol) the value at n
// of a problem of N runs is the n-run problem's value, bit for bit (the first n runs of one
// sequence); n = N is evaluate(); lhs and grid designs are not nested and offer no other size.
TEST(StartupProfileProblem, SampledValueIsTheSmallerStudy) {
  const std::vector<double> x{35, 0.4};
  for (const char* design : {"random", "sobol", "halton"}) {
    const std::string extra = std::string(", seed: 5");
    auto with = [&](int runs) {
      std::string yaml = tiny("{kind: weighted, weights: {mean: 1, pct_mi: 0.1}}", "{max_pct_mi: 50}", extra);
      const std::string grid = "design: grid, grid: 2";
      yaml.replace(yaml.find(grid), grid.size(), "design: " + std::string(design) + ", runs: " + std::to_string(runs));
      return settings_from(yaml);
    };
    StartupProfileProblem big(with(8));
    StartupProfileProblem small(with(3));
    EXPECT_EQ(big.sample_size(), 8u);
    EXPECT_EQ(big.max_sample_size(), 8u);
    const opt::Evaluation a = big.evaluate_sampled(x, 3);
    const opt::Evaluation b = small.evaluate(x);
    EXPECT_EQ(a.objective, b.objective) << design;
    EXPECT_EQ(a.inequality, b.inequality) << design;
    EXPECT_EQ(a.metrics.at("runs"), 3) << design;
    EXPECT_EQ(a.metrics.at("ir_magnitude_mean"), b.metrics.at("ir_magnitude_mean")) << design;
    const opt::Evaluation full = big.evaluate(x);
    EXPECT_EQ(big.evaluate_sampled(x, 8).objective, full.objective) << design;
    EXPECT_EQ(big.evaluate_sampled(x, 8, 2).objective, full.objective) << design;
    EXPECT_THROW(big.evaluate_sampled(x, 9), std::invalid_argument);
    EXPECT_THROW(big.evaluate_sampled(x, 0), std::invalid_argument);
  }
  StartupProfileProblem grid(settings_from(tiny("{kind: mean}")));
  EXPECT_EQ(grid.sample_size(), 4u);
  EXPECT_EQ(grid.max_sample_size(), 0u);
  EXPECT_THROW(grid.evaluate_sampled(x, 2), std::invalid_argument);
  EXPECT_EQ(grid.evaluate_sampled(x, 4).objective, grid.evaluate(x).objective);
}

// design.ball_count: the count as one more (rounded) variable; each count evaluates exactly as a
// problem whose abu has those balls (mass total / n, the diameter of a steel sphere of that mass).
TEST(StartupProfileProblem, BallCountVariableIsTheRoundedCountAtTheTotalMass) {
  const std::string mc = "montecarlo: {design: lhs, runs: 6, seed: 4, threads: 1}\n";
  const std::string seg = "design:\n  segments:\n    - end_frequency_hz: {min: 20, max: 40, x0: 35}\n"
                          "      duration_s: 0.4\n";
  StartupProfileProblem p(settings_from(mc + seg + "  ball_count: {min: 2, max: 5, x0: 3, total_mass_kg: 2.4e-4}\n"));
  const auto vars = p.variables();
  ASSERT_EQ(vars.size(), 2u);
  EXPECT_EQ(vars[1].name, "balls");
  EXPECT_DOUBLE_EQ(vars[1].lower, 1.5);  // every count an interval of width 1
  EXPECT_DOUBLE_EQ(vars[1].upper, 5.5);
  EXPECT_EQ(p.initial_point(), (std::vector<double>{35, 3}));
  EXPECT_EQ(p.ball_count_variable(), std::optional<std::size_t>(1));
  EXPECT_EQ(p.balls_at({35, 1.5}), 2u);
  EXPECT_EQ(p.balls_at({35, 3.49}), 3u);
  EXPECT_EQ(p.balls_at({35, 3.5}), 4u);
  EXPECT_EQ(p.balls_at({35, 5.5}), 5u);  // the upper end clamps
  const AbuParameters abu = p.abu_at({35, 4.2});
  ASSERT_EQ(abu.balls.size(), 4u);
  EXPECT_DOUBLE_EQ(abu.balls[0].mass_kg, 6e-5);
  // steel (7850 kg/m^3): d = cbrt(6 m / (pi rho)) = 2.4440 mm for 6e-5 kg
  EXPECT_NEAR(abu.balls[3].diameter_m, std::cbrt(6 * 6e-5 / (M_PI * 7850)), 1e-15);
  EXPECT_NEAR(abu.balls[3].diameter_m, 2.4440e-3, 1e-7);

  // x = (35, 3.8): exactly the problem of a 4-ball abu with that profile
  const opt::Evaluation e = p.evaluate({35, 3.8});
  ASSERT_TRUE(e.ok) << e.message;
  EXPECT_EQ(e.metrics.at("balls"), 4);
  StartupProfileSettings four = settings_from(mc + seg);
  four.study.setup.abu = abu_with_ball_count(four.study.setup.abu, 4, p.settings().design.ball_count);
  const MonteCarloStats st = direct_stats(four, StartupProfile({{35, 0.4}}));
  EXPECT_DOUBLE_EQ(e.objective, st.magnitude.mean / 1e-7);
  // another count is another Monte Carlo (other masses, other initial angles)
  const opt::Evaluation two = p.evaluate({35, 2});
  ASSERT_TRUE(two.ok);
  EXPECT_EQ(two.metrics.at("balls"), 2);
  EXPECT_NE(two.objective, e.objective);
  // out of sample: the balls at x too
  EXPECT_EQ(p.evaluate_out_of_sample_at({35, 3.8}).metrics.at("balls"), 4);

  // a given diameter replaces the density; identity: the mass and diameter are in it, the bounds are not
  StartupProfileProblem d(settings_from(mc + seg + "  ball_count: {min: 2, max: 5, total_mass_kg: 2.4e-4, diameter_m: 0.003}\n"));
  EXPECT_DOUBLE_EQ(d.abu_at({35, 2}).balls[1].diameter_m, 0.003);
  EXPECT_DOUBLE_EQ(d.initial_point()[1], 2);  // x0 defaults to min
  EXPECT_NE(d.identity(), p.identity());
  StartupProfileProblem wider(settings_from(mc + seg + "  ball_count: {min: 1, max: 6, x0: 3, total_mass_kg: 2.4e-4}\n"));
  EXPECT_EQ(wider.identity(), p.identity());
  StartupProfileProblem heavier(settings_from(mc + seg + "  ball_count: {min: 2, max: 5, x0: 3, total_mass_kg: 3e-4}\n"));
  EXPECT_NE(heavier.identity(), p.identity());
  // without ball_count the identity is what it was (archives of older problems still answer)
  EXPECT_EQ(StartupProfileProblem(settings_from(mc + seg)).identity_text().find("ball_count"), std::string::npos);
}

TEST(StartupProfileProblem, BallCountErrorsNameKeyValueAndRule) {
  const std::string lhs = "montecarlo: {design: lhs, runs: 6, seed: 4, threads: 1}\n";
  const std::string seg = "design:\n  segments:\n    - end_frequency_hz: {min: 20, max: 40, x0: 35}\n"
                          "      duration_s: 0.4\n  ball_count: ";
  const auto err = [&](const std::string& bc, const std::string& m = "") {
    return error_of([&] { StartupProfileProblem p(settings_from((m.empty() ? lhs : m) + seg + bc + "\n")); });
  };
  EXPECT_NE(err("{min: 2.5, max: 5, total_mass_kg: 2e-4}").find("design.ball_count.min = 2.5: must be a whole number"),
            std::string::npos) << err("{min: 2.5, max: 5, total_mass_kg: 2e-4}");
  EXPECT_NE(err("{min: 4, max: 3, total_mass_kg: 2e-4}").find("design.ball_count.min = 4: must be below"), std::string::npos);
  EXPECT_NE(err("{min: 2, max: 4, x0: 5, total_mass_kg: 2e-4}").find("design.ball_count.x0 = 5"), std::string::npos);
  EXPECT_NE(err("{min: 2, max: 4}").find("design.ball_count.total_mass_kg"), std::string::npos);
  EXPECT_NE(err("{min: 2, max: 13, total_mass_kg: 2e-4}").find("design.ball_count.max = 13"), std::string::npos);
  EXPECT_NE(err("{min: 2, max: 4, total_mass_kg: 2e-4, diameter_m: 0.003, density_kg_m3: 7000}")
                .find("design.ball_count.density_kg_m3"), std::string::npos);
  EXPECT_NE(err("{min: 2, max: 4, total_mass_kg: 2e-4}", "montecarlo: {design: grid, grid: 2, threads: 1}\n")
                .find("montecarlo.design = grid: cannot be used with design.ball_count"), std::string::npos);
  // twelve balls of 3 cm do not fit on the report's 11.5 mm track
  const std::string big = err("{min: 2, max: 12, total_mass_kg: 2e-4, diameter_m: 0.03}");
  EXPECT_NE(big.find("design.ball_count: with"), std::string::npos) << big;
}
