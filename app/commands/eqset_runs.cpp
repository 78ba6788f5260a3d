// abuopt eqset CONFIG --runs RUNS_CSV: the final states of a Monte Carlo against the equilibrium
// sets (docs/equilibrium_sets.md section 6).
#include "commands/eqset_runs.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/output_file.hpp"
#include "abuopt/common/text.hpp"
#include "abuopt/core/final_states.hpp"

namespace abuopt::app {

namespace {

namespace fs = std::filesystem;

const char* kRunsRule = "must be the runs.csv that `abuopt montecarlo CONFIG --out DIR` writes";

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : line) {
    if (c == ',') {
      out.push_back(cur);
      cur.clear();
    } else if (c != '\r') {
      cur += c;
    }
  }
  out.push_back(cur);
  return out;
}

double field_number(const std::string& text, const std::string& path, long line, const std::string& column) {
  std::size_t used = 0;
  double v = NAN;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !std::isfinite(v))
    throw ConfigError("--runs", path + " line " + std::to_string(line) + " column " + column + " = '" + text + "'",
                      "must be a finite number");
  return v;
}

struct RunsTable {
  std::vector<FinalStateInput> runs;
  std::size_t failed = 0;  // status other than ok
  std::set<double> mu;     // the distinct mu of the runs
};

RunsTable read_runs(const std::string& path, std::size_t n_balls) {
  std::ifstream in(path);
  if (!in) throw ConfigError("--runs", path, "cannot be read (no such file?)");
  std::string line;
  if (!std::getline(in, line)) throw ConfigError("--runs", path, std::string(kRunsRule) + " (the file is empty)");
  const auto header = split_csv_line(line);
  std::map<std::string, std::size_t> col;
  for (std::size_t k = 0; k < header.size(); ++k) col[header[k]] = k;
  std::size_t angles = 0;
  while (col.count("beta_final_" + std::to_string(angles + 1))) ++angles;
  for (const char* need : {"index", "settled", "settling_time_s", "status"})
    if (!col.count(need)) throw ConfigError("--runs", path, std::string(kRunsRule) + " (no column " + need + ")");
  if (angles != n_balls)
    throw ConfigError("--runs", path,
                      "has " + std::to_string(angles) + " beta_final columns, the config " + std::to_string(n_balls) +
                          " balls: give the config the Monte Carlo ran");
  RunsTable t;
  long line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line == "\r") continue;
    const auto f = split_csv_line(line);
    if (f.size() != header.size())
      throw ConfigError("--runs", path + " line " + std::to_string(line_no),
                        "must have " + std::to_string(header.size()) + " fields like the header");
    if (f[col["status"]] != "ok") {
      ++t.failed;
      continue;
    }
    FinalStateInput r;
    r.index = static_cast<long>(field_number(f[col["index"]], path, line_no, "index"));
    for (std::size_t k = 1; k <= angles; ++k) {
      const std::string c = "beta_final_" + std::to_string(k);
      r.beta_final.push_back(field_number(f[col[c]], path, line_no, c));
    }
    r.settled = field_number(f[col["settled"]], path, line_no, "settled") != 0;
    r.settling_time_s = field_number(f[col["settling_time_s"]], path, line_no, "settling_time_s");
    auto optional_column = [&](const char* name) -> std::optional<double> {
      if (!col.count(name) || f[col[name]].empty()) return std::nullopt;
      return field_number(f[col[name]], path, line_no, name);
    };
    r.friction_mu = optional_column("mu");
    r.imbalance_mass_kg = optional_column("imbalance_mass_kg");
    r.stiffness_N_per_m = optional_column("stiffness_N_per_m");
    if (r.friction_mu) t.mu.insert(*r.friction_mu);
    t.runs.push_back(std::move(r));
  }
  return t;
}

std::string fixed(double v, int d) { return format_fixed(v, d); }

std::string interval_text(const Interval& i, int d) { return "[" + fixed(i.lo, d) + ", " + fixed(i.hi, d) + "]"; }

