// Monte Carlo statistics against hand-computed values for five made-up runs (one failed), the
// Wilson interval against closed forms, the type-7 quantile, JSON and CSV output.
#include "abuopt/core/monte_carlo_stats.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <vector>
#include <stdexcept>

namespace abuopt {
namespace {

MonteCarloSample sample(std::size_t i, RunStatus st, double mag_e7, double x_e7, bool settled, double t, double amp) {
  MonteCarloSample s;
  s.index = i;
  s.beta0 = {0.5 * static_cast<double>(i), 1.0};
  s.friction_mu = 0.02;
  s.imbalance_kgm = 2.0e-6;  // threshold of %MI: 20e-7
  s.outcome.status = st;
  s.outcome.residual_imbalance_kgm = mag_e7 * 1e-7;
  s.outcome.residual_imbalance_x_kgm = x_e7 * 1e-7;
  s.outcome.settled = settled;
  s.outcome.settling_time_s = t;
  s.outcome.max_amplitude_mm = amp;
  s.outcome.beta_final = {1.5, 4.5};
  s.outcome.events = 7;
  s.outcome.rhs_evaluations = 1234;
  return s;
}

// Five runs; run 2 failed (its huge values must not enter any statistic).
//   |I_r| [1e-7]: 10, 30, (100), 20, 25   sorted ok: 10 20 25 30
//   I_r,x [1e-7]:  5, 20, (100), 25,  1   sorted ok:  1  5 20 25
//   settled: y y (y) n y, times 4 8 (1) - 6;  amplitude 0.2 0.5 (9.9) 0.3 0.1
std::vector<MonteCarloSample> five_runs() {
  return {sample(0, RunStatus::Ok, 10, 5, true, 4, 0.2), sample(1, RunStatus::Ok, 30, 20, true, 8, 0.5),
          sample(2, RunStatus::SolverFailure, 100, 100, true, 1, 9.9), sample(3, RunStatus::Ok, 20, 25, false, 0, 0.3),
          sample(4, RunStatus::Ok, 25, 1, true, 6, 0.1)};
}

constexpr double kTol = 1e-12;  // relative to 1e-7-sized values below, written in units of 1e-7

TEST(MonteCarloStats, CountsAndFailedRunsAreExcluded) {
  const MonteCarloStats s = compute_statistics(five_runs());
  EXPECT_EQ(s.runs, 5u);
  EXPECT_EQ(s.ok, 4u);
  EXPECT_EQ(s.failed, 1u);
  EXPECT_EQ(s.status_counts[static_cast<int>(RunStatus::Ok)], 4u);
  EXPECT_EQ(s.status_counts[static_cast<int>(RunStatus::SolverFailure)], 1u);
  EXPECT_EQ(s.status_counts[static_cast<int>(RunStatus::ChatterLimit)], 0u);
  EXPECT_EQ(s.status_counts[static_cast<int>(RunStatus::StepLimit)], 0u);
  EXPECT_EQ(s.magnitude.count, 4u);
  EXPECT_EQ(s.report_x.count, 4u);
}

TEST(MonteCarloStats, MagnitudeByHand) {
  const ResidualImbalanceStats m = compute_statistics(five_runs()).magnitude;
  EXPECT_NEAR(m.mean * 1e7, 21.25, kTol);   // (10 + 30 + 20 + 25) / 4
  EXPECT_NEAR(m.min * 1e7, 10.0, kTol);
  EXPECT_NEAR(m.max * 1e7, 30.0, kTol);     // not the failed run's 100
  EXPECT_NEAR(m.median * 1e7, 22.5, kTol);  // h = 1.5: 20 + 0.5 (25 - 20)
  EXPECT_NEAR(m.p10 * 1e7, 13.0, kTol);     // h = 0.3: 10 + 0.3 (20 - 10)
  EXPECT_NEAR(m.p90 * 1e7, 28.5, kTol);     // h = 2.7: 25 + 0.7 (30 - 25)
  EXPECT_NEAR(m.p95 * 1e7, 29.25, kTol);    // h = 2.85: 25 + 0.85 (30 - 25)
  EXPECT_EQ(m.mi_count, 3u);                // 30, 20 (I_r = I counts: >=), 25
  EXPECT_DOUBLE_EQ(m.pct_mi, 75.0);
  // Wilson, k = 3, n = 4, z = 1.959963984540054 (evaluated by hand from the formula)
  EXPECT_NEAR(m.pct_mi_ci95[0], 30.0641842582, 1e-6);
  EXPECT_NEAR(m.pct_mi_ci95[1], 95.4412739190, 1e-6);
}

TEST(MonteCarloStats, ReportDefinitionByHand) {
  const ResidualImbalanceStats x = compute_statistics(five_runs()).report_x;
  EXPECT_NEAR(x.mean * 1e7, 12.75, kTol);   // (5 + 20 + 25 + 1) / 4
  EXPECT_NEAR(x.min * 1e7, 1.0, kTol);
  EXPECT_NEAR(x.max * 1e7, 25.0, kTol);
  EXPECT_NEAR(x.median * 1e7, 12.5, kTol);  // 5 + 0.5 (20 - 5)
  EXPECT_NEAR(x.p10 * 1e7, 2.2, kTol);      // 1 + 0.3 (5 - 1)
  EXPECT_NEAR(x.p90 * 1e7, 23.5, kTol);     // 20 + 0.7 (25 - 20)
  EXPECT_NEAR(x.p95 * 1e7, 24.25, kTol);    // 20 + 0.85 (25 - 20)
  EXPECT_EQ(x.mi_count, 2u);                // 20, 25
  EXPECT_DOUBLE_EQ(x.pct_mi, 50.0);
  // Wilson, k = 2, n = 4: symmetric about 50 %
  EXPECT_NEAR(x.pct_mi_ci95[0], 15.0038989152, 1e-6);
  EXPECT_NEAR(x.pct_mi_ci95[1], 84.9961010848, 1e-6);
}

TEST(MonteCarloStats, LimitCyclesSettlingAndAmplitudeByHand) {
  const MonteCarloStats s = compute_statistics(five_runs());
  EXPECT_EQ(s.not_settled, 1u);
  EXPECT_DOUBLE_EQ(s.pct_lc, 25.0);  // 1 of 4 ok runs
  EXPECT_EQ(s.settled, 3u);
  EXPECT_DOUBLE_EQ(s.settling_mean_s, 6.0);    // (4 + 8 + 6) / 3
  EXPECT_DOUBLE_EQ(s.settling_median_s, 6.0);
  EXPECT_DOUBLE_EQ(s.settling_max_s, 8.0);
  EXPECT_DOUBLE_EQ(s.amplitude_max_mm, 0.5);   // not the failed run's 9.9
  EXPECT_NEAR(s.amplitude_mean_mm, 0.275, 1e-15);
}

TEST(MonteCarloStats, PerRunThresholdForUncertainImbalanceMass) {
  auto runs = five_runs();
  runs[0].imbalance_kgm = 0.5e-6;  // this run's own m_I e is small: 10e-7 >= 5e-7 counts
  EXPECT_EQ(compute_statistics(runs).magnitude.mi_count, 4u);
}

TEST(MonteCarloStats, WilsonIntervalClosedForms) {
  // k = 0: lower 0, upper z^2 / (n + z^2)
  const double z = 1.959963984540054;
  auto w0 = wilson_interval(0, 10);
  EXPECT_NEAR(w0.first, 0.0, 1e-15);
  EXPECT_NEAR(w0.second, z * z / (10 + z * z), 1e-12);
  EXPECT_NEAR(w0.second, 0.277532799863, 1e-9);
  // k = n: mirror image
  auto w1 = wilson_interval(10, 10);
  EXPECT_NEAR(w1.first, 10 / (10 + z * z), 1e-12);
  EXPECT_NEAR(w1.second, 1.0, 1e-15);
  // the report's final profile: %MI 1.56 % of 1024 runs = 16 runs
  auto w = wilson_interval(16, 1024);
  EXPECT_NEAR(100 * w.first, 0.9640326541, 1e-6);
  EXPECT_NEAR(100 * w.second, 2.5230283623, 1e-6);
  auto none = wilson_interval(0, 0);
  EXPECT_TRUE(std::isnan(none.first));
  EXPECT_TRUE(std::isnan(none.second));
}

TEST(MonteCarloStats, QuantileType7) {
  const std::vector<double> one{3.0};
  EXPECT_EQ(quantile_type7(one, 0.0), 3.0);
  EXPECT_EQ(quantile_type7(one, 0.9), 3.0);
  const std::vector<double> v{1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  EXPECT_DOUBLE_EQ(quantile_type7(v, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(quantile_type7(v, 1.0), 10.0);
  EXPECT_DOUBLE_EQ(quantile_type7(v, 0.5), 5.5);   // R: quantile(1:10, 0.5) = 5.5
  EXPECT_DOUBLE_EQ(quantile_type7(v, 0.1), 1.9);   // R: 1.9
  EXPECT_DOUBLE_EQ(quantile_type7(v, 0.95), 9.55); // R: 9.55
  EXPECT_TRUE(std::isnan(quantile_type7({}, 0.5)));
}

TEST(MonteCarloStats, NoOkRunsGivesNaNAndJsonNull) {
  std::vector<MonteCarloSample> runs{sample(0, RunStatus::StepLimit, 1, 1, true, 1, 1),
                                     sample(1, RunStatus::ChatterLimit, 1, 1, true, 1, 1),
                                     sample(2, RunStatus::EventLimit, 1, 1, true, 1, 1)};
  const MonteCarloStats s = compute_statistics(runs);
  EXPECT_EQ(s.failed, 3u);
  EXPECT_EQ(s.ok, 0u);
  EXPECT_TRUE(std::isnan(s.magnitude.mean));
  EXPECT_TRUE(std::isnan(s.pct_lc));
  const auto j = to_json(s);
  EXPECT_TRUE(j["magnitude"]["mean"].is_null());
  EXPECT_TRUE(j["pct_lc"].is_null());
  EXPECT_EQ(j["status_counts"]["step_limit"], 1);
  EXPECT_EQ(j["status_counts"]["chatter_limit"], 1);
  EXPECT_EQ(j["status_counts"]["event_limit"], 1);
  EXPECT_NE(format_summary(s).find("event_limit 1"), std::string::npos) << format_summary(s);
}

TEST(MonteCarloStats, JsonHasTheDocumentedKeys) {
  MonteCarloResult r;
  r.samples = five_runs();
  r.wall_time_s = 2.5;
  r.concurrency = 3;
  const auto j = to_json(compute_statistics(r));
  EXPECT_EQ(j["runs"], 5);
  EXPECT_EQ(j["failed"], 1);
  EXPECT_EQ(j["ok"], 4);
  EXPECT_DOUBLE_EQ(j["pct_lc"].get<double>(), 25.0);
  EXPECT_DOUBLE_EQ(j["wall_time_s"].get<double>(), 2.5);
  EXPECT_EQ(j["concurrency"], 3);
  for (const char* def : {"magnitude", "report_x"}) {
    for (const char* k : {"mean", "max", "median", "p10", "p90", "p95", "pct_mi", "mi_count", "count"})
      EXPECT_TRUE(j[def].contains(k)) << def << "." << k;
    ASSERT_TRUE(j[def]["pct_mi_ci95"].is_array());
    EXPECT_EQ(j[def]["pct_mi_ci95"].size(), 2u);
  }
  EXPECT_DOUBLE_EQ(j["magnitude"]["pct_mi"].get<double>(), 75.0);
  EXPECT_DOUBLE_EQ(j["settling_time_s"]["max"].get<double>(), 8.0);
  EXPECT_DOUBLE_EQ(j["max_amplitude_mm"]["max"].get<double>(), 0.5);
  EXPECT_EQ(j["status_counts"]["solver_failure"], 1);
}

TEST(MonteCarloStats, CsvHasOneLinePerRunAndRoundTrips) {
  auto runs = five_runs();
  runs[1].overrides.imbalance_mass_kg = 5.5e-4;
  runs[1].beta0[0] = 0.1;  // shortest round-trip form
  std::ostringstream os;
  write_runs_csv(os, runs);
  std::istringstream is(os.str());
  std::string line;
  std::getline(is, line);
  EXPECT_EQ(line,
            "index,beta0_1,beta0_2,mu,imbalance_mass_kg,imbalance_angle_rad,stiffness_N_per_m,restitution,beta_final_1,"
            "beta_final_2,"
            "ir_magnitude_kgm,ir_x_kgm,settled,settling_time_s,max_amplitude_mm,events,rhs_evaluations,status");
  std::getline(is, line);
  EXPECT_EQ(line, "0,0,1,0.02,,0,0,0,1.5,4.5,1e-06,5e-07,1,4,0.2,7,1234,ok");
  std::getline(is, line);
  EXPECT_EQ(line, "1,0.1,1,0.02,0.00055,0,0,0,1.5,4.5,3e-06,2e-06,1,8,0.5,7,1234,ok");
  std::getline(is, line);
  EXPECT_EQ(line.substr(line.rfind(',') + 1), "solver_failure");
  int rest = 0;
  while (std::getline(is, line)) ++rest;
  EXPECT_EQ(rest, 2);
}

// ---- smooth statistics ----

// Ten ok runs with |I_r| = 1..10 (1e-7 kg m), one failed; the threshold 20e-7 makes r = I_r / 20.
std::vector<MonteCarloSample> ten_runs() {
  std::vector<MonteCarloSample> v;
  for (int k = 1; k <= 10; ++k) v.push_back(sample(k, RunStatus::Ok, k, -k, true, 1, 0.1));
  v.push_back(sample(11, RunStatus::ChatterLimit, 1000, 1000, true, 1, 0.1));
  return v;
}

// Quantile (type 7) and CVaR by hand: level 0.8, h = 9 * 0.8 = 7.2, Q = 8 + 0.2 (9 - 8) = 8.2;
// CVaR = 8.2 + (0.8 + 1.8) / (10 * 0.2) = 9.5, the mean of the worst 20 % (9, 10). Level 0: the mean.
TEST(SmoothStatistics, QuantileAndCvarByHand) {
  const SmoothImbalanceStats s = compute_smooth_statistics(ten_runs(), false, 0.8);
  EXPECT_EQ(s.count, 10u);
  EXPECT_NEAR(s.quantile / 1e-7, 8.2, kTol);
  EXPECT_NEAR(s.cvar / 1e-7, 9.5, kTol);
  EXPECT_NEAR(compute_smooth_statistics(ten_runs(), false, 0.0).cvar / 1e-7, 5.5, kTol);
  // I_r,x = -k: quantile of -10..-1 at 0.8 is -2.8
  EXPECT_NEAR(compute_smooth_statistics(ten_runs(), true, 0.8).quantile / 1e-7, -2.8, kTol);
  EXPECT_THROW(compute_smooth_statistics(ten_runs(), false, 1.0), std::invalid_argument);
}

// Silverman's rule: 0.9 sd n^(-1/5); r = k / 20 for k = 1..10 has sd = sqrt(55/6) / 20.
TEST(SmoothStatistics, BandwidthIsSilvermansRule) {
  const double sd = std::sqrt(55.0 / 6.0) / 20.0;
  const SmoothImbalanceStats s = compute_smooth_statistics(ten_runs(), false, 0.9);
  EXPECT_NEAR(s.bandwidth, 0.9 * sd * std::pow(10.0, -0.2), 1e-15);
  EXPECT_EQ(smoothing_bandwidth({1.0}), 0.0);
  EXPECT_EQ(smoothing_bandwidth({2.0, 2.0, 2.0}), 0.0);
}

// The smoothed exceedance: Phi((r - 1) / h) summed by hand for the ten runs (no run exceeds:
// exact %MI 0, smoothed small but positive), and a run crossing its threshold moves it
// continuously where the count jumps by 100/n.
TEST(SmoothStatistics, SmoothedExceedanceByHandAndContinuousAcrossTheThreshold) {
  const SmoothImbalanceStats s = compute_smooth_statistics(ten_runs(), false, 0.9);
  double p = 0;
  for (int k = 1; k <= 10; ++k) p += 0.5 * std::erfc(-(k / 20.0 - 1.0) / (s.bandwidth * std::sqrt(2.0)));
  EXPECT_NEAR(s.pct_mi, 10.0 * p, 1e-12);
  EXPECT_GT(s.pct_mi, 0.0);
  EXPECT_EQ(compute_statistics(ten_runs()).magnitude.pct_mi, 0.0);

  auto with_last = [](double mag_e7) {
    std::vector<MonteCarloSample> v = ten_runs();
    v[9].outcome.residual_imbalance_kgm = mag_e7 * 1e-7;
    return v;
  };
  const auto below = with_last(19.999), above = with_last(20.001);  // r = 0.99995, 1.00005
  EXPECT_NEAR(compute_statistics(above).magnitude.pct_mi - compute_statistics(below).magnitude.pct_mi, 10.0, kTol);
  const double jump = compute_smooth_statistics(above, false, 0.9).pct_mi -
                      compute_smooth_statistics(below, false, 0.9).pct_mi;
  EXPECT_GT(jump, 0.0);
  EXPECT_LT(jump, 0.01);  // ~ 100/n * 1e-4 / h * phi(0): continuous
}

// As n grows the bandwidth shrinks as n^(-1/5) and the smoothed value tends to the count: r
// evenly spread on [0, 4] (exact exceedance 3/4; interior smoothing of a uniform density is exact,
// what is left is the edge at 0, below Phi(-1/h)).
TEST(SmoothStatistics, TendsToTheCountAsRunsGrow) {
  double previous_gap = 1.0;
  for (int n : {64, 1024, 16384}) {
    std::vector<MonteCarloSample> v;
    for (int i = 0; i < n; ++i) v.push_back(sample(i, RunStatus::Ok, 80.0 * (i + 0.5) / n, 0, true, 1, 0.1));
    const SmoothImbalanceStats s = compute_smooth_statistics(v, false, 0.9);
    const double exact = compute_statistics(v).magnitude.pct_mi;
    EXPECT_NEAR(exact, 75.0, 100.0 / n);
    EXPECT_NEAR(s.bandwidth, 0.9 * (4.0 / std::sqrt(12.0)) * std::pow(n, -0.2), 0.01);
    const double gap = std::fabs(s.pct_mi - exact);
    EXPECT_LT(gap, previous_gap);
    previous_gap = gap;
  }
  EXPECT_LT(previous_gap, 0.05);
}

}  // namespace
}  // namespace abuopt
