// abuopt optimize CONFIG: optimises a startup profile (design variables: segment end frequencies
// and durations) by Monte Carlo on common random numbers, with an evaluation archive so that a
// rerun of the same command resumes; then checks the best design out of sample against the
// report's final profile. docs/optimize.md describes every key and output.
#include <cctype>
#include <utility>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "abuopt/common/config_sections.hpp"
#include "abuopt/common/stop.hpp"
#include "abuopt/common/config_error.hpp"
#include "abuopt/common/gnuplot.hpp"
#include "abuopt/common/plot_style.hpp"
#include "abuopt/common/progress.hpp"
#include "abuopt/common/output_file.hpp"
#include "abuopt/common/provenance.hpp"
#include "abuopt/common/text.hpp"
#include "abuopt/core/simulation_config.hpp"
#include "abuopt/optimizer/evaluation_archive.hpp"
#include "abuopt/optimizer/minimize.hpp"
#include "abuopt/optimizer/optimizer_options.hpp"
#include "abuopt/optimizer/penalty_problem.hpp"
#include "abuopt/parallel/parallel.hpp"
#include "abuopt/problems/startup_profile_problem.hpp"
#include "abuopt/studies/optimize_run.hpp"
#include "abuopt/studies/out_of_sample.hpp"
#include "abuopt/studies/sweep.hpp"
#include "abuopt/studies/terms.hpp"
#include "commands/commands.hpp"

namespace abuopt::app {

namespace {

namespace fs = std::filesystem;
using opt::format_number;
using problems::StartupProfileProblem;

struct OptimizeArgs {
  std::string config;
  std::string out;
  bool json = false, progress = false;
  std::optional<long> max_evaluations;
  std::optional<long> threads;
};

struct LoadedConfig {
  problems::StartupProfileSettings settings;
  opt::OptimizerOptions options;  // with options.sao from `optimizer.sao` or the top-level `sao`
};

LoadedConfig load_config(const OptimizeArgs& a) {
  LoadedConfig c;
  YamlReader root = YamlReader::load_file(a.config);
  c.settings = problems::read_startup_profile_settings(root);
  YamlReader optimizer = root.child("optimizer");
  YamlReader sao = root.child("sao");
  c.options = opt::read_optimizer_options(optimizer, &sao);
  finish_config(root);  // the same file may configure `abuopt sweep` and `abuopt pareto`
  if (a.max_evaluations) {
    if (*a.max_evaluations < 1)
      throw ConfigError("--max-evaluations", std::to_string(*a.max_evaluations), "must be >= 1");
    c.options.max_evaluations = *a.max_evaluations;
  }
  if (a.threads) {
    if (*a.threads < 0) throw ConfigError("--threads", std::to_string(*a.threads), "must be >= 0 (0 = all cores)");
    c.settings.threads = static_cast<std::size_t>(*a.threads);
  }
  c.options.validate();
  return c;
}

std::string vector_text(const std::vector<opt::Variable>& vars, const std::vector<double>& x) {
  std::ostringstream os;
  os << std::setprecision(5);
  for (std::size_t i = 0; i < x.size() && i < vars.size(); ++i) os << (i ? " " : "") << vars[i].name << "=" << x[i];
  return os.str();
}

std::string profile_text(const StartupProfile& p) {
  std::ostringstream os;
  os << std::setprecision(5);
  double f = p.start_frequency_hz();
  for (std::size_t i = 0; i < p.segments().size(); ++i) {
    const auto& s = p.segments()[i];
    os << (i ? ", " : "") << f << "->" << s.end_frequency_hz << " Hz/" << s.duration_s << " s";
    f = s.end_frequency_hz;
  }
  os << " (" << p.duration_s() << " s)";
  return os.str();
}

nlohmann::json profile_json(const StartupProfile& p) {
  nlohmann::json segs = nlohmann::json::array();
  for (const auto& s : p.segments()) segs.push_back({{"end_frequency_hz", s.end_frequency_hz}, {"duration_s", s.duration_s}});
  return {{"start_frequency_hz", p.start_frequency_hz()}, {"segments", segs}, {"duration_s", p.duration_s()}};
}

// Metrics as JSON: the counts (runs, failed runs) as integers, the rest as numbers.
nlohmann::json metrics_json(const std::map<std::string, double>& metrics) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [k, v] : metrics) {
    const bool count = k == "runs" || k == "failed_runs";
    if (count && std::isfinite(v) && v == std::floor(v) && std::fabs(v) < 9e15)
      j[k] = static_cast<long long>(v);
    else
      j[k] = v;
  }
  return j;
}

