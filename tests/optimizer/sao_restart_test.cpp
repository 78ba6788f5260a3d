// SAO's global phase by default on stochastic problems and its restarts after convergence
// (docs/sao.md, "Global phase": when it runs, its size, restarts).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "abuopt/optimizer/benchmarks/benchmark_factory.hpp"
#include "abuopt/optimizer/sao.hpp"
#include "two_basins.hpp"

namespace {

using namespace abuopt;

using test::TwoBasins;

bool same_history(const opt::OptimizationResult& a, const opt::OptimizationResult& b) {
  if (a.history.size() != b.history.size()) return false;
  for (std::size_t i = 0; i < a.history.size(); ++i)
    if (a.history[i].x != b.history[i].x || a.history[i].objective != b.history[i].objective) return false;
  return true;
}

TEST(SaoGlobalAuto, OnForStochasticProblemsOnly) {
  opt::SaoGlobalPhase gp;  // the defaults: auto, automatic size
  EXPECT_TRUE(gp.enabled(true));
  EXPECT_FALSE(gp.enabled(false));
  gp.points = 10;  // a size given: on whatever the problem (the meaning before `mode` existed)
  EXPECT_TRUE(gp.enabled(false));
  gp.mode = opt::GlobalPhaseMode::Never;
  EXPECT_FALSE(gp.enabled(true));
  gp.mode = opt::GlobalPhaseMode::Always;
  gp.points = 0;
  EXPECT_TRUE(gp.enabled(false));
  // the problems: a sampled problem is stochastic by default, the noisy benchmarks say so, the
  // smooth ones are not
  EXPECT_FALSE(opt::benchmarks::make_benchmark("hs071")->stochastic());
  EXPECT_TRUE(opt::benchmarks::make_benchmark("noisy_hs071")->stochastic());
  opt::benchmarks::BenchmarkSettings sampled;
  sampled.noise_samples = 16;
  EXPECT_TRUE(opt::benchmarks::make_benchmark("noisy_cantilever", sampled)->stochastic());
  opt::benchmarks::BenchmarkSettings silent;
  silent.noise_amplitude = 0;
  EXPECT_FALSE(opt::benchmarks::make_benchmark("noisy_cantilever", silent)->stochastic());
}

// The automatic size: 4 (n + 1) points and as many infill points, at most max_evaluations / 6 each,
// at least 2; a given size is used as given.
TEST(SaoGlobalAuto, SizeFollowsTheDimensionAndTheBudget) {
  opt::SaoGlobalPhase gp;
  EXPECT_EQ(gp.design_points(4, 1000), 20);  // hs071: the measured 20 + 20
  EXPECT_EQ(gp.infill_points(4, 1000), 20);
  EXPECT_EQ(gp.design_points(5, 150), 24);   // the startup problem at 150 evaluations
  EXPECT_EQ(gp.design_points(5, 120), 20);   // 120 / 6
  EXPECT_EQ(gp.design_points(2, 6), 2);      // the floor
  EXPECT_EQ(gp.design_points(2, 0), 12);     // no budget: 4 (n + 1)
  gp.points = 7;
  gp.iterations = 3;
  EXPECT_EQ(gp.design_points(4, 1000), 7);
  EXPECT_EQ(gp.infill_points(4, 1000), 3);
}

// Deterministic problem, defaults: no global phase, the run is the one with mode never, evaluation
// by evaluation (so the smooth benchmarks keep their counts). Stochastic problem: the defaults are
// mode always; the first 1 + 12 evaluations are the start and the automatic design (n = 2).
TEST(SaoGlobalAuto, DefaultsFollowTheProblemKind) {
  opt::OptimizerOptions o;
  o.max_evaluations = 60;
  opt::SaoOptions never;
  never.global_phase.mode = opt::GlobalPhaseMode::Never;
  opt::SaoOptions always;
  always.global_phase.mode = opt::GlobalPhaseMode::Always;
  TwoBasins d1(false), d2(false), s1(true), s2(true);
  const auto det_default = opt::minimize_sao(d1, o, opt::SaoOptions{});
  const auto det_never = opt::minimize_sao(d2, o, never);
  EXPECT_TRUE(same_history(det_default, det_never));
  EXPECT_NEAR(det_default.objective, -1.0, 1e-2);  // the shallow basin of the start
  const auto sto_default = opt::minimize_sao(s1, o, opt::SaoOptions{});
  const auto sto_always = opt::minimize_sao(s2, o, always);
  EXPECT_TRUE(same_history(sto_default, sto_always));
  EXPECT_NEAR(sto_default.objective, -2.0, 1e-3);  // the deep one
  std::cout << "[measure] two basins, defaults: deterministic " << det_default.brief_report() << "; stochastic "
            << sto_default.brief_report() << "\n";
}

// A trust region that converges with budget left restarts (n + 1 infill points, a new region at the
// incumbent) until the budget is spent exactly; without restarts it stops early. The result is
// the best point of the whole run, so a restart never makes it worse.
TEST(SaoRestart, SpendsTheBudgetExactlyAndNeverWorsens) {
  for (long budget : {45L, 80L}) {
    opt::OptimizerOptions o;
    o.max_evaluations = budget;
    opt::SaoOptions with;
    with.global_phase.mode = opt::GlobalPhaseMode::Always;
    opt::SaoOptions without = with;
    without.global_phase.restart = false;
    TwoBasins p1(false), p2(false);
    const auto r_with = opt::minimize_sao(p1, o, with);
    const auto r_without = opt::minimize_sao(p2, o, without);
    std::cout << "[measure] budget " << budget << ": restarts " << r_with.brief_report() << " (" << r_with.message
              << "); none " << r_without.brief_report() << "\n";
    EXPECT_LT(r_without.evaluations, budget);  // converged with budget left
    EXPECT_EQ(r_with.evaluations, budget);
    EXPECT_EQ(static_cast<long>(r_with.history.size()), budget);
    // the run without restarts is a prefix of the run with them
    ASSERT_LE(r_without.history.size(), r_with.history.size());
    for (std::size_t i = 0; i < r_without.history.size(); ++i) EXPECT_EQ(r_with.history[i].x, r_without.history[i].x);
    EXPECT_LE(r_with.objective, r_without.objective);
  }
}

// Restarts do not trigger when fewer than n + 2 evaluations are left, nor without a budget limit
// reached... and the run with restarts is the same whatever the number of evaluation threads.
TEST(SaoRestart, IndependentOfEvaluationThreads) {
  opt::SaoOptions with;
  with.global_phase.mode = opt::GlobalPhaseMode::Always;
  std::vector<opt::OptimizationResult> runs;
  for (std::size_t threads : {1u, 2u, 4u}) {
    opt::OptimizerOptions o;
    o.max_evaluations = 70;
    o.evaluation_threads = threads;
    TwoBasins p(true);
    runs.push_back(opt::minimize_sao(p, o, with));
  }
  EXPECT_TRUE(same_history(runs[0], runs[1]));
  EXPECT_TRUE(same_history(runs[0], runs[2]));
}

}  // namespace
