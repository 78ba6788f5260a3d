// `abuopt sweep`, `abuopt pareto`, `abuopt archive export` and provenance, end to end on the built
// binary with small run counts: files, resuming from the archive, export values equal bit for bit
// to what the commands reported, provenance in every result/summary JSON and in the archive.
#include <gtest/gtest.h>

#include "abuopt_cli.hpp"
#include "startup_problem_yaml.hpp"

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;
using Result = abuopt::test::CliResult;

Result run(const std::string& args) { return abuopt::test::run_abuopt(args); }

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::path(ABUOPT_BINARY_DIR) / "sweep_cli_test" / name;
  fs::remove_all(d);
  fs::create_directories(d.parent_path());
  return d;
}

std::string write_config(const std::string& name, const std::string& text) {
  const fs::path d = fs::path(ABUOPT_BINARY_DIR) / "sweep_cli_test";
  fs::create_directories(d);
  const fs::path path = d / name;
  std::ofstream(path) << text;
  return path.string();
}

nlohmann::json read_json(const fs::path& p) {
  std::ifstream f(p);
  return nlohmann::json::parse(f);
}

// CSV without quoted commas (the files here have none): header -> column, rows of cells.
struct Csv {
  std::map<std::string, std::size_t> col;
  std::vector<std::vector<std::string>> rows;
  const std::string& at(std::size_t r, const std::string& name) const { return rows.at(r).at(col.at(name)); }
};
Csv read_csv(const fs::path& p) {
  std::ifstream f(p);
  Csv c;
  std::string line;
  auto split = [](const std::string& l) {
    std::vector<std::string> v;
    std::stringstream ss(l);
    for (std::string cell; std::getline(ss, cell, ',');) v.push_back(cell);
    if (!l.empty() && l.back() == ',') v.emplace_back();
    return v;
  };
  std::getline(f, line);
  const auto head = split(line);
  for (std::size_t i = 0; i < head.size(); ++i) c.col[head[i]] = i;
  while (std::getline(f, line)) c.rows.push_back(split(line));
  return c;
}

std::uint64_t bits(double v) {
  std::uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}
double parse(const std::string& s) { return std::strtod(s.c_str(), nullptr); }

// FNV-1a 64 of a file, as the provenance's config_hash should be (computed here independently).
std::string fnv_of_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  std::uint64_t h = 14695981039346656037ULL;
  for (unsigned char ch : os.str()) {
    h ^= ch;
    h *= 1099511628211ULL;
  }
  char out[32];
  std::snprintf(out, sizeof out, "fnv1a64:%016llx", static_cast<unsigned long long>(h));
  return out;
}

void expect_provenance(const nlohmann::json& j, const std::string& config) {
  ASSERT_TRUE(j.contains("provenance")) << j.dump(1);
  EXPECT_EQ(j["provenance"]["abuopt_version"], "0.1.0");
  const std::string commit = j["provenance"]["git_commit"];
  EXPECT_FALSE(commit.empty());
  EXPECT_EQ(j["provenance"]["config_hash"], fnv_of_file(config));
}

const std::string kBase =
    abuopt_test::kReportAbuAndProfile + "simulation:\n  method: event_driven\n" + abuopt_test::lhs_montecarlo(8) +
    abuopt_test::kThreeSegmentDesign + R"(objective:
  kind: mean
validation:
  runs: 16
  design: random
  seed: 70
)";

}  // namespace

