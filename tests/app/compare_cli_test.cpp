// `abuopt compare` end to end on the built binary: the shipped benchmark comparison runs (exit 0,
// the table on stdout, the CSVs under --out), and a bad config is one message with exit status 2.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

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
       }) {
    const std::string cfg = write_config("compare_bad.yaml", c.yaml);
    const Result r = run("compare " + cfg + " --out " + fresh_dir("compare_cli_bad"));
    EXPECT_EQ(r.status, 2) << c.yaml << r.out << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << "expected '" << c.message << "' in: " << r.err;
    EXPECT_EQ(r.err.find("terminate"), std::string::npos) << r.err;
  }
  const Result missing = run("compare " + kConfigs + "compare/no_such.yaml");
  EXPECT_EQ(missing.status, 2) << missing.err;
  EXPECT_NE(missing.err.find("no_such.yaml"), std::string::npos) << missing.err;
}
