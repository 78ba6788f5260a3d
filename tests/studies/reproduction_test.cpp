// Reproduction studies: the shipped study files carry every published number of spec section 7,
// the YAML merge and its error messages, --runs, the conclusion checks on hand-made statistics,
// and a tiny end-to-end run of the library.
#include "abuopt/studies/reproduction.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "abuopt/common/config_error.hpp"
#include "abuopt/core/ball_contact.hpp"

namespace abuopt {
namespace {

const std::string kReportDir = std::string(ABUOPT_SOURCE_DIR) + "/configs/report";

const std::vector<ReproductionTable>& shipped() {
  static const std::vector<ReproductionTable> t = read_reproduction_tables(kReportDir);
  return t;
}

const ReproductionTable& table(const std::string& id) {
  for (const auto& t : shipped())
    if (t.id == id) return t;
  throw std::runtime_error("no table " + id);
}

struct Row {
  double value, mean, max, lc, mi;  // lc < 0: not published
};

void expect_rows(const std::string& id, const std::vector<Row>& rows, std::size_t runs) {
  const ReproductionTable& t = table(id);
  ASSERT_EQ(t.cases.size(), rows.size()) << id;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const ReproductionCase& c = t.cases[i];
    SCOPED_TRACE(id + " " + c.id);
    ASSERT_TRUE(c.value.has_value());
    EXPECT_DOUBLE_EQ(*c.value, rows[i].value);
    ASSERT_TRUE(c.reference.mean_1e7 && c.reference.max_1e7 && c.reference.pct_mi);
    EXPECT_DOUBLE_EQ(*c.reference.mean_1e7, rows[i].mean);
    EXPECT_DOUBLE_EQ(*c.reference.max_1e7, rows[i].max);
    EXPECT_DOUBLE_EQ(*c.reference.pct_mi, rows[i].mi);
    if (rows[i].lc >= 0) {
      ASSERT_TRUE(c.reference.pct_lc.has_value());
      EXPECT_DOUBLE_EQ(*c.reference.pct_lc, rows[i].lc);
    }
    EXPECT_EQ(c.study.runs, runs);
    EXPECT_EQ(c.study.design.kind, InitialConditionKind::Grid);
    EXPECT_EQ(study_design(c.study).size(), runs);
    EXPECT_DOUBLE_EQ(c.study.setup.abu.friction_mu, 0.02);
    EXPECT_LE(c.study.setup.options.end_time_s, 0.0) << "end time must default to twice the profile";
  }
}

// Spec section 7, every number of every table.
TEST(ReproductionTables, ShippedInTheReportsOrder) {
  std::vector<std::string> ids;
  for (const auto& t : shipped()) ids.push_back(t.id);
  EXPECT_EQ(ids, report_table_ids());
}

TEST(ReproductionTables, Table41EveryPublishedNumber) {
  expect_rows("4.1",
              {{1, 11.54, 44.65, 0, 15.43},
               {2, 11.41, 33.47, 0, 15.43},
               {3, 10.05, 30.89, 0.49, 11.04},
               {4, 10.00, 28.52, 1.37, 9.18},
               {5, 9.76, 28.28, 0.49, 8.69},
               {6, 9.57, 27.99, 0.49, 7.23},
               {7, 9.67, 27.35, 1.07, 6.35},
               {8, 9.76, 27.64, 2.05, 5.76},
               {9, 9.49, 26.86, 1.07, 5.27},
               {10, 9.37, 39.67, 1.46, 5.47}},
              1024);
  for (const auto& c : table("4.1").cases) {
    const StartupProfile& p = c.study.setup.profile;
    ASSERT_EQ(p.segments().size(), 1u);
    EXPECT_DOUBLE_EQ(p.final_frequency_hz(), 29.5);
    EXPECT_DOUBLE_EQ(p.duration_s(), *c.value);
  }
}

TEST(ReproductionTables, Table42EveryPublishedNumber) {
  expect_rows("4.2",
              {{2, 9.87, 28.43, 6.05, 8.79},
               {4, 9.33, 28.07, 3.03, 4.79},
               {6, 8.67, 25.71, 2.54, 3.32},
               {8, 8.75, 25.71, 1.17, 2.25},
               {10, 8.85, 24.67, 0.49, 1.56}},
              1024);
  for (const auto& c : table("4.2").cases) {
    const auto& s = c.study.setup.profile.segments();
    ASSERT_EQ(s.size(), 2u);
    EXPECT_DOUBLE_EQ(s[0].end_frequency_hz, 25.0);
    EXPECT_DOUBLE_EQ(s[0].duration_s, 1.0);
    EXPECT_DOUBLE_EQ(s[1].end_frequency_hz, 29.5);
    EXPECT_DOUBLE_EQ(s[1].duration_s, *c.value);
  }
}

TEST(ReproductionTables, Table43EveryPublishedNumber) {
  expect_rows("4.3",
              {{1, 9.37, 47.41, 0, 3.13},
               {2, 9.35, 37.22, 0, 3.52},
               {3, 9.22, 43.93, 0, 2.73},
               {4, 8.74, 27.37, 0, 3.13},
               {8, 8.53, 25.56, 0, 2.34},
               {12, 8.61, 25.56, 0, 2.73},
               {16, 8.64, 25.56, 0, 3.13},
               {20, 8.55, 25.56, 0, 2.34}},
              256);
  for (const auto& c : table("4.3").cases) {
    const auto& s = c.study.setup.profile.segments();
    ASSERT_EQ(s.size(), 3u);
    EXPECT_DOUBLE_EQ(s[1].duration_s, 10.0);
    EXPECT_DOUBLE_EQ(s[2].end_frequency_hz, 100.0);
    EXPECT_DOUBLE_EQ(s[2].duration_s, *c.value);
  }
}

TEST(ReproductionTables, Table44EveryPublishedNumber) {
  expect_rows("4.4",
              {{19, 8.53, 25.56, -1, 2.34},
               {2, 25.11, 52.34, -1, 61.33},
               {4, 20.73, 52.60, -1, 41.02},
               {6, 12.78, 51.95, -1, 19.14},
               {8, 21.49, 52.56, -1, 45.70},
               {10, 20.20, 49.48, -1, 47.66},
               {19, 17.13, 50.25, -1, 37.11}},
              256);
  const ReproductionTable& t = table("4.4");
  // The three-step case is the base profile: the report's final design.
  const StartupProfile& three = t.find_case("three_step")->study.setup.profile;
  const StartupProfile fin = StartupProfile::report_final();
  ASSERT_EQ(three.segments().size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_DOUBLE_EQ(three.segments()[i].end_frequency_hz, fin.segments()[i].end_frequency_hz);
    EXPECT_DOUBLE_EQ(three.segments()[i].duration_s, fin.segments()[i].duration_s);
  }
  const StartupProfile& one = t.find_case("one_step_19")->study.setup.profile;
  ASSERT_EQ(one.segments().size(), 1u);
  EXPECT_DOUBLE_EQ(one.final_frequency_hz(), 100.0);
  EXPECT_DOUBLE_EQ(one.duration_s(), 19.0);
  ASSERT_EQ(t.conclusions.size(), 1u);
  EXPECT_EQ(t.conclusions[0].check, ConclusionCheck::BeatsAll);
  EXPECT_EQ(t.conclusions[0].case_id, "three_step");
  ASSERT_EQ(t.plots.size(), 1u);
  EXPECT_EQ(t.plots[0].kind, PlotKind::FinalPositions);
  EXPECT_EQ(t.plots[0].case_ids, (std::vector<std::string>{"three_step", "one_step_19"}));
}

TEST(ReproductionTables, FinalProfileAndFriction) {
  const ReproductionTable& f = table("final");
  ASSERT_EQ(f.cases.size(), 1u);
  const ReproductionCase& c = f.cases[0];
  EXPECT_EQ(c.study.runs, 1024u);
  EXPECT_DOUBLE_EQ(*c.reference.mean_1e7, 8.96);
  EXPECT_DOUBLE_EQ(*c.reference.pct_mi, 1.56);
  EXPECT_DOUBLE_EQ(*c.reference.max_1e7, 24.0);
  EXPECT_FALSE(c.reference.note.empty());  // "about 2.4e-6"
  EXPECT_DOUBLE_EQ(c.study.setup.profile.duration_s(), 19.0);

  const ReproductionTable& mu = table("mu");
  const std::vector<double> expected = {0.02, 0.025, 0.03, 0.035, 0.04};
  ASSERT_EQ(mu.cases.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_DOUBLE_EQ(mu.cases[i].study.setup.abu.friction_mu, expected[i]);
    EXPECT_DOUBLE_EQ(*mu.cases[i].value, expected[i]);
    EXPECT_EQ(mu.cases[i].study.uncertain.friction.sampling, FrictionSampling::Nominal);  // uses abu.friction_mu
    EXPECT_TRUE(mu.cases[i].reference.empty());
    EXPECT_EQ(mu.cases[i].study.runs, 1024u);
  }
  EXPECT_FALSE(mu.expectation.empty());
  ASSERT_EQ(mu.conclusions.size(), 1u);
  EXPECT_EQ(mu.conclusions[0].check, ConclusionCheck::WorsensWithValue);
  // Conclusion (b) is carried by tables 4.1 and 4.2.
  EXPECT_EQ(table("4.1").conclusions.at(0).check, ConclusionCheck::PctMiDecreasesWithValue);
  EXPECT_EQ(table("4.2").conclusions.at(0).check, ConclusionCheck::PctMiDecreasesWithValue);
}

// --- reading --------------------------------------------------------------------------------------

const char* kTiny = R"(
table:
  id: tiny
  title: "a tiny table"
  source: "made up"
  parameter: {name: dt, unit: s}
  conclusions:
    - {id: b, check: pct_mi_decreases_with_value, claim: "slower is better"}
  plots:
    - {kind: trend}
base:
  abu: {friction_mu: 0.02}
  profile:
    segments:
      - {end_frequency_hz: 25.0, duration_s: 0.2}
      - {end_frequency_hz: 30.0, duration_s: 0.2}
  simulation: {end_time_s: 0.6}
  montecarlo: {design: grid, grid: 2, seed: 1}
cases:
  - {id: short, value: 0.2, reference: {mean: 1.5, pct_mi: 10}}
  - {id: long, value: 0.5, abu: {friction_mu: 0.03},
     profile: {segments: [{end_frequency_hz: 30.0, duration_s: 0.5}]}}
)";

