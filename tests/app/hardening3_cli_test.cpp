// The command line under the third round of hostile input (issue 29): memory that must not grow
// with an allowed value, YAML that must not crash or hang the reader, signals every command must
// honour, exit statuses, silent acceptance, unbounded totals and misleading messages.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "abuopt_child.hpp"
#include "abuopt_cli.hpp"
#include "startup_problem_yaml.hpp"

namespace abuopt {
namespace {

namespace fs = std::filesystem;
using test::run_abuopt;
using test::run_child;
using test::SignalPlan;

const std::string kSrc = ABUOPT_SOURCE_DIR;
const std::string kBin = ABUOPT_BINARY_DIR;
const std::string kSim = kSrc + "/configs/report_final_profile.yaml";

#define EXPECT_HAS(text, part) EXPECT_NE((text).find(part), std::string::npos) << (text)

// A copy of the report's config with `extra` appended (a later section replaces nothing: the
// appended keys are new ones under `simulation:`, which is the file's last section).
std::string config_with(const std::string& name, const std::string& simulation_extra) {
  const std::string path = kBin + "/" + name;
  std::ifstream in(kSim);
  std::ofstream out(path);
  out << in.rdbuf() << simulation_extra;
  return path;
}

// Class 1: the run's memory does not grow with the end time when no trajectory is recorded (the
// exact stuck-phase propagator used to store its forcing table over the whole span: 12.6 GB at
// end_time_s 1e6). 1e7 s of simulated time: bounded memory and a quick end.
TEST(Hardening3Cli, MemoryDoesNotGrowWithTheEndTime) {
  const std::string cfg = config_with("h3_long_end.yaml", "  end_time_s: 1.0e7\n");
  const auto r = run_child({"simulate", cfg});
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_LT(r.max_rss_kb, 100 * 1024) << "peak memory " << r.max_rss_kb << " kB\n" << r.output;
  EXPECT_LT(r.wall_s, 5.0) << r.output;
  std::printf("end_time_s 1e7: peak %ld kB, %.2f s\n", r.max_rss_kb, r.wall_s);
  fs::remove(cfg);
}

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::path(kBin) / "hardening3" / name;
  fs::remove_all(d);
  fs::create_directories(d.parent_path());
  return d;
}

std::string write_file(const std::string& name, const std::string& text) {
  const fs::path d = fs::path(kBin) / "hardening3";
  fs::create_directories(d);
  std::ofstream(d / name, std::ios::binary) << text;
  return (d / name).string();
}

nlohmann::json read_json(const fs::path& p) {
  std::ifstream f(p);
  return nlohmann::json::parse(f);
}

// A small design problem (sections of `abuopt optimize`) for the archive and total-work cases.
const std::string kOptimizeForArchive =
    abuopt_test::kReportAbuAndProfile + abuopt_test::lhs_montecarlo(4) + abuopt_test::kThreeSegmentDesign + R"(objective:
  kind: mean
validation:
  enabled: false
optimizer:
  algorithm: cobyla
  max_evaluations: 4
)";

// A guard for the cases that used to hang: SIGKILL after 20 s ends the child (the test then fails
// on its status) instead of the test waiting forever.
const SignalPlan kKillAfter20s{SIGKILL, 20.0, "", 0};

const char* kReportSections = R"(abu:
  friction_mu: 0.02
  balls:
    - {mass_kg: 1.4e-4, diameter_m: 3.0e-3}
    - {mass_kg: 1.4e-4, diameter_m: 3.0e-3}
profile:
  start_frequency_hz: 0
  segments:
    - {end_frequency_hz: 25.0, duration_s: 1.0}
    - {end_frequency_hz: 29.5, duration_s: 10.0}
    - {end_frequency_hz: 100.0, duration_s: 8.0}
simulation:
  method: event_driven
)";