nlohmann::json num_json(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json interval_json(const Interval& i) { return nlohmann::json::array({num_json(i.lo), num_json(i.hi)}); }

nlohmann::json group_json(const FinalStateGroup& g) {
  return {{"count", g.count},
          {"share", num_json(g.share)},
          {"share_ci95", interval_json(g.share_ci)},
          {"depth_mean", num_json(g.depth_mean)},
          {"depth_mean_ci95", interval_json(g.depth_mean_ci)},
          {"depth_median", num_json(g.depth_median)},
          {"depth_median_ci95", interval_json(g.depth_median_ci)},
          {"lock_gauge_mean", num_json(g.lock_gauge_mean)},
          {"gauge_settle_mean", num_json(g.gauge_settle_mean)},
          {"settle_hz", {{"p10", num_json(g.settle_hz_p10)}, {"median", num_json(g.settle_hz_median)},
                         {"p90", num_json(g.settle_hz_p90)}}},
          {"locked_share", num_json(g.locked_share)},
          {"held_by_cluster_share", num_json(g.held_share)}};
}

void print_group(const char* name, const FinalStateGroup& g) {
  std::cout << "  " << std::left << std::setw(6) << name << std::right << std::setw(5) << g.count << " runs  "
            << fixed(100 * g.share, 1) << " % " << interval_text({100 * g.share_ci.lo, 100 * g.share_ci.hi}, 1) << "\n";
  if (g.count == 0) return;
  std::cout << "         depth |U|/r_lock: mean " << fixed(g.depth_mean, 3) << " " << interval_text(g.depth_mean_ci, 3)
            << ", median " << fixed(g.depth_median, 3) << " " << interval_text(g.depth_median_ci, 3) << "\n"
            << "         settling speed [Hz]: p10 " << fixed(g.settle_hz_p10, 2) << ", median "
            << fixed(g.settle_hz_median, 2) << ", p90 " << fixed(g.settle_hz_p90, 2) << "; gauge there: mean "
            << fixed(g.gauge_settle_mean, 3) << "\n"
            << "         lock gauge: mean " << fixed(g.lock_gauge_mean, 3) << ", locked (<= 1) "
            << fixed(100 * g.locked_share, 1) << " %; held up by a cluster " << fixed(100 * g.held_share, 1) << " %\n";
}

}  // namespace

int run_eqset_runs(const SimulationSetup& setup, const EqsetRunsArgs& a) {
  EarlySplit split = EarlySplit::speed;
  if (a.split == "passage")
    split = EarlySplit::passage;
  else if (a.split != "speed")
    throw ConfigError("--split", a.split, "must be speed or passage");
  if (a.edge_hz && !(std::isfinite(*a.edge_hz) && *a.edge_hz > 0 && *a.edge_hz <= kMaxFrequencyHz))
    throw ConfigError("--edge", format_number(*a.edge_hz), "must be a speed in (0, 1e4] Hz");
  const RunsTable t = read_runs(a.runs_csv, setup.abu.balls.size());
  AbuParameters nominal = setup.abu;
  if (t.mu.size() == 1) nominal.friction_mu = *t.mu.begin();  // `montecarlo --mu` ran them all at that mu
  const FinalStateAnalysis r = analyse_final_states(nominal, setup.profile, t.runs, split, a.edge_hz);

  std::string csv_path;
  if (!a.out.empty()) {
    std::error_code ec;
    fs::create_directories(a.out, ec);
    if (ec || !fs::is_directory(a.out))
      throw OutputError("cannot create the output directory " + a.out + " (--out: " +
                        (ec ? ec.message() : std::string("not a directory")) + ")");
    csv_path = (fs::path(a.out) / "final_states.csv").string();
    AtomicFile f(csv_path);
    f << "index,group,settling_time_s,settle_hz,r_lock_kgm,depth,gauge_settle,lock_gauge,cluster_floor_depth,"
         "largest_cluster\n";
    for (const auto& x : r.records)
      f << x.index << "," << (x.early ? "early" : "late") << "," << csv_number(x.settling_time_s) << ","
        << csv_number(x.settle_hz) << "," << csv_number(x.r_lock_kgm) << "," << csv_number(x.depth) << ","
        << csv_number(x.gauge_settle) << "," << csv_number(x.lock_gauge) << "," << csv_number(x.floor_depth) << ","
        << x.largest_cluster << "\n";
    f.commit();
  }
  const auto band = lock_band_hz(nominal);
  if (a.json) {
    nlohmann::json j;
    j["runs_csv"] = a.runs_csv;
    j["runs_ok"] = t.runs.size();
    j["runs_failed"] = t.failed;
    j["settled"] = r.settled;
    j["not_settled"] = r.not_settled;
    j["mu"] = t.mu.size() == 1 ? nlohmann::json(*t.mu.begin()) : nlohmann::json(nullptr);
    j["r_lock_kgm"] = r.r_lock_kgm;
    j["lock_band_hz"] = {band.first, band.second};
    j["split"] = a.split;
    j["edge_hz"] = r.edge_hz;
    j["edge_time_s"] = r.edge_time_s ? nlohmann::json(*r.edge_time_s) : nlohmann::json(nullptr);
    j["depth_mean"] = num_json(r.depth_mean);
    j["depth_mean_ci95"] = interval_json(r.depth_mean_ci);
    j["early"] = group_json(r.early);
    j["late"] = group_json(r.late);
    j["csv"] = csv_path.empty() ? nlohmann::json(nullptr) : nlohmann::json(csv_path);
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << r.settled << " settled runs of " << a.runs_csv << " (" << r.not_settled << " still moving at the end, "
              << t.failed << " failed: left out); ";
    if (t.mu.size() == 1)
      std::cout << "mu " << format_number(*t.mu.begin()) << ", r_lock " << fixed(r.r_lock_kgm / 1e-7, 2) << "e-7 kg m\n";
    else
      std::cout << t.mu.size() << " values of mu: each run's depth in its own r_lock\n";
    std::cout << "  mean depth |U|/r_lock " << fixed(r.depth_mean, 3) << " " << interval_text(r.depth_mean_ci, 3)
              << "; lock gauge over " << fixed(band.first, 2) << " .. " << fixed(band.second, 2) << " Hz\n";
    if (split == EarlySplit::speed)
      std::cout << "  early: settled below resonance where r_in > 2 r_lock (below " << fixed(r.edge_hz, 2)
                << " Hz); late: the rest\n";
    else
      std::cout << "  early: settled before the profile first reached " << fixed(r.edge_hz, 2) << " Hz"
                << (r.edge_time_s ? " (t = " + fixed(*r.edge_time_s, 3) + " s)" : std::string(" (it never does)"))
                << "; late: the rest\n";
    print_group("early", r.early);
    print_group("late", r.late);
    if (!csv_path.empty()) std::cout << "csv: " << csv_path << "\n";
  }
  return r.settled ? 0 : 3;
}