TEST(ReproductionReading, MergesTheCaseOverTheBase) {
  const ReproductionTable t = read_reproduction_table_string(kTiny, "tiny.yaml");
  EXPECT_EQ(t.id, "tiny");
  EXPECT_EQ(t.parameter_name, "dt");
  ASSERT_EQ(t.cases.size(), 2u);
  EXPECT_EQ(t.cases[0].label, "dt = 0.2 s");  // default label from the parameter
  EXPECT_EQ(t.cases[0].study.setup.profile.segments().size(), 2u);
  EXPECT_DOUBLE_EQ(t.cases[0].study.setup.abu.friction_mu, 0.02);
  EXPECT_DOUBLE_EQ(*t.cases[0].reference.mean_1e7, 1.5);
  EXPECT_FALSE(t.cases[0].reference.max_1e7.has_value());
  // The case's profile replaces the base's segment list; its abu key merges into the base's abu.
  EXPECT_EQ(t.cases[1].study.setup.profile.segments().size(), 1u);
  EXPECT_DOUBLE_EQ(t.cases[1].study.setup.abu.friction_mu, 0.03);
  EXPECT_DOUBLE_EQ(t.cases[1].study.setup.options.end_time_s, 0.6);
  EXPECT_EQ(t.cases[1].study.runs, 4u);
  EXPECT_TRUE(t.cases[1].reference.empty());
  ASSERT_EQ(t.plots.size(), 1u);
  EXPECT_EQ(t.plots[0].name, "tiny_trend");
}

