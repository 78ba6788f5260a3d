// Design sweeps (studies/sweep.hpp): the designs against their definitions and known values, the
// plan (bounds hit exactly, unswept variables at x0), the settings' messages, and resuming a sweep
// killed with SIGKILL without re-evaluating a stored point.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <set>
#include <thread>

#include "abuopt/common/config_error.hpp"
#include "abuopt/optimizer/evaluation_archive.hpp"
#include "abuopt/studies/sweep.hpp"

namespace {

namespace fs = std::filesystem;
using abuopt::ConfigError;
using abuopt::opt::EvaluationArchive;
using abuopt::opt::Variable;

std::vector<Variable> three_vars() {
  return {{"f1", 15, 28, 13}, {"dt2", 1, 12, 11}, {"dt3", 1, 10, 9}};
}

std::string archive_path(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("abuopt_sweep_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path p = dir / (name + ".sqlite");
  fs::remove(p);
  fs::remove(p.string() + "-wal");
  fs::remove(p.string() + "-shm");
  return p.string();
}

abuopt::SweepSettings settings_of(const std::string& yaml, const std::vector<Variable>& vars) {
  abuopt::YamlReader root = abuopt::YamlReader::load_string(yaml);
  return abuopt::read_sweep_settings(root.child("sweep"), vars);
}

std::string message_of(const std::string& yaml) {
  try {
    const auto s = settings_of(yaml, three_vars());
    abuopt::plan_sweep(s, three_vars(), {25, 10, 8});
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST(SweepDesign, GridVariesTheLastVariableFastestAndHitsBothEnds) {
  const auto g = abuopt::grid_unit_design({3, 2});
  ASSERT_EQ(g.size(), 6u);
  const std::vector<std::vector<double>> expected{{0, 0}, {0, 1}, {0.5, 0}, {0.5, 1}, {1, 0}, {1, 1}};
  EXPECT_EQ(g, expected);
}

TEST(SweepDesign, SobolStartsWithTheKnownJoeKuoPoints) {
  // Sobol' in 3 dimensions, Joe-Kuo direction numbers, Gray-code order (the points scipy's
  // qmc.Sobol(d=3, scramble=False) gives; worked by hand in docs/sweep.md).
  const std::vector<std::vector<double>> expected{
      {0, 0, 0},           {0.5, 0.5, 0.5},     {0.75, 0.25, 0.25},  {0.25, 0.75, 0.75},
      {0.375, 0.375, 0.625}, {0.875, 0.875, 0.125}, {0.625, 0.125, 0.875}, {0.125, 0.625, 0.375}};
  EXPECT_EQ(abuopt::sobol_unit_design(8, 3), expected);
}

TEST(SweepDesign, SobolFirstPowerOfTwoPointsStratifyEveryAxis) {
  // The first 2^m points put exactly one point in each interval [k/2^m, (k+1)/2^m) of every axis.
  const auto pts = abuopt::sobol_unit_design(32, 10);
  for (std::size_t j = 0; j < 10; ++j) {
    std::set<int> cells;
    for (const auto& p : pts) cells.insert(static_cast<int>(std::floor(p[j] * 32)));
    EXPECT_EQ(cells.size(), 32u) << "axis " << j;
  }
}

TEST(SweepDesign, LatinHypercubeHasOnePointPerStratumAndDependsOnlyOnItsSeed) {
  const auto a = abuopt::lhs_unit_design(20, 3, 5);
  for (std::size_t j = 0; j < 3; ++j) {
    std::set<int> cells;
    for (const auto& p : a) {
      EXPECT_GE(p[j], 0.0);
      EXPECT_LE(p[j], 1.0);
      cells.insert(std::min(19, static_cast<int>(std::floor(p[j] * 20))));
    }
    EXPECT_EQ(cells.size(), 20u) << "axis " << j;
  }
  EXPECT_EQ(a, abuopt::lhs_unit_design(20, 3, 5));
  EXPECT_NE(a, abuopt::lhs_unit_design(20, 3, 6));
}

TEST(SweepPlan, GridOfASubsetKeepsTheOthersAtX0AndHitsTheBoundsExactly) {
  const auto vars = three_vars();
  const auto s = settings_of("sweep: {method: grid, variables: [dt2, dt3], points: 12, levels: {dt3: 4}}", vars);
  const abuopt::SweepPlan plan = abuopt::plan_sweep(s, vars, {25, 10, 8});
  ASSERT_EQ(plan.x.size(), 48u);
  EXPECT_EQ(plan.levels, (std::vector<std::size_t>{12, 4}));
  for (const auto& x : plan.x) EXPECT_EQ(x[0], 25.0);
  EXPECT_EQ(plan.x.front(), (std::vector<double>{25, 1, 1}));
  EXPECT_EQ(plan.x.back(), (std::vector<double>{25, 12, 10}));
  EXPECT_EQ(plan.x[1][2], 4.0);   // 1 + 9/3
  EXPECT_EQ(plan.x[4][1], 2.0);   // 1 + 11/11: dt2's second level
}

TEST(SweepPlan, SobolAndLhsCoverEveryFreeVariableByDefault) {
  const auto vars = three_vars();
  const auto plan = abuopt::plan_sweep(settings_of("sweep: {method: sobol, points: 8}", vars), vars, {25, 10, 8});
  ASSERT_EQ(plan.x.size(), 8u);
  EXPECT_EQ(plan.x[0], (std::vector<double>{15, 1, 1}));        // the first Sobol' point: the lower corner
  EXPECT_EQ(plan.x[1], (std::vector<double>{21.5, 6.5, 5.5}));  // the centre
  const auto lhs = abuopt::plan_sweep(settings_of("sweep: {method: lhs, points: 5, seed: 3}", vars), vars, {25, 10, 8});
  EXPECT_EQ(lhs.x.size(), 5u);
}

TEST(SweepSettings, BadInputNamesTheKeyTheValueAndTheRule) {
  EXPECT_NE(message_of("sweep: {method: grid, variables: [dt9], points: 3}").find("sweep.variables[0] = dt9: not a free variable"),
            std::string::npos);
  EXPECT_NE(message_of("sweep: {method: grid}").find("sweep.points"), std::string::npos);
  EXPECT_NE(message_of("sweep: {method: grid, points: 1}").find("sweep.points = 1: a grid needs >= 2 levels"), std::string::npos)
      << message_of("sweep: {method: grid, points: 1}");
  EXPECT_NE(message_of("sweep: {method: lhs, points: 4, levels: {dt2: 3}}").find("only with method: grid"),
            std::string::npos);
  EXPECT_NE(message_of("sweep: {method: grid, points: 3, seed: 4}").find("sweep.seed"), std::string::npos);
  EXPECT_NE(message_of("sweep: {method: halton, points: 3}").find("sweep.method = halton"), std::string::npos)
      << message_of("sweep: {method: halton, points: 3}");
  EXPECT_NE(message_of("sweep: {method: grid, points: 3, pointz: 4}").find("pointz"), std::string::npos);
  EXPECT_NE(message_of("sweep: {method: grid, points: 1000}").find("must be <= 1000000"), std::string::npos);
  EXPECT_NE(message_of("sweep: {method: grid, variables: [dt2], points: 3, levels: {dt3: 3}}").find("not swept"),
            std::string::npos);
}

namespace {

// f = sum (x_i - 1)^2 with a sleep, counting what it evaluated.
struct SlowBowl : abuopt::opt::Problem {
  int sleep_ms = 0;
  std::vector<std::vector<double>> evaluated;
  std::string name() const override { return "bowl"; }
  std::vector<Variable> variables() const override { return {{"a", -2, 2, 4}, {"b", -2, 2, 4}}; }
  std::vector<std::string> inequality_names() const override { return {"g"}; }
  abuopt::opt::Evaluation evaluate(const std::vector<double>& x) override {
    if (sleep_ms) std::this_thread::sleep_for(std::chrono::milliseconds(sleep_ms));
    evaluated.push_back(x);
    abuopt::opt::Evaluation e;
    e.objective = (x[0] - 1) * (x[0] - 1) + (x[1] - 1) * (x[1] - 1);
    e.inequality = {x[0] + x[1] - 1};  // feasible when a + b <= 1
    e.metrics["runs"] = 1;
    return e;
  }
};

}  // namespace

TEST(RunSweep, SweepKilledWithSigkillResumesWithoutReevaluatingStoredPoints) {
  const std::string path = archive_path("killed");
  SlowBowl problem;
  const auto vars = problem.variables();
  const auto plan = abuopt::plan_sweep(settings_of("sweep: {method: grid, points: 15}", vars), vars, {0, 0});
  ASSERT_EQ(plan.x.size(), 225u);
  { EvaluationArchive create(path, "bowl-sweep"); }

  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {  // 225 points x 10 ms: killed long before the end
    EvaluationArchive archive(path, "bowl-sweep");
    SlowBowl slow;
    slow.sleep_ms = 10;
    abuopt::run_sweep(slow, archive, plan);
    ::_exit(0);
  }
  EvaluationArchive watcher(path, "bowl-sweep");
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (watcher.count() < 20 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the child finished before it was killed";
  const long stored = watcher.count();
  ASSERT_GE(stored, 20);
  ASSERT_LT(stored, 225);

  EvaluationArchive archive(path, "bowl-sweep");
  const abuopt::SweepResult r = abuopt::run_sweep(problem, archive, plan);
  EXPECT_EQ(r.archive_hits, stored);
  EXPECT_EQ(r.computed, 225 - stored);
  EXPECT_EQ(static_cast<long>(problem.evaluated.size()), 225 - stored);  // only the missing points
  ASSERT_EQ(r.points.size(), 225u);
  std::size_t feasible = 0;
  for (const auto& p : r.points) {
    EXPECT_EQ(p.x, plan.x[p.index]);
    EXPECT_EQ(p.e.objective, (p.x[0] - 1) * (p.x[0] - 1) + (p.x[1] - 1) * (p.x[1] - 1));  // same value either way
    feasible += p.feasible;
  }
  // a + b <= 1 on the 15 x 15 grid a = -2 + 4 i / 14: the pairs with -4 + 4 (i + j) / 14 <= 1
  std::size_t expected = 0;
  for (int i = 0; i < 15; ++i)
    for (int j = 0; j < 15; ++j) expected += (-4 + (i + j) * 4.0 / 14.0 <= 1 + 1e-6);
  EXPECT_EQ(feasible, expected);
  EXPECT_EQ(abuopt::run_sweep(problem, archive, plan).archive_hits, 225);  // a third run computes nothing
}

TEST(RunSweep, AStopFlagEndsTheSweepAfterTheCurrentPoint) {
  const std::string path = archive_path("stopped");
  SlowBowl problem;
  const auto vars = problem.variables();
  const auto plan = abuopt::plan_sweep(settings_of("sweep: {method: sobol, points: 16}", vars), vars, {0, 0});
  EvaluationArchive archive(path, "bowl-stop");
  std::atomic<bool> stop{false};
  const auto r = abuopt::run_sweep(
      problem, archive, plan, [&](const abuopt::SweepPoint&, std::size_t done, std::size_t, double) { stop = done == 5; },
      &stop);
  EXPECT_TRUE(r.interrupted);
  EXPECT_EQ(r.points.size(), 5u);
  EXPECT_EQ(archive.count(), 5);
}
