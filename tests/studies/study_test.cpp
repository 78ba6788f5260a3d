// The study file (studies/study.hpp): reading, the family's bounds relative to the natural
// frequency, the relative constraints, the resonance note and the bad-input messages.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "abuopt/common/config_error.hpp"
#include "abuopt/studies/study.hpp"

namespace {

using namespace abuopt;
using namespace abuopt::studies;
namespace fs = std::filesystem;

const std::string kQuick = std::string(ABUOPT_SOURCE_DIR) + "/configs/studies/quick.yaml";
// The file the tests edit: the quick study as it was (a global and a local stage), kept fixed.
const std::string kFixture = std::string(ABUOPT_SOURCE_DIR) + "/tests/studies/data/study_fixture.yaml";

std::string quick_text() {
  std::ifstream in(kFixture);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Writes `text` to a temporary file and reads it as a study.
StudyFile read_text(const std::string& text) {
  const fs::path p = fs::temp_directory_path() / ("abuopt_study_test_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(p) << text;
  StudyFile f = read_study_file(p.string());
  fs::remove(p);
  return f;
}

// The ConfigError message of reading `text` ("" when it reads).
std::string error_of(const std::string& text) {
  try {
    read_text(text);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

std::string replace(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

TEST(StudyFile, QuickStudyReads) {
  const StudyFile f = read_study_file(kQuick);  // a local polish from a known start, replications, validation
  ASSERT_EQ(f.stages.size(), 3u);
  EXPECT_EQ(f.stages[0].kind, StageKind::Local);
  EXPECT_EQ(f.stages[2].kind, StageKind::Validate);
  EXPECT_EQ(f.stages[2].seeds.size(), 4u);
  EXPECT_TRUE(f.frequencies_natural);
  ASSERT_EQ(f.choices.size(), 1u);
  EXPECT_EQ(f.choices[0].balls.size(), 2u);
  EXPECT_EQ(f.choices[0].label, "balls2");
  EXPECT_FALSE(f.ball_count_variable);
  EXPECT_EQ(f.base.runs, 128u);
  EXPECT_EQ(f.base.uncertain.envelope.friction_mu.kind, DistributionKind::Uniform);
  EXPECT_EQ(f.base.uncertain.envelope.imbalance_mass_factor.hi, 1.2);
  const StudyFile g = read_study_file(kFixture);  // the file the other tests edit
  ASSERT_EQ(g.stages.size(), 4u);
  EXPECT_EQ(g.stages[0].kind, StageKind::Global);
  EXPECT_EQ(g.stages[3].kind, StageKind::Validate);
  EXPECT_EQ(g.base.runs, 64u);
}

TEST(StudyFile, FrequencyBoundsFollowTheNaturalFrequency) {
  const std::string text = quick_text();
  const StudyFile soft = read_text(text);
  const StudyFile stiff = read_text(replace(text, "abu: {}", "abu: {stiffness_N_per_m: 4.28e4}"));
  const auto s1 = settings_of_choice(soft, 0, {{"amplitude_max_mm", 0.5}});
  const auto s2 = settings_of_choice(stiff, 0, {{"amplitude_max_mm", 0.5}});
  const double fn1 = s1.study.setup.abu.natural_frequency_hz(), fn2 = s2.study.setup.abu.natural_frequency_hz();
  EXPECT_NEAR(fn1, 28.9, 0.05);  // the report's ABU
  EXPECT_NEAR(fn2 / fn1, 2.0, 1e-12);  // four times as stiff: twice the natural frequency
  EXPECT_NEAR(s1.design.segments[0].end_frequency_hz.lower, 0.6 * fn1, 1e-12);
  EXPECT_NEAR(s2.design.segments[0].end_frequency_hz.lower, 0.6 * fn2, 1e-12);
  EXPECT_NEAR(s2.design.segments[1].end_frequency_hz.upper, 1.1 * fn2, 1e-12);
  EXPECT_NEAR(s2.design.segments[0].end_frequency_hz.value, 0.9 * fn2, 1e-12);
  // fixed values stay in Hz (the operating speed)
  EXPECT_EQ(s2.design.segments[2].end_frequency_hz.value, 100.0);
  EXPECT_FALSE(s2.design.segments[2].end_frequency_hz.free);
}

TEST(StudyFile, RelativeConstraintsUseTheBaseline) {
  const StudyFile f = read_study_file(kFixture);
  const auto s = settings_of_choice(f, 0, {{"amplitude_max_mm", 0.484}});
  ASSERT_TRUE(s.constraints.max_amplitude_mm);
  EXPECT_DOUBLE_EQ(*s.constraints.max_amplitude_mm, 0.484);
  ASSERT_TRUE(s.constraints.max_startup_time_s);
  EXPECT_DOUBLE_EQ(*s.constraints.max_startup_time_s, 19.0);
  ASSERT_TRUE(s.constraints.max_angular_acceleration_rad_s2);  // 2 pi x 2 x 25 Hz / 1 s
  EXPECT_NEAR(*s.constraints.max_angular_acceleration_rad_s2, 2 * M_PI * 50, 1e-9);
}

TEST(StudyFile, BallCountsAtATotalMass) {
  const std::string text =
      replace(quick_text(), "objective: {kind: mean}", "choices: {balls: {counts: [2, 3], total_mass_kg: 4.2e-4}}\nobjective: {kind: mean}");
  const StudyFile f = read_text(text);
  ASSERT_EQ(f.choices.size(), 2u);
  EXPECT_EQ(f.choices[1].label, "balls3");
  const AbuParameters three = abu_of_choice(f, 1);
  ASSERT_EQ(three.balls.size(), 3u);
  EXPECT_NEAR(three.balls[0].mass_kg, 1.4e-4, 1e-18);
  EXPECT_NEAR(three.balls[0].diameter_m, 3e-3, 1e-15);  // the first ball's mass: its diameter
}

TEST(StudyFile, BallDiameterFollowsTheMassAtTheFirstBallsDensity) {
  const std::string text =
      replace(quick_text(), "objective: {kind: mean}", "choices: {balls: {counts: [2, 6], total_mass_kg: 2.8e-4}}\nobjective: {kind: mean}");
  const AbuParameters six = abu_of_choice(read_text(text), 1);  // the second choice: 6 balls
  ASSERT_EQ(six.balls.size(), 6u);
  EXPECT_NEAR(six.balls[0].mass_kg, 2.8e-4 / 6, 1e-18);
  // steel balls of 1.4e-4 kg are 3 mm across: a third of the mass is 3 mm x 3^(-1/3) = 2.0801 mm
  EXPECT_NEAR(six.balls[5].diameter_m, 2.0801e-3, 1e-7);
}

TEST(StudyFile, ResonanceOutOfReachIsSaid) {
  const std::string text = replace(replace(quick_text(), "frequency_unit: natural", "frequency_unit: hz"),
                                   "{min: 0.97, max: 1.1, x0: 1.02}", "{min: 20, max: 28, x0: 25}");
  const std::string text2 = replace(text, "{min: 0.6, max: 0.99, x0: 0.9}", "{min: 15, max: 25, x0: 20}");
  const StudyFile f = read_text(text2);
  const auto s = settings_of_choice(f, 0, {{"amplitude_max_mm", 0.5}});
  const std::string note = resonance_reach_text(s.design, 28.9);
  EXPECT_NE(note.find("cannot reach the resonance"), std::string::npos) << note;
  EXPECT_NE(note.find("28.9 Hz"), std::string::npos) << note;
  EXPECT_NE(note.find("f2 in [20, 28] Hz"), std::string::npos) << note;
  // a fixed end frequency at the resonance (here 28.92 Hz, 0.1 % off f_n) is a family that reaches it
  problems::ProfileDesign fixed_at_fn = s.design;
  fixed_at_fn.segments.front().end_frequency_hz = {false, 28.92, 0, 0, 0};
  EXPECT_EQ(resonance_reach_text(fixed_at_fn, 28.9), "");
  fixed_at_fn.segments.front().end_frequency_hz.value = 27.0;  // 6.6 % off: not
  EXPECT_NE(resonance_reach_text(fixed_at_fn, 28.9), "");
  // the quick study's own family reaches it
  const StudyFile q = read_study_file(kQuick);
  const auto sq = settings_of_choice(q, 0, {{"amplitude_max_mm", 0.5}});
  EXPECT_EQ(resonance_reach_text(sq.design, sq.study.setup.abu.natural_frequency_hz()), "");
}

TEST(StudyFile, BadInputNamesKeyValueAndRule) {
  const std::string q = quick_text();
  std::string e = error_of(replace(q, "runs: 64, seed: 21", "runs: 64, seed: 21, colour: red"));
  EXPECT_NE(e.find("sampling.colour"), std::string::npos) << e;
  e = error_of(replace(q, "{kind: global, optimizer: {algorithm: direct_l, max_evaluations: 30}}",
                       "{kind: global, optimizer: {algorithm: direct_l, max_evaluations: 30}, seeds: [1]}"));
  EXPECT_NE(e.find("stages[0].seeds"), std::string::npos) << e;
  EXPECT_NE(e.find("only used by replicate, validate and pareto"), std::string::npos) << e;
  e = error_of(replace(q, "kind: validate", "kind: check"));
  EXPECT_NE(e.find("stages[3].kind = check"), std::string::npos) << e;
  e = error_of(replace(q, "  - {kind: replicate, seeds: [101, 102, 103], runs: 64}\n", "") + "");
  EXPECT_EQ(e, "");
  e = error_of(replace(q, "- {kind: global, optimizer: {algorithm: direct_l, max_evaluations: 30}}",
                       "- {kind: replicate, seeds: [1]}"));
  EXPECT_NE(e.find("stages[0].kind = replicate"), std::string::npos) << e;
  e = error_of(replace(q, "amplitude_vs_baseline: 1.0", "amplitude_vs_baseline: 1.0\n  max_amplitude_mm: 0.5"));
  EXPECT_NE(e.find("constraints.amplitude_vs_baseline"), std::string::npos) << e;
  e = error_of(replace(q, "algorithm: cobyla", "algorithm: nelder"));
  EXPECT_NE(e.find("unknown algorithm"), std::string::npos) << e;
  e = error_of(replace(q, "friction_mu: {uniform: [0.02, 0.04]}", "friction_mu: {uniform: [0.04, 0.02]}"));
  EXPECT_NE(e.find("envelope.friction_mu"), std::string::npos) << e;
  e = error_of(replace(q, "runs: 64, seed: 21}", "runs: 64, seed: 21, friction: {range: [0.02, 0.04]}}"));
  EXPECT_NE(e.find("sampling.friction"), std::string::npos) << e;
  EXPECT_NE(e.find("envelope"), std::string::npos) << e;
  e = error_of(replace(q, "{min: 0.97, max: 1.1, x0: 1.02}", "{min: 0.97, max: 1.1, x0: 1.5}"));
  EXPECT_NE(e.find("family.segments[1].end_frequency_hz"), std::string::npos) << e;
}

TEST(StudyInterval, StudentT) {
  const Interval i = interval_of({1.0, 2.0, 3.0});
  EXPECT_DOUBLE_EQ(i.mean, 2.0);
  EXPECT_NEAR(i.hi - i.mean, 4.303 / std::sqrt(3.0), 1e-12);
  EXPECT_EQ(interval_of({5.0}).lo, 5.0);
}

}  // namespace

// The headline says "Recommended" only for a design that held up on fresh samples and beat the
// baseline there (docs/study.md): the verdict from the replications and the validation's ratio.
TEST(StudyVerdict, RecommendedOnlyWhenItHeldUpAndBeatTheBaseline) {
  StudyResult r;
  EXPECT_EQ(verdict_of(r), Verdict::None);
  r.designs.resize(1);
  r.recommended = 0;
  EXPECT_EQ(verdict_of(r), Verdict::Unvalidated);  // no validate stage
  r.validation.done = true;
  r.validation.ratio_mean_ir = {0.83, 0.81, 0.85, 4};
  EXPECT_EQ(verdict_of(r), Verdict::Recommended);
  r.validation.ratio_mean_ir = {0.97, 0.91, 1.03, 4};
  EXPECT_EQ(verdict_of(r), Verdict::NoBetter);
  r.validation.ratio_mean_ir = {1.11, 1.01, 1.21, 4};
  EXPECT_EQ(verdict_of(r), Verdict::Worse);
  r.validation.ratio_mean_ir = {0.8, 0.8, 0.8, 1};  // one sample: no interval
  EXPECT_EQ(verdict_of(r), Verdict::Unvalidated);
  r.validation.ratio_mean_ir = {0.83, 0.81, 0.85, 4};
  r.candidate = true;  // not feasible on every replication: a candidate, however good its ratio
  EXPECT_EQ(verdict_of(r), Verdict::Candidate);
  EXPECT_EQ(headline_of(Verdict::Candidate), "Candidate design");
  EXPECT_EQ(headline_of(Verdict::Recommended), "Recommended design");
  EXPECT_EQ(headline_of(Verdict::Worse), "Best design found");
  EXPECT_EQ(to_string(Verdict::NoBetter), "no_better");
}

TEST(StudyFile, BallSetsAndTheVariableCount) {
  const std::string sets = replace(quick_text(), "objective: {kind: mean}",
                                   "choices:\n  balls:\n    sets:\n"
                                   "      - {ball_count: 3, ball_mass_kg: 9e-5, ball_diameter_m: 2.5e-3}\n"
                                   "      - {name: mixed, balls: [{mass_kg: 1e-4, diameter_m: 3e-3}, {mass_kg: 2e-4, diameter_m: 3e-3}]}\n"
                                   "objective: {kind: mean}");
  const StudyFile f = read_text(sets);
  ASSERT_EQ(f.choices.size(), 2u);
  EXPECT_EQ(f.choices[0].label, "set1");
  EXPECT_EQ(f.choices[1].label, "mixed");
  EXPECT_EQ(abu_of_choice(f, 0).balls.size(), 3u);
  EXPECT_DOUBLE_EQ(abu_of_choice(f, 1).balls[1].mass_kg, 2e-4);
  EXPECT_EQ(choice_name(f.choices[1]), "mixed");
  const std::string var = replace(quick_text(), "objective: {kind: mean}",
                                  "choices: {balls: {counts: [3, 2, 4], total_mass_kg: 2.4e-4, mode: variable}}\n"
                                  "objective: {kind: mean}");
  const StudyFile v = read_text(var);
  ASSERT_TRUE(v.ball_count_variable);
  const auto s = settings_of_variable_count(v, {{"amplitude_max_mm", 0.5}});
  ASSERT_TRUE(s.design.ball_count.free);
  EXPECT_EQ(s.design.ball_count.lower, 2);
  EXPECT_EQ(s.design.ball_count.upper, 4);
  EXPECT_EQ(s.design.ball_count.value, 3);  // the first count listed
  // the first ball's density, as the enumerated counts: 1.4e-4 kg in a 3 mm sphere
  EXPECT_FALSE(s.design.ball_count.diameter_m.has_value());
  EXPECT_NEAR(s.design.ball_count.density_kg_m3, 1.4e-4 / (M_PI / 6.0 * 27e-9), 1e-6);
  const problems::StartupProfileProblem p(s);
  EXPECT_EQ(p.variables().back().name, "balls");
  // the variable's ABU at each count is the enumerated choice's
  for (std::size_t i = 0; i < v.choices.size(); ++i) {
    std::vector<double> x = p.initial_point();
    x.back() = static_cast<double>(v.choices[i].balls.size());
    const AbuParameters a = p.abu_at(x), b = abu_of_choice(v, i);
    ASSERT_EQ(a.balls.size(), b.balls.size());
    EXPECT_DOUBLE_EQ(a.balls[0].mass_kg, b.balls[0].mass_kg);
    EXPECT_DOUBLE_EQ(a.balls[0].diameter_m, b.balls[0].diameter_m);
  }
}