TEST(ReproductionReading, MergeYamlKeepsTheBase) {
  const YAML::Node base = YAML::Load("{a: {x: 1, y: 2}, s: [1, 2, 3], k: v}");
  const YAML::Node over = YAML::Load("{a: {y: 5, z: 6}, s: [9]}");
  const YAML::Node m = merge_yaml(base, over);
  EXPECT_EQ(m["a"]["x"].as<int>(), 1);
  EXPECT_EQ(m["a"]["y"].as<int>(), 5);
  EXPECT_EQ(m["a"]["z"].as<int>(), 6);
  EXPECT_EQ(m["s"].size(), 1u);
  EXPECT_EQ(m["k"].as<std::string>(), "v");
  EXPECT_EQ(base["a"]["y"].as<int>(), 2);  // untouched
  EXPECT_EQ(base["s"].size(), 3u);
}

std::string error_of(const std::string& yaml) {
  try {
    read_reproduction_table_string(yaml, "bad.yaml");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "<no error>";
}

std::string replace(std::string s, const std::string& from, const std::string& to) {
  const auto pos = s.find(from);
  if (pos == std::string::npos) throw std::runtime_error("test setup: '" + from + "' not found");
  return s.replace(pos, from.size(), to);
}

TEST(ReproductionReading, ErrorsNameTheFileCaseKeyAndRule) {
  std::string e = error_of(replace(kTiny, "abu: {friction_mu: 0.03}", "abu: {friction_mu: 0.03, frction: 1}"));
  EXPECT_NE(e.find("bad.yaml"), std::string::npos) << e;
  EXPECT_NE(e.find("cases[1] (long)"), std::string::npos) << e;
  EXPECT_NE(e.find("abu.frction"), std::string::npos) << e;

  e = error_of(replace(kTiny, "reference: {mean: 1.5", "reference: {maen: 1.5"));
  EXPECT_NE(e.find("cases[0].reference.maen"), std::string::npos) << e;

  e = error_of(replace(kTiny, "{id: long,", "{id: short,"));
  EXPECT_NE(e.find("unique"), std::string::npos) << e;

  e = error_of(replace(kTiny, "check: pct_mi_decreases_with_value", "check: faster"));
  EXPECT_NE(e.find("beats_all"), std::string::npos) << e;

  e = error_of(replace(kTiny, "check: pct_mi_decreases_with_value", "check: beats_all, case: nope"));
  EXPECT_NE(e.find("nope"), std::string::npos) << e;

  e = error_of(replace(kTiny, "{kind: trend}", "{kind: final_positions, cases: [short, missing]}"));
  EXPECT_NE(e.find("missing"), std::string::npos) << e;

  e = error_of(replace(kTiny, "{kind: trend}", "{kind: trend, colour: red}"));
  EXPECT_NE(e.find("colour"), std::string::npos) << e;

  e = error_of(replace(kTiny, "duration_s: 0.5", "duration_s: -1"));
  EXPECT_NE(e.find("profile.segments[0].duration_s = -1"), std::string::npos) << e;

  e = error_of(replace(kTiny, "grid: 2, seed: 1", "grid: 2, seed: 1, runs: 5"));
  EXPECT_NE(e.find("runs"), std::string::npos) << e;
}

TEST(ReproductionReading, SelectTablesByIdAndUnknownIds) {
  const auto sel = select_tables(shipped(), {"4.4", "final"});
  ASSERT_EQ(sel.size(), 2u);
  EXPECT_EQ(sel[0].id, "4.4");
  EXPECT_EQ(sel[1].id, "final");
  EXPECT_EQ(select_tables(shipped(), {}).size(), shipped().size());
  try {
    select_tables(shipped(), {"4.5"});
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("table ids = 4.5"), std::string::npos) << m;
    EXPECT_NE(m.find("4.1, 4.2, 4.3, 4.4, final, mu"), std::string::npos) << m;
  }
}

