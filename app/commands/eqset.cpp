// abuopt eqset CONFIG --freq HZ | --scan FROM:TO:STEP: the equilibrium set at constant speed
// (report fig 4.3): where all balls can stay stuck, the steady amplitude there, and the band of
// speeds around resonance where the set does not cover the whole (beta_1, beta_2) plane.
// Derivation and usage: docs/equilibrium_sets.md.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "abuopt/common/config_sections.hpp"
#include "abuopt/common/config_error.hpp"
#include "abuopt/common/number_text.hpp"
#include "abuopt/common/output_file.hpp"
#include "abuopt/common/config_fields.hpp"
#include "abuopt/common/gnuplot.hpp"
#include "abuopt/common/plot_style.hpp"
#include "abuopt/common/text.hpp"
#include "abuopt/core/equilibrium_residual.hpp"
#include "abuopt/core/equilibrium_set.hpp"
#include "abuopt/core/simulation_config.hpp"
#include "commands/commands.hpp"
#include "commands/eqset_runs.hpp"

namespace abuopt::app {

namespace {

namespace fs = std::filesystem;

constexpr long kMaxGrid = 4096;
constexpr double kMaxFrequencyHz = kMaxEquilibriumFrequencyHz;
constexpr std::size_t kMaxScanPoints = 100000;

struct EqsetArgs {
  std::string config;
  std::optional<double> freq, mu;
  std::optional<std::string> scan;
  std::optional<long> grid;
  std::string out;
  bool json = false;
  EqsetRunsArgs runs;  // --runs RUNS_CSV (commands/eqset_runs.hpp)
  bool lock_set = false;
  std::optional<double> alpha;
};

// The optional `eqset` section of the config; command-line options override it.
struct EqsetConfig {
  std::optional<double> frequency_hz;
  std::optional<std::vector<double>> scan_hz;  // from, to, step
  std::optional<long> grid;
  std::vector<double> other_angles_rad;        // balls 3..N
};

struct Scan {
  double from = 0, to = 0, step = 0;
};

std::string num_text(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

void check_scan(const Scan& s, const std::string& option, const std::string& text) {
  const std::string rule = "must be FROM:TO:STEP in Hz with 0 < FROM <= TO and STEP > 0";
  if (!(std::isfinite(s.from) && std::isfinite(s.to) && std::isfinite(s.step)) || !(s.from > 0) ||
      !(s.to >= s.from) || !(s.step > 0))
    throw ConfigError(option, text, rule);
  if (s.to > kMaxFrequencyHz)  // the cap of --freq holds for every frequency of the scan
    throw ConfigError(option, text, "must stay within (0, 1e6] Hz (above it the steady amplitude overflows double "
                                    "precision), as --freq");
  if ((s.to - s.from) / s.step + 1 > static_cast<double>(kMaxScanPoints))
    throw ConfigError(option, text, "must give at most " + std::to_string(kMaxScanPoints) + " frequencies");
}

Scan parse_scan(const std::string& text) {
  const std::string rule = "must be FROM:TO:STEP in Hz with 0 < FROM <= TO and STEP > 0";
  const std::vector<double> v = parse_number_list(text, ':', "--scan", rule);
  if (v.size() != 3) throw ConfigError("--scan", text, rule);
  Scan s{v[0], v[1], v[2]};
  check_scan(s, "--scan", text);
  return s;
}

// The eqset section's field list (common/config_fields.hpp).
void describe_fields(FieldArchive& a, EqsetConfig& c) {
  a.field("frequency_hz", c.frequency_hz, Rule::positive());
  a.field("grid", c.grid, Rule::in_range(2, kMaxGrid));
  a.field("scan_hz", c.scan_hz);
  if (a.reading() && c.scan_hz) {
    const auto& v = *c.scan_hz;
    std::ostringstream text;
    text << "[";
    for (std::size_t k = 0; k < v.size(); ++k) text << (k ? ", " : "") << v[k];
    text << "]";
    if (v.size() != 3) throw ConfigError(a.path("scan_hz"), text.str(), "must be [from, to, step] in Hz");
    check_scan(Scan{v[0], v[1], v[2]}, a.path("scan_hz"), text.str());
  }
  a.field("other_angles_rad", c.other_angles_rad);
}

EqsetConfig read_eqset_section(YamlReader r) {
  EqsetConfig c;
  read_fields(r, c);
  return c;
}

nlohmann::json band_json(const std::optional<std::pair<double, double>>& b) {
  if (!b) return nullptr;
  return nlohmann::json::array({b->first, b->second});
}

fs::path make_out_dir(const std::string& dir, const std::string& option) {
  // an output that cannot be made is a write failure (exit 4), as for every other command
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw OutputError("cannot create the output directory " + dir + " (" + option + ": " +
                      (ec ? ec.message() : std::string("not a directory")) + ")");
  return fs::path(dir);
}

int run_single(const EqsetArgs& a, const EquilibriumSet& set, const EqsetConfig& cfg, double freq, std::size_t n) {
  const EquilibriumGrid g = set.grid(freq, n, cfg.other_angles_rad);
  const std::size_t nb = g.n_balls;
  // An amplitude that is not finite is no result (an undamped table exactly at resonance): say so
  // instead of printing NaN or inf, before any file is written.
  for (double amp : g.amplitude_mm)
    if (!std::isfinite(amp)) {
      std::cerr << "abuopt: error: the steady amplitude is not finite at " << num_text(freq)
                << " Hz (an undamped table at its resonance, abu.damping_Ns_per_m = 0?): no equilibrium set to draw\n";
      return 3;
    }
  const fs::path dir = make_out_dir(a.out.empty() ? "results/eqset-" + num_text(freq) + "Hz" : a.out, "--out");
  const fs::path csv = dir / "equilibrium_set.csv";
  {
    AtomicFile f(csv);
    f << "beta1_rad,beta2_rad,amplitude_mm,in_set";
    for (std::size_t b = 0; b < nb; ++b) f << ",margin_" << b + 1;
    f << "\n";
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = 0; j < n; ++j) {
        const std::size_t k = g.index(i, j);
        // With hard contact in_set is -1 where the balls overlap (excluded: not a configuration).
        const int in = !g.excluded.empty() && g.excluded[k] ? -1 : int(g.in_set[k]);
        f << csv_number(g.beta(i)) << "," << csv_number(g.beta(j)) << "," << csv_number(g.amplitude_mm[k]) << "," << in;
        for (std::size_t b = 0; b < nb; ++b) f << "," << csv_number(g.margins[k * nb + b]);
        f << "\n";
      }
    f.commit();
  }
  double in_min = INFINITY, in_max = -INFINITY;
  for (std::size_t k = 0; k < n * n; ++k)
    if (g.in_set[k]) {
      in_min = std::min(in_min, g.amplitude_mm[k]);
      in_max = std::max(in_max, g.amplitude_mm[k]);
    }

  // Hard contact, two balls: the touching configurations (a line of zero area the grid misses),
  // sampled on the contact lines beta_2 = beta_1 +- delta (docs/equilibrium_sets.md section 5).
  std::optional<EquilibriumSet::ContactLine> line;
  std::size_t excluded = 0;
  for (char e : g.excluded) excluded += e ? 1 : 0;
  fs::path line_csv;
  if (!g.excluded.empty() && nb == 2) {
    line = set.contact_line(freq, n);
    line_csv = dir / "contact_line.csv";
    AtomicFile f(line_csv);
    f << "beta1_rad,beta2_rad,side,in_set\n";
    for (int side = 0; side < 2; ++side)
      for (std::size_t k = 0; k < n; ++k) {
        const double b1 = 2 * M_PI * static_cast<double>(k) / static_cast<double>(n);
        f << csv_number(b1) << "," << csv_number(b1 + (side == 0 ? line->spacing_rad : -line->spacing_rad)) << ","
          << (side == 0 ? "ahead" : "behind") << "," << int(line->in_set[side][k]) << "\n";
      }
    f.commit();
  }

  GridPlot plot;
  plot.csv_path = csv.string();
  plot.png_path = (dir / "equilibrium_set.png").string();
  plot.width_px = 820;
  plot.height_px = 760;
  std::ostringstream title;
  title << "Equilibrium set at " << freq << " Hz (W = " << std::setprecision(4) << set.speed_ratio(freq)
        << ", μ = " << set.mu() << "): " << std::setprecision(3) << 100 * g.coverage() << " % of the grid in the set";
  plot.labels = {title.str(), plot_style::kBeta1, plot_style::kBeta2};
  plot.angle_axes = true;
  plot.fill_column = 4;
  // A categorical key (not a colour scale): in the set, outside, overlapping balls (hard contact).
  plot.categories = {{1, plot_style::kInSet, "in the equilibrium set"}, {0, plot_style::kOutOfSet, "outside it"}};
  if (!g.excluded.empty()) plot.categories.push_back({-1, "#999999", "balls overlap (excluded)"});
  plot.contour_column = 3;
  plot.contour_levels = 8;
  plot.contour_title = "steady amplitude [mm] (contours)";
  const PlotStatus ps = Gnuplot().grid(plot);

  if (a.json) {
    nlohmann::json j;
    j["frequency_hz"] = freq;
    j["speed_ratio"] = set.speed_ratio(freq);
    j["natural_frequency_hz"] = set.natural_frequency_hz();
    j["mu"] = set.mu();
    j["grid"] = n;
    j["coverage"] = g.coverage();
    j["full_coverage_closed_form"] = set.full_coverage_margin(freq) >= 0;
    j["amplitude_mm"] = {{"min", g.min_amplitude_mm()}, {"max", g.max_amplitude_mm()}};
    if (in_min <= in_max)
      j["amplitude_in_set_mm"] = {{"min", in_min}, {"max", in_max}};
    else
      j["amplitude_in_set_mm"] = nullptr;
    j["csv"] = csv.string();
    if (!g.excluded.empty()) {
      j["ball_contact"] = "hard";
      j["excluded_overlapping"] = excluded;
      if (line)
        j["contact_line"] = {{"spacing_rad", line->spacing_rad}, {"samples", n}, {"coverage_ahead", line->coverage(0)},
                             {"coverage_behind", line->coverage(1)}, {"csv", line_csv.string()}};
    }
    j["png"] = plot.png_path;
    j["pdf"] = ps.pdf_path;
    j["plot"] = {{"status", to_string(ps.state)}, {"message", ps.message}, {"script", ps.script_path}};
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << std::setprecision(6);
    std::cout << "frequency:         " << freq << " Hz (W = " << set.speed_ratio(freq) << ", natural frequency "
              << set.natural_frequency_hz() << " Hz), mu = " << set.mu() << "\n";
    std::cout << "coverage:          " << g.coverage() << " of the " << n << " x " << n << " grid over (beta_1, beta_2)"
              << (set.full_coverage_margin(freq) >= 0
                      ? (g.excluded.empty() ? " (closed form: the whole plane)"
                                            : " (closed form: every configuration whose balls do not overlap)")
                      : "")
              << "\n";
    std::cout << "amplitude [mm]:    " << g.min_amplitude_mm() << " .. " << g.max_amplitude_mm() << " (all points)";
    if (in_min <= in_max) std::cout << ", " << in_min << " .. " << in_max << " (in the set)";
    if (!g.excluded.empty()) {
      std::cout << "\ncontact (hard):    " << excluded << " grid points have overlapping balls (excluded, in_set = -1)";
      if (line)
        std::cout << "\ncontact line:      touching (|beta_1 - beta_2| = " << line->spacing_rad << " rad): "
                  << line->coverage(0) << " (ball 2 ahead) and " << line->coverage(1) << " (behind) of " << n
                  << " points each in the set; " << line_csv.string();
    }
    std::cout << "\ncsv:               " << csv.string() << "\n";
    std::cout << "plot:              " << (ps.ran() ? plot.png_path : ps.message) << "\n";
  }
  return 0;
}

// Residual-imbalance columns of the scan (docs/equilibrium_sets.md section 4), I_r in 1e-7 kg m.
constexpr double kIrUnit = 1e-7;

const char* kResidualHeader =
    "frequency_hz,coverage,inscribed_ir,set_ir_min,set_ir_median,set_ir_mean,set_ir_max,set_irx_min,"
    "set_irx_median,set_irx_max,balance_fraction,balance_ir_min,balance_ir_median,balance_ir_max,balance_irx_median,"
    "boundary_ir_min,boundary_ir_median,boundary_ir_max,boundary_irx_median";

double ir_units(double kgm) { return kgm / kIrUnit; }

// One row of the residual table; NaN where a statistic has no grid point (empty in the CSV, "-" in
// the text table).
std::vector<double> residual_row(const EquilibriumResidual& r) {
  return {r.frequency_hz,
          r.coverage,
          ir_units(r.inscribed_kgm),
          ir_units(r.in_set.magnitude.min),
          ir_units(r.in_set.magnitude.median),
          ir_units(r.in_set.magnitude.mean),
          ir_units(r.in_set.magnitude.max),
          ir_units(r.in_set.x.min),
          ir_units(r.in_set.x.median),
          ir_units(r.in_set.x.max),
          r.around_balance_fraction,
          ir_units(r.around_balance.magnitude.min),
          ir_units(r.around_balance.magnitude.median),
          ir_units(r.around_balance.magnitude.max),
          ir_units(r.around_balance.x.median),
          ir_units(r.boundary.magnitude.min),
          ir_units(r.boundary.magnitude.median),
          ir_units(r.boundary.magnitude.max),
          ir_units(r.boundary.x.median)};
}

nlohmann::json stats_json(const ResidualStatistics& s) {
  if (s.count == 0) return nullptr;
  return {{"count", s.count}, {"min", ir_units(s.min)}, {"median", ir_units(s.median)}, {"mean", ir_units(s.mean)},
          {"max", ir_units(s.max)}};
}

nlohmann::json pair_json(const ResidualPair& p) {
  return {{"ir", stats_json(p.magnitude)}, {"ir_x", stats_json(p.x)}};
}

int run_scan(const EqsetArgs& a, const EquilibriumSet& set, const EqsetConfig& cfg, const Scan& sc, std::size_t n) {
  const EquilibriumScan s = set.scan(sc.from, sc.to, sc.step, n, cfg.other_angles_rad);
  const std::vector<EquilibriumResidual> res =
      equilibrium_residual_scan(set, sc.from, sc.to, sc.step, n, cfg.other_angles_rad);
  const auto exact = sc.to > sc.from ? set.exact_band_hz(sc.from, sc.to) : std::nullopt;
  const double locked = ir_units(locked_residual_kgm(set));
  std::string csv_path, plot_text, residual_csv, residual_plot_text;
  PlotStatus ps, rps;
  if (!a.out.empty()) {
    const fs::path dir = make_out_dir(a.out, "--out");
    csv_path = (dir / "coverage.csv").string();
    AtomicFile f(csv_path);
    f << "frequency_hz,coverage\n";
    for (std::size_t k = 0; k < s.frequency_hz.size(); ++k)
      f << csv_number(s.frequency_hz[k]) << "," << csv_number(s.coverage[k]) << "\n";
    f.commit();
    XYLinesPlot plot;
    plot.csv_path = csv_path;
    plot.png_path = (dir / "coverage.png").string();
    std::ostringstream title;
    title << "Equilibrium-set coverage (μ = " << set.mu() << ", natural frequency " << std::setprecision(4)
          << set.natural_frequency_hz() << " Hz)";
    plot.labels = {title.str(), plot_style::kFreqHz, "fraction of the (β_1, β_2) plane in the set"};
    plot.series = {{1, 2, "coverage", "linespoints"}};
    ps = Gnuplot().xy_lines(plot);
    plot_text = ps.ran() ? plot.png_path : ps.message;

    residual_csv = (dir / "residual.csv").string();
    AtomicFile r(residual_csv);
    r << kResidualHeader << "\n";
    for (const auto& e : res) {
      const auto row = residual_row(e);
      // An empty field: no grid point in that part at this frequency (e.g. the boundary columns
      // outside the band, where the whole plane is in the set).
      for (std::size_t c = 0; c < row.size(); ++c) r << (c ? "," : "") << (std::isfinite(row[c]) ? csv_number(row[c]) : "");
      r << "\n";
    }
    r.commit();
    XYLinesPlot rp;
    rp.csv_path = residual_csv;
    rp.png_path = (dir / "residual.png").string();
    std::ostringstream rt;
    rt << "Residual imbalance the equilibrium set allows (μ = " << set.mu() << ", r_{lock} = " << std::setprecision(3)
       << locked << "·10^{-7} kg m)";
    rp.labels = {rt.str(), plot_style::kFreqHz, std::string(plot_style::kIr) + " (log scale)"};
    // Four curves (the CSV has every statistic): r_in reaches hundreds where the others are tens, so
    // the y axis is logarithmic; the key sits in the empty bottom corner, away from the x label.
    rp.key = "bottom right box opaque";
    rp.log_y = true;
    rp.height_px = 650;
    rp.series = {{1, 3, "r_in (closed form: every |I_r| below it is in the set)", "lines"},
                 {1, 5, "median |I_r| over the set", "lines"},
                 {1, 4, "min |I_r| over the set", "lines"},
                 {1, 13, "median |I_r| around the balancing points (dashed; often on the median over the set)", "lines dt 2"}};
    rps = Gnuplot().xy_lines(rp);
    residual_plot_text = rps.ran() ? rp.png_path : rps.message;
  }
  if (a.json) {
    nlohmann::json j;
    j["mu"] = s.mu;
    j["grid"] = s.grid_n;
    j["natural_frequency_hz"] = s.natural_frequency_hz;
    j["band_hz"] = band_json(s.band_hz);
    j["exact_band_hz"] = band_json(exact);
    j["locked_ir"] = locked;
    nlohmann::json cov = nlohmann::json::array();
    for (std::size_t k = 0; k < s.frequency_hz.size(); ++k) {
      const auto& e = res[k];
      cov.push_back({{"frequency_hz", s.frequency_hz[k]},
                     {"coverage", s.coverage[k]},
                     {"inscribed_ir", ir_units(e.inscribed_kgm)},
                     {"in_set", pair_json(e.in_set)},
                     {"balance_fraction", e.around_balance_fraction},
                     {"around_balance", pair_json(e.around_balance)},
                     {"boundary", pair_json(e.boundary)}});
    }
    j["coverage"] = cov;
    if (!csv_path.empty()) {
      j["csv"] = csv_path;
      j["plot"] = {{"status", to_string(ps.state)}, {"message", ps.message}, {"script", ps.script_path}};
      j["residual_csv"] = residual_csv;
      j["residual_plot"] = {{"status", to_string(rps.state)}, {"message", rps.message}, {"script", rps.script_path}};
    }
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << std::setprecision(6);
    std::cout << "# equilibrium-set coverage and the residual imbalance it allows, mu = " << s.mu << ", " << n << " x "
              << n << " grid; I_r in 1e-7 kg m\n";
    std::cout << "# set: grid points in the set; balance: its part around the balancing points; boundary: that "
                 "part's edge\n";
    std::cout << "# frequency_hz coverage r_in set_ir_min set_ir_median set_ir_max set_irx_median balance_fraction "
                 "balance_ir_median boundary_ir_min boundary_ir_median\n";
    auto col = [](double v) {  // "-": no grid point in that part (the boundary outside the band)
      if (!std::isfinite(v)) return std::string("-");
      std::ostringstream os;
      os << std::setprecision(4) << v;
      return os.str();
    };
    for (std::size_t k = 0; k < s.frequency_hz.size(); ++k) {
      const auto& e = res[k];
      std::cout << std::setw(12) << s.frequency_hz[k] << " " << s.coverage[k] << " " << col(ir_units(e.inscribed_kgm))
                << " " << col(ir_units(e.in_set.magnitude.min)) << " " << col(ir_units(e.in_set.magnitude.median))
                << " " << col(ir_units(e.in_set.magnitude.max)) << " " << col(ir_units(e.in_set.x.median)) << " "
                << col(e.around_balance_fraction) << " " << col(ir_units(e.around_balance.magnitude.median)) << " "
                << col(ir_units(e.boundary.magnitude.min)) << " " << col(ir_units(e.boundary.magnitude.median))
                << "\n";
    }
    std::cout << "natural frequency: " << s.natural_frequency_hz << " Hz\n";
    if (s.band_hz)
      std::cout << "band (coverage < 1 on the grid): " << s.band_hz->first << " .. " << s.band_hz->second << " Hz\n";
    else
      std::cout << "band (coverage < 1 on the grid): none in " << sc.from << " .. " << sc.to << " Hz\n";
    if (exact)
      std::cout << "band (closed form, continuous plane): " << exact->first << " .. " << exact->second << " Hz\n";
    std::cout << "locked residual (in the set at every speed, closed form): |I_r| <= " << locked << "e-7 kg m\n";
    if (!csv_path.empty())
      std::cout << "csv: " << csv_path << "\nplot: " << plot_text << "\nresidual csv: " << residual_csv
                << "\nresidual plot: " << residual_plot_text << "\n";
  }
  return 0;
}

int run_eqset(const EqsetArgs& a) {
  // Option values first: a bad option is reported before the config is read.
  if (a.freq && !(std::isfinite(*a.freq) && *a.freq > 0 && *a.freq <= kMaxFrequencyHz))
    throw ConfigError("--freq", num_text(*a.freq),
                      "must be a frequency in (0, 1e6] Hz (above it the steady amplitude overflows double precision)");
  if (a.grid && (*a.grid < 2 || *a.grid > kMaxGrid))
    throw ConfigError("--grid", std::to_string(*a.grid), "must be in [2, " + std::to_string(kMaxGrid) + "] (points per axis)");
  if (a.mu && !(std::isfinite(*a.mu) && *a.mu >= 0 && *a.mu < 1))
    throw ConfigError("--mu", num_text(*a.mu), "must be in [0, 1) (a friction coefficient)");
  std::optional<Scan> scan;
  if (a.scan) scan = parse_scan(*a.scan);

  if (!a.runs.runs_csv.empty() && a.mu)
    throw ConfigError("--mu", num_text(*a.mu), "cannot be given with --runs (the runs.csv gives each run's mu)");
  if (!a.runs.runs_csv.empty() && a.grid)
    throw ConfigError("--grid", std::to_string(*a.grid), "has no use with --runs (no grid: the runs' own angles)");
  if (a.lock_set && a.grid && *a.grid > 1024)  // ~80 us per point (281 speeds): 1024^2 points take about 90 s
    throw ConfigError("--grid", std::to_string(*a.grid), "must be at most 1024 with --lock-set (points per axis)");
  if (a.lock_set && !a.out.empty())
    throw ConfigError("--out", a.out, "has no use with --lock-set (it prints its figures; --json for one object)");

  YamlReader root = YamlReader::load_file(a.config);
  const SimulationSetup setup = read_simulation_setup(root);
  const EqsetConfig cfg = read_eqset_section(root.child("eqset"));
  finish_config(root);  // a montecarlo (or any other known) section is not used here
  if (a.alpha && !(std::isfinite(*a.alpha) && *a.alpha >= 0))
    throw ConfigError("--alpha", num_text(*a.alpha), "must be an angular acceleration >= 0 in rad/s^2");
  if (a.lock_set) {
    const std::size_t nb = setup.abu.balls.size();
    if (nb < 2) throw ConfigError("abu.balls", std::to_string(nb) + " balls", "the lock-set grid needs at least 2 balls");
    if (cfg.other_angles_rad.size() != nb - 2)
      throw ConfigError("eqset.other_angles_rad", std::to_string(cfg.other_angles_rad.size()) + " angles",
                        "must give the fixed angles of balls 3.." + std::to_string(nb) + " (" + std::to_string(nb - 2) +
                            " values)");
    AbuParameters abu = setup.abu;
    if (a.mu) abu.friction_mu = *a.mu;
    return run_eqset_lock_set(abu, cfg.other_angles_rad, static_cast<std::size_t>(a.grid ? *a.grid : 160),
                              a.alpha.value_or(0.0), a.json);
  }
  if (!a.runs.runs_csv.empty()) {
    EqsetRunsArgs r = a.runs;
    r.out = a.out;
    r.json = a.json;
    return run_eqset_runs(setup, r);
  }
  const std::size_t nb = setup.abu.balls.size();
  if (nb < 2) throw ConfigError("abu.balls", std::to_string(nb) + " balls", "the equilibrium-set grid needs at least 2 balls");
  if (cfg.other_angles_rad.size() != nb - 2)
    throw ConfigError("eqset.other_angles_rad", std::to_string(cfg.other_angles_rad.size()) + " angles",
                      "must give the fixed angles of balls 3.." + std::to_string(nb) + " (" + std::to_string(nb - 2) +
                          " values)");

  const EquilibriumSet set(setup.abu, a.mu ? *a.mu : -1.0);
  if (!a.freq && !scan) {
    if (cfg.frequency_hz) {
      const auto n = static_cast<std::size_t>(a.grid ? *a.grid : cfg.grid.value_or(128));
      return run_single(a, set, cfg, *cfg.frequency_hz, n);
    }
    if (cfg.scan_hz) {
      const auto& v = *cfg.scan_hz;
      const auto n = static_cast<std::size_t>(a.grid ? *a.grid : cfg.grid.value_or(64));
      return run_scan(a, set, cfg, Scan{v[0], v[1], v[2]}, n);
    }
    throw ConfigError("--freq", "<missing>", "give --freq HZ or --scan FROM:TO:STEP (or eqset.frequency_hz / eqset.scan_hz in the config)");
  }
  if (scan) return run_scan(a, set, cfg, *scan, static_cast<std::size_t>(a.grid ? *a.grid : cfg.grid.value_or(64)));
  return run_single(a, set, cfg, *a.freq, static_cast<std::size_t>(a.grid ? *a.grid : cfg.grid.value_or(128)));
}

}  // namespace

void register_eqset(CLI::App& app) {
  auto args = std::make_shared<EqsetArgs>();
  CLI::App* sub = app.add_subcommand(
      "eqset",
      "Equilibrium set at constant speed (report fig 4.3): the ball angles (beta_1, beta_2) where all balls\n"
      "can stay stuck, with the steady vibration amplitude there.\n"
      "  --freq HZ: writes DIR/equilibrium_set.csv, .png and .pdf (set and amplitude contours); prints coverage\n"
      "  --scan FROM:TO:STEP: prints per frequency the coverage and the residual imbalance the set allows\n"
      "    (smallest/median/largest |I_r|, I_r,x over the set and around the balancing points), the band\n"
      "    where the coverage is below 1; with --out also residual.csv/.png/.pdf. '-' (an empty CSV field): that\n"
      "    part has no grid point (the boundary columns outside the band, where the set is the plane).\n"
      "  --runs RUNS_CSV: where the runs of `abuopt montecarlo CONFIG --out DIR` (DIR/runs.csv) stopped against\n"
      "    the sets: settling speed, gauge, depth |U|/r_lock, the runs locked early (before the band) and late;\n"
      "    with --out DIR also DIR/final_states.csv (one line per settled run).\n"
      "  --lock-set: the share of uniform starts in the lock set (a grid, --grid, default 160), their depth and\n"
      "    lock gauge; with --alpha the share out of a ramp's reach (docs/equilibrium_sets.md section 6).\n"
      "Exit status: 0 ok, 2 bad input, 3 no settled run (--runs).");
  sub->add_option("config", args->config, "YAML config (section abu; optional section eqset)")->required();
  auto* freq = sub->add_option("--freq", args->freq, "constant speed in Hz (> 0)");
  auto* scan = sub->add_option("--scan", args->scan, "frequency scan FROM:TO:STEP in Hz, e.g. 10:50:0.5");
  freq->excludes(scan);
  auto* runs = sub->add_option("--runs", args->runs.runs_csv, "runs.csv of `abuopt montecarlo --out DIR`: final states against the sets");
  runs->excludes(freq);
  runs->excludes(scan);
  auto* lock = sub->add_flag("--lock-set", args->lock_set,
                             "uniform starts in the lock set (in the set of every speed): share, depth, lock gauge");
  lock->excludes(freq);
  lock->excludes(scan);
  lock->excludes(runs);
  sub->add_option("--alpha", args->alpha, "--lock-set: the peak angular acceleration of a ramp in rad/s^2 (its reach)")
      ->needs(lock);
  sub->add_option("--split", args->runs.split, "--runs: early runs by settling speed (speed, default) or before the first passage of the band edge (passage)")->needs(runs);
  sub->add_option("--edge", args->runs.edge_hz, "--runs: the band edge of the split in Hz (default: the speed below resonance where r_in = 2 r_lock)")->needs(runs);
  sub->add_option("--grid", args->grid, "points per axis of the (beta_1, beta_2) grid, >= 2 (default 128; scan 64)");
  sub->add_option("--mu", args->mu, "override the friction coefficient abu.friction_mu, in [0, 1)");
  sub->add_option("--out", args->out,
                  "output directory (default for --freq: results/eqset-<freq>Hz; --scan writes files only when given)");
  sub->add_flag("--json", args->json, "print the result as one JSON object");
  sub->callback([args] { set_exit_code(run_eqset(*args)); });
}

}  // namespace abuopt::app