nlohmann::json evaluation_json(const opt::Evaluation& e, const std::vector<std::string>& names) {
  nlohmann::json j = {{"ok", e.ok}, {"objective", e.objective}, {"metrics", metrics_json(e.metrics)}};
  if (!e.message.empty()) j["message"] = e.message;
  nlohmann::json g = nlohmann::json::object();
  for (std::size_t i = 0; i < e.inequality.size() && i < names.size(); ++i) g[names[i]] = e.inequality[i];
  j["constraints"] = g;
  j["max_violation"] = opt::max_constraint_violation(e);
  return j;
}

std::string csv_text(const std::string& s) { return csv_field(s); }

void write_history_csv(const fs::path& path, const opt::OptimizationResult& r) {
  std::set<std::string> metric_names;
  for (const auto& h : r.history)
    for (const auto& [k, v] : h.metrics) metric_names.insert(k);
  AtomicFile f(path);
  f << "evaluation,from_archive,for_gradient,ok,feasible,objective,max_violation";
  for (const auto& n : r.variable_names) f << "," << n;
  for (const auto& n : r.inequality_names) f << ",g_" << n;
  for (const auto& n : metric_names) f << "," << n;
  f << ",wall_time_s,elapsed_s,message\n";
  for (const auto& h : r.history) {
    f << h.index + 1 << "," << h.from_archive << "," << h.for_gradient << "," << h.ok << "," << h.feasible << ","
      << csv_number(h.objective) << "," << csv_number(h.max_violation);
    for (std::size_t i = 0; i < r.variable_names.size(); ++i) f << "," << (i < h.x.size() ? csv_number(h.x[i]) : "");
    for (std::size_t i = 0; i < r.inequality_names.size(); ++i)
      f << "," << (i < h.inequality.size() ? csv_number(h.inequality[i]) : "");
    for (const auto& n : metric_names) {
      auto it = h.metrics.find(n);
      f << "," << (it == h.metrics.end() ? "" : csv_number(it->second));
    }
    f << "," << csv_number(h.wall_time_s) << "," << csv_number(h.elapsed_s) << "," << csv_text(h.message) << "\n";
  }
  f.commit();
}

// convergence.csv (+ .png and .pdf): objective of every evaluation, of the feasible ones, best
// feasible so far. Returns the plot's status (its PNG and PDF paths when made).
// convergence.png: the objective of every evaluation (its quantity and unit on the y axis), the
// feasible ones filled, the best feasible so far as steps, and the largest constraint violation
// (relative, log scale, right axis) of the infeasible ones, so a reader sees why a low point is not
// the best.
PlotStatus write_convergence(const fs::path& dir, const opt::OptimizationResult& r, const std::string& ylabel) {
  const fs::path csv = dir / "convergence.csv", png = dir / "convergence.png";
  bool any_violation = false;
  {
    AtomicFile f(csv);
    f << "evaluation,objective,feasible_objective,best_feasible_objective,max_violation\n";
    double best = std::numeric_limits<double>::infinity();
    for (const auto& h : r.history) {
      if (h.feasible && h.objective < best) best = h.objective;
      any_violation = any_violation || (std::isfinite(h.max_violation) && h.max_violation > 0 && !h.feasible);
      f << h.index + 1 << "," << (h.ok && std::isfinite(h.objective) ? format_number(h.objective) : "") << ","
        << (h.feasible ? format_number(h.objective) : "") << "," << (std::isfinite(best) ? format_number(best) : "")
        << "," << (std::isfinite(h.max_violation) ? format_number(h.max_violation) : "") << "\n";
    }
    f.commit();
  }
  if (parallel::interrupted()) {  // mpirun kills the job a second after the Ctrl-C: the results first
    PlotStatus skipped;
    skipped.message = "skipped: interrupted under mpirun (a rerun with the same --out plots it)";
    return skipped;
  }
  std::ostringstream b;
  const std::string q = Gnuplot::quote("convergence.csv");
  b << "set datafile separator ','\n"
    << "set title " << plot_style::literal("Convergence of " + r.algorithm + " on " + r.problem_name) << "\n"
    << "set xlabel 'evaluation'\nset ylabel " << plot_style::literal("objective: " + ylabel) << "\n"
    << "set key at screen 0.5, 0.02 center bottom horizontal maxrows 2 box opaque\nset bmargin 7\nset grid\n";
  if (any_violation)
    b << "set y2label 'largest constraint violation (relative; infeasible points)'\nset logscale y2\n"
         "set y2tics nomirror\nset ytics nomirror\n";
  b << "plot " << q << " skip 1 using 1:2 with points lt 1 pt 6 ps 1.4 title 'every evaluation', \\\n"
    << "     " << q << " skip 1 using 1:3 with points lt 1 pt 7 ps 0.8 title 'feasible (filled)', \\\n"
    << "     " << q << " skip 1 using 1:4 with steps lt 3 lw 2 title 'best feasible so far'";
  if (any_violation)
    b << ", \\\n     " << q << " skip 1 using 1:(($5 > 0 && strlen(strcol(3)) == 0) ? $5 : NaN) axes x1y2 "
      << "with points lt 4 pt 2 ps 1.0 title 'constraint violation (right axis, x)'";
  b << "\n";
  return Gnuplot().run(b.str(), (dir / "convergence.gp").string(), png.string(), 900, 650);
}