TEST(ReproductionReading, RunsOverrideUsesTheNearestSquareGrid) {
  std::vector<ReproductionTable> t = select_tables(shipped(), {"4.3", "final"});
  std::string note = override_runs(t, 16);
  for (const auto& tb : t)
    for (const auto& c : tb.cases) {
      EXPECT_EQ(c.study.runs, 16u);
      EXPECT_EQ(c.study.design.grid_points_per_axis, 4u);
    }
  EXPECT_NE(note.find("4 x 4 grid = 16 runs"), std::string::npos) << note;
  note = override_runs(t, 1000);
  EXPECT_EQ(t[0].cases[0].study.runs, 1024u);
  EXPECT_NE(note.find("32 x 32 grid = 1024 runs"), std::string::npos) << note;
  EXPECT_THROW(override_runs(t, 0), ConfigError);
}

// --- conclusions on hand-made statistics ---------------------------------------------------------

CaseSummary row(const std::string& id, std::optional<double> value, double mean, double sem, double mi,
                double lo, double hi) {
  CaseSummary s;
  s.table_id = "t";
  s.case_id = id;
  s.label = id;
  s.value = value;
  s.runs = s.ok = 256;
  s.mean_x = mean;
  s.sem_x = sem;
  s.pct_mi_x = mi;
  s.ci_x = {lo, hi};
  return s;
}