int run_eqset_lock_set(const AbuParameters& abu, const std::vector<double>& other_beta, std::size_t grid,
                       double alpha_rad_s2, bool json) {
  const LockSetStatistics st = lock_set_statistics(abu, grid, other_beta, alpha_rad_s2);
  const double rl = lock_radius_kgm(abu);
  const auto band = lock_band_hz(abu);
  if (json) {
    nlohmann::json j;
    j["mu"] = abu.friction_mu;
    j["r_lock_kgm"] = rl;
    j["lock_band_hz"] = {band.first, band.second};
    j["grid"] = grid;
    j["share"] = st.share;
    j["depth_mean"] = num_json(st.depth_mean);
    j["lock_gauge_mean"] = num_json(st.lock_gauge_mean);
    j["floor"] = num_json(st.share * st.depth_mean);
    j["alpha_rad_s2"] = alpha_rad_s2;
    j["reach"] = st.reach;
    j["unreached_share"] = st.unreached_share;
    j["unreached_depth_mean"] = num_json(st.unreached_depth_mean);
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::cout << "mu " << format_number(abu.friction_mu) << ": r_lock " << fixed(rl / 1e-7, 2)
            << "e-7 kg m; lock set = in the set of every speed of " << fixed(band.first, 2) << " .. "
            << fixed(band.second, 2) << " Hz\n"
            << "  uniform starts (" << grid << " x " << grid << " grid over beta_1, beta_2) in the lock set: "
            << fixed(100 * st.share, 1) << " %, mean depth |U|/r_lock " << fixed(st.depth_mean, 3)
            << ", mean lock gauge " << fixed(st.lock_gauge_mean, 3) << "; share x depth " << fixed(st.share * st.depth_mean, 3)
            << " r_lock\n";
  if (alpha_rad_s2 > 0)
    std::cout << "  a ramp at " << format_number(alpha_rad_s2) << " rad/s^2 uses " << fixed(st.reach, 3)
              << " of the friction at resonance; locked starts with lock gauge <= " << fixed(1 - st.reach, 3) << ": "
              << fixed(100 * st.unreached_share, 1) << " %, mean depth " << fixed(st.unreached_depth_mean, 3)
              << "; share x depth " << fixed(st.unreached_share * st.unreached_depth_mean, 3) << " r_lock\n";
  return 0;
}

}  // namespace abuopt::app
