// Two-objective problems of `abuopt compare` (studies/front_comparison.hpp): a bad `fronts:` entry
// is one ConfigError naming its key; the budget split of the epsilon-constraint series; on a small
// front problem (8 Monte Carlo runs per evaluation, 48 evaluations, 2 seeds; NSGA-II, MOEA/D and the
// epsilon-constraint series): the equal-evaluations
// rule, hypervolume.csv equal to opt::hypervolume_2d of the points written to fronts.csv (1e-12),
// and a rerun on the same archive answering every run bit for bit. A few seconds.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "abuopt/common/config_error.hpp"
#include "abuopt/optimizer/multi_objective.hpp"
#include "abuopt/studies/front_comparison.hpp"

namespace {

namespace fs = std::filesystem;
using namespace abuopt;

// A small front problem: the report's two-ball design, T free, 8 LHS runs per evaluation.
std::string front_yaml(const std::string& methods, const std::string& extra = "",
                       const std::string& reference = "reference: {objective: 25, second: 23}",
                       const std::string& constraints = "max_pct_mi: 10, max_amplitude_mm: 0.55, amplitude: max") {
  return "label: small_front\nmax_evaluations: 48\nseeds: 2\nseed: 304\n" + reference + "\n" + extra +
         "startup_profile:\n"
         "  abu: {friction_mu: 0.02}\n"
         "  profile:\n"
         "    start_frequency_hz: 0\n"
         "    segments:\n"
         "      - {end_frequency_hz: 25.0, duration_s: 1.0}\n"
         "      - {end_frequency_hz: 29.5, duration_s: 10.0}\n"
         "      - {end_frequency_hz: 100.0, duration_s: 8.0}\n"
         "  motor: {kind: ideal}\n"
         "  simulation: {method: event_driven, rtol: 1.0e-6}\n"
         "  design:\n"
         "    segments:\n"
         "      - end_frequency_hz: {min: 15, max: 28, x0: 25}\n"
         "        duration_s: {min: 0.3, max: 3, x0: 1}\n"
         "      - end_frequency_hz: {min: 28, max: 32, x0: 29.5}\n"
         "        duration_s: {min: 1, max: 12, x0: 10}\n"
         "      - end_frequency_hz: 100\n"
         "        duration_s: {min: 1, max: 10, x0: 8}\n"
         "  objective: {kind: mean, definition: magnitude}\n"
         "  constraints: {" + constraints + "}\n"
         "  montecarlo: {design: lhs, runs: 8, seed: 11, threads: 0}\n"
         "  validation: {design: random, runs: 64, seed: 12}\n"
         "methods:\n" + methods;
}

const std::string kMethods =
    "  - {label: NSGA-II, algorithm: pagmo_nsga2, population: 8}\n"
    "  - {label: MOEA/D, algorithm: pagmo_moead, population: 8}\n"
    "  - {label: eps, algorithm: epsilon_constraint, bounds_s: [10, 16, 23], warm_start: false,\n"
    "     inner: {algorithm: cobyla, options: {initial_step: 0.1}}}\n";

FrontProblem read(const std::string& text) {
  YamlReader r = YamlReader::load_string(text, "fronts[0]");
  return read_front_problem(r);
}

// The key a bad entry's ConfigError names ("<key> = <value>: <rule>"; "" if none is thrown).
std::string rejected_key(const std::string& text) {
  try {
    read(text);
  } catch (const ConfigError& e) {
    const std::string m = e.what();
    return m.substr(0, m.find(" = "));
  }
  return "";
}

TEST(FrontComparison, BadEntriesAreRejectedNamingTheKey) {
  EXPECT_EQ(rejected_key(front_yaml("  - {algorithm: pagmo_spea2}\n")), "methods[0].algorithm");
  EXPECT_EQ(rejected_key(front_yaml("  - {algorithm: pagmo_moead, population: 3}\n")), "methods[0].population");
  EXPECT_EQ(rejected_key(front_yaml("  - {algorithm: pagmo_moead, population: 50}\n")), "methods[0].population");
  EXPECT_EQ(rejected_key(front_yaml("  - {algorithm: epsilon_constraint, bounds_s: []}\n")), "methods[0].bounds_s");
  EXPECT_EQ(rejected_key(front_yaml("  - {algorithm: epsilon_constraint, bounds_s: [10, 10, 20]}\n")),
            "methods[0].bounds_s");
  // the loosest bound beyond the reference's second coordinate
  EXPECT_EQ(rejected_key(front_yaml("  - {algorithm: epsilon_constraint, bounds_s: [10, 25]}\n")), "methods[0].bounds_s");
  EXPECT_EQ(rejected_key(front_yaml(kMethods, "", "")), "reference");
  EXPECT_EQ(rejected_key(front_yaml(kMethods, "", "reference: {objective: -1, second: 23}")), "reference.objective");
  EXPECT_EQ(rejected_key(front_yaml("  - {algorithm: pagmo_nsga2, population: 10}\n")), "methods[0].population");
  EXPECT_EQ(rejected_key(front_yaml("  - {algorithm: pagmo_nsga2, population: 52}\n")), "methods[0].population");
  EXPECT_EQ(rejected_key(front_yaml(kMethods, "", "reference: {objective: 25, second: 23}",
                                    "max_startup_time_s: 19, max_pct_mi: 10")),
            "startup_profile.constraints.max_startup_time_s");
  // 48 evaluations over 2 x 8 - 1 = 15 runs leave 3 per run, fewer than 5 variables + 2
  EXPECT_EQ(rejected_key(front_yaml("  - {algorithm: epsilon_constraint, bounds_s: [4, 6, 8, 10, 12, 14, 16, 18]}\n")),
            "methods[0].bounds_s");
  EXPECT_EQ(rejected_key(front_yaml("  - {algorithm: epsilon_constraint, bounds_s: [10, 20]}\n",
                                    "second_objective: end_time_s\n")),
            "methods[0].algorithm");
  EXPECT_EQ(rejected_key(front_yaml("  - {label: a, algorithm: pagmo_nsga2}\n  - {label: a, algorithm: pagmo_nsga2}\n")),
            "methods[1].label");
  EXPECT_EQ(rejected_key(front_yaml("  - {algorithm: pagmo_nsga2, populaton: 8}\n")), "methods[0].populaton");
  EXPECT_EQ(rejected_key(front_yaml(kMethods)), "");
}

TEST(FrontComparison, EpsilonConstraintBudgetSplit) {
  EXPECT_EQ(epsilon_constraint_runs(6, true), 11u);
  EXPECT_EQ(epsilon_constraint_runs(6, false), 6u);
  EXPECT_EQ(epsilon_constraint_inner_budget(240, 6, true), 21);  // 11 x 21 = 231 <= 240 < 231 + 21
  EXPECT_EQ(epsilon_constraint_inner_budget(240, 6, false), 40);
  for (long budget : {24L, 48L, 240L, 401L})
    for (std::size_t bounds : {2u, 3u, 6u})
      for (bool warm : {true, false}) {
        const long runs = static_cast<long>(epsilon_constraint_runs(bounds, warm));
        const long inner = epsilon_constraint_inner_budget(budget, bounds, warm);
        EXPECT_LE(runs * inner, budget);
        EXPECT_GT(runs * inner + runs, budget);  // short of the budget by less than one evaluation per run
      }
}

std::vector<std::vector<std::string>> csv_rows(const fs::path& p) {
  std::ifstream f(p);
  std::vector<std::vector<std::string>> rows;
  std::string line;
  std::getline(f, line);
  while (std::getline(f, line)) {
    std::vector<std::string> cells;
    std::istringstream is(line);
    for (std::string c; std::getline(is, c, ',');) cells.push_back(c);
    if (!line.empty() && line.back() == ',') cells.emplace_back();
    rows.push_back(cells);
  }
  return rows;
}

TEST(FrontComparison, HypervolumeOfTheWrittenFrontsAtEqualEvaluations) {
  const FrontProblem fp = read(front_yaml(kMethods));
  const fs::path dir = fs::temp_directory_path() / ("abuopt_front_test_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const FrontComparison c = run_front_comparison({fp}, (dir / "archive").string(), 2);
  ASSERT_EQ(c.runs.size(), 6u);  // 2 seeds x 3 methods
  for (const FrontRun& r : c.runs) {
    SCOPED_TRACE(r.method + " run " + std::to_string(r.run) + ": " + r.reason);
    EXPECT_LE(r.evaluations, fp.max_evaluations);
    if (r.method != "eps") {
      EXPECT_EQ(r.evaluations, fp.max_evaluations);  // NSGA-II and MOEA/D spend the budget
      EXPECT_EQ(r.inner_budget, 0);
    } else {
      EXPECT_EQ(r.inner_budget, 16);  // 48 / 3 bounds without warm starts
      EXPECT_LE(r.evaluations, 3 * r.inner_budget);
    }
    EXPECT_TRUE(r.validated);
    EXPECT_GE(r.hv_in, 0.0);
  }
  // at least one front from each method, with a positive hypervolume in and out of sample
  for (const char* m : {"NSGA-II", "MOEA/D", "eps"}) {
    double best_in = 0, best_out = 0;
    for (const FrontRun& r : c.runs)
      if (r.method == m) best_in = std::max(best_in, r.hv_in), best_out = std::max(best_out, r.hv_out);
    EXPECT_GT(best_in, 0.0) << m;
    EXPECT_GT(best_out, 0.0) << m;
  }

  opt::WrittenFiles files;
  write_front_outputs(c, dir.string(), files, false);
  // hypervolume.csv against opt::hypervolume_2d of the points of fronts.csv
  std::map<std::string, std::vector<std::pair<double, double>>> in, out;
  for (const auto& f : csv_rows(dir / "fronts.csv")) {
    ASSERT_EQ(f.size(), 11u);
    const std::string key = f[1] + "/" + f[2];
    in[key].emplace_back(std::stod(f[4]), std::stod(f[5]));
    if (f[9] == "1") out[key].emplace_back(std::stod(f[7]), std::stod(f[8]));
  }
  const auto hv = csv_rows(dir / "hypervolume.csv");
  ASSERT_EQ(hv.size(), 6u);
  for (const auto& h : hv) {
    const std::string key = h[1] + "/" + h[2];
    EXPECT_NEAR(std::stod(h[6]), opt::hypervolume_2d(in[key], fp.reference), 1e-12) << key;
    EXPECT_NEAR(std::stod(h[7]), opt::hypervolume_2d(out[key], fp.reference), 1e-12) << key;
    EXPECT_EQ(std::stoul(h[8]), in[key].size());
    EXPECT_EQ(std::stoul(h[9]), out[key].size());
  }

  // a rerun on the same archive: the same runs, bit for bit
  const FrontComparison again = run_front_comparison({fp}, (dir / "archive").string(), 1);
  for (std::size_t i = 0; i < c.runs.size(); ++i) {
    EXPECT_EQ(again.runs[i].evaluations, c.runs[i].evaluations);
    EXPECT_EQ(again.runs[i].hv_in, c.runs[i].hv_in);
    EXPECT_EQ(again.runs[i].hv_out, c.runs[i].hv_out);
  }
  fs::remove_all(dir);
}

}  // namespace