TEST(SweepCli, GridSweepWritesEveryPointResumesAndExportsTheSameBits) {
  const std::string cfg = write_config("grid.yaml", std::string(kBase) +
                                                        "constraints: {max_startup_time_s: 15}\n"
                                                        "sweep: {method: grid, variables: [dt2, dt3], levels: {dt2: 3, dt3: 2}}\n");
  const fs::path out = fresh_dir("grid");
  const Result first = run("sweep " + cfg + " --out " + out.string());
  ASSERT_EQ(first.status, 0) << first.output;
  EXPECT_NE(first.output.find("6 of 6 points (6 computed, 0 from the archive, 0 failed)"), std::string::npos)
      << first.output;
  const Csv a = read_csv(out / "sweep.csv");
  ASSERT_EQ(a.rows.size(), 6u);
  // dt2 in {1, 6.5, 12} (slowest), dt3 in {1, 10}; f1, dt1, f2 at x0; T <= 15 decides feasibility.
  const double dt2[] = {1, 1, 6.5, 6.5, 12, 12}, dt3[] = {1, 10, 1, 10, 1, 10};
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(parse(a.at(i, "dt2")), dt2[i]);
    EXPECT_EQ(parse(a.at(i, "dt3")), dt3[i]);
    EXPECT_EQ(parse(a.at(i, "f1")), 25.0);
    EXPECT_EQ(a.at(i, "runs"), "8");
    EXPECT_EQ(a.at(i, "feasible"), (1 + dt2[i] + dt3[i] <= 15) ? "1" : "0") << i;
    EXPECT_EQ(parse(a.at(i, "objective")), parse(a.at(i, "ir_magnitude_mean")));  // objective kind mean
    EXPECT_GT(parse(a.at(i, "objective_hw95")), 0.0);
    EXPECT_EQ(a.at(i, "objective_hw95"), a.at(i, "ir_magnitude_mean_hw95"));
  }
  const nlohmann::json s = read_json(out / "summary.json");
  // depth_mean = mean |I_r| / r_lock; r_lock = 2 bbar sqrt(1 - bbar^2) M L mu / (1 + mu) = 15.90e-7 kg m
  // at mu 0.02 (docs/equilibrium_sets.md section 4).
  ASSERT_TRUE(s["r_lock_kgm"].is_number());
  const double r_lock = s["r_lock_kgm"].get<double>();
  EXPECT_NEAR(r_lock / 1e-7, 15.90, 0.005);
  for (std::size_t i = 0; i < 6; ++i)
    EXPECT_NEAR(parse(a.at(i, "depth_mean")), parse(a.at(i, "ir_magnitude_mean")) * 1e-7 / r_lock, 1e-12) << i;
  expect_provenance(s, cfg);
  EXPECT_EQ(s["points_evaluated"], 6);
  EXPECT_EQ(s["computed"], 6);
  if (first.output.find("gnuplot not found") == std::string::npos) {
    EXPECT_TRUE(fs::exists(out / "sweep_map.png")) << first.output;
    EXPECT_TRUE(fs::exists(out / "sweep_map.pdf")) << first.output;
  }
  // A three-segment family holds the 2003 design: the map marks it.
  std::ifstream gp(out / "sweep_map.gp");
  const std::string script((std::istreambuf_iterator<char>(gp)), std::istreambuf_iterator<char>());
  EXPECT_NE(script.find("2003 report design (dt2 10, dt3 8)"), std::string::npos) << script;

  // The rerun computes nothing and reports the same values.
  const Result again = run("sweep " + cfg + " --out " + out.string());
  ASSERT_EQ(again.status, 0) << again.output;
  EXPECT_NE(again.output.find("6 of 6 points (0 computed, 6 from the archive"), std::string::npos) << again.output;
  const Csv b = read_csv(out / "sweep.csv");
  for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(a.at(i, "objective"), b.at(i, "objective"));

  // A finer grid on the same archive computes only its new points (dt3 = 5.5 is new).
  const std::string finer = write_config("finer.yaml", std::string(kBase) +
                                                           "constraints: {max_startup_time_s: 15}\n"
                                                           "sweep: {method: grid, variables: [dt2, dt3], levels: {dt2: 3, dt3: 3}}\n");
  const Result third = run("sweep " + finer + " --out " + out.string());
  ASSERT_EQ(third.status, 0) << third.output;
  EXPECT_NE(third.output.find("9 of 9 points (3 computed, 6 from the archive"), std::string::npos) << third.output;

  // Export: 9 evaluations, the metadata of the three runs, values equal bit for bit to sweep.csv.
  const fs::path exp = fresh_dir("grid-export");
  const Result e = run("archive export " + (out / "archive.sqlite").string() + " " + exp.string());
  ASSERT_EQ(e.status, 0) << e.output;
  const nlohmann::json doc = read_json(exp / "archive.json");
  EXPECT_EQ(doc["schema"], "abuopt-archive-export");
  EXPECT_EQ(doc["schema_version"], 1);
  ASSERT_EQ(doc["problems"].size(), 1u);
  const auto& p = doc["problems"][0];
  EXPECT_EQ(p["problem_id"], s["problem_id"]);
  ASSERT_EQ(p["evaluations"].size(), 9u);
  ASSERT_EQ(p["metadata"].size(), 3u);
  for (const auto& m : p["metadata"]) {
    EXPECT_EQ(m["command"], "sweep");
    EXPECT_EQ(m["abuopt_version"], "0.1.0");
  }
  EXPECT_EQ(p["metadata"][0]["config_hash"], fnv_of_file(cfg));
  EXPECT_EQ(p["metadata"][2]["config_hash"], fnv_of_file(finer));
  const Csv ex = read_csv(exp / p["csv"].get<std::string>());
  ASSERT_EQ(ex.rows.size(), 9u);
  const Csv c = read_csv(out / "sweep.csv");  // the finer run: all 9 points
  std::size_t matched = 0;
  for (std::size_t i = 0; i < 9; ++i)
    for (std::size_t k = 0; k < 9; ++k) {
      if (ex.at(k, "dt2") != c.at(i, "dt2") || ex.at(k, "dt3") != c.at(i, "dt3")) continue;
      ++matched;
      EXPECT_EQ(bits(parse(ex.at(k, "objective"))), bits(parse(c.at(i, "objective"))));
      EXPECT_EQ(bits(p["evaluations"][k]["objective"].get<double>()), bits(parse(c.at(i, "objective"))));
      EXPECT_EQ(ex.at(k, "pct_mi"), c.at(i, "pct_mi"));
      EXPECT_EQ(ex.at(k, "g_startup_time"), c.at(i, "g_startup_time"));
    }
  EXPECT_EQ(matched, 9u);
}

