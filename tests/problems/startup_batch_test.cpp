// Evaluation concurrency on the startup problem (issue 9 item 4): SAO with a design in every
// region, on a 4-run Monte Carlo, gives the same history, bit for bit, with 1, 2 and 4 evaluation
// workers (the Monte Carlo threads shared among them), and the problem declares itself
// thread-safe only while no Monte Carlo runner is set, or one that takes concurrent studies.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "abuopt/core/batch_runner.hpp"
#include "abuopt/optimizer/minimize.hpp"
#include "abuopt/problems/startup_profile_problem.hpp"

namespace {

using namespace abuopt;

const std::string kConfig = R"(
profile:
  segments:
    - {end_frequency_hz: 25.0, duration_s: 0.3}
    - {end_frequency_hz: 29.5, duration_s: 0.3}
montecarlo: {design: grid, grid: 2, threads: 2}
design:
  segments:
    - end_frequency_hz: {min: 15, max: 28, x0: 25}
      duration_s: {min: 0.2, max: 0.6, x0: 0.3}
    - end_frequency_hz: 29.5
      duration_s: 0.3
constraints: {max_startup_time_s: 20}
)";

problems::StartupProfileSettings settings() {
  YamlReader root = YamlReader::load_string(kConfig);
  problems::StartupProfileSettings s = problems::read_startup_profile_settings(root);
  root.finish();
  return s;
}

opt::OptimizationResult run(std::size_t workers) {
  problems::StartupProfileProblem p(settings());
  opt::OptimizerOptions o;
  o.algorithm = "SAO";
  o.max_evaluations = 14;
  o.sao.doe = opt::DoeKind::Lhs;
  o.evaluation_threads = workers;
  o.handle_sigint = false;
  return opt::minimize(p, o);
}

TEST(StartupBatch, SameHistoryWithOneTwoAndFourWorkers) {
  const opt::OptimizationResult r1 = run(1);
  ASSERT_EQ(r1.history.size(), 14u);
  int ok = 0;
  for (const auto& h : r1.history) ok += h.ok ? 1 : 0;
  EXPECT_GE(ok, 10);  // real simulations, not failed guards
  for (std::size_t w : {2u, 4u}) {
    const opt::OptimizationResult rw = run(w);
    ASSERT_EQ(rw.history.size(), r1.history.size()) << w;
    EXPECT_EQ(rw.reason, r1.reason);
    EXPECT_EQ(rw.x, r1.x);
    for (std::size_t i = 0; i < r1.history.size(); ++i) {
      const auto &a = r1.history[i], &b = rw.history[i];
      EXPECT_EQ(a.x, b.x) << w << " workers, evaluation " << i;
      EXPECT_EQ(a.objective, b.objective) << w << " workers, evaluation " << i;
      EXPECT_EQ(a.inequality, b.inequality) << w << " workers, evaluation " << i;
      auto ma = a.metrics, mb = b.metrics;
      ma.erase("mc_wall_time_s");  // a timing field
      mb.erase("mc_wall_time_s");
      EXPECT_EQ(ma, mb) << w << " workers, evaluation " << i;
    }
  }
}

TEST(StartupBatch, ThreadSafeOnlyWithoutAMonteCarloRunner) {
  problems::StartupProfileProblem p(settings());
  EXPECT_TRUE(p.thread_safe());
  const std::vector<double> x = p.initial_point();
  const opt::Evaluation plain = p.evaluate(x);
  const opt::Evaluation shared = p.evaluate_shared(x, 2);  // one of two at once: 1 thread
  EXPECT_EQ(plain.objective, shared.objective);
  EXPECT_EQ(plain.metrics.at("pct_mi"), shared.metrics.at("pct_mi"));
  p.set_monte_carlo_runner(std::make_shared<ThreadPoolRunner>(1));
  EXPECT_FALSE(p.thread_safe());
  EXPECT_EQ(p.evaluate(x).objective, plain.objective);
  // a runner that takes studies from several threads at once (MPI ranks) keeps it thread-safe
  p.set_monte_carlo_runner(std::make_shared<ThreadPoolRunner>(1), true);
  EXPECT_TRUE(p.thread_safe());
  EXPECT_EQ(p.evaluate_shared(x, 2).objective, plain.objective);
  p.set_monte_carlo_runner(nullptr, true);  // no runner: the flag means nothing
  EXPECT_TRUE(p.thread_safe());
}

}  // namespace
