// `abuopt compare` end to end on the built binary: the shipped benchmark comparison runs (exit 0,
// the table on stdout, the CSVs under --out), and a bad config is one message with exit status 2.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;

struct Result {
  int status;
  std::string out;  // stdout
  std::string err;  // stderr
};

// Runs the binary with stdout captured and stderr in a file beside it.
Result run(const std::string& args) {
  // One file per test process: ctest runs the tests of this file in parallel.
  const std::string err_file =
      std::string(ABUOPT_BINARY_DIR) + "/compare_cli_stderr." + std::to_string(getpid()) + ".txt";
  const std::string cmd = std::string(ABUOPT_EXE) + " " + args + " 2>" + err_file;
  std::array<char, 4096> buf{};
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return {-1, "", ""};
  while (fgets(buf.data(), buf.size(), p)) out += buf.data();
  const int st = pclose(p);
  std::ifstream f(err_file);
  std::string err((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out, err};
}

std::string write_config(const std::string& name, const std::string& text) {
  const std::string path = std::string(ABUOPT_BINARY_DIR) + "/" + name;
  std::ofstream(path) << text;
  return path;
}

std::string fresh_dir(const std::string& name) {
  const fs::path dir = fs::path(ABUOPT_BINARY_DIR) / name;
  fs::remove_all(dir);
  return dir.string();
}

const std::string kConfigs = std::string(ABUOPT_SOURCE_DIR) + "/configs/";

}  // namespace

TEST(CompareCli, ShippedBenchmarksRunAndWriteTheCsvs) {
  const std::string out = fresh_dir("compare_cli_out");
  const Result r = run("compare " + kConfigs + "compare/benchmarks.yaml --out " + out);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  // the table: one row per (problem, solver) of the config
  for (const char* word : {"hs071", "cantilever", "two_bar_truss", "rosenbrock2", "noisy_cantilever", "SAO", "SAO-noisy",
                           "COBYLA", "BOBYQA", "SLSQP", "IPOPT"})
    EXPECT_NE(r.out.find(word), std::string::npos) << word << " missing from the table:\n" << r.out;
  EXPECT_NE(r.out.find("written to " + out), std::string::npos) << r.out;
  for (const char* file : {"runs.csv", "convergence.csv", "data_profile.csv", "performance_profile.csv", "plots.gp"}) {
    const fs::path p = fs::path(out) / file;
    ASSERT_TRUE(fs::exists(p)) << p;
    EXPECT_GT(fs::file_size(p), 0u) << p;
  }
  // 5 problems x 3 starts x 6 solvers runs, plus the header
  std::ifstream runs(fs::path(out) / "runs.csv");
  int lines = 0;
  for (std::string line; std::getline(runs, line);) ++lines;
  EXPECT_EQ(lines, 1 + 5 * 3 * 6);
  // progress goes to stderr, one line per run
  EXPECT_NE(r.err.find("[90/90]"), std::string::npos) << r.err;
}

TEST(CompareCli, JsonListsEveryRun) {
  const std::string cfg = write_config("compare_small.yaml",
                                       "problems:\n  - {benchmark: two_bar_truss, max_evaluations: 60}\n"
                                       "solvers:\n  - {label: SAO, algorithm: sao}\n  - {algorithm: cobyla}\n");
  const Result r = run("compare " + cfg + " --json --out " + fresh_dir("compare_cli_json"));
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["runs"].size(), 2u);
  EXPECT_EQ(j["runs"][0]["solver"], "SAO");
  EXPECT_EQ(j["runs"][0]["algorithm"], "SAO(auto)");
  EXPECT_TRUE(j["runs"][0]["feasible"].get<bool>());
  EXPECT_EQ(j["solvers"][1], "cobyla");
}