TEST(ReproductionConclusions, BeatsAll) {
  const CaseSummary best = row("three", 19, 8.5, 0.3, 2.3, 1.1, 5.0);
  // Clear on both figures against both others.
  Verdict v = check_beats_all(best, {row("one6", 6, 12.8, 0.5, 19.1, 14.8, 24.4), row("one19", 19, 17.1, 0.6, 37.1, 31.4, 43.2)});
  EXPECT_EQ(v.outcome, VerdictOutcome::Confirmed) << v.evidence;
  EXPECT_NE(v.evidence.find("4 of 4"), std::string::npos) << v.evidence;
  // Lower, but the mean gap (0.5) is within 1.96 sqrt(0.3^2 + 0.4^2) = 0.98.
  v = check_beats_all(best, {row("close", 6, 9.0, 0.4, 9.0, 6.0, 13.0)});
  EXPECT_EQ(v.outcome, VerdictOutcome::Weak) << v.evidence;
  // %MI intervals overlap.
  v = check_beats_all(best, {row("close", 6, 12.0, 0.4, 4.0, 2.0, 7.0)});
  EXPECT_EQ(v.outcome, VerdictOutcome::Weak);
  // One other case has a lower %MI.
  v = check_beats_all(best, {row("one6", 6, 12.8, 0.5, 19.1, 14.8, 24.4), row("better", 8, 12.0, 0.5, 1.0, 0.2, 3.0)});
  EXPECT_EQ(v.outcome, VerdictOutcome::NotReproduced);
  v = check_beats_all(best, {});
  EXPECT_EQ(v.outcome, VerdictOutcome::NotTested);
}

TEST(ReproductionConclusions, PctMiDecreasesComparesTheExtremeValues) {
  // Rows out of order: the check uses the smallest and the largest value, not the first and last.
  std::vector<CaseSummary> rows = {row("dt5", 5, 9.8, 0.2, 8.7, 7.1, 10.6), row("dt1", 1, 11.5, 0.3, 15.4, 13.3, 17.8),
                                   row("dt10", 10, 9.4, 0.2, 5.5, 4.2, 7.0)};
  Verdict v = check_pct_mi_decreases(rows);
  EXPECT_EQ(v.outcome, VerdictOutcome::Confirmed) << v.evidence;
  EXPECT_NE(v.evidence.find("dt1"), std::string::npos);
  EXPECT_NE(v.evidence.find("dt10"), std::string::npos);
  rows[2] = row("dt10", 10, 9.4, 0.2, 13.0, 11.0, 15.2);  // lower, intervals overlap
  EXPECT_EQ(check_pct_mi_decreases(rows).outcome, VerdictOutcome::Weak);
  rows[2] = row("dt10", 10, 9.4, 0.2, 16.0, 13.9, 18.4);  // higher
  EXPECT_EQ(check_pct_mi_decreases(rows).outcome, VerdictOutcome::NotReproduced);
  EXPECT_EQ(check_pct_mi_decreases({rows[0]}).outcome, VerdictOutcome::NotTested);
  EXPECT_EQ(check_pct_mi_decreases({row("x", std::nullopt, 1, 0.1, 1, 0, 2), row("y", std::nullopt, 1, 0.1, 0, 0, 1)}).outcome,
            VerdictOutcome::NotTested);
}