// Class 2 (crashes) and 3 (hangs) of YAML: one mechanism in the reader (the parser's events are
// checked before a node is built): a loop of aliases, nested aliases that expand exponentially
// (wherever they are: a value, a list, the top level, an unknown key), a tag.
TEST(Hardening3Cli, YamlAliasLoopsAndBillionLaughsAreBadInputAtOnce) {
  struct Case {
    std::string name, yaml, expect;
  };
  std::string laughs = "a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (int i = 1; i <= 9; ++i)
    laughs += "a" + std::to_string(i) + ": &a" + std::to_string(i) + " [" + [&] {
      std::string l;
      for (int k = 0; k < 10; ++k) l += std::string(k ? ", " : "") + "*a" + std::to_string(i - 1);
      return l;
    }() + "]\n";
  const std::vector<Case> cases = {
      {"self_alias", std::string(kReportSections) + "montecarlo: {runs: &a [*a]}\n", "refers to the node it is part of"},
      {"self_alias_value", "abu:\n  friction_mu: &a [*a]\n", "refers to the node it is part of"},
      {"laughs_top", laughs, "values (the limit of a config)"},
      {"laughs_unknown_key", std::string(kReportSections) + "extra:\n" + [&] {
         std::string t;
         std::istringstream in(laughs);
         for (std::string line; std::getline(in, line);) t += "  " + line + "\n";
         return t;
       }(), "values (the limit of a config)"},
      {"laughs_segments", laughs + "profile:\n  segments: *a9\n", "values (the limit of a config)"},
      {"deep", "abu: " + std::string(200, '[') + std::string(200, ']') + "\n", "levels deep"},
      {"tag", std::string(kReportSections) + "montecarlo: {runs: !!int 8}\n", "has the YAML tag"},
      {"custom_tag", "abu:\n  friction_mu: !mytag 0.02\n", "has the YAML tag '!mytag'"},
  };
  for (const Case& c : cases) {
    const std::string cfg = write_file(c.name + ".yaml", c.yaml);
    const auto r = run_child({"simulate", cfg}, kKillAfter20s);
    EXPECT_EQ(r.status, 2) << c.name << ": " << r.output << " (signal " << r.signal << ")";
    EXPECT_HAS(r.output, c.expect);
    EXPECT_LT(r.wall_s, 5.0) << c.name;
  }
}

TEST(Hardening3Cli, AFifoAsTheConfigIsRefusedNotWaitedFor) {
  const std::string fifo = (fs::path(kBin) / "hardening3" / "config.fifo").string();
  fs::create_directories(fs::path(fifo).parent_path());
  fs::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto r = run_child({"simulate", fifo}, kKillAfter20s);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_HAS(r.output, "is not a regular file");
  EXPECT_LT(r.wall_s, 5.0);
  fs::remove(fifo);
}

// Class 6 at the YAML scalar reader: a null value (~, null, or nothing) is neither a value nor
// the default; a null element of a list likewise.
TEST(Hardening3Cli, NullValuesAreNotDefaults) {
  const std::string mu = write_file("null_mu.yaml", std::string(kReportSections) + "montecarlo: {runs: ~}\n");
  auto r = run_child({"simulate", mu});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_HAS(r.output, "montecarlo.runs = ~: has no value");
  const std::string ball = write_file("null_ball.yaml", "abu:\n  friction_mu: 0.02\n  balls:\n    - ~\n    - {mass_kg: 1.4e-4, diameter_m: 3.0e-3}\n");
  r = run_child({"simulate", ball});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_HAS(r.output, "abu.balls[0] = ~: has no value");
  const std::string empty = write_file("empty_value.yaml", "abu:\n  friction_mu:\n");
  r = run_child({"simulate", empty});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_HAS(r.output, "abu.friction_mu = ~: has no value");
}

// Class 8: a file with CR-only line endings (classic Mac) is read as the lines it has.
TEST(Hardening3Cli, CrOnlyLineEndingsAreLineBreaks) {
  std::string text = kReportSections;
  for (char& c : text)
    if (c == '\n') c = '\r';
  const std::string cfg = write_file("cr_only.yaml", text);
  const auto cr = run_child({"simulate", cfg, "--json"});
  EXPECT_EQ(cr.status, 0) << cr.output;
  const auto lf = run_child({"simulate", write_file("lf.yaml", kReportSections), "--json"});
  ASSERT_EQ(lf.status, 0) << lf.output;
  EXPECT_EQ(nlohmann::json::parse(cr.output)["residual_imbalance"], nlohmann::json::parse(lf.output)["residual_imbalance"]);
}