TEST(CompareCli, BadConfigIsOneMessageWithExitStatus2) {
  struct Case {
    std::string yaml;
    std::string message;
  };
  for (const Case& c : {
           Case{"problems:\n  - {benchmark: hs072}\nsolvers:\n  - {algorithm: cobyla}\n", "hs072"},
           Case{"problems:\n  - {benchmark: hs071}\nsolvers:\n  - {algorithm: simplex}\n",
                "solvers[0].algorithm = simplex: unknown algorithm"},
           Case{"problems:\n  - {benchmark: hs071, max_evaluations: 0}\nsolvers:\n  - {algorithm: sao}\n",
                "max_evaluations = 0"},
           Case{"problems:\n  - {benchmark: hs071}\nsolvers:\n  - {algorithm: sao, sao: {min_radius: 0}}\n",
                "sao.min_radius = 0: must be in (0, initial_radius = 0.1]"},
           Case{"problems:\n  - {benchmark: hs071}\nsolvers:\n  - {algorithm: cobyla, sao: {}}\n",
                "only for algorithm sao"},
           Case{"problems:\n  - {benchmark: hs071}\nsolvers:\n  - {algorithm: cobyla}\nsolverz: []\n", "solverz"},
           Case{"problems: []\nsolvers:\n  - {algorithm: cobyla}\n", "problems"},
           Case{"problems:\n  - {benchmark: hs071, startup_profile: {}}\nsolvers:\n  - {algorithm: cobyla}\n",
                "give either benchmark or startup_profile"},
           // the out-of-sample trajectory needs a validated (startup_profile) problem
           Case{"problems:\n  - {benchmark: hs071, validation_checkpoints: 4}\nsolvers:\n  - {algorithm: cobyla}\n",
                "validation_checkpoints"},
           Case{"fronts:\n  - {label: f, max_evaluations: 40}\n", "fronts[0].reference = <missing>: is required"},
       }) {
    const std::string cfg = write_config("compare_bad.yaml", c.yaml);
    const Result r = run("compare " + cfg + " --out " + fresh_dir("compare_cli_bad"));
    EXPECT_EQ(r.status, 2) << c.yaml << r.out << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << "expected '" << c.message << "' in: " << r.err;
    EXPECT_EQ(r.err.find("terminate"), std::string::npos) << r.err;
  }
  // more checkpoints than evaluations: the quick suite's two_ball_19s has 24
  {
    std::ifstream in(kConfigs + "compare/adopt_suite_quick.yaml");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string from = "validation_checkpoints: 4", to = "validation_checkpoints: 25";
    ASSERT_NE(text.find(from), std::string::npos);
    text.replace(text.find(from), from.size(), to);
    const Result r = run("compare " + write_config("compare_bad_checkpoints.yaml", text) + " --out " +
                         fresh_dir("compare_cli_bad"));
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find("problems[0].validation_checkpoints = 25: must be in [0, 24]"), std::string::npos) << r.err;
  }
  const Result missing = run("compare " + kConfigs + "compare/no_such.yaml");
  EXPECT_EQ(missing.status, 2) << missing.err;
  EXPECT_NE(missing.err.find("no_such.yaml"), std::string::npos) << missing.err;
}

namespace {

// runs.csv without its wall_time_s column (the only field a resumed comparison may change).
std::string runs_without_times(const std::string& dir) {
  std::ifstream f(fs::path(dir) / "runs.csv");
  std::string out, line;
  int column = -1;
  while (std::getline(f, line)) {
    std::vector<std::string> fields;
    std::string field;
    bool quoted = false;
    for (char c : line) {
      if (c == '"') quoted = !quoted;
      if (c == ',' && !quoted) {
        fields.push_back(field);
        field.clear();
      } else {
        field += c;
      }
    }
    fields.push_back(field);
    if (column < 0)
      for (std::size_t i = 0; i < fields.size(); ++i)
        if (fields[i] == "wall_time_s") column = static_cast<int>(i);
    for (std::size_t i = 0; i < fields.size(); ++i)
      if (static_cast<int>(i) != column) out += fields[i] + "|";
    out += "\n";
  }
  return out;
}

long json_sum(const nlohmann::json& j, const char* key) {
  long s = 0;
  for (const auto& r : j["runs"]) s += r[key].get<long>();
  return s;
}

}  // namespace

