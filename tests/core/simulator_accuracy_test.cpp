// Long study (ctest label "long"): the default tolerances against a tight reference over 1024
// random initial conditions of the report's final profile (issue goal: every final angle within
// 1e-3 rad). Takes about a minute on two cores; bench/simulator_accuracy prints the same figures.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <random>
#include <thread>
#include <vector>

#include "abuopt/core/simulator.hpp"

using namespace abuopt;

TEST(SimulatorAccuracy, DefaultTolerancesWithin1e3RadOf1024TightRuns) {
  SimulationSetup fast, ref;
  ref.options.rtol = 1e-10;
  ref.options.atol = 1e-13;
  const Simulator sf(fast), sr(ref);
  std::mt19937_64 rng(20031);
  std::uniform_real_distribution<double> u(0, 2 * M_PI);
  std::vector<std::vector<double>> ics(1024);
  for (auto& ic : ics) ic = {u(rng), u(rng)};
  std::vector<double> dev(ics.size(), 0.0);
  std::vector<int> ok(ics.size(), 0);
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t i; (i = next++) < ics.size();) {
      const RunOutcome a = sf.run(ics[i]), b = sr.run(ics[i]);
      ok[i] = a.ok() && b.ok();
      for (int k = 0; k < 2; ++k) {
        double d = std::fabs(a.beta_final[k] - b.beta_final[k]);
        dev[i] = std::max(dev[i], std::min(d, 2 * M_PI - d));
      }
    }
  };
  std::vector<std::thread> pool;
  for (unsigned t = 0; t < std::max(1u, std::thread::hardware_concurrency()); ++t) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
  EXPECT_EQ(std::count(ok.begin(), ok.end(), 0), 0);
  const double worst = *std::max_element(dev.begin(), dev.end());
  EXPECT_LT(worst, 1e-3);  // measured: 1.6e-4 rad
  RecordProperty("max_angle_difference_rad", std::to_string(worst));
}
