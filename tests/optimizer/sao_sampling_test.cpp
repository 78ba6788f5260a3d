// The sample size that follows the need (docs/sao.md, "Adaptive sample size"): the sampled noisy
// benchmarks (noise of a mean of n runs, sd a (1 + |f|) / sqrt n, nested runs), the driver and the
// archive keyed by (x, n), SAO with a fixed n identical to SAO without the schedule, the schedule
// n_k = n0 2^ceil(log2 (r0 / r_k)^p) with its noise doubling, resumption from an archive bit for
// bit, and the measured saving in simulations on noisy hs071 from many random starts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "abuopt/common/config_error.hpp"
#include "abuopt/optimizer/benchmarking.hpp"
#include "abuopt/optimizer/benchmarks/benchmark_factory.hpp"
#include "abuopt/optimizer/benchmarks/noisy_problem.hpp"
#include "abuopt/optimizer/evaluation_archive.hpp"
#include "abuopt/optimizer/minimize.hpp"
#include "abuopt/optimizer/sao.hpp"

namespace {

using namespace abuopt;

std::unique_ptr<opt::Problem> sampled(const std::string& name, double amplitude, std::size_t samples,
                                      std::uint64_t seed = 1) {
  opt::benchmarks::BenchmarkSettings s;
  s.noise_amplitude = amplitude;
  s.noise_samples = samples;
  s.noise_seed = seed;
  return opt::benchmarks::make_benchmark("noisy_" + name, s);
}

double metric(const opt::EvaluationRecord& r, const char* name) {
  const auto it = r.metrics.find(name);
  return it == r.metrics.end() ? std::nan("") : it->second;
}

TEST(SampledNoise, StandardDeviationFallsAsOneOverSqrtN) {
  // sd of f~_n - f over many designs: a (1 + |f|) / sqrt(n) (closed form of a mean of n
  // independent unit-variance runs); 4000 designs give the sd to about 1.1 % (1 / sqrt(2 * 4000))
  auto p = sampled("rosenbrock", 0.1, 256);
  for (std::size_t n : {1, 4, 64, 256}) {
    double sum = 0, sum2 = 0;
    const int designs = 4000;
    for (int i = 0; i < designs; ++i) {
      const std::vector<double> x{-1.0 + 0.0005 * i, 0.5 + 0.0001 * i};
      const opt::Evaluation e = p->evaluate_sampled(x, n);
      const double f = e.metrics.at("noise_free_objective");
      const double z = (e.objective - f) / (0.1 * (1 + std::fabs(f)));
      sum += z;
      sum2 += z * z;
      EXPECT_EQ(e.metrics.at("runs"), static_cast<double>(n));
    }
    const double mean = sum / designs, sd = std::sqrt(sum2 / designs - mean * mean);
    EXPECT_NEAR(sd * std::sqrt(static_cast<double>(n)), 1.0, 0.05) << "n = " << n;
    EXPECT_NEAR(mean * std::sqrt(static_cast<double>(n)), 0.0, 0.07) << "n = " << n;
  }
}

TEST(SampledNoise, FirstNRunsOfOneSequence) {
  // the value at N is evaluate(); and n e_n - (n - 1) e_{n-1} is one run's noise, sqrt(3) u with
  // u in [-1, 1): bounded by sqrt(3) for every n (a fresh sample per n would break this)
  auto p = sampled("hs071", 0.1, 64);
  const std::vector<double> x{1.5, 4.5, 3.5, 1.5};
  const opt::Evaluation full = p->evaluate(x);
  const opt::Evaluation at_n = p->evaluate_sampled(x, 64);
  EXPECT_EQ(full.objective, at_n.objective);
  EXPECT_EQ(full.inequality, at_n.inequality);
  EXPECT_EQ(full.equality, at_n.equality);
  const double f = full.metrics.at("noise_free_objective");
  double previous = 0;
  double largest = 0;
  for (std::size_t n = 1; n <= 64; ++n) {
    const double e = (p->evaluate_sampled(x, n).objective - f) / (0.1 * (1 + std::fabs(f)));
    const double run = static_cast<double>(n) * e - static_cast<double>(n - 1) * previous;
    largest = std::max(largest, std::fabs(run));
    previous = e;
  }
  EXPECT_LE(largest, std::sqrt(3.0) + 1e-9);
  EXPECT_GT(largest, 1.0);  // the runs do differ
  EXPECT_THROW(p->evaluate_sampled(x, 0), std::invalid_argument);
  EXPECT_THROW(p->evaluate_sampled(x, 65), std::invalid_argument);
  // a problem that is not sampled has no other size
  auto plain = opt::benchmarks::make_benchmark("noisy_hs071");
  EXPECT_EQ(plain->sample_size(), 0u);
  EXPECT_EQ(plain->max_sample_size(), 0u);
  EXPECT_THROW(plain->evaluate_sampled(x, 8), std::invalid_argument);
}

TEST(SaoSampling, FixedSampleSizeIsIdenticalToNoSchedule) {
  // samples {initial: N, max: N}: every evaluation at the problem's own size, evaluation for
  // evaluation the run without a schedule
  for (const char* name : {"hs071", "cantilever"}) {
    opt::OptimizerOptions o;
    o.max_evaluations = 80;
    o.constraint_tolerance = 1e-2;
    auto a = sampled(name, 0.05, 128);
    auto b = sampled(name, 0.05, 128);
    opt::SaoOptions plain;
    opt::SaoOptions fixed;
    fixed.samples.initial = 128;
    const opt::OptimizationResult ra = opt::minimize_sao(*a, o, plain);
    const opt::OptimizationResult rb = opt::minimize_sao(*b, o, fixed);
    ASSERT_EQ(ra.history.size(), rb.history.size()) << name;
    for (std::size_t i = 0; i < ra.history.size(); ++i) {
      EXPECT_EQ(ra.history[i].x, rb.history[i].x) << name << " evaluation " << i;
      EXPECT_EQ(ra.history[i].objective, rb.history[i].objective) << name << " evaluation " << i;
    }
    EXPECT_EQ(ra.samples, 128 * ra.evaluations);
    EXPECT_EQ(rb.samples, ra.samples);
    EXPECT_EQ(ra.x, rb.x);
  }
}

// The schedule replayed from the iteration records: n_k = min(n_max, max(n_{k-1}, floor_k,
// n0 2^ceil(log2 (r0 / r_k)^p))), floor_k = 2 n_{k-1} after a failed step whose shortfall was
// within sqrt(2) sigma of the merit (or exactly 0), else floor_{k-1}.
void expect_schedule(const opt::OptimizationResult& r, std::size_t n0, std::size_t n_max, double p, double r0,
                     bool expect_noise_doubling) {
  std::size_t previous = n0, floor = n0;
  bool doubled = false;
  ASSERT_FALSE(r.iteration_records.empty());
  for (const opt::IterationRecord& it : r.iteration_records) {
    const double ratio = std::pow(r0 / it.radius, p);
    std::size_t scheduled = n0;
    if (ratio > 1) scheduled = n0 << static_cast<int>(std::ceil(std::log2(ratio) - 1e-9));
    scheduled = std::min(std::max(scheduled, n0), n_max);
    const std::size_t expected = std::min(n_max, std::max({previous, floor, scheduled}));
    ASSERT_EQ(static_cast<std::size_t>(it.runs), expected) << "iteration " << it.iteration << " radius " << it.radius;
    const bool failed = it.step == opt::IterationStep::Rejected ||
                        (it.step == opt::IterationStep::Accepted && it.rho <= 0.25);
    if (failed && (it.predicted_reduction - it.actual_reduction <= std::sqrt(2.0) * it.noise ||
                   it.actual_reduction == 0)) {
      floor = std::min(n_max, 2 * expected);
      doubled = doubled || floor > expected;
    }
    previous = expected;
  }
  if (expect_noise_doubling) {
    EXPECT_TRUE(doubled);
  }
}

TEST(SaoSampling, ScheduleFollowsTheRadiusOnANoiseFreeProblem) {
  // amplitude 0: no noise, so the size follows the radius alone
  auto p = sampled("hs071", 0.0, 1024);
  opt::OptimizerOptions o;
  o.max_evaluations = 200;
  opt::SaoOptions sao;
  sao.samples.initial = 8;
  sao.samples.max = 512;
  sao.samples.exponent = 2;
  const opt::OptimizationResult r = opt::minimize_sao(*p, o, sao);
  expect_schedule(r, 8, 512, 2, sao.initial_radius, false);
  // the radius shrank below r0 / 2 at least once, so the size grew
  EXPECT_GT(r.iteration_records.back().runs, 8);
  long total = 0;
  for (const auto& h : r.history) total += static_cast<long>(metric(h, "runs"));
  EXPECT_EQ(total, r.samples);
}

TEST(SaoSampling, ScheduleDoublesWhenNoiseHidesTheStep) {
  auto p = sampled("hs071", 0.2, 1024, 7);
  opt::OptimizerOptions o;
  o.max_evaluations = 150;
  o.constraint_tolerance = 1e-2;
  opt::SaoOptions sao;
  sao.samples.initial = 4;
  sao.samples.exponent = 1;
  const opt::OptimizationResult r = opt::minimize_sao(*p, o, sao);
  expect_schedule(r, 4, 1024, 1, sao.initial_radius, true);
  // the result is the best feasible point among those on the most runs (the least noisy estimates)
  double most = 0, best = std::numeric_limits<double>::infinity();
  for (const auto& h : r.history)
    if (h.feasible) most = std::max(most, metric(h, "runs"));
  for (const auto& h : r.history)
    if (h.feasible && metric(h, "runs") == most) best = std::min(best, h.objective);
  ASSERT_TRUE(r.feasible);
  EXPECT_EQ(r.metrics.at("runs"), most);
  EXPECT_EQ(r.objective, best);
}

TEST(SaoSampling, BadSettingsNameKeyValueAndRule) {
  // each bad setting is one ConfigError whose message contains `text` (key, value and rule)
  auto expect_error = [](const std::function<void()>& call, const std::string& text) {
    try {
      call();
      ADD_FAILURE() << "no ConfigError; expected " << text;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    }
  };
  opt::SaoOptions s;
  s.samples.initial = -1;
  expect_error([&] { s.validate(); }, "sao.samples.initial = -1");
  s.samples.initial = 64;
  s.samples.max = 32;
  expect_error([&] { s.validate(); }, "sao.samples.max = 32: must be 0");
  // a problem whose size cannot be chosen, and one whose largest size is too small
  s.samples.max = 0;
  auto plain = opt::benchmarks::make_benchmark("noisy_hs071");
  opt::OptimizerOptions o;
  o.max_evaluations = 10;
  expect_error([&] { opt::minimize_sao(*plain, o, s); }, "sao.samples.initial = 64: needs a problem whose sample size");
  auto small = sampled("hs071", 0.1, 32);
  expect_error([&] { opt::minimize_sao(*small, o, s); },
               "sao.samples.initial = 64: must be <= the problem's largest sample size 32");
  // YAML: the section is read, and written only when on
  const std::string text = opt::to_yaml(opt::SaoOptions{});
  EXPECT_EQ(text.find("samples"), std::string::npos) << text;
  opt::SaoOptions on;
  on.samples.initial = 16;
  on.samples.max = 256;
  EXPECT_NE(opt::to_yaml(on).find("samples"), std::string::npos);
}

TEST(SaoSampling, ArchiveKeysValuesBySampleSizeAndResumesBitForBit) {
  const std::string path = testing::TempDir() + "/sao_sampling_archive.sqlite";
  std::remove(path.c_str());
  opt::OptimizerOptions o;
  o.max_evaluations = 60;
  o.constraint_tolerance = 1e-2;
  opt::SaoOptions sao;
  sao.samples.initial = 8;
  sao.samples.max = 256;
  opt::OptimizationResult first, second;
  {
    auto p = sampled("hs071", 0.1, 256, 3);
    opt::EvaluationArchive archive(path, "sampled-hs071");
    opt::ArchivedProblem ap(*p, archive);
    first = opt::minimize_sao(ap, o, sao);
    EXPECT_EQ(ap.hits(), 0);
    // every value stored with its run count: 0 for the problem's own 256, n otherwise
    long stored_at_other_sizes = 0;
    for (const auto& e : archive.entries()) {
      const double runs = e.evaluation.metrics.at("runs");
      EXPECT_EQ(e.runs, runs == 256 ? 0 : static_cast<long>(runs));
      if (e.runs != 0) ++stored_at_other_sizes;
    }
    EXPECT_GT(stored_at_other_sizes, 0);
    EXPECT_EQ(archive.count(), first.evaluations);
  }
  {
    auto p = sampled("hs071", 0.1, 256, 3);
    opt::EvaluationArchive archive(path, "sampled-hs071");
    opt::ArchivedProblem ap(*p, archive);
    second = opt::minimize_sao(ap, o, sao);
    EXPECT_EQ(ap.misses(), 0);  // every evaluation answered from the archive
  }
  ASSERT_EQ(first.history.size(), second.history.size());
  for (std::size_t i = 0; i < first.history.size(); ++i) {
    EXPECT_EQ(first.history[i].x, second.history[i].x);
    EXPECT_EQ(first.history[i].objective, second.history[i].objective);
    EXPECT_EQ(first.history[i].inequality, second.history[i].inequality);
  }
  EXPECT_EQ(first.x, second.x);
  EXPECT_EQ(first.samples, second.samples);
  std::remove(path.c_str());
}

// Simulations (the sum of the evaluations' run counts) until the first evaluation whose point is
// feasible on the noise-free problem within tol and has noise-free f within 1 % of f*; -1: never.
long simulations_to_one_percent(const opt::OptimizationResult& r, opt::Problem& clean, double f_star, double tol) {
  long sims = 0;
  for (const auto& h : r.history) {
    sims += static_cast<long>(metric(h, "runs"));
    const opt::Evaluation e = clean.evaluate(h.x);
    if (opt::is_feasible(e, tol) && e.objective - f_star <= 0.01 * std::max(1.0, std::fabs(f_star))) return sims;
  }
  return -1;
}

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

struct Tally {
  int solved = 0;
  std::vector<double> sims;  // of the solved starts
  std::vector<double> gaps;  // per start: (f(result) - f*) / max(1, |f*|), noise-free; inf if infeasible
  std::vector<double> total; // per start: simulations of the whole run
  std::vector<double> to_solve;  // per start: simulations to solve, inf if never
  std::string text;
};

Tally run_starts(const std::string& name, double amplitude, std::size_t n_max, const opt::SaoOptions& sao,
                 int starts, std::uint64_t seed, long budget) {
  Tally t;
  auto clean = opt::benchmarks::make_benchmark(name);
  const double f_star = clean->best_known()->objective;
  auto probe = sampled(name, amplitude, n_max);
  const auto x0s = opt::starting_points(*probe, starts, seed);
  for (int k = 0; k < starts; ++k) {
    auto p = sampled(name, amplitude, n_max);
    opt::OptimizerOptions o;
    o.max_evaluations = budget;
    o.constraint_tolerance = 1e-2;
    o.seed = seed + static_cast<std::uint64_t>(k);
    const opt::OptimizationResult r = opt::minimize_sao(*p, o, sao, x0s[k]);
    const long sims = simulations_to_one_percent(r, *clean, f_star, 1e-2);
    // the result's noise-free value relative to f*, infinite when infeasible on the clean problem
    const opt::Evaluation fin = clean->evaluate(r.x);
    t.gaps.push_back(opt::is_feasible(fin, 1e-2) ? (fin.objective - f_star) / std::max(1.0, std::fabs(f_star))
                                                 : std::numeric_limits<double>::infinity());
    t.total.push_back(static_cast<double>(r.samples));
    t.to_solve.push_back(sims > 0 ? static_cast<double>(sims) : std::numeric_limits<double>::infinity());
    if (sims > 0) {
      ++t.solved;
      t.sims.push_back(static_cast<double>(sims));
    }
    t.text += " " + std::to_string(sims);
  }
  return t;
}

// Measured (docs/sao.md): the sampled noisy benchmarks (one run's noise 2 % relative, 256 runs at
// most: sd 0.125 % at 256, 0.5 % at 16), 12 starts each (the shipped one and 11 random, seed 401:
// 36 runs per schedule; the docs' tables add seeds 402, 501, 502), SAO's defaults at a fixed 256 runs against the schedule from
// 16 to 256. Solved: a point feasible within 1e-2 on the noise-free problem and within 1 % of f*
// there. Counted: the simulations until then. The data profile over the runs, solved within S
// simulations for S = 1k .. 32k and at all, must favour the schedule at small S and lose at most a
// tenth of the solved runs at the end.
TEST(SaoSampling, FewerSimulationsThanFixedSizeOnNoisyBenchmarks) {
  const double amplitude = std::getenv("AMP") ? std::atof(std::getenv("AMP")) : 0.02;
  const std::size_t n_max = 256;
  const int starts = 12;
  const long budget = 300;
  std::vector<double> fixed_all, adaptive_all;  // per run: simulations to solve, inf if never
  // seed 401 in the default suite (36 runs per schedule; ~6 s, kept short for the sanitizer
  // builds); ABUOPT_MEASURE_SEEDS="401 402" (and AMP=0.05, ...) reproduce the tables of docs/sao.md
  std::vector<std::uint64_t> seeds{401};
  if (const char* env = std::getenv("ABUOPT_MEASURE_SEEDS")) {
    seeds.clear();
    for (char* p = const_cast<char*>(env); *p;) {
      char* end = nullptr;
      const unsigned long long v = std::strtoull(p, &end, 10);
      if (end == p) break;
      seeds.push_back(v);
      p = end;
    }
  }
  for (const std::string name : {"hs071", "cantilever", "two_bar_truss"}) {
    for (const std::uint64_t seed : seeds) {
      // the trust region's schedule is what is measured: the global phase (on by default on these
      // stochastic problems) is off in both arms, as when the figures of docs/sao.md were taken
      opt::SaoOptions fixed;  // every evaluation at 256 runs
      fixed.global_phase.mode = opt::GlobalPhaseMode::Never;
      opt::SaoOptions adaptive = fixed;
      adaptive.samples.initial = 16;
      adaptive.samples.max = static_cast<int>(n_max);
      const Tally f = run_starts(name, amplitude, n_max, fixed, starts, seed, budget);
      const Tally a = run_starts(name, amplitude, n_max, adaptive, starts, seed, budget);
      fixed_all.insert(fixed_all.end(), f.to_solve.begin(), f.to_solve.end());
      adaptive_all.insert(adaptive_all.end(), a.to_solve.begin(), a.to_solve.end());
      std::cout << "[measure] sampled " << name << " a=" << amplitude << " seed " << seed << ": fixed 256 solved "
                << f.solved << "/" << starts << " median sims " << median(f.sims) << " gap " << median(f.gaps)
                << " total " << median(f.total) << " (" << f.text << "); adaptive 16..256 solved " << a.solved << "/"
                << starts << " median sims " << median(a.sims) << " gap " << median(a.gaps) << " total "
                << median(a.total) << " (" << a.text << ")\n";
    }
  }
  auto within = [](const std::vector<double>& v, double s) {
    return static_cast<int>(std::count_if(v.begin(), v.end(), [s](double x) { return x <= s; }));
  };
  std::cout << "[measure] solved within S simulations, of " << fixed_all.size() << " runs (fixed 256 / adaptive):";
  for (const double s : {1024.0, 2048.0, 4096.0, 8192.0, 16384.0, 32768.0, 1e300})
    std::cout << " " << (s > 1e299 ? std::string("all") : std::to_string(static_cast<long>(s))) << ": "
              << within(fixed_all, s) << "/" << within(adaptive_all, s);
  std::cout << "\n";
  auto quantile = [](std::vector<double> v, double q) {  // of all runs, unsolved = inf
    std::sort(v.begin(), v.end());
    return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
  };
  std::cout << "[measure] simulations to solve over all runs (inf: not solved), q25 / median / q75: fixed "
            << quantile(fixed_all, 0.25) << " / " << quantile(fixed_all, 0.5) << " / " << quantile(fixed_all, 0.75)
            << "; adaptive " << quantile(adaptive_all, 0.25) << " / " << quantile(adaptive_all, 0.5) << " / "
            << quantile(adaptive_all, 0.75) << "\n";
  for (const double s : {2048.0, 4096.0, 8192.0}) EXPECT_GE(within(adaptive_all, s), within(fixed_all, s)) << s;
  EXPECT_GT(within(adaptive_all, 4096.0), within(fixed_all, 4096.0));
  EXPECT_GE(10 * within(adaptive_all, 1e300), 9 * within(fixed_all, 1e300));
}

}  // namespace