// One line for the log: where the plot is, or why not.
std::string convergence_text(const PlotStatus& s) {
  if (s.ran()) return "wrote " + s.png_path + " and " + s.pdf_path;
  return "convergence plot " + s.message;
}

void write_best_profile(const fs::path& path, const StartupProfileProblem& problem, const opt::OptimizationResult& r,
                        const std::string& config) {
  SimulationSetup setup = problem.settings().study.setup;
  setup.profile = problem.profile_at(r.x);
  setup.abu = problem.abu_at(r.x);  // with design.ball_count: the balls at x
  AtomicFile f(path);
  f << "# Best startup profile of `abuopt optimize " << config << "` (" << r.algorithm << ", "
    << r.evaluations << " evaluations, " << to_string(r.reason) << ").\n"
    << "# " << vector_text(problem.variables(), r.x) << "; objective " << format_number(r.objective)
    << (r.feasible ? " (feasible)" : " (NOT feasible)") << "\n"
    << "# Run it: abuopt simulate " << path.string() << "   (or add a montecarlo section for abuopt montecarlo)\n"
    << to_yaml(setup);
  f.commit();
}

int run_optimize(const OptimizeArgs& a) {
  LoadedConfig cfg = load_config(a);
  // The problem and its penalty form when constraints.penalty_weight > 0 (what the optimiser sees),
  // later the archive in front of it: studies/optimize_run.hpp (abuopt.optimize runs the same).
  OptimizeRun run(cfg.settings, cfg.options);
  StartupProfileProblem& problem = run.problem();
  const auto& st = problem.settings();
  // under mpirun every Monte Carlo (the evaluations and the validation) is spread over the ranks,
  // and a batch of independent evaluations (SAO's design, finite-difference neighbours) runs as
  // concurrent studies whose runs share the ranks (docs/cluster.md, "Batches of evaluations")
  if (parallel::session() && parallel::session()->size() > 1) {
    problem.set_monte_carlo_runner(parallel::make_runner(st.threads), parallel::session()->concurrent_studies());
    run.options().scheduler = parallel::make_evaluation_scheduler();
  }
  const std::vector<opt::Variable> vars = problem.variables();
  const std::vector<std::string> g_names = run.optimised().inequality_names();

  const fs::path out = a.out.empty() ? fs::path("results") / fs::path(a.config).stem() : fs::path(a.out);
  const OutputDirLock lock(out);  // creates it; one run per output directory
  const std::string id = problem.identity();
  const Provenance prov = provenance_of(a.config);
  run.open_archive((out / "archive.sqlite").string(), "optimize", a.config, prov.config_hash);

  // Progress to stdout, or to stderr with --json (stdout then holds the JSON alone).
  std::ostream& log = a.json ? std::cerr : std::cout;
  const long stored = run.stored_at_start();
  log << "optimize " << a.config << ": problem " << id << ", " << vars.size() << " variables, "
      << g_names.size() << " constraints, algorithm " << cfg.options.algorithm << ", budget "
      << cfg.options.max_evaluations << " evaluations\n"
      << "  Monte Carlo: " << st.study.runs << " runs per evaluation"
      << (st.objective.robust_friction_mu.empty()
              ? std::string()
              : " x " + std::to_string(st.objective.robust_friction_mu.size()) + " friction values")
      << ", design " << to_string(st.study.design.kind) << ", seed " << st.study.seed << " (same for every design)\n"
      << "  archive " << (out / "archive.sqlite").string() << ": " << stored << " stored evaluations of this problem"
      << (stored ? " (resuming: repeats are answered from it)" : "") << "\n";
  for (std::size_t i = 0; i < vars.size(); ++i)
    log << "  " << vars[i].name << " in [" << format_number(vars[i].lower) << ", " << format_number(vars[i].upper)
        << "], x0 " << format_number(problem.initial_point()[i]) << "\n";

  // The bar (stderr) counts evaluations against the budget; the log lines go around it.
  ProgressReporter bar("optimize", "evaluations", static_cast<std::size_t>(std::max(0L, cfg.options.max_evaluations)),
                       a.progress ? ProgressMode::Always : ProgressMode::Auto);
  const opt::EvaluationCallback progress = [&](const opt::Progress& p) {
    const auto& r = p.last;
    std::ostringstream os;
    os << "eval " << std::setw(4) << p.evaluations << "  " << vector_text(vars, r.x) << "  f=";
    if (r.ok)
      os << std::setprecision(6) << r.objective;
    else
      os << "FAILED (" << r.message << ")";
    os << "  viol=";
    if (r.ok)
      os << std::setprecision(3) << r.max_violation;
    else
      os << "-";
    os << "  best=";
    if (p.have_feasible)
      os << std::setprecision(6) << p.best_objective;
    else
      os << "none";
    os << (r.from_archive ? "  [archive]" : "  [computed " + format_number(std::round(r.wall_time_s * 10) / 10) + " s]");
    if (r.for_gradient) os << " [fd]";
    log << std::flush;
    bar.message(os.str(), a.json ? stderr : stdout);
    bar.update(static_cast<std::size_t>(std::max(0L, static_cast<long>(p.evaluations))));
    return true;
  };

  const StopScope stop_scope;  // SIGINT / SIGTERM end the run after the current evaluation's runs
  opt::OptimizationResult r = run.minimize(progress);
  bar.finish();
  log << "\n" << r.brief_report() << "\n";
  if (!r.message.empty()) log << "  " << r.message << "\n";

  nlohmann::json j;
  j["config"] = a.config;
  j["problem_id"] = id;
  j["provenance"] = {{"abuopt_version", prov.abuopt_version},
                     {"git_commit", prov.git_commit},
                     {"config_hash", prov.config_hash}};
  j["out"] = out.string();
  j["algorithm"] = r.algorithm;
  j["reason"] = to_string(r.reason);
  j["message"] = r.message;
  j["success"] = r.success();
  j["evaluations"] = r.evaluations;
  j["archive_hits"] = r.archive_hits;
  j["computed_evaluations"] = r.evaluations - r.archive_hits;
  j["failed_evaluations"] = r.failed_evaluations;
  j["gradient_evaluations"] = r.gradient_evaluations;
  j["wall_time_s"] = r.wall_time_s;
  nlohmann::json jv = nlohmann::json::array();
  for (std::size_t i = 0; i < vars.size(); ++i)
    jv.push_back({{"name", vars[i].name},
                  {"lower", vars[i].lower},
                  {"upper", vars[i].upper},
                  {"scale", vars[i].scale},
                  {"x0", problem.initial_point()[i]}});
  j["variables"] = jv;
  j["constraints"] = g_names;
  j["montecarlo"] = {{"runs", st.study.runs},
                     {"design", to_string(st.study.design.kind)},
                     {"seed", st.study.seed},
                     {"robust_friction_mu", st.objective.robust_friction_mu}};
  j["objective"] = {{"kind", to_string(st.objective.kind)}, {"definition", to_string(st.objective.definition)}};

  const bool have_best = !r.x.empty();
  if (have_best) {
    nlohmann::json bx = nlohmann::json::object();
    for (std::size_t i = 0; i < vars.size(); ++i) bx[vars[i].name] = r.x[i];
    nlohmann::json bg = nlohmann::json::object();
    for (std::size_t i = 0; i < g_names.size() && i < r.inequality.size(); ++i) bg[g_names[i]] = r.inequality[i];
    j["best"] = {{"x", bx},
                 {"objective", r.objective},
                 {"feasible", r.feasible},
                 {"max_violation", r.max_violation},
                 {"constraints", bg},
                 {"metrics", metrics_json(r.metrics)},
                 {"profile", profile_json(problem.profile_at(r.x))}};
    log << "best design: " << vector_text(vars, r.x) << "\n  profile " << profile_text(problem.profile_at(r.x))
        << "\n  objective " << format_number(r.objective) << (r.feasible ? " (feasible)" : " (NOT feasible)") << "\n";
    if (st.constraints.penalty_weight > 0) {
      // Penalty form: "feasible" above only means "no declared constraints"; show the real ones.
      log << "  penalty form (weight " << format_number(st.constraints.penalty_weight) << "), relative constraints:";
      bool any = false;
      for (const auto& [k, v] : r.metrics)
        if (k.rfind("g_", 0) == 0) {
          log << " " << k.substr(2) << " = " << std::setprecision(4) << v << (v > 0 ? " (violated)" : "");
          any = true;
        }
      log << (any ? "" : " none") << "\n";
    }
  } else {
    log << "no evaluation finished: nothing to report\n";
  }

  // Files first (a Ctrl-C during the validation below still leaves them), result.json again after it.
  write_history_csv(out / "history.csv", r);
  const PlotStatus plot = write_convergence(out, r, objective_label(st));
  if (have_best) write_best_profile(out / "best_profile.yaml", problem, r, a.config);
  j["files"] = {{"history", (out / "history.csv").string()},
                {"convergence_csv", (out / "convergence.csv").string()},
                {"archive", (out / "archive.sqlite").string()}};
  if (have_best) j["files"]["best_profile"] = (out / "best_profile.yaml").string();
  if (plot.ran()) {
    j["files"]["convergence_png"] = plot.png_path;
    j["files"]["convergence_pdf"] = plot.pdf_path;
  }
  j["convergence_plot"] = {{"status", to_string(plot.state)}, {"message", plot.message}, {"script", plot.script_path}};
  const fs::path result_json = out / "result.json";
  auto write_json = [&] { write_file_atomic(result_json, j.dump(2) + "\n"); };
  write_json();

  const bool interrupted = r.reason == opt::TerminationReason::Interrupted;
  if (have_best && st.validation.enabled && !interrupted) {
    const auto& v = st.validation;
    log << "\nvalidation: " << v.runs << " fresh initial conditions (" << to_string(v.design) << ", seed " << v.seed
        << ") for the best design and for the report's final profile ...\n"
        << std::flush;
    const OutOfSampleComparison cmp = run.compare_out_of_sample(r);
    const StartupProfile& report = cmp.report;
    const std::vector<ComparisonRow>& rows = cmp.rows;
    const OutOfSampleVerdict verdict = out_of_sample_verdict(rows);
    log << comparison_table(rows) << verdict.text << "  " << terms_pointer() << "\n";
    log << "  report profile: " << profile_text(report) << "\n";
    j["validation"] = {{"runs", v.runs},
                       {"design", to_string(v.design)},
                       {"seed", v.seed},
                       {"best", {{"in_sample", evaluation_json(rows[0].e, g_names)},
                                 {"out_of_sample", evaluation_json(rows[1].e, g_names)}}},
                       {"report_profile", {{"profile", profile_json(report)},
                                           {"in_sample", evaluation_json(rows[2].e, g_names)},
                                           {"out_of_sample", evaluation_json(rows[3].e, g_names)}}},
                       {"worse_than_report_profile", verdict.worse}};
    write_json();
  } else if (interrupted) {
    std::cerr << "abuopt: interrupted by " << stop_signal_name() << " after " << r.evaluations
        << " evaluations: the best design so far is written, every evaluation is in the archive; rerun the same "
           "command to resume from the archive\n";
  }

  log << "wrote " << (out / "history.csv").string() << ", " << result_json.string()
      << (have_best ? ", " + (out / "best_profile.yaml").string() : std::string()) << "\n"
      << convergence_text(plot) << "\n";
  if (a.json) std::cout << j.dump(2) << "\n";
  if (interrupted) return stop_exit_status();
  if (r.reason == opt::TerminationReason::EvaluationError) {
    std::cerr << "abuopt: error: the optimisation ended on an evaluation error: "
              << (r.message.empty() ? std::string("(no message)") : r.message)
              << " (the files above hold the evaluations up to it)\n";
    return 3;
  }
  if (!r.has_feasible_point()) {
    std::cerr << "abuopt: no feasible design found in " << r.evaluations
              << " evaluations (every design violates a constraint or failed)";
    if (!r.x.empty()) {  // the result holds the least-violating design: name what it breaks
      std::cerr << "; the least-violating design breaks";
      const char* sep = " ";
      for (std::size_t i = 0; i < g_names.size() && i < r.inequality.size(); ++i)
        if (r.inequality[i] > 0) std::cerr << std::exchange(sep, ", ") << g_names[i] << " (g = " << format_significant(r.inequality[i], 3) << " > 0)";
    }
    // free frequencies whose bounds cannot reach this ABU's resonance (bounds set for another ABU)
    const double fn = st.study.setup.abu.natural_frequency_hz();
    std::string freq_bounds;
    bool reaches = false;
    for (const opt::Variable& v : vars)
      if (v.name.size() > 1 && v.name[0] == 'f' && std::isdigit(static_cast<unsigned char>(v.name[1]))) {
        freq_bounds += (freq_bounds.empty() ? "" : ", ") + v.name + " in [" + format_number(v.lower) + ", " +
                       format_number(v.upper) + "] Hz";
        if (v.lower <= fn && fn <= v.upper) reaches = true;
      }
    if (!freq_bounds.empty() && !reaches)
      std::cerr << "; no free frequency can reach this ABU's natural frequency " << format_significant(fn, 4)
                << " Hz (" << freq_bounds << "): the design's bounds may be set for another ABU";
    std::cerr << "\n";
    return 3;
  }
  return 0;
}

}  // namespace