TEST(SweepCli, ArchiveExportEqualsWhatOptimizeReportedBitForBit) {
  const std::string quick = std::string(ABUOPT_SOURCE_DIR) + "/configs/optimize/quick.yaml";
  const fs::path out = fresh_dir("optimize");
  const Result r = run("optimize " + quick + " --out " + out.string() + " --max-evaluations 6");
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json result = read_json(out / "result.json");
  expect_provenance(result, quick);

  const fs::path exp = fresh_dir("optimize-export");
  const Result e = run("archive export " + (out / "archive.sqlite").string() + " " + exp.string());
  ASSERT_EQ(e.status, 0) << e.output;
  const nlohmann::json doc = read_json(exp / "archive.json");
  ASSERT_EQ(doc["problems"].size(), 1u);
  const auto& p = doc["problems"][0];
  EXPECT_EQ(p["problem_id"], result["problem_id"]);
  ASSERT_EQ(p["metadata"].size(), 1u);
  EXPECT_EQ(p["metadata"][0]["command"], "optimize");
  EXPECT_EQ(p["metadata"][0]["git_commit"], result["provenance"]["git_commit"]);

  // history.csv (what optimize reported) against the export, row by row in evaluation order.
  const Csv h = read_csv(out / "history.csv");
  const Csv x = read_csv(exp / p["csv"].get<std::string>());
  ASSERT_EQ(h.rows.size(), 6u);
  ASSERT_EQ(x.rows.size(), 6u);
  ASSERT_EQ(p["evaluations"].size(), 6u);
  for (std::size_t i = 0; i < 6; ++i) {
    for (const char* k : {"objective", "f1", "dt1", "f2", "dt2", "dt3", "g_startup_time", "g_pct_mi",
                          "ir_magnitude_mean", "pct_mi", "amplitude_max_mm"}) {
      EXPECT_EQ(bits(parse(x.at(i, k))), bits(parse(h.at(i, k)))) << k << " row " << i;
    }
    EXPECT_EQ(bits(p["evaluations"][i]["objective"].get<double>()), bits(parse(h.at(i, "objective"))));
    EXPECT_EQ(bits(p["evaluations"][i]["x"]["dt2"].get<double>()), bits(parse(h.at(i, "dt2"))));
  }
  // The best design of result.json is one of the stored evaluations, to the bit.
  bool found = false;
  for (const auto& ev : p["evaluations"])
    found = found || (bits(ev["objective"].get<double>()) == bits(result["best"]["objective"].get<double>()) &&
                      ev["x"] == result["best"]["x"]);
  EXPECT_TRUE(found);
}