// Classes 5, 6, 8 at the option parser: one check of every option value (app/commands/
// option_values.cpp) and one reader of typed numbers (common/number_text.hpp).
TEST(Hardening3Cli, OptionValuesAreCheckedInOnePlace) {
  struct Case {
    std::vector<std::string> args;
    std::string expect;
  };
  const std::string mc = kSrc + "/configs/montecarlo_final_profile.yaml";
  const std::string eq = kSrc + "/configs/eqset.yaml";
  const std::vector<Case> cases = {
      {{"simulate", kSim, "--beta0", "nan,1"}, "--beta0 = nan,1: 'nan' is not a finite number"},
      {{"simulate", kSim, "--beta0", "inf,1"}, "'inf' is not a finite number"},
      {{"simulate", kSim, "--beta0", "-inf,1"}, "'-inf' is not a finite number"},
      {{"simulate", kSim, "--beta0", "nan(0x1),1"}, "is not a finite number"},
      {{"simulate", kSim, "--beta0", "1,,2"}, "has an empty item"},
      {{"simulate", kSim, "--mu", "inf"}, "--mu = inf: 'inf' is not a finite number"},
      {{"simulate", kSim, "--mu", "abc"}, "--mu"},
      {{"simulate", kSim, "--trajectory", ""}, "--trajectory = '': needs a value"},
      {{"simulate", kSim, "--trajectory", "/dev/null", "--trajectory-interval", "x"}, "--trajectory-interval"},
      {{"montecarlo", mc, "--runs", ""}, "--runs = '': needs a value"},
      {{"montecarlo", mc, "--out", ""}, "--out = '': needs a value"},
      {{"montecarlo", mc, "--seed", "99999999999999999999"}, "--seed = 99999999999999999999: must be a whole number"},
      {{"eqset", eq, "--scan", "1e308:1e308:1"}, "--scan = 1e308:1e308:1: must stay within (0, 1e6] Hz"},
      {{"eqset", eq, "--scan", "10:nan:1"}, "is not a finite number"},
  };
  for (const Case& c : cases) {
    const auto r = run_child(c.args);
    std::string line;
    for (const auto& a : c.args) line += a + " ";
    EXPECT_EQ(r.status, 2) << line << "\n" << r.output;
    EXPECT_HAS(r.output, c.expect);
    EXPECT_EQ(r.output.find("Value "), std::string::npos) << line << r.output;  // not CLI11's validator text
    EXPECT_LT(r.output.size(), 600u) << line << r.output;                      // no 309-digit bound
  }
  // a subnormal angle is a number (it was "not a comma-separated list")
  const auto tiny = run_child({"simulate", kSim, "--beta0", "4.9e-324,1", "--json"});
  EXPECT_EQ(tiny.status, 0) << tiny.output;
}

// Class 5: write failures are exit 4 for every command.
TEST(Hardening3Cli, AnUnwritableEqsetOutIsExitFour) {
  const fs::path file = fs::path(write_file("not_a_dir", "x"));
  const auto r = run_child({"eqset", kSrc + "/configs/eqset.yaml", "--freq", "29", "--grid", "8", "--out",
                            (file / "sub").string()});
  EXPECT_EQ(r.status, 4) << r.output;
  EXPECT_HAS(r.output, "cannot create the output directory");
}

// An archive that cannot be written (a file-size limit stands in for a full disk) is exit 4 as for
// every other output file, not 3 ("disk I/O error" as a failed computation).
TEST(Hardening3Cli, AnArchiveWriteFailureIsExitFour) {
  const std::string cfg = write_file("sweep_full.yaml", std::string(kOptimizeForArchive) +
                                                            "sweep: {method: sobol, variables: [dt2, dt3], points: 4}\n");
  const fs::path out = fresh_dir("archive_full");
  const auto r = test::run_abuopt("sweep " + cfg + " --out " + out.string(), "trap '' XFSZ; ulimit -f 4;");
  EXPECT_EQ(r.status, 4) << r.output;
  EXPECT_HAS(r.output, "cannot write the evaluation archive");
}