void register_optimize(CLI::App& app) {
  auto args = std::make_shared<OptimizeArgs>();
  CLI::App* sub = app.add_subcommand(
      "optimize",
      "Optimise a startup profile: segment end frequencies and durations chosen by an optimiser\n"
      "(COBYLA, BOBYQA, SLSQP, IPOPT, DIRECT_L, SAO, ...), each design evaluated by a Monte Carlo over\n"
      "the same initial ball angles; constraints on startup time, amplitude and %MI. Every evaluation\n"
      "is archived in OUT/archive.sqlite: rerunning the same command resumes. At the end the best design\n"
      "and the report's final profile are evaluated on a fresh, larger set of initial conditions.\n"
      "Exit status: 0 ok, 2 bad input, 3 no feasible design found or the run ended on an evaluation\n"
      "error (the reason is printed), 4 an output file could not be written, 130 interrupted (Ctrl-C), 143 terminated (SIGTERM).");
  sub->footer("\n" + terms_pointer());
  sub->add_option("config", args->config,
                  "YAML config (abu, profile, motor, simulation, montecarlo, design, objective, constraints,\n"
                  "validation, optimizer, sao); see configs/optimize/ and docs/optimize.md")
      ->required();
  sub->add_option("--out", args->out, "output directory (default results/<config stem>)");
  sub->add_flag("--json", args->json, "print result.json to stdout (progress goes to stderr)");
  sub->add_flag("--progress", args->progress,
                "show evaluations done of the budget, rate and ETA on stderr also when it is not a terminal");
  sub->add_option("--max-evaluations", args->max_evaluations, "evaluation budget (overrides optimizer.max_evaluations)");
  sub->add_option("--threads", args->threads, "Monte Carlo worker threads (0 = all cores; overrides montecarlo.threads)");
  sub->callback([args] { set_exit_code(run_optimize(*args)); });
}

}  // namespace abuopt::app