// The resumable comparison (issue 9): a small startup-profile comparison (16 Monte Carlo runs per
// evaluation, 2 starts x 2 solvers, one run at a time) killed with SIGKILL once its first run has
// ended and a second is under way, then rerun with the same --out: the same runs.csv (wall times
// aside) as an uninterrupted comparison, the first run answered wholly from its archive and the
// rerun computing fewer evaluations than the uninterrupted one.
TEST(CompareCli, KilledComparisonResumesFromItsArchives) {
  const std::string cfg = write_config(
      "compare_resume.yaml",
      "problems:\n"
      "  - label: startup\n"
      "    max_evaluations: 14\n"
      "    starts: 2\n"
      "    seed: 3\n"
      "    startup_profile:\n"
      "      abu: {friction_mu: 0.02}\n"
      "      profile:\n"
      "        start_frequency_hz: 0\n"
      "        segments:\n"
      "          - {end_frequency_hz: 25.0, duration_s: 1.0}\n"
      "          - {end_frequency_hz: 29.5, duration_s: 10.0}\n"
      "          - {end_frequency_hz: 100.0, duration_s: 8.0}\n"
      "      motor: {kind: ideal}\n"
      "      simulation: {method: event_driven, rtol: 1.0e-6}\n"
      "      montecarlo: {design: sobol, runs: 16, seed: 11, threads: 1}\n"
      "      validation: {runs: 32, seed: 5}\n"
      "      design:\n"
      "        segments:\n"
      "          - end_frequency_hz: {min: 15, max: 28, x0: 25}\n"
      "            duration_s: {min: 0.3, max: 3, x0: 1}\n"
      "          - end_frequency_hz: {min: 28, max: 32, x0: 29.5}\n"
      "            duration_s: {min: 1, max: 12, x0: 10}\n"
      "          - end_frequency_hz: 100\n"
      "            duration_s: {min: 1, max: 10, x0: 8}\n"
      "      objective: {kind: mean, definition: magnitude}\n"
      "      constraints: {max_startup_time_s: 20, max_pct_mi: 20, max_amplitude_mm: 0.55, amplitude: max}\n"
      "threads: 1\n"
      "solvers:\n"
      "  - {label: SAO, algorithm: sao, sao: {initial_radius: 0.2, samples: {initial: 8, max: 16}}}\n"
      "  - {label: COBYLA, algorithm: cobyla}\n");
  const std::string whole = fresh_dir("compare_resume_whole");
  const Result plain = run("compare " + cfg + " --json --out " + whole);
  ASSERT_EQ(plain.status, 0) << plain.out << plain.err;
  const auto jp = nlohmann::json::parse(plain.out);
  ASSERT_EQ(jp["runs"].size(), 4u);
  EXPECT_EQ(json_sum(jp, "archive_hits"), 0);
  // one progress line per run, with the time so far and an ETA until the last
  EXPECT_NE(plain.err.find("[1/4] startup start 0 SAO: "), std::string::npos) << plain.err;
  EXPECT_NE(plain.err.find(", ETA "), std::string::npos) << plain.err;
  EXPECT_NE(plain.err.find("[4/4] startup start 1 COBYLA: "), std::string::npos) << plain.err;

  // the same comparison, killed (SIGKILL: nothing of its own gets to run) after its first run
  const std::string out = fresh_dir("compare_resume_killed");
  const std::string err_file = out + ".stderr";
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    if (!freopen(err_file.c_str(), "w", stderr) || !freopen("/dev/null", "w", stdout)) _exit(127);
    execl(ABUOPT_EXE, ABUOPT_EXE, "compare", cfg.c_str(), "--out", out.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  bool first_ended = false;
  for (int i = 0; i < 6000 && !first_ended; ++i) {  // at most 60 s
    std::ifstream f(err_file);
    const std::string err((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    first_ended = err.find("[1/4]") != std::string::npos;
    if (!first_ended) usleep(10000);
  }
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(first_ended) << "the first run did not end within 60 s";
  ASSERT_TRUE(WIFSIGNALED(status)) << "the comparison ended before it was killed; make it longer";
  EXPECT_FALSE(fs::exists(fs::path(out) / "runs.csv"));

  const Result resumed = run("compare " + cfg + " --json --out " + out);
  ASSERT_EQ(resumed.status, 0) << resumed.out << resumed.err;
  const auto jr = nlohmann::json::parse(resumed.out);
  ASSERT_EQ(jr["runs"].size(), 4u);
  EXPECT_EQ(runs_without_times(out), runs_without_times(whole));
  // the finished first run replayed from its archive; the whole rerun computed less
  EXPECT_EQ(jr["runs"][0]["archive_hits"], jr["runs"][0]["evaluations"]);
  EXPECT_EQ(jr["runs"][0]["computed_evaluations"], 0);
  EXPECT_LT(json_sum(jr, "computed_evaluations"), json_sum(jp, "computed_evaluations"));
  EXPECT_EQ(json_sum(jr, "evaluations"), json_sum(jp, "evaluations"));
  EXPECT_NE(resumed.err.find("answered from the archive"), std::string::npos) << resumed.err;
  fs::remove(err_file);
}