TEST(ReproductionConclusions, WorsensWithValue) {
  std::vector<CaseSummary> rows = {row("mu0.02", 0.02, 8.7, 0.15, 2.1, 1.4, 3.2), row("mu0.03", 0.03, 9.6, 0.15, 3.0, 2.1, 4.2),
                                   row("mu0.04", 0.04, 10.9, 0.16, 6.5, 5.1, 8.2)};
  Verdict v = check_worsens_with_value(rows);
  EXPECT_EQ(v.outcome, VerdictOutcome::Confirmed) << v.evidence;
  EXPECT_NE(v.evidence.find("mean rises in 2 of 2 steps, %MI in 2 of 2"), std::string::npos) << v.evidence;
  rows[2].pct_mi_x = 3.0;  // mean up clearly, %MI up but intervals overlap
  rows[2].ci_x = {2.1, 4.2};
  EXPECT_EQ(check_worsens_with_value(rows).outcome, VerdictOutcome::Weak);
  rows[2].mean_x = 8.0;  // mean down
  EXPECT_EQ(check_worsens_with_value(rows).outcome, VerdictOutcome::NotReproduced);
}

TEST(ReproductionConclusions, CheckConclusionsFillsIdsAndClaims) {
  ReproductionTable t = read_reproduction_table_string(kTiny, "tiny.yaml");
  std::vector<CaseSummary> rows = {row("short", 0.2, 9, 0.1, 20, 15, 25), row("long", 0.5, 8, 0.1, 5, 3, 8)};
  const auto v = check_conclusions(t, rows);
  ASSERT_EQ(v.size(), 1u);
  EXPECT_EQ(v[0].outcome, VerdictOutcome::Confirmed);
  EXPECT_EQ(v[0].table_id, "tiny");
  EXPECT_EQ(v[0].conclusion_id, "b");
  EXPECT_EQ(v[0].one_line().rfind("(b) [table tiny] CONFIRMED: slower is better -- ", 0), 0u) << v[0].one_line();
  // A beats_all conclusion whose case did not run is NOT TESTED, not an error.
  t.conclusions = {{"a", "x beats all", ConclusionCheck::BeatsAll, "absent"}};
  EXPECT_EQ(check_conclusions(t, rows).at(0).outcome, VerdictOutcome::NotTested);
}

TEST(ReproductionConclusions, SummaryFromSamples) {
  const ReproductionTable t = read_reproduction_table_string(kTiny, "tiny.yaml");
  MonteCarloResult r;
  const double I = t.cases[0].study.setup.abu.imbalance_kgm();
  const std::vector<double> irx = {0.5 * I, 1.5 * I, 0.25 * I, 0.75 * I};
  for (std::size_t i = 0; i < irx.size(); ++i) {
    MonteCarloSample s;
    s.index = i;
    s.imbalance_kgm = I;
    s.outcome.residual_imbalance_x_kgm = irx[i];
    s.outcome.residual_imbalance_kgm = irx[i] * 1.2;
    s.outcome.settled = true;
    s.outcome.beta_final = {0, 0};
    r.samples.push_back(s);
  }
  const CaseSummary s = summarize_case(t, t.cases[0], r);
  const double e7 = I * 1e7;
  EXPECT_NEAR(s.mean_x, 0.75 * e7, 1e-12);
  EXPECT_NEAR(s.max_x, 1.5 * e7, 1e-12);
  EXPECT_DOUBLE_EQ(s.pct_mi_x, 25.0);
  EXPECT_DOUBLE_EQ(s.pct_mi_mag, 25.0);  // 1.2 x 0.75 I < I
  // Sample standard deviation of {0.5, 1.5, 0.25, 0.75} I is 0.5401 I; / sqrt(4).
  EXPECT_NEAR(s.sem_x, std::sqrt((0.0625 + 0.5625 + 0.25 + 0.0) / 3.0) / 2.0 * e7, 1e-9);
  EXPECT_EQ(s.label, "dt = 0.2 s");
  // The report's 10 % lies inside the Wilson interval of 1 in 4.
  ASSERT_TRUE(reference_pct_mi_inside(s).has_value());
  EXPECT_TRUE(*reference_pct_mi_inside(s));
  const std::string line = tables_csv_line(s);
  EXPECT_EQ(line.rfind("tiny,short,dt = 0.2 s,0.2,4,4,0,", 0), 0u) << line;
  const std::string header = tables_csv_header();
  EXPECT_EQ(std::count(line.begin(), line.end(), ','), std::count(header.begin(), header.end(), ','));
}

// --- the library end to end on a tiny table (real simulator, a few runs) --------------------------