TEST(SweepCli, MonteCarloSummaryCarriesProvenance) {
  const std::string cfg = std::string(ABUOPT_SOURCE_DIR) + "/configs/montecarlo_final_profile.yaml";
  const fs::path out = fresh_dir("montecarlo");
  const Result r = run("montecarlo " + cfg + " --design random --runs 4 --seed 3 --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  expect_provenance(read_json(out / "summary.json"), cfg);
  const Result v = run("--version");
  EXPECT_NE(v.output.find("abuopt 0.1.0 ("), std::string::npos) << v.output;
}

TEST(SweepCli, ParetoSeriesWritesTheFrontAndValidatesItOutOfSample) {
  const std::string cfg = write_config("pareto.yaml", std::string(kBase) +
                                                          "optimizer: {algorithm: cobyla, max_evaluations: 5, initial_step: 0.1}\n"
                                                          "pareto: {max_startup_time_s: [18, 12]}\n");
  const fs::path out = fresh_dir("pareto");
  const Result r = run("pareto " + cfg + " --out " + out.string());
  ASSERT_TRUE(r.status == 0 || r.status == 3) << r.output;
  const Csv c = read_csv(out / "pareto.csv");
  ASSERT_EQ(c.rows.size(), 2u);
  EXPECT_EQ(parse(c.at(0, "epsilon_s")), 12.0);  // sorted
  EXPECT_EQ(parse(c.at(1, "epsilon_s")), 18.0);
  for (std::size_t i = 0; i < 2; ++i) {
    if (c.at(i, "feasible") != "1") continue;
    EXPECT_LE(parse(c.at(i, "startup_time_s")), parse(c.at(i, "epsilon_s")) * (1 + 1e-6));
    EXPECT_FALSE(c.at(i, "out_of_sample_objective").empty());
  }
  // Warm start: the looser bound starts from the tighter one's best, so it is no worse.
  if (c.at(0, "feasible") == "1" && c.at(1, "feasible") == "1") {
    EXPECT_LE(parse(c.at(1, "objective")), parse(c.at(0, "objective")));
  }
  const nlohmann::json s = read_json(out / "summary.json");
  expect_provenance(s, cfg);
  EXPECT_EQ(s["report_profile"]["startup_time_s"], 19.0);
  EXPECT_TRUE(s["report_profile"]["out_of_sample"]["ok"].get<bool>());
  EXPECT_EQ(s["report_profile"]["out_of_sample"]["metrics"]["runs"], 16);

  // The bound on T belongs to the series: a config that sets it is refused, naming the key.
  const std::string bad = write_config("pareto-bad.yaml", std::string(kBase) +
                                                              "constraints: {max_startup_time_s: 20}\n"
                                                              "pareto: {max_startup_time_s: [18, 12]}\n");
  const Result b = run("pareto " + bad + " --out " + fresh_dir("pareto-bad").string());
  EXPECT_EQ(b.status, 2) << b.output;
  EXPECT_NE(b.output.find("constraints.max_startup_time_s = 20: must be absent"), std::string::npos) << b.output;
}

// pareto.method nsga2 / moead: the shipped configs/sweep/pareto_time_nsga2.yaml at a reduced size
// (8 runs per evaluation, 40 evaluations, 32 validation runs): the budget spent exactly, the front's
// files as compare writes them (hypervolume.csv equal to summary.json), a rerun answered from the
// archive bit for bit; MOEA/D likewise; bad keys are status 2 naming the key.
std::string reduced_nsga2_config(const std::vector<std::pair<std::string, std::string>>& edits = {}) {
  std::ifstream in(std::string(ABUOPT_SOURCE_DIR) + "/configs/sweep/pareto_time_nsga2.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto replace = [&](const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
  };
  replace("  runs: 128\n", "  runs: 8\n");
  replace("  runs: 1024\n", "  runs: 32\n");
  replace("  max_evaluations: 440", "  max_evaluations: 40");
  for (const auto& [from, to] : edits) replace(from, to);
  return text;
}

TEST(SweepCli, ParetoByNsga2AndMoeadWritesTheValidatedFrontAndResumes) {
  const std::string cfg = write_config("pareto_time_nsga2.yaml", reduced_nsga2_config());
  const fs::path out = fresh_dir("pareto-nsga2");
  const Result r = run("pareto " + cfg + " --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("NSGA-II (population 20, seed 304)"), std::string::npos) << r.output;
  const Csv hv = read_csv(out / "hypervolume.csv");
  ASSERT_EQ(hv.rows.size(), 1u);
  EXPECT_EQ(hv.at(0, "method"), "NSGA-II");
  EXPECT_EQ(hv.at(0, "evaluations"), "40");  // NSGA-II spends the budget
  EXPECT_EQ(hv.at(0, "validated"), "1");
  EXPECT_GT(parse(hv.at(0, "hv_in")), 0.0);
  const Csv fronts = read_csv(out / "fronts.csv");
  ASSERT_GE(fronts.rows.size(), 1u);
  for (std::size_t i = 0; i < fronts.rows.size(); ++i) {
    // T = dt1 + dt2 + dt3 of the design box: 2.3 s to 25 s
    EXPECT_GE(parse(fronts.at(i, "second")), 2.3 - 1e-9);
    EXPECT_LE(parse(fronts.at(i, "second")), 25 + 1e-9);
    EXPECT_FALSE(fronts.at(i, "validated_objective").empty()) << i;  // every point out of sample
  }
  const nlohmann::json s = read_json(out / "summary.json");
  expect_provenance(s, cfg);
  EXPECT_EQ(s["method"], "nsga2");
  EXPECT_EQ(s["algorithm"], "pagmo_nsga2");
  EXPECT_EQ(s["evaluations"], 40);
  EXPECT_EQ(s["points"].size(), fronts.rows.size());
  EXPECT_NEAR(s["hypervolume"]["in_sample"].get<double>(), parse(hv.at(0, "hv_in")), 1e-9);
  EXPECT_NEAR(s["hypervolume"]["out_of_sample"].get<double>(), parse(hv.at(0, "hv_out")), 1e-9);
  EXPECT_TRUE(fs::exists(out / "archive" / "pareto_time_nsga2" / "run0-NSGA-II.sqlite"));

  // A rerun: every evaluation from the archive, the same front to the bit.
  const Result again = run("pareto " + cfg + " --out " + out.string());
  ASSERT_EQ(again.status, 0) << again.output;
  const nlohmann::json s2 = read_json(out / "summary.json");
  EXPECT_EQ(bits(s2["hypervolume"]["in_sample"].get<double>()), bits(s["hypervolume"]["in_sample"].get<double>()));
  EXPECT_EQ(bits(s2["hypervolume"]["out_of_sample"].get<double>()),
            bits(s["hypervolume"]["out_of_sample"].get<double>()));
  EXPECT_EQ(s2["points"], s["points"]);

  const std::string moead =
      write_config("pareto_time_moead.yaml", reduced_nsga2_config({{"method: nsga2", "method: moead"}, {"population: 20", "population: 10"}}));
  const fs::path mout = fresh_dir("pareto-moead");
  const Result m = run("pareto " + moead + " --out " + mout.string());
  ASSERT_EQ(m.status, 0) << m.output;
  const nlohmann::json ms = read_json(mout / "summary.json");
  EXPECT_EQ(ms["algorithm"], "pagmo_moead");
  EXPECT_EQ(ms["population"], 10);
  EXPECT_EQ(ms["evaluations"], 40);
  EXPECT_GT(ms["hypervolume"]["in_sample"].get<double>(), 0.0);
  EXPECT_TRUE(fs::exists(mout / "archive" / "pareto_time_moead" / "run0-MOEA_D.sqlite"));

  // Bad input: status 2 naming the key, the value and the rule.
  using Edits = std::vector<std::pair<std::string, std::string>>;
  const std::pair<Edits, std::string> bad[] = {
      {{{"method: nsga2", "method: nsga2\n  max_startup_time_s: [10, 20]"}},
       "pareto.max_startup_time_s = [10, 20]: means nothing for method nsga2"},
      {{{"population: 20", "population: 10"}}, "pareto.population = 10: NSGA-II needs a multiple of 4, at least 8"},
      {{{"method: nsga2", "method: moead"}, {"population: 20", "population: 3"}},
       "pareto.population = 3: MOEA/D needs at least 4"},
      {{{"population: 20", "population: 480"}},
       "pareto.max_evaluations = 40: NSGA-II needs at least one population (480 evaluations)"},
      {{{"method: nsga2", "method: nsga3"}}, "pareto.method = nsga3: must be epsilon_constraint, nsga2 or moead"},
  };
  int k = 0;
  for (const auto& [edits, message] : bad) {
    const std::string c = write_config("pareto-bad-" + std::to_string(k) + ".yaml", reduced_nsga2_config(edits));
    const Result b = run("pareto " + c + " --out " + fresh_dir("pareto-bad-" + std::to_string(k++)).string());
    EXPECT_EQ(b.status, 2) << b.output;
    EXPECT_NE(b.output.find(message), std::string::npos) << b.output;
  }
  const std::string no_ref = write_config("pareto-noref.yaml", std::string(kBase) +
                                                                   "pareto: {method: moead, max_evaluations: 20}\n");
  const Result nr = run("pareto " + no_ref + " --out " + fresh_dir("pareto-noref").string());
  EXPECT_EQ(nr.status, 2) << nr.output;
  EXPECT_NE(nr.output.find("pareto.reference = <missing>: is required for method moead"), std::string::npos) << nr.output;
  const std::string algo = write_config("pareto-algo.yaml", std::string(kBase) +
                                                                "optimizer: {algorithm: cobyla}\n"
                                                                "pareto: {method: nsga2, max_evaluations: 40, "
                                                                "reference: {objective: 25, second: 23}}\n");
  const Result al = run("pareto " + algo + " --out " + fresh_dir("pareto-algo").string());
  EXPECT_EQ(al.status, 2) << al.output;
  EXPECT_NE(al.output.find("optimizer.algorithm = cobyla: must be absent with pareto.method nsga2"), std::string::npos)
      << al.output;
  // pagmo's population is pareto.population here, not optimizer.population (which would be ignored)
  const std::string pop = write_config("pareto-opt-pop.yaml", std::string(kBase) +
                                                                  "optimizer: {population: 12}\n"
                                                                  "pareto: {method: nsga2, max_evaluations: 40, "
                                                                  "reference: {objective: 25, second: 23}}\n");
  const Result po = run("pareto " + pop + " --out " + fresh_dir("pareto-opt-pop").string());
  EXPECT_EQ(po.status, 2) << po.output;
  EXPECT_NE(po.output.find("optimizer.population = 12: must be absent with pareto.method nsga2"), std::string::npos)
      << po.output;
  EXPECT_NE(po.output.find("its population pareto.population"), std::string::npos) << po.output;
  const std::string eps = write_config("pareto-eps-pop.yaml", std::string(kBase) +
                                                                  "pareto: {max_startup_time_s: [12, 18], population: 20}\n");
  const Result ep = run("pareto " + eps + " --out " + fresh_dir("pareto-eps-pop").string());
  EXPECT_EQ(ep.status, 2) << ep.output;
  EXPECT_NE(ep.output.find("pareto.population = 20: only for method nsga2 or moead"), std::string::npos) << ep.output;
}

TEST(SweepCli, BadSweepInputIsStatus2WithTheKey) {
  const std::string cfg = write_config("bad.yaml", std::string(kBase) + "sweep: {method: grid, variables: [f3], points: 3}\n");
  const Result r = run("sweep " + cfg + " --out " + fresh_dir("bad").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("sweep.variables[0] = f3: not a free variable of the design"), std::string::npos) << r.output;
  const Result missing = run("archive export /nonexistent/archive.sqlite " + fresh_dir("none").string());
  EXPECT_EQ(missing.status, 2) << missing.output;
  EXPECT_NE(missing.output.find("archive = /nonexistent/archive.sqlite: no such file"), std::string::npos)
      << missing.output;
}

TEST(SweepCli, CtrlCStopsAfterTheCurrentPointWritesThePointsSoFarAndTheRerunFinishes) {
  const std::string cfg = write_config("sigint.yaml", std::string(kBase) +
                                                          "sweep: {method: sobol, variables: [dt2, dt3], points: 64}\n");
  const fs::path out = fresh_dir("sigint");
  const fs::path log = fs::path(ABUOPT_BINARY_DIR) / "sweep_cli_test" / "sigint.log";
  // Background job in sh: SIGINT is ignored there by default; abuopt installs its own handler.
  // The signal goes once the second point is reported (the wait allows 2 min for a loaded machine).
  const std::string script = std::string(ABUOPT_EXE) + " sweep " + cfg + " --out " + out.string() + " > " +
                             log.string() + " 2>&1 & pid=$!; for i in $(seq 2400); do grep -q 'point    2/' " +
                             log.string() + " && break; sleep 0.05; done; kill -INT $pid; wait $pid; echo rc=$?";
  FILE* p = popen(script.c_str(), "r");  // /bin/sh -c script
  ASSERT_NE(p, nullptr);
  std::string text;
  char buf[256];
  while (fgets(buf, sizeof buf, p)) text += buf;
  pclose(p);
  std::ifstream in(log);
  const std::string output((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_NE(output.find("point    2/64"), std::string::npos) << "the sweep never reached its second point\n" << output;
  ASSERT_NE(text.find("rc=130"), std::string::npos) << text << output;
  EXPECT_NE(output.find("interrupted by SIGINT (Ctrl-C): kept the "), std::string::npos) << output;
  EXPECT_NE(output.find("rerun the same command"), std::string::npos) << output;
  const Csv part = read_csv(out / "sweep.csv");
  EXPECT_GE(part.rows.size(), 2u);
  EXPECT_LT(part.rows.size(), 64u);
  const nlohmann::json s = read_json(out / "summary.json");
  EXPECT_TRUE(s["interrupted"].get<bool>());

  const Result rest = run("sweep " + cfg + " --out " + out.string());
  ASSERT_EQ(rest.status, 0) << rest.output;
  EXPECT_NE(rest.output.find("64 of 64 points (" + std::to_string(64 - part.rows.size()) + " computed, " +
                             std::to_string(part.rows.size()) + " from the archive"),
            std::string::npos)
      << rest.output;
}

// A family with another segment count (here a dwell, as configs/studies/limit/) does not hold the 2003
// design: its map marks none, even where the swept names f2 / dt2 exist in both.
TEST(SweepCli, MapMarksThe2003DesignOnlyInAThreeSegmentFamily) {
  const std::string cfg = write_config("dwell.yaml", R"(abu:
  friction_mu: 0.02
profile:
  start_frequency_hz: 0
  segments:
    - {end_frequency_hz: 25.0, duration_s: 1.0}
    - {end_frequency_hz: 29.0, duration_s: 1.0}
    - {end_frequency_hz: 29.0, duration_s: 2.0}
    - {end_frequency_hz: 100.0, duration_s: 4.3}
simulation:
  method: event_driven
montecarlo:
  design: lhs
  runs: 4
  seed: 7
design:
  segments:
    - {}
    - end_frequency_hz: {min: 28.9, max: 29.5, x0: 29.0}
      duration_s: {min: 1, max: 10, x0: 1}
    - {hold: true, duration_s: 2.0}
    - {}
objective:
  kind: mean
sweep: {method: grid, variables: [f2, dt2], levels: {f2: 2, dt2: 2}}
)");
  const fs::path out = fresh_dir("dwell");
  const Result r = run("sweep " + cfg + " --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream gp(out / "sweep_map.gp");
  ASSERT_TRUE(gp) << r.output;
  const std::string script((std::istreambuf_iterator<char>(gp)), std::istreambuf_iterator<char>());
  EXPECT_NE(script.find("best feasible point"), std::string::npos) << script;
  EXPECT_EQ(script.find("2003 report design"), std::string::npos) << script;
}

