// The files `compare` writes for its plots (issue 13: curves were drawn under the wrong names; issue
// 12: solver labels reached gnuplot unquoted). The plot data is read back and every named series
// is checked against the run it belongs to.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "abuopt/optimizer/benchmarking.hpp"

namespace abuopt {
namespace {

namespace fs = std::filesystem;

opt::RunRecord run(const std::string& solver, std::vector<std::pair<long, double>> points, long evaluations) {
  opt::RunRecord r;
  r.problem = "hs071";
  r.solver = solver;
  r.start = 0;
  r.dimension = 4;
  r.result.evaluations = evaluations;
  for (auto [e, best] : points) r.convergence.push_back({e, best});
  r.feasible = !points.empty();
  return r;
}

// Four solvers: the second never found a feasible point (no curve), the third reaches f* after
// positive gaps, the fourth is at f* from its first feasible point (a gap of 0: drawn on the floor
// line of the log axis, a tenth of the smallest positive gap).
opt::ComparisonResult three_solvers(const std::string& label_of_first) {
  opt::ComparisonResult r;
  r.problems = {"hs071"};
  r.solvers = {label_of_first, "BOBYQA", "SLSQP", "IPOPT"};
  r.f_star = {17.0};
  r.f_star_source = {"given"};
  r.runs = {run(label_of_first, {{3, 20.0}, {10, 18.0}}, 30), run("BOBYQA", {}, 30),
            run("SLSQP", {{2, 25.0}, {5, 17.17}, {9, 17.0}}, 12), run("IPOPT", {{4, 17.0}}, 8)};
  return r;
}

std::string read(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// The data blocks of a gnuplot data file (blocks separated by two blank lines), as (x, y) rows.
std::vector<std::vector<std::pair<double, double>>> blocks(const std::string& text) {
  std::vector<std::vector<std::pair<double, double>>> out(1);
  std::istringstream in(text);
  std::string line;
  int blank = 0;
  while (std::getline(in, line)) {
    if (line.empty()) {
      if (++blank == 2 && !out.back().empty()) out.emplace_back();
      continue;
    }
    blank = 0;
    if (line[0] == '#') continue;
    std::istringstream ls(line);
    double x = 0, y = 0;
    ls >> x >> y;
    out.back().push_back({x, y});
  }
  if (out.back().empty()) out.pop_back();
  return out;
}

TEST(ComparisonPlots, EveryConvergenceCurveIsDrawnUnderItsOwnSolver) {
  const opt::ComparisonResult r = three_solvers("Ipopt");
  const fs::path dir = fs::path(ABUOPT_BINARY_DIR) / "comparison_plot_test_out";
  fs::remove_all(dir);
  opt::write_comparison(r, dir.string(), /*make_plots=*/false);
  const auto data = blocks(read(dir / "convergence_hs071.dat"));
  const std::string script = read(dir / "plots.gp");

  // Each "index N ... title 'NAME...'" of the convergence plot: block N must be NAME's run.
  const std::regex series("'convergence_hs071\\.dat' index ([0-9]+) using 1:2 with lines lt [0-9]+ title '([^']*)' noenhanced");
  std::map<std::string, long> index_of;
  for (auto it = std::sregex_iterator(script.begin(), script.end(), series); it != std::sregex_iterator(); ++it) {
    const std::string title = (*it)[2];
    index_of[title.substr(0, title.find(" ("))] = std::stol((*it)[1]);
  }
  ASSERT_EQ(index_of.size(), 3u) << script;
  ASSERT_TRUE(index_of.count("Ipopt") && index_of.count("SLSQP") && index_of.count("IPOPT")) << script;
  // The smallest positive gap is SLSQP's 17.17 - 17: the floor is a tenth of it.
  const double floor_gap = 0.17 / 17.0 / 10.0;
  EXPECT_NE(script.find("f* reached (gap 0, drawn at 0.001)"), std::string::npos) << script;
  const auto& ipopt = data.at(static_cast<std::size_t>(index_of.at("IPOPT")));
  ASSERT_FALSE(ipopt.empty());
  for (const auto& [x, y] : ipopt) EXPECT_NEAR(y, floor_gap, 1e-15) << "IPOPT is at f* from evaluation 4";
  for (const opt::RunRecord& run : r.runs) {
    if (run.convergence.empty() || run.convergence.front().best <= 17.0) continue;  // checked above
    const auto& block = data.at(static_cast<std::size_t>(index_of.at(run.solver)));
    // The first point of the block is the run's first point, with the gap (f - f*) / max(|f*|, 1).
    ASSERT_FALSE(block.empty()) << run.solver;
    EXPECT_EQ(block.front().first, run.convergence.front().evaluation) << run.solver;
    EXPECT_NEAR(block.front().second, (run.convergence.front().best - 17.0) / 17.0, 1e-12) << run.solver;
    // Every positive gap of the run is in its block, and no point of another run.
    for (const auto& [x, y] : block) {
      bool found = false;
      for (const auto& c : run.convergence)
        found = found || std::abs(y - std::max((c.best - 17.0) / 17.0, floor_gap)) < 1e-12;
      EXPECT_TRUE(found) << run.solver << ": " << x << " " << y;
    }
  }
  // The solver without a feasible point is named, with no data; a zero gap is on the floor (> 0).
  EXPECT_NE(script.find("NaN with lines lt 2 title 'BOBYQA (no feasible point)'"), std::string::npos) << script;
  EXPECT_NE(script.find("title 'BOBYQA (no feasible point)' noenhanced"), std::string::npos) << script;
  EXPECT_NE(script.find("SLSQP (reaches f* at evaluation 9)"), std::string::npos) << script;
  EXPECT_NE(script.find("title 'IPOPT (reaches f* at evaluation 4)' noenhanced"), std::string::npos) << script;
  for (const auto& b : data)
    for (const auto& [x, y] : b) EXPECT_GT(y, 0.0) << "a zero gap was written as " << y;
  fs::remove_all(dir);
}

TEST(ComparisonPlots, ASolverLabelCannotInjectGnuplotCommands) {
  const std::string evil = "x'\nsystem \"touch /tmp/abuopt_pwned\"\n'";
  const opt::ComparisonResult r = three_solvers(evil);
  const fs::path dir = fs::path(ABUOPT_BINARY_DIR) / "comparison_plot_inject_out";
  fs::remove_all(dir);
  opt::write_comparison(r, dir.string(), /*make_plots=*/false);
  const std::string script = read(dir / "plots.gp");
  // Every line of the script is a line we wrote: no line starts with the injected command, and
  // every single quote in a label is doubled inside one quoted string.
  std::istringstream in(script);
  std::string line;
  while (std::getline(in, line)) EXPECT_NE(line.rfind("system", 0), 0u) << line;
  EXPECT_NE(script.find("title 'x'' system \"touch /tmp/abuopt_pwned\" '''"), std::string::npos) << script;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace abuopt