// Class 7: the total work of one command is bounded; more is asked for with an explicit option
// that the message names.
TEST(Hardening3Cli, TotalWorkAboveTheLimitNeedsAnExplicitOption) {
  auto r = run_child({"reproduce", "--runs", "10000001", "--configs", kSrc + "/configs/report", "--out",
                      fresh_dir("reproduce_total").string()});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_HAS(r.output, "--max-total-runs");
  EXPECT_LT(r.wall_s, 5.0);
  std::string bounds = "pareto: {max_startup_time_s: [";
  for (int i = 0; i < 1000; ++i) bounds += std::string(i ? ", " : "") + std::to_string(5 + i * 0.01);
  bounds += "]}\n";
  const std::string cfg = write_file("pareto_1000.yaml", std::string(kOptimizeForArchive) + bounds);
  r = run_child({"pareto", cfg, "--out", fresh_dir("pareto_1000").string()});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_HAS(r.output, "pareto.max_startup_time_s = 1000 bounds: at most 100 bounds");
  EXPECT_HAS(r.output, "--max-bounds");
}

// ---- Class 4: signals. Every long command polls the one stop request (common/stop.hpp). ----

void expect_stopped(const test::ChildResult& r, int status, const std::string& what) {
  EXPECT_EQ(r.status, status) << what << " (signal " << r.signal << ")\n" << r.output;
  EXPECT_LT(r.after_signal_s, 2.0) << what << ": ended " << r.after_signal_s << " s after the signal";
  EXPECT_HAS(r.output, status == 143 ? "SIGTERM" : "SIGINT");
  std::printf("%s: ended %.2f s after the signal\n", what.c_str(), r.after_signal_s);
}

TEST(Hardening3Cli, MontecarloStopsOnSigintAndSigtermAndWritesNothingHalf) {
  const std::string mc = kSrc + "/configs/montecarlo_final_profile.yaml";
  for (const int sig : {SIGINT, SIGTERM}) {
    const fs::path out = fresh_dir(sig == SIGINT ? "mc_int" : "mc_term");
    const auto r = run_child({"montecarlo", mc, "--design", "random", "--runs", "200000", "--out", out.string()},
                             SignalPlan{sig, 1.5, "", 0});
    expect_stopped(r, sig == SIGINT ? 130 : 143, sig == SIGINT ? "montecarlo SIGINT" : "montecarlo SIGTERM");
    EXPECT_HAS(r.output, "nothing written");
    EXPECT_FALSE(fs::exists(out / "runs.csv"));
    EXPECT_FALSE(fs::exists(out / "summary.json"));
  }
}

// optimize: the interrupted run keeps its evaluations in the archive; the rerun resumes (the
// evaluations so far from the archive) and ends where an uninterrupted run ends.
const std::string kOptimize =
    abuopt_test::kReportAbuAndProfile + "simulation:\n  method: event_driven\n" + abuopt_test::lhs_montecarlo(96) +
    abuopt_test::kThreeSegmentDesign + R"(objective:
  kind: mean
constraints:
  max_startup_time_s: 20
validation:
  enabled: false
optimizer:
  algorithm: cobyla
  max_evaluations: 6
  initial_step: 0.1
)";

TEST(Hardening3Cli, OptimizeStopsOnSigintKeepsTheArchiveAndTheRerunEndsAsAnUninterruptedRun) {
  const std::string cfg = write_file("optimize.yaml", kOptimize);
  const fs::path out = fresh_dir("optimize_int"), ref = fresh_dir("optimize_ref");
  const auto r = run_child({"optimize", cfg, "--out", out.string()}, SignalPlan{SIGINT, 0, "eval    2", 120});
  expect_stopped(r, 130, "optimize SIGINT");
  EXPECT_HAS(r.output, "every evaluation is in the archive");
  ASSERT_TRUE(fs::exists(out / "archive.sqlite"));
  const auto rest = run_child({"optimize", cfg, "--out", out.string()});
  ASSERT_EQ(rest.status, 0) << rest.output;
  EXPECT_HAS(rest.output, "[archive]");
  const auto whole = run_child({"optimize", cfg, "--out", ref.string()});
  ASSERT_EQ(whole.status, 0) << whole.output;
  EXPECT_EQ(read_json(out / "result.json")["x"], read_json(ref / "result.json")["x"]);
}

const char* kSweep = R"(sweep: {method: sobol, variables: [dt2, dt3], points: 32}
)";

