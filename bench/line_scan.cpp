// Line scan of the startup-profile statistics (issue 9, docs/sao.md "Smooth statistics"): the
// designs x(t) = a + t (b - a), t = 0 .. 1 in `points` steps, each evaluated by the config's Monte
// Carlo (the same initial conditions for every design: common random numbers), and for each the
// exact statistics (%MI count, mean |I_r|) and the smooth ones (smoothed exceedance, |I_r| quantile
// and CVaR at 0.9). Not a Google Benchmark: it writes a CSV and prints, per statistic, how rough it
// is along the line:
//   jumps: steps |d_i| > 4 median |d| (d_i = s(t_{i+1}) - s(t_i); with median 0, as for the count,
//          every step that moves at all);
//   noise: RMS of the second differences s_{i+1} - 2 s_i + s_{i-1}, relative to the range of s
//          (a smooth curve sampled at 200 points has ~1e-4; white noise ~1).
// Usage: line_scan CONFIG A B [points=200] [out.csv]   (A, B: comma-separated design vectors)
// scripts/line_scan.sh runs it on configs/optimize/cobyla.yaml and plots the result.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "abuopt/common/config_error.hpp"
#include "abuopt/core/batch_runner.hpp"
#include "abuopt/core/monte_carlo_stats.hpp"
#include "abuopt/problems/startup_profile_problem.hpp"

using namespace abuopt;

namespace {

std::vector<double> parse_vector(const std::string& text) {
  std::vector<double> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) v.push_back(std::stod(item));
  return v;
}

struct Roughness {
  int jumps = 0;
  double noise = 0;
};

Roughness roughness(const std::vector<double>& s) {
  Roughness r;
  if (s.size() < 3) return r;
  std::vector<double> d;
  for (std::size_t i = 0; i + 1 < s.size(); ++i) d.push_back(std::fabs(s[i + 1] - s[i]));
  std::vector<double> sorted = d;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
  const double median = sorted[sorted.size() / 2];
  for (double x : d) r.jumps += x > 4 * median ? 1 : 0;
  const auto [lo, hi] = std::minmax_element(s.begin(), s.end());
  double ss = 0;
  for (std::size_t i = 1; i + 1 < s.size(); ++i) ss += std::pow(s[i + 1] - 2 * s[i] + s[i - 1], 2);
  const double range = *hi - *lo;
  r.noise = range > 0 ? std::sqrt(ss / static_cast<double>(s.size() - 2)) / range : 0.0;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::cerr << "usage: line_scan CONFIG A B [points=200] [out.csv]\n";
    return 2;
  }
  try {
    YamlReader root = YamlReader::load_file(argv[1]);
    const problems::StartupProfileSettings settings = problems::read_startup_profile_settings(root);
    const problems::StartupProfileProblem problem(settings);
    const std::vector<double> a = parse_vector(argv[2]), b = parse_vector(argv[3]);
    const int points = argc > 4 ? std::atoi(argv[4]) : 200;
    const std::string out = argc > 5 ? argv[5] : "line_scan.csv";
    if (a.size() != problem.variables().size() || b.size() != a.size() || points < 3) {
      std::cerr << "line_scan: A and B need " << problem.variables().size() << " values each, points >= 3\n";
      return 2;
    }
    std::ofstream csv(out);
    csv << "t,pct_mi,pct_mi_smooth,ir_mean,ir_q90,ir_cvar90,bandwidth\n";
    std::vector<std::vector<double>> columns(5);
    ThreadPoolRunner runner(settings.threads);
    const double unit = 1e-7;
    for (int i = 0; i < points; ++i) {
      const double t = static_cast<double>(i) / (points - 1);
      std::vector<double> x(a.size());
      for (std::size_t k = 0; k < a.size(); ++k) x[k] = a[k] + t * (b[k] - a[k]);
      MonteCarloStudy study = settings.study;
      study.setup.profile = problem.profile_at(x);
      const MonteCarloResult r = run_monte_carlo(study, runner);
      const MonteCarloStats st = compute_statistics(r);
      const SmoothImbalanceStats sm = compute_smooth_statistics(r.samples, false, 0.9);
      const double row[5] = {st.magnitude.pct_mi, sm.pct_mi, st.magnitude.mean / unit, sm.quantile / unit,
                             sm.cvar / unit};
      csv << t;
      for (int c = 0; c < 5; ++c) {
        csv << "," << row[c];
        columns[c].push_back(row[c]);
      }
      csv << "," << sm.bandwidth << "\n";
    }
    csv.close();
    if (!csv) {
      std::cerr << "line_scan: could not write " << out << "\n";
      return 4;
    }
    const char* names[5] = {"%MI (count)", "%MI smoothed", "mean |I_r|", "|I_r| q0.9", "|I_r| CVaR0.9"};
    std::printf("%-16s %6s %10s\n", "statistic", "jumps", "noise");
    for (int c = 0; c < 5; ++c) {
      const Roughness r = roughness(columns[c]);
      std::printf("%-16s %6d %10.3g\n", names[c], r.jumps, r.noise);
    }
    std::printf("(%d designs, %zu runs each; written to %s)\n", points, settings.study.runs, out.c_str());
  } catch (const ConfigError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
  return 0;
}
