// abuopt montecarlo CONFIG: Monte Carlo over initial ball angles (and uncertain parameters) for one
// startup profile; prints the statistics of both residual-imbalance definitions.
#include <unistd.h>

#include <cmath>
#include <cstdio>
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
#include "abuopt/common/gnuplot.hpp"
#include "abuopt/common/output_file.hpp"
#include "abuopt/common/plot_style.hpp"
#include "abuopt/common/text.hpp"
#include "abuopt/common/progress.hpp"
#include "abuopt/common/stop.hpp"
#include "abuopt/common/provenance.hpp"
#include "abuopt/core/monte_carlo.hpp"
#include "abuopt/core/monte_carlo_stats.hpp"
#include "abuopt/core/simulation_config.hpp"
#include "abuopt/parallel/parallel.hpp"
#include "abuopt/studies/terms.hpp"
#include "commands/commands.hpp"

namespace abuopt::app {

namespace {

struct MonteCarloArgs {
  std::string config;
  std::optional<long> runs, grid, threads;
  std::optional<long long> seed;
  std::optional<double> mu;
  std::optional<std::string> design;
  bool json = false, progress = false;
  std::string out;
};

std::string num_text(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

// Applies the command-line options over the config; each bad value names its option.
void apply_overrides(const MonteCarloArgs& a, MonteCarloConfig& cfg) {
  MonteCarloStudy& s = cfg.study;
  if (a.design) s.design.kind = initial_condition_kind_from_string(*a.design, "--design");
  if (a.grid) {
    if (*a.grid < 1) throw ConfigError("--grid", std::to_string(*a.grid), "must be >= 1 (points per axis)");
    if (!a.design) s.design.kind = InitialConditionKind::Grid;
    s.design.grid_points_per_axis = static_cast<std::size_t>(*a.grid);
  }
  if (a.runs && *a.runs < 1) throw ConfigError("--runs", std::to_string(*a.runs), "must be >= 1");
  if (a.threads && *a.threads < 0)
    throw ConfigError("--threads", std::to_string(*a.threads), "must be >= 0 (0 = all cores)");
  if (a.seed && *a.seed < 0) throw ConfigError("--seed", std::to_string(*a.seed), "must be >= 0");
  if (a.mu && !(std::isfinite(*a.mu) && *a.mu >= 0 && *a.mu < 1))
    throw ConfigError("--mu", num_text(*a.mu), "must be in [0, 1) (a friction coefficient)");

  const InitialConditionDesign d = study_design(s);
  if (a.runs) {
    s.runs = static_cast<std::size_t>(*a.runs);
    if (s.design.kind == InitialConditionKind::Grid && d.size() != s.runs)
      throw ConfigError("--runs", std::to_string(*a.runs),
                        "must equal grid^balls = " + std::to_string(d.grid_points_per_axis) + "^" +
                            std::to_string(d.balls) + " = " + std::to_string(d.size()) +
                            " with the grid design (use --grid, or --design random|lhs|halton|sobol)");
  } else if (s.design.kind == InitialConditionKind::Grid) {
    if (d.size() > kMaxDesignPoints)
      throw ConfigError(a.grid ? "--grid" : "montecarlo.grid", std::to_string(d.grid_points_per_axis),
                        "grid^balls (balls = " + std::to_string(d.balls) + ") must be <= 2^32 runs");
    s.runs = d.size();
  }
  if (a.threads) cfg.threads = static_cast<std::size_t>(*a.threads);
  if (a.seed) {
    s.seed = static_cast<std::uint64_t>(*a.seed);
    s.design.seed = s.seed;
  }
  if (a.mu) {  // replaces the friction of the config, wherever it was given
    s.uncertain.envelope.friction_mu = ParameterDistribution{};
    s.uncertain.friction = FrictionUncertainty{};
    s.uncertain.friction.sampling = FrictionSampling::Fixed;
    s.uncertain.friction.value = *a.mu;
  }
  validate(s, "montecarlo");  // the config as the options left it (read unchecked, so options can fix it)
}

std::string friction_text(const MonteCarloStudy& s) {
  if (s.uncertain.envelope.friction_mu.given()) return s.uncertain.envelope.friction_mu.text();
  const FrictionUncertainty& f = s.uncertain.friction;
  switch (f.sampling) {
    case FrictionSampling::Nominal: return num_text(s.setup.abu.friction_mu);
    case FrictionSampling::Fixed: return num_text(f.value);
    case FrictionSampling::List: {
      std::string t = "list [";
      for (std::size_t i = 0; i < f.values.size(); ++i) t += (i ? ", " : "") + num_text(f.values[i]);
      return t + "] (cycled)";
    }
    case FrictionSampling::Range: return "uniform [" + num_text(f.lo) + ", " + num_text(f.hi) + "]";
  }
  return "?";
}

nlohmann::json study_json(const MonteCarloArgs& a, const MonteCarloConfig& cfg, double end_time_s) {
  const MonteCarloStudy& s = cfg.study;
  const InitialConditionDesign d = study_design(s);
  nlohmann::json j = {{"config", a.config},
                      {"design", to_string(d.kind)},
                      {"balls", d.balls},
                      {"runs", s.runs},
                      {"seed", s.seed},
                      {"friction", friction_text(s)},
                      {"imbalance_mass", to_string(s.uncertain.imbalance_mass.sampling)},
                      {"imbalance_angle", to_string(s.uncertain.imbalance_angle.sampling)},
                      {"imbalance_without_balls_kgm", s.setup.abu.imbalance_kgm()},
                      {"profile_duration_s", s.setup.profile.duration_s()},
                      {"end_time_s", end_time_s}};
  const Envelope& e = s.uncertain.envelope;
  if (!e.empty()) {
    nlohmann::json env = nlohmann::json::object();
    for (std::size_t k = 0; k < Envelope::kParameters; ++k)
      if (e.parameter(k).given()) env[Envelope::key(k)] = e.parameter(k).text();
    j["envelope"] = env;
  }
  if (d.kind == InitialConditionKind::Grid) j["grid"] = d.grid_points_per_axis;
  if (d.kind == InitialConditionKind::Halton || d.kind == InitialConditionKind::Sobol) j["shift"] = d.random_shift;
  return j;
}

// residual_histogram.png/.pdf: both residual-imbalance definitions of every ok run (from runs.csv,
// by column name), 40 bins from 0 to the largest |I_r|, with the %MI threshold I = m_I e.
PlotStatus plot_residual_histogram(const std::string& dir, const MonteCarloResult& result, double imbalance_kgm,
                                   const std::string& what) {
  std::size_t ok = 0;
  for (const MonteCarloSample& smp : result.samples) ok += smp.outcome.ok() ? 1 : 0;
  const double threshold = imbalance_kgm * 1e7;
  std::ostringstream b;
  b << "set datafile separator ','\nset datafile columnheaders\n"
    // `what`: "<config>, profile ...|<design>": the title names the profile, a label the sample
    << "set title " << plot_style::literal("Residual imbalance of " + std::to_string(ok) + " runs: " + what.substr(0, what.find('|')))
    << "\nset label 2 " << plot_style::literal(what.find('|') == std::string::npos ? std::string() : what.substr(what.find('|') + 1))
    << " at graph 0.98, graph 0.95 right front boxed\nset style textbox opaque noborder fillcolor rgb '#ffffff'\n"
    << "set xlabel 'residual imbalance [10^{-7} kg m]'\nset ylabel 'runs per bin'\n"
    << "ir(c) = (strcol('status') eq 'ok') ? column(c) * 1e7 : NaN\n"
    << "stats 'runs.csv' using (ir('ir_magnitude_kgm')) nooutput\n"
    << "w = STATS_max > 0 ? STATS_max / 40 : 1\n"
    << "bin(x) = w * (floor(x / w) + 0.5)\n"
    << "set boxwidth w\nset style fill transparent solid 0.45 border\nset xrange [0:*]\nset yrange [0:*]\n"
    << "set grid\nset key below horizontal\n"  // below the axes: never over the (tallest, leftmost) bars
    << "set arrow 1 from " << format_number(threshold) << ", graph 0 to " << format_number(threshold)
    << ", graph 1 nohead dt 2 lw 2 lc rgb '" << plot_style::kRed << "'\n"
    << "plot 'runs.csv' using (bin(ir('ir_magnitude_kgm'))):(1.0) smooth frequency with boxes lt 1 title '|I_r|', \\\n"
    << "     '' using (bin(ir('ir_x_kgm'))):(1.0) smooth frequency with boxes lt 2 title 'I_{r,x} (report eq. 4.2)', \\\n"
    << "     NaN with lines dt 2 lw 2 lc rgb '" << plot_style::kRed << "' title 'I = m_I e (%MI threshold)'\n";
  const std::filesystem::path d(dir);
  return Gnuplot().run(b.str(), (d / "residual_histogram.gp").string(), (d / "residual_histogram.png").string(), 900,
                       600);
}

PlotStatus write_outputs(const std::string& dir, const MonteCarloResult& result, const nlohmann::json& summary,
                         double imbalance_kgm, const std::string& what) {
  AtomicFile csv(std::filesystem::path(dir) / "runs.csv");
  write_runs_csv(csv.stream(), result.samples);
  csv.commit();
  write_file_atomic(std::filesystem::path(dir) / "summary.json", summary.dump(2) + "\n");
  return plot_residual_histogram(dir, result, imbalance_kgm, what);
}

int run_montecarlo(const MonteCarloArgs& a) {
  YamlReader root = YamlReader::load_file(a.config);
  SimulationSetup setup = read_simulation_setup(root);
  MonteCarloConfig cfg = read_monte_carlo_config_unchecked(root, std::move(setup));
  finish_config(root);
  apply_overrides(a, cfg);
  std::optional<OutputDirLock> lock;  // one run per output directory
  if (!a.out.empty()) lock.emplace(a.out);

  const MonteCarloStudy& s = cfg.study;
  const double end_time_s = Simulator(s.setup).end_time_s();  // validates the setup
  // threads per process; under mpirun the runs are spread over every rank (parallel.hpp)
  const std::shared_ptr<BatchRunner> runner = parallel::make_runner(cfg.threads);

  ProgressReporter bar("Monte Carlo", "runs", s.runs, a.progress ? ProgressMode::Always : ProgressMode::Auto);
  ProgressCallback progress;
  if (bar.enabled())
    progress = [&bar](std::size_t done, std::size_t total, double) {
      bar.set_total(total);
      bar.update(done);
    };
  const StopScope stop_scope;  // SIGINT / SIGTERM stop the runs (abuopt/common/stop.hpp)
  MonteCarloResult result;
  try {
    result = run_monte_carlo(s, *runner, progress);
  } catch (const Interrupted& e) {
    bar.finish();
    throw Interrupted(std::string(e.what()) + "; nothing written (the statistics need every run" +
                      (a.out.empty() ? "" : ", " + a.out + " is unchanged") +
                      "); a rerun computes the same runs and the same result");
  }
  bar.finish();
  const MonteCarloStats stats = compute_statistics(result);

  nlohmann::json summary = to_json(stats, result, s);
  summary["study"] = study_json(a, cfg, end_time_s);
  // the interval of the mean: from the strata or the scrambled Sobol' replicates when the envelope has them
  const IntervalLayout layout = interval_layout(s);
  const double hw = summary["magnitude"]["mean_ci95_half_width"].is_number()
                        ? summary["magnitude"]["mean_ci95_half_width"].get<double>() : std::nan("");
  const double hw_x = summary["report_x"]["mean_ci95_half_width"].is_number()
                          ? summary["report_x"]["mean_ci95_half_width"].get<double>() : std::nan("");
  const std::string interval_text =
      layout.kind == IntervalKind::Replicates ? "from the means of 16 scrambled Sobol' replicates"
      : layout.kind == IntervalKind::Strata   ? "stratified: " + std::to_string(layout.groups) + " cells of the envelope"
                                              : "independent runs";
  summary["study"]["mean_interval"] = interval_text;
  const Provenance prov = provenance_of(a.config);
  summary["provenance"] = {{"abuopt_version", prov.abuopt_version},
                           {"git_commit", prov.git_commit},
                           {"config_hash", prov.config_hash}};
  PlotStatus plot;
  if (!a.out.empty()) {
    // The title names the config and its profile (segments: end frequency in duration), then the sample.
    std::ostringstream what;
    what << "profile " << format_number(s.setup.profile.start_frequency_hz());
    for (const auto& seg : s.setup.profile.segments())
      what << " → " << format_number(seg.end_frequency_hz) << " Hz in " << format_number(seg.duration_s) << " s";
    what << "|" << std::filesystem::path(a.config).stem().string() << ": " << to_string(study_design(s).kind) << " design, seed " << s.seed << ", μ = " << friction_text(s);
    plot = write_outputs(a.out, result, summary, s.setup.abu.imbalance_kgm(), what.str());
  }

  if (a.json) {
    std::cout << summary.dump(2) << "\n";
  } else {
    const InitialConditionDesign d = study_design(s);
    std::cout << "Monte Carlo: " << a.config << "\n"
              << "  design " << to_string(d.kind);
    if (d.kind == InitialConditionKind::Grid)
      std::cout << " " << d.grid_points_per_axis << "^" << d.balls;
    std::cout << ", " << s.runs << " runs, seed " << s.seed << ", mu " << friction_text(s) << "\n"
              << "  profile " << s.setup.profile.duration_s() << " s, end time " << end_time_s
              << " s, imbalance without balls I = " << std::setprecision(4) << s.setup.abu.imbalance_kgm() * 1e7
              << "e-7 kg m\n";
    const Envelope& e = s.uncertain.envelope;
    if (!e.empty()) {
      std::cout << "  envelope (drawn per run):";
      for (std::size_t k = 0; k < Envelope::kParameters; ++k)
        if (e.parameter(k).given()) std::cout << " " << Envelope::key(k) << " " << e.parameter(k).text() << ";";
      std::cout << "  sampling " << enum_name(kEnvelopeSamplingNames, e.sampling) << "\n";
    }
    std::cout << std::setprecision(6) << format_summary(stats);
    if (!e.empty())
      std::cout << "95 % interval of the mean: |I_r| +- " << std::setprecision(3) << hw * 1e7 << ", I_r,x +- "
                << hw_x * 1e7 << " [1e-7 kg m] (" << interval_text << ")\n"
                << std::setprecision(6);
    std::cout << terms_pointer() << "\n";
    if (!a.out.empty())
      std::cout << "wrote " << a.out << "/runs.csv and " << a.out << "/summary.json\n"
                << (plot.ran() ? "plot: " + plot.png_path + " and " + plot.pdf_path : "plot " + plot.message) << "\n";
  }
  if (stats.ok == 0) {
    std::cerr << "abuopt: every run failed (" << stats.failed << " of " << s.runs
              << "; the status counts above say why), so there is no statistic to report\n";
    return 3;
  }
  return 0;
}

}  // namespace

void register_montecarlo(CLI::App& app) {
  auto args = std::make_shared<MonteCarloArgs>();
  CLI::App* sub = app.add_subcommand(
      "montecarlo",
      "Monte Carlo over initial ball angles (and uncertain friction/imbalance) for one startup profile:\n"
      "mean/median/max/quantiles of the residual imbalance (|I_r| and the report's I_r,x), %MI with its\n"
      "95 % Wilson interval, %LC, settling time, peak amplitude, failed runs. Uses all cores; results do\n"
      "not depend on the thread count. Options override the config's `montecarlo` section.\n"
      "Exit status: 0 ok, 2 bad input, 3 every run failed.");
  sub->footer("\n" + terms_pointer());
  sub->add_option("config", args->config, "YAML config (sections abu, profile, motor, simulation, montecarlo)")
      ->required();
  sub->add_option("--runs", args->runs, "number of runs (grid design: must equal grid^balls)");
  sub->add_option("--grid", args->grid, "grid design with this many points per axis (grid^balls runs)");
  sub->add_option("--design", args->design, "initial-condition design: grid, random, lhs, halton, sobol");
  sub->add_option("--seed", args->seed, "seed of the design and of the uncertain parameters");
  sub->add_option("--threads", args->threads, "worker threads (0 = all cores)");
  sub->add_option("--mu", args->mu, "fixed friction coefficient for every run (overrides montecarlo.friction)");
  sub->add_flag("--progress", args->progress,
                "show runs done, rate and ETA on stderr also when it is not a terminal (on a terminal: always)");
  sub->add_flag("--json", args->json, "print one JSON object (summary and study) instead of the text summary");
  sub->add_option("--out", args->out,
                  "write runs.csv (one line per run), summary.json and residual_histogram.png/.pdf (both I_r\n"
                  "definitions, with the %MI threshold; gnuplot script beside it) into this directory");
  sub->callback([args] { set_exit_code(run_montecarlo(*args)); });
}

}  // namespace abuopt::app