TEST(Hardening3Cli, SweepAndParetoStopOnSigtermKeepWhatIsDoneAndResume) {
  const std::string cfg = write_file("sweep.yaml", std::string(kOptimize) + kSweep);
  const fs::path out = fresh_dir("sweep_term");
  const auto r = run_child({"sweep", cfg, "--out", out.string()}, SignalPlan{SIGTERM, 0, "point    2/", 120});
  expect_stopped(r, 143, "sweep SIGTERM");
  EXPECT_HAS(r.output, "rerun the same command");
  EXPECT_TRUE(read_json(out / "summary.json")["interrupted"].get<bool>());
  const auto rest = run_child({"sweep", cfg, "--out", out.string()});
  EXPECT_EQ(rest.status, 0) << rest.output;
  EXPECT_HAS(rest.output, "from the archive");

  std::string pareto = kOptimize;  // the bound on T belongs to the series
  const std::string bound = "constraints:\n  max_startup_time_s: 20\n";
  pareto.erase(pareto.find(bound), bound.size());
  const std::string pcfg = write_file("pareto.yaml", pareto + "pareto: {max_startup_time_s: [18, 14, 12]}\n");
  const fs::path pout = fresh_dir("pareto_term");
  const auto p = run_child({"pareto", pcfg, "--out", pout.string()}, SignalPlan{SIGTERM, 0, "eval    1", 120});
  expect_stopped(p, 143, "pareto SIGTERM");
  EXPECT_HAS(p.output, "rerun the same command to resume");
  const auto prest = run_child({"pareto", pcfg, "--out", pout.string()});
  EXPECT_TRUE(prest.status == 0 || prest.status == 3) << prest.output;
  EXPECT_FALSE(read_json(pout / "summary.json")["interrupted"].get<bool>());
}

TEST(Hardening3Cli, CompareStopsOnSigintKeepsTheArchiveWritesNoHalfTableAndResumes) {
  std::string sp;
  {
    std::istringstream in(kOptimize);
    for (std::string line; std::getline(in, line);)
      if (line.rfind("optimizer:", 0) == 0) break;
      else sp += "      " + line + "\n";
  }
  const std::string cfg = write_file("compare.yaml", "tau: 0.01\nproblems:\n  - label: sp\n    max_evaluations: 12\n"
                                                     "    starts: 3\n    seed: 1\n    startup_profile:\n" + sp +
                                                     "solvers:\n  - label: COBYLA\n    algorithm: cobyla\n"
                                                     "  - label: SBPLX\n    algorithm: sbplx\n");
  const fs::path out = fresh_dir("compare_int");
  const auto r = run_child({"compare", cfg, "--out", out.string(), "--progress"}, SignalPlan{SIGINT, 0.3, "[1/", 120});
  // 6 runs of 12 evaluations (about 5 s on a quiet machine): the signal comes after the first run
  // ends, whatever the machine's speed, so it always lands while the comparison is working
  expect_stopped(r, 130, "compare SIGINT");
  EXPECT_HAS(r.output, "computed evaluations in");
  EXPECT_FALSE(fs::exists(out / "runs.csv"));
  const auto rest = run_child({"compare", cfg, "--out", out.string()});
  EXPECT_EQ(rest.status, 0) << rest.output;
  EXPECT_TRUE(fs::exists(out / "runs.csv"));
}

TEST(Hardening3Cli, ReproduceStopsOnSigintAndSaysWhatItKept) {
  const fs::path out = fresh_dir("reproduce_int");
  const auto r = run_child({"reproduce", "--only", "final", "--runs", "40000", "--no-plots", "--configs",
                            kSrc + "/configs/report", "--out", out.string()},
                           SignalPlan{SIGINT, 1.5, "", 0});
  expect_stopped(r, 130, "reproduce SIGINT");
  EXPECT_HAS(r.output, "kept in " + out.string());
}

// A command that does not poll (simulate) ends at once on the signal, with 128 + signal.
TEST(Hardening3Cli, ACommandOutsideAStopScopeEndsAtOnceWithItsStatus) {
  const std::string cfg = config_with("h3_slow_simulate.yaml", "  end_time_s: 1.0e5\n  stuck_integrator: rk\n  closed_form_tail: false\n");
  const auto r = run_child({"simulate", cfg}, SignalPlan{SIGTERM, 1.0, "", 0});
  if (r.after_signal_s < 0) GTEST_SKIP() << "the simulation ended before the signal";
  EXPECT_EQ(r.status, 143) << r.output;
  EXPECT_LT(r.after_signal_s, 1.0);
  EXPECT_HAS(r.output, "terminated (SIGTERM)");
  fs::remove(cfg);
}

}  // namespace
}  // namespace abuopt
