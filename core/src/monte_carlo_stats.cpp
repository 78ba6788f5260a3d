#include "abuopt/core/monte_carlo_stats.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <ostream>
#include <sstream>
#include <stdexcept>

namespace abuopt {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double mean_of(const std::vector<double>& v) {
  if (v.empty()) return kNaN;
  double s = 0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

ResidualImbalanceStats imbalance_stats(std::vector<double> values, const std::vector<double>& thresholds,
                                       std::size_t distinct) {
  ResidualImbalanceStats r;
  r.count = values.size();
  r.distinct = distinct;
  for (std::size_t i = 0; i < values.size(); ++i)
    if (values[i] >= thresholds[i]) ++r.mi_count;
  // Runs that reuse another's simulation (exchangeable balls) carry no new information: the
  // interval is that of the proportion over the distinct runs.
  const auto ci = distinct == r.count || r.count == 0
                      ? wilson_interval(r.mi_count, r.count)
                      : wilson_interval_p(static_cast<double>(r.mi_count) / static_cast<double>(r.count),
                                          static_cast<double>(distinct));
  r.pct_mi_ci95 = {100.0 * ci.first, 100.0 * ci.second};
  if (values.empty()) {
    r.mean = r.min = r.max = r.median = r.p10 = r.p90 = r.p95 = r.pct_mi = kNaN;
    return r;
  }
  r.mean = mean_of(values);  // summed in index order: independent of thread count
  r.pct_mi = 100.0 * static_cast<double>(r.mi_count) / static_cast<double>(r.count);
  std::sort(values.begin(), values.end());
  r.min = values.front();
  r.max = values.back();
  r.median = quantile_type7(values, 0.5);
  r.p10 = quantile_type7(values, 0.10);
  r.p90 = quantile_type7(values, 0.90);
  r.p95 = quantile_type7(values, 0.95);
  return r;
}

std::string num(double v) {
  if (std::isnan(v)) return "nan";
  char buf[64];
  auto res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

std::string fixed(double v, int digits) {
  if (std::isnan(v)) return "n/a";
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(digits);
  os << v;
  return os.str();
}

nlohmann::json json_number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json imbalance_json(const ResidualImbalanceStats& r) {
  return {{"count", r.count},
          {"mean", json_number(r.mean)},
          {"min", json_number(r.min)},
          {"max", json_number(r.max)},
          {"median", json_number(r.median)},
          {"p10", json_number(r.p10)},
          {"p90", json_number(r.p90)},
          {"p95", json_number(r.p95)},
          {"mi_count", r.mi_count},
          {"pct_mi", json_number(r.pct_mi)},
          {"pct_mi_ci95", nlohmann::json::array({json_number(r.pct_mi_ci95[0]), json_number(r.pct_mi_ci95[1])})}};
}

std::string imbalance_lines(const char* name, const ResidualImbalanceStats& r) {
  auto e7 = [](double v) { return fixed(v * 1e7, 2); };
  std::ostringstream os;
  os << "  " << name << "\n"
     << "    mean " << e7(r.mean) << "  median " << e7(r.median) << "  max " << e7(r.max) << "  p10 " << e7(r.p10)
     << "  p90 " << e7(r.p90) << "  p95 " << e7(r.p95) << "  [1e-7 kg m]\n"
     << "    %MI " << fixed(r.pct_mi, 2) << " %  (" << r.mi_count << " of " << r.count << ", 95 % CI "
     << fixed(r.pct_mi_ci95[0], 2) << " .. " << fixed(r.pct_mi_ci95[1], 2) << " %)\n";
  return os.str();
}

}  // namespace

double quantile_type7(const std::vector<double>& sorted, double p) {
  if (sorted.empty()) return kNaN;
  const double h = (static_cast<double>(sorted.size()) - 1.0) * std::clamp(p, 0.0, 1.0);
  const std::size_t lo = static_cast<std::size_t>(std::floor(h));
  if (lo + 1 >= sorted.size()) return sorted.back();
  return sorted[lo] + (h - static_cast<double>(lo)) * (sorted[lo + 1] - sorted[lo]);
}

std::pair<double, double> wilson_interval(std::size_t k, std::size_t n, double z) {
  if (n == 0) return {kNaN, kNaN};
  return wilson_interval_p(static_cast<double>(k) / static_cast<double>(n), static_cast<double>(n), z);
}

std::pair<double, double> wilson_interval_p(double p, double nn, double z) {
  if (!(nn > 0)) return {kNaN, kNaN};
  const double z2 = z * z;
  const double denom = 1.0 + z2 / nn;
  const double centre = (p + z2 / (2.0 * nn)) / denom;
  const double half = z / denom * std::sqrt(p * (1.0 - p) / nn + z2 / (4.0 * nn * nn));
  return {std::max(0.0, centre - half), std::min(1.0, centre + half)};
}

std::string status_key(RunStatus s) { return to_string(s); }  // outcome.hpp's names

MonteCarloStats compute_statistics(const std::vector<MonteCarloSample>& samples) {
  MonteCarloStats st;
  st.runs = samples.size();
  std::vector<double> mag, rx, thresholds, settling, amplitude;
  std::size_t distinct = 0;  // ok runs simulated for themselves
  for (const auto& s : samples) {
    const auto k = static_cast<std::size_t>(s.outcome.status);
    if (k < kRunStatusCount) ++st.status_counts[k];
    if (!s.outcome.ok()) {
      ++st.failed;
      continue;
    }
    ++st.ok;
    distinct += !s.reused;
    mag.push_back(s.outcome.residual_imbalance_kgm);
    rx.push_back(s.outcome.residual_imbalance_x_kgm);
    thresholds.push_back(s.imbalance_kgm);
    amplitude.push_back(s.outcome.max_amplitude_mm);
    if (s.outcome.settled)
      settling.push_back(s.outcome.settling_time_s);
    else
      ++st.not_settled;
  }
  st.distinct = distinct;
  st.magnitude = imbalance_stats(mag, thresholds, distinct);
  st.report_x = imbalance_stats(rx, thresholds, distinct);
  st.pct_lc = st.ok ? 100.0 * static_cast<double>(st.not_settled) / static_cast<double>(st.ok) : kNaN;
  st.settled = settling.size();
  st.settling_mean_s = mean_of(settling);
  std::vector<double> sorted = settling;
  std::sort(sorted.begin(), sorted.end());
  st.settling_median_s = quantile_type7(sorted, 0.5);
  st.settling_max_s = sorted.empty() ? kNaN : sorted.back();
  st.amplitude_mean_mm = mean_of(amplitude);
  st.amplitude_max_mm = amplitude.empty() ? kNaN : *std::max_element(amplitude.begin(), amplitude.end());
  return st;
}

double smoothing_bandwidth(const std::vector<double>& values) {
  const std::size_t n = values.size();
  if (n < 2) return 0.0;
  const double m = mean_of(values);
  double ss = 0;
  for (double v : values) ss += (v - m) * (v - m);
  const double sd = std::sqrt(ss / static_cast<double>(n - 1));
  return 0.9 * sd * std::pow(static_cast<double>(n), -0.2);
}

SmoothImbalanceStats compute_smooth_statistics(const std::vector<MonteCarloSample>& samples, bool report_x,
                                               double level) {
  if (!(level >= 0 && level < 1))
    throw std::invalid_argument("compute_smooth_statistics: level " + num(level) + " must be in [0, 1)");
  SmoothImbalanceStats st;
  st.level = level;
  std::vector<double> values, ratios;
  for (const auto& s : samples) {
    if (!s.outcome.ok()) continue;
    const double v = report_x ? s.outcome.residual_imbalance_x_kgm : s.outcome.residual_imbalance_kgm;
    values.push_back(v);
    ratios.push_back(v / s.imbalance_kgm);
  }
  st.count = values.size();
  if (values.empty()) {
    st.bandwidth = st.pct_mi = st.quantile = st.cvar = kNaN;
    return st;
  }
  const double n = static_cast<double>(values.size());
  st.bandwidth = smoothing_bandwidth(ratios);
  double p = 0;
  for (double r : ratios)
    p += st.bandwidth > 0 ? 0.5 * std::erfc(-(r - 1.0) / (st.bandwidth * std::sqrt(2.0))) : (r >= 1.0 ? 1.0 : 0.0);
  st.pct_mi = 100.0 * p / n;
  std::vector<double> sorted = values;
  std::sort(sorted.begin(), sorted.end());
  st.quantile = quantile_type7(sorted, level);
  double tail = 0;
  for (double v : values) tail += std::max(0.0, v - st.quantile);
  st.cvar = st.quantile + tail / (n * (1.0 - level));
  return st;
}

MonteCarloStats compute_statistics(const MonteCarloResult& result) {
  MonteCarloStats st = compute_statistics(result.samples);
  st.wall_time_s = result.wall_time_s;
  st.concurrency = result.concurrency;
  return st;
}

nlohmann::json to_json(const MonteCarloStats& s) {
  nlohmann::json counts = nlohmann::json::object();
  for (std::size_t k = 0; k < kRunStatusCount; ++k) counts[status_key(static_cast<RunStatus>(k))] = s.status_counts[k];
  return {{"runs", s.runs},
          {"ok", s.ok},
          {"distinct_simulations", s.distinct},
          {"failed", s.failed},
          {"status_counts", counts},
          {"pct_lc", json_number(s.pct_lc)},
          {"not_settled", s.not_settled},
          {"wall_time_s", s.wall_time_s},
          {"concurrency", s.concurrency},
          {"magnitude", imbalance_json(s.magnitude)},
          {"report_x", imbalance_json(s.report_x)},
          {"settling_time_s",
           {{"settled", s.settled},
            {"mean", json_number(s.settling_mean_s)},
            {"median", json_number(s.settling_median_s)},
            {"max", json_number(s.settling_max_s)}}},
          {"max_amplitude_mm", {{"max", json_number(s.amplitude_max_mm)}, {"mean", json_number(s.amplitude_mean_mm)}}},
          {"quantile_definition", "linear interpolation between order statistics (Hyndman-Fan type 7)"}};
}

std::string format_summary(const MonteCarloStats& s) {
  std::ostringstream os;
  os << "runs " << s.runs << ": ok " << s.ok << ", failed " << s.failed;
  if (s.distinct != s.ok)
    os << " (" << s.distinct << " distinct: the others are the same starts with the identical balls exchanged)";
  if (s.failed) {
    os << " (";
    bool first = true;
    for (std::size_t k = 1; k < kRunStatusCount; ++k)
      if (s.status_counts[k]) {
        os << (first ? "" : ", ") << status_key(static_cast<RunStatus>(k)) << " " << s.status_counts[k];
        first = false;
      }
    os << "; excluded from the statistics below)";
  }
  os << "\n";
  os << "residual imbalance over " << s.ok << " ok runs:\n";
  os << imbalance_lines("|I_r| (magnitude)", s.magnitude);
  os << imbalance_lines("I_r,x (report eq 4.2)", s.report_x);
  os << "%LC " << fixed(s.pct_lc, 2) << " %  (" << s.not_settled << " runs not settled at the end time)\n";
  os << "settling time over " << s.settled << " settled runs: mean " << fixed(s.settling_mean_s, 3) << " s, median "
     << fixed(s.settling_median_s, 3) << " s, max " << fixed(s.settling_max_s, 3) << " s\n";
  os << "peak amplitude: max " << fixed(s.amplitude_max_mm, 4) << " mm, mean " << fixed(s.amplitude_mean_mm, 4)
     << " mm\n";
  if (s.wall_time_s > 0) {
    os << "wall time " << fixed(s.wall_time_s, 2) << " s on " << s.concurrency << " thread"
       << (s.concurrency == 1 ? "" : "s") << " (" << fixed(static_cast<double>(s.runs) / s.wall_time_s, 1)
       << " runs/s)\n";
  }
  return os.str();
}

IntervalLayout interval_layout(const MonteCarloStudy& s) {
  if (joint_sampling(s)) return {IntervalKind::Replicates, Envelope::kReplicates};
  const std::size_t h = s.uncertain.envelope.deterministic() ? 1 : s.uncertain.envelope.strata();
  if (h > 1) return {IntervalKind::Strata, h};
  return {};
}

double mean_half_width95(const std::vector<MonteCarloSample>& samples, const IntervalLayout& layout, bool report_x) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::size_t g = layout.kind == IntervalKind::Independent ? 1 : std::max<std::size_t>(layout.groups, 1);
  // per group: count, mean and sum of squares (Welford)
  std::vector<double> n(g, 0.0), mean(g, 0.0), m2(g, 0.0);
  for (const auto& s : samples) {
    if (!s.outcome.ok()) continue;
    const double x = report_x ? s.outcome.residual_imbalance_x_kgm : s.outcome.residual_imbalance_kgm;
    const std::size_t k = s.index % g;
    n[k] += 1;
    const double d = x - mean[k];
    mean[k] += d / n[k];
    m2[k] += d * (x - mean[k]);
  }
  if (layout.kind != IntervalKind::Replicates) {
    double var = 0;  // of the (stratified) mean, equal weights 1/g
    for (std::size_t k = 0; k < g; ++k) {
      if (n[k] < 2) return nan;
      var += m2[k] / (n[k] - 1) / n[k] / static_cast<double>(g * g);
    }
    return 1.96 * std::sqrt(var);
  }
  std::vector<double> means;
  for (std::size_t k = 0; k < g; ++k)
    if (n[k] > 0) means.push_back(mean[k]);
  if (means.size() < 2) return nan;
  double m = 0, var = 0;
  for (double x : means) m += x;
  m /= static_cast<double>(means.size());
  for (double x : means) var += (x - m) * (x - m);
  var /= static_cast<double>(means.size() - 1);
  // t quantile 0.975 with nu degrees of freedom (Cornish-Fisher; 2.131 for nu = 15, within 1e-3)
  const double nu = static_cast<double>(means.size() - 1), z = 1.959964;
  const double t = z + (z * z * z + z) / (4 * nu) + (5 * std::pow(z, 5) + 16 * z * z * z + 3 * z) / (96 * nu * nu);
  return t * std::sqrt(var / static_cast<double>(means.size()));
}

void write_runs_csv(std::ostream& os, const std::vector<MonteCarloSample>& samples) {
  std::size_t n = 0;
  for (const auto& s : samples) n = std::max({n, s.beta0.size(), s.outcome.beta_final.size()});
  os << "index";
  for (std::size_t j = 1; j <= n; ++j) os << ",beta0_" << j;
  os << ",mu,imbalance_mass_kg,imbalance_angle_rad,stiffness_N_per_m,restitution";
  for (std::size_t j = 1; j <= n; ++j) os << ",beta_final_" << j;
  os << ",ir_magnitude_kgm,ir_x_kgm,settled,settling_time_s,max_amplitude_mm,events,rhs_evaluations,status\n";
  for (const auto& s : samples) {
    const RunOutcome& o = s.outcome;
    os << s.index;
    for (std::size_t j = 0; j < n; ++j) os << ',' << (j < s.beta0.size() ? num(s.beta0[j]) : "");
    os << ',' << num(s.friction_mu) << ','
       << (s.overrides.imbalance_mass_kg ? num(*s.overrides.imbalance_mass_kg) : std::string()) << ','
       << num(s.overrides.imbalance_angle_rad) << ',' << num(s.stiffness_N_per_m) << ',' << num(s.restitution);
    for (std::size_t j = 0; j < n; ++j) os << ',' << (j < o.beta_final.size() ? num(o.beta_final[j]) : "");
    os << ',' << num(o.residual_imbalance_kgm) << ',' << num(o.residual_imbalance_x_kgm) << ','
       << (o.settled ? 1 : 0) << ',' << num(o.settling_time_s) << ',' << num(o.max_amplitude_mm) << ',' << o.events
       << ',' << o.rhs_evaluations << ',' << status_key(o.status) << '\n';
  }
}

}  // namespace abuopt

namespace abuopt {

nlohmann::json to_json(const MonteCarloStats& s, const MonteCarloResult& result, const MonteCarloStudy& study) {
  nlohmann::json j = to_json(s);
  const IntervalLayout layout = interval_layout(study);
  j["magnitude"]["mean_ci95_half_width"] = mean_half_width95(result.samples, layout);
  j["report_x"]["mean_ci95_half_width"] = mean_half_width95(result.samples, layout, true);
  return j;
}

}  // namespace abuopt