TEST(ReproductionRun, WritesEveryFileAsCasesFinish) {
  const ReproductionTable t = read_reproduction_table_string(kTiny, "tiny.yaml");
  const std::string out = std::string(ABUOPT_BINARY_DIR) + "/reproduction_test_out";
  std::filesystem::remove_all(out);
  ReproductionOptions opt;
  opt.out_dir = out;
  opt.threads = 1;
  opt.plots = false;
  std::vector<std::string> log;
  opt.log = [&log](const std::string& l) { log.push_back(l); };
  const ReproductionReport r = run_reproduction({t}, opt);
  ASSERT_EQ(r.tables.size(), 1u);
  ASSERT_EQ(r.tables[0].rows.size(), 2u);
  EXPECT_EQ(r.tables[0].rows[0].runs, 4u);
  ASSERT_EQ(log.size(), 2u);  // one line per case
  EXPECT_NE(log[0].find("[1/2] tiny dt = 0.2 s: 4 runs in"), std::string::npos) << log[0];
  EXPECT_TRUE(std::filesystem::exists(out + "/runs/tiny/short.csv"));
  EXPECT_TRUE(std::filesystem::exists(out + "/runs/tiny/long.csv"));
  std::ifstream csv(out + "/tables.csv");
  std::string line;
  int lines = 0;
  while (std::getline(csv, line)) ++lines;
  EXPECT_EQ(lines, 3);
  std::ifstream md(out + "/report.md");
  const std::string text((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("| dt = 0.5 s |"), std::string::npos);
  EXPECT_NE(text.find("(b) [table tiny]"), std::string::npos);
  EXPECT_EQ(r.verdicts().size(), 1u);
  const std::string txt = format_table_text(r.tables[0]);
  EXPECT_NE(txt.find("dt = 0.2 s"), std::string::npos);
}

// --- contact_variant: the same cases with hard ball contact as an extra column set ----------------

TEST(ReproductionContact, ShippedTablesAskForIt) {
  EXPECT_EQ(table("4.4").contact_variant, BallContact::Hard);
  EXPECT_EQ(table("final").contact_variant, BallContact::Hard);
  EXPECT_FALSE(table("4.1").contact_variant.has_value());
  for (const ReproductionCase& c : table("4.4").cases) EXPECT_EQ(c.study.setup.abu.ball_contact, BallContact::None);
}

TEST(ReproductionContact, VariantMustDifferFromTheReportsModel) {
  std::string y = kTiny;
  const std::string key = "  conclusions:";
  ASSERT_NE(y.find(key), std::string::npos);
  std::string bad = y;
  bad.replace(bad.find(key), key.size(), "  contact_variant: none\n" + key);
  try {
    read_reproduction_table_string(bad, "tiny.yaml");
    FAIL() << "contact_variant: none accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("contact_variant"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("hard"), std::string::npos) << e.what();
  }
  std::string good = y;
  good.replace(good.find(key), key.size(), "  contact_variant: hard\n" + key);
  EXPECT_EQ(read_reproduction_table_string(good, "tiny.yaml").contact_variant, BallContact::Hard);
}

TEST(ReproductionContact, CountsOverlappingFinalStates) {
  AbuParameters p = table("4.4").cases.front().study.setup.abu;
  const double delta = contact_spacing(p, 0, 1);  // 0.2617 rad for two 3 mm balls on 11.5 mm
  MonteCarloResult r;
  for (double gap : {0.0, 0.5 * delta, delta, 2.0 * delta, 6.0}) {
    MonteCarloSample s;
    s.outcome.beta_final = {1.0, 1.0 + gap};
    r.samples.push_back(s);
  }
  // 0 and delta/2 overlap; delta touches; 2 delta is apart; 6 rad is 2 pi - 6 = 0.28 > delta around the back.
  EXPECT_EQ(count_overlapping_final_states(p, r), 2u);
}

// Table 4.4 on a 6 x 6 grid, two cases, with and without the variant: the contact columns exist,
// no contact run ends overlapping, and every no-contact number and file is the same as without it.
TEST(ReproductionContact, ExtraColumnsAndNoContactUnchanged) {
  ReproductionTable t = table("4.4");
  t.cases.erase(std::remove_if(t.cases.begin(), t.cases.end(),
                               [](const ReproductionCase& c) { return c.id != "three_step" && c.id != "one_step_2"; }),
                t.cases.end());
  ASSERT_EQ(t.cases.size(), 2u);
  std::vector<ReproductionTable> with{t};
  override_runs(with, 36);
  std::vector<ReproductionTable> without = with;
  without[0].contact_variant.reset();
  auto run = [](const std::vector<ReproductionTable>& tables, const std::string& name) {
    ReproductionOptions opt;
    opt.out_dir = std::string(ABUOPT_BINARY_DIR) + "/" + name;
    std::filesystem::remove_all(opt.out_dir);
    opt.threads = 2;
    opt.plots = false;
    return run_reproduction(tables, opt);
  };
  const ReproductionReport a = run(with, "reproduction_contact_on");
  const ReproductionReport b = run(without, "reproduction_contact_off");
  const TableResult& ta = a.tables.at(0);
  const TableResult& tb = b.tables.at(0);
  ASSERT_EQ(ta.contact_rows.size(), 2u);
  EXPECT_TRUE(tb.contact_rows.empty());
  std::size_t overlapping_without = 0;
  for (const ContactRow& r : ta.contact_rows) {
    EXPECT_EQ(r.summary.runs, 36u);
    EXPECT_EQ(r.summary.failed, 0u);
    EXPECT_EQ(r.overlapping_with, 0u) << r.summary.label;
    overlapping_without += r.overlapping_without;
  }
  EXPECT_GT(overlapping_without, 0u) << "the grid without contact should end some runs overlapping";
  // The no-contact columns: identical numbers (wall time aside) and identical per-run files.
  for (std::size_t k = 0; k < 2; ++k) {
    CaseSummary x = ta.rows[k], y = tb.rows[k];
    x.wall_time_s = y.wall_time_s = 0;
    EXPECT_EQ(tables_csv_line(x), tables_csv_line(y));
    auto slurp = [](const std::string& f) {
      std::ifstream in(f);
      return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    };
    const std::string id = t.cases[k].id;
    const std::string on = std::string(ABUOPT_BINARY_DIR) + "/reproduction_contact_on/runs/4.4/";
    const std::string off = std::string(ABUOPT_BINARY_DIR) + "/reproduction_contact_off/runs/4.4/";
    EXPECT_EQ(slurp(on + id + ".csv"), slurp(off + id + ".csv"));
    EXPECT_TRUE(std::filesystem::exists(on + id + "_contact_hard.csv"));
    EXPECT_FALSE(std::filesystem::exists(off + id + "_contact_hard.csv"));
  }
  ASSERT_EQ(ta.verdicts.size(), tb.verdicts.size());
  for (std::size_t k = 0; k < ta.verdicts.size(); ++k) EXPECT_EQ(ta.verdicts[k].outcome, tb.verdicts[k].outcome);
  // The column set in the terminal table, the Markdown and tables_contact.csv.
  const std::string txt = format_table_text(ta);
  EXPECT_NE(txt.find("mean I_r,x (contact)"), std::string::npos) << txt;
  EXPECT_NE(txt.find("%MI (contact)"), std::string::npos) << txt;
  EXPECT_NE(txt.find("What ball contact (hard) changes"), std::string::npos) << txt;
  EXPECT_EQ(format_table_text(tb).find("(contact)"), std::string::npos);
  const std::string md = format_table_markdown(ta);
  EXPECT_NE(md.find("| mean I_r,x (contact) |"), std::string::npos) << md;
  EXPECT_NE(md.find("| %MI (contact) (95 % CI) |"), std::string::npos) << md;
  ASSERT_FALSE(a.tables_contact_csv_path.empty());
  EXPECT_TRUE(b.tables_contact_csv_path.empty());
  std::ifstream csv(a.tables_contact_csv_path);
  std::string header, line;
  std::getline(csv, header);
  EXPECT_EQ(header, tables_contact_csv_header());
  int lines = 0;
  while (std::getline(csv, line)) {
    ASSERT_LT(lines, 2);
    const ContactRow& r = ta.contact_rows[lines++];
    EXPECT_EQ(line, tables_csv_line(r.summary) + ",hard," + std::to_string(r.overlapping_without) + ",0");
  }
  EXPECT_EQ(lines, 2);
}

}  // namespace
}  // namespace abuopt
