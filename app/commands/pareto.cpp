// abuopt pareto CONFIG: the Pareto front of startup time against the objective (mean |I_r|) by the
// epsilon-constraint method (studies/pareto.hpp): one optimisation per bound on the startup time,
// each archived, then each front point and the report's profile out of sample. docs/sweep.md.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "abuopt/common/config_sections.hpp"
#include "abuopt/common/stop.hpp"
#include "abuopt/common/config_error.hpp"
#include "abuopt/common/output_file.hpp"
#include "abuopt/common/progress.hpp"
#include "abuopt/common/provenance.hpp"
#include "abuopt/common/text.hpp"
#include "abuopt/optimizer/minimize.hpp"
#include "abuopt/optimizer/optimizer_options.hpp"
#include "abuopt/problems/startup_profile_problem.hpp"
#include "abuopt/studies/front_comparison.hpp"
#include "abuopt/studies/pareto.hpp"
#include "abuopt/studies/sweep.hpp"
#include "commands/commands.hpp"

namespace abuopt::app {

namespace {

namespace fs = std::filesystem;

struct ParetoArgs {
  std::string config;
  std::string out;
  bool json = false;
  bool progress = false;
  std::optional<long> threads;
  long max_bounds = 100;  // each bound is a whole optimisation: a total the user asks for explicitly
};

nlohmann::json evaluation_json(const opt::Evaluation& e) {
  nlohmann::json j = {{"ok", e.ok}, {"objective", e.ok ? nlohmann::json(e.objective) : nlohmann::json()},
                      {"metrics", e.metrics}};
  if (!e.message.empty()) j["message"] = e.message;
  return j;
}

// pareto.method nsga2 / moead: one run of pagmo's method on both objectives, through compare's
// fronts machinery (front_comparison.hpp): fronts.csv, hypervolume.csv, front_<stem>.png,
// summary.json; archive OUT/archive/<stem>/ (a rerun resumes).
int run_population_front(const ParetoArgs& a, const problems::StartupProfileSettings& settings,
                         const opt::OptimizerOptions& options, const ParetoSettings& ps) {
  const std::string label = fs::path(a.config).stem().string();
  const FrontProblem fp = pareto_front_problem(settings, options, ps, label);
  const problems::StartupProfileProblem shape(settings);  // validates; names
  const auto vars = shape.variables();
  const fs::path out = a.out.empty() ? fs::path("results") / fs::path(a.config).stem() : fs::path(a.out);
  const OutputDirLock lock(out);
  const Provenance prov = provenance_of(a.config);
  std::ostream& log = a.json ? std::cerr : std::cout;
  const FrontMethod& m = fp.methods.front();
  log << "pareto " << a.config << ": " << m.label << " (population " << ps.population << ", seed " << fp.seed << ") on "
      << objective_label(settings) << " and the startup time at once, " << ps.max_evaluations << " evaluations of "
      << settings.study.runs << " runs each; then every front point out of sample"
      << (settings.validation.enabled ? " (" + std::to_string(settings.validation.runs) + " runs)" : " (validation off)")
      << "\n  archive " << (out / "archive").string() << "/ (a rerun resumes)\n"
      << std::flush;
  const StopScope stop_scope;  // SIGINT / SIGTERM end the run after the current evaluation or batch
  const FrontComparison c = run_front_comparison({fp}, (out / "archive").string(), 1);
  const bool interrupted = stop_requested();
  opt::WrittenFiles written;
  write_front_outputs(c, out.string(), written);
  const FrontRun& run = c.runs.front();
  log << format_front_table(c);
  log << "\n  T [s]   objective (in)   out of sample   feasible out\n";
  for (auto it = run.points.rbegin(); it != run.points.rend(); ++it) {  // by T (points are by objective)
    const FrontPoint& p = *it;
    if (!p.non_dominated) continue;
    std::ostringstream os;
    os << std::fixed << std::setprecision(2) << std::setw(7) << p.second << std::setprecision(4) << std::setw(15)
       << p.objective;
    if (p.validation && p.validation->ok)
      os << std::setw(16) << p.validation->objective << std::setw(12) << (p.validated_feasible ? "yes" : "NO");
    else
      os << std::setw(16) << "-" << std::setw(12) << "-";
    log << os.str() << "\n";
  }

  nlohmann::json j;
  j["config"] = a.config;
  j["provenance"] = {{"abuopt_version", prov.abuopt_version},
                     {"git_commit", prov.git_commit},
                     {"config_hash", prov.config_hash}};
  j["method"] = to_string(ps.method);
  j["algorithm"] = m.kind == FrontMethod::Kind::Moead ? "pagmo_moead" : "pagmo_nsga2";
  j["population"] = ps.population;
  j["seed"] = fp.seed;
  j["max_evaluations"] = ps.max_evaluations;
  j["evaluations"] = run.evaluations;
  j["reason"] = run.reason;
  j["objective"] = {{"kind", problems::to_string(settings.objective.kind)}, {"label", objective_label(settings)}};
  j["montecarlo"] = {{"runs", settings.study.runs}, {"seed", settings.study.seed}};
  j["validation"] = {{"runs", settings.validation.runs}, {"seed", settings.validation.seed}};
  j["reference"] = {{"objective", ps.reference.first}, {"startup_time_s", ps.reference.second}};
  j["hypervolume"] = {{"in_sample", run.hv_in},
                      {"out_of_sample", run.validated ? nlohmann::json(run.hv_out) : nlohmann::json()}};
  nlohmann::json pts = nlohmann::json::array();
  for (const FrontPoint& p : run.points) {
    nlohmann::json x = nlohmann::json::object();
    for (std::size_t i = 0; i < vars.size() && i < p.x.size(); ++i) x[vars[i].name] = p.x[i];
    nlohmann::json q = {{"startup_time_s", p.second}, {"objective", p.objective}, {"non_dominated", p.non_dominated},
                        {"x", x}};
    if (p.validation) {
      q["out_of_sample"] = evaluation_json(*p.validation);
      q["feasible_out_of_sample"] = p.validated_feasible;
    }
    pts.push_back(q);
  }
  j["points"] = pts;
  j["interrupted"] = interrupted;
  j["files"] = written.files;
  j["skipped_plots"] = written.skipped_plots;
  write_file_atomic(out / "summary.json", j.dump(2) + "\n");
  log << "wrote " << (out / "fronts.csv").string() << ", " << (out / "hypervolume.csv").string() << ", "
      << (out / "summary.json").string();
  for (const std::string& f : written.files)
    if (f.size() > 4 && f.substr(f.size() - 4) == ".png") log << ", " << f;
  log << "\n";
  if (a.json) std::cout << j.dump(2) << "\n";
  if (interrupted) {
    std::cerr << "abuopt: interrupted by " << stop_signal_name() << ": kept the front so far (fronts.csv, "
              << "summary.json) and every evaluation in the archive; rerun the same command to resume\n";
    return stop_exit_status();
  }
  if (run.reason.rfind("failure: ", 0) == 0)  // the run itself ended in an error: say which (exit 3)
    std::cerr << "abuopt: the " << to_string(ps.method) << " run failed: " << run.reason.substr(9) << "\n";
  else if (run.points.empty())
    std::cerr << "abuopt: no feasible design in " << run.evaluations << " evaluations (" << run.reason << ")\n";
  return run.points.empty() || run.reason.rfind("failure: ", 0) == 0 ? 3 : 0;
}

int run_pareto_command(const ParetoArgs& a) {
  YamlReader root = YamlReader::load_file(a.config);
  problems::StartupProfileSettings settings = problems::read_startup_profile_settings(root);
  const ParetoSettings ps = read_pareto_settings(root.child("pareto"));
  YamlReader optimizer = root.child("optimizer");
  if (ps.method != ParetoSettings::Method::EpsilonConstraint)
    for (const char* key : {"algorithm", "max_evaluations", "population"})  // the method, budget, population: pareto's
      if (optimizer.has(key))
        throw ConfigError(optimizer.key_path(key), yaml_value_text(optimizer.node()[key]),
                          "must be absent with pareto.method " + to_string(ps.method) + ": the method is pareto.method, " +
                              "its budget pareto.max_evaluations, its population pareto.population (optimizer gives " +
                              "seed, constraint_tolerance, evaluation_threads, max_time_s)");
  YamlReader sao = root.child("sao");
  opt::OptimizerOptions options = opt::read_optimizer_options(optimizer, &sao);
  finish_config(root);  // the file may also configure `abuopt optimize` and `abuopt sweep`
  options.validate();
  if (a.threads) {
    if (*a.threads < 0) throw ConfigError("--threads", std::to_string(*a.threads), "must be >= 0 (0 = all cores)");
    settings.threads = static_cast<std::size_t>(*a.threads);
  }
  if (ps.method != ParetoSettings::Method::EpsilonConstraint) return run_population_front(a, settings, options, ps);
  if (a.max_bounds < 2) throw ConfigError("--max-bounds", std::to_string(a.max_bounds), "must be >= 2");
  if (ps.max_startup_time_s.size() > static_cast<std::size_t>(a.max_bounds))
    throw ConfigError("pareto.max_startup_time_s", std::to_string(ps.max_startup_time_s.size()) + " bounds",
                      "at most " + std::to_string(a.max_bounds) + " bounds in one run (each is an optimisation of up to " +
                          std::to_string(options.max_evaluations) +
                          " evaluations, twice with the warm start); pass --max-bounds N to allow more");
  const problems::StartupProfileProblem shape(settings);  // validates; names and labels
  const auto vars = shape.variables();

  const fs::path out = a.out.empty() ? fs::path("results") / fs::path(a.config).stem() : fs::path(a.out);
  const OutputDirLock lock(out);
  const Provenance prov = provenance_of(a.config);
  std::ostream& log = a.json ? std::cerr : std::cout;
  log << "pareto " << a.config << ": " << ps.max_startup_time_s.size() << " bounds on the startup time, each solved by "
      << options.algorithm << " (budget " << options.max_evaluations << ")" << (ps.warm_start ? ", from x0 and from the previous bound's best" : ", from x0")
      << "; objective " << objective_label(settings) << ", " << settings.study.runs << " runs per evaluation\n"
      << "  archive " << (out / "archive.sqlite").string() << " (a rerun resumes)\n"
      << std::flush;

  // Progress: evaluations against the budget of every bound and start (an optimiser that stops
  // early moves the bar on to the next bound), with rate and ETA on stderr (docs/figures.md).
  const std::size_t per_bound =
      static_cast<std::size_t>(std::max(1L, options.max_evaluations)) * (ps.warm_start ? 2u : 1u);
  ProgressReporter bar("pareto", "evaluations", per_bound * ps.max_startup_time_s.size(),
                       a.progress ? ProgressMode::Always : ProgressMode::Auto);
  std::FILE* log_file = a.json ? stderr : stdout;
  std::size_t current = static_cast<std::size_t>(-1), done = 0;
  const ParetoProgress progress = [&](std::size_t k, std::size_t n, const opt::Progress& p) {
    if (k != current) {
      current = k;
      done = std::max(done, k * per_bound);
      bar.message("bound " + std::to_string(k + 1) + "/" + std::to_string(n) + ": T <= " +
                      format_number(ps.max_startup_time_s[k]) + " s",
                  log_file);
    }
    bar.update(++done);
    if (!p.last.for_gradient && (p.evaluations % 10 == 0 || p.evaluations == 1)) {
      std::ostringstream line;
      line << "  eval " << std::setw(4) << p.evaluations << "  best="
           << (p.have_feasible ? format_number(p.best_objective) : "none") << (p.last.from_archive ? "  [archive]" : "");
      bar.message(line.str(), log_file);
    }
    return true;
  };
  const StopScope stop_scope;  // SIGINT / SIGTERM end the current point's run (abuopt/common/stop.hpp)
  const ParetoResult r = run_pareto(settings, options, ps, (out / "archive.sqlite").string(), a.config,
                                    prov.config_hash, progress, true);
  bar.finish();
  const std::string plot = write_pareto_outputs(out, shape, r);

  log << "\n  T bound   T [s]  objective (in)   out-of-sample        %MI in/out   evals  kept run\n";
  for (const auto& p : r.points) {
    std::ostringstream os;
    os << std::fixed << std::setprecision(2) << std::setw(9) << p.epsilon << std::setw(8) << p.startup_time_s
       << std::setprecision(4) << std::setw(11) << p.result.objective << (p.result.feasible ? "  " : " *")
       << (p.dominated ? "d" : " ");
    if (p.out_of_sample.ok) {
      const double hw = objective_half_width(settings, p.out_of_sample);
      os << std::setw(10) << p.out_of_sample.objective << " +- " << std::setw(6) << hw;
    } else {
      os << std::setw(20) << "-";
    }
    auto pm = [](const opt::Evaluation& e) {
      auto it = e.metrics.find("pct_mi");
      return it == e.metrics.end() ? std::string("-") : format_fixed(it->second, 1);
    };
    os << std::setw(7) << pm(in_sample_evaluation(p)) << "/" << std::left
       << std::setw(6) << pm(p.out_of_sample) << std::right << std::setw(6) << p.evaluations << "  "
       << (p.warm_start_won ? "warm " : "x0 ") << to_string(p.result.reason);
    log << os.str() << "\n";
  }
  log << "  (* no feasible point for this bound; d dominated by another front point; +- 95 % half-width)\n";
  if (r.report_out_of_sample.ok)
    log << "  2003 report profile (T = " << format_number(r.report_startup_time_s) << " s): in-sample "
        << format_fixed(r.report_in_sample.objective, 4) << ", out-of-sample "
        << format_fixed(r.report_out_of_sample.objective, 4) << " +- "
        << format_fixed(objective_half_width(settings, r.report_out_of_sample), 4) << "\n";

  nlohmann::json j;
  j["config"] = a.config;
  j["provenance"] = {{"abuopt_version", prov.abuopt_version},
                     {"git_commit", prov.git_commit},
                     {"config_hash", prov.config_hash}};
  j["method"] = "epsilon_constraint";
  j["algorithm"] = options.algorithm;
  j["max_evaluations"] = options.max_evaluations;
  j["warm_start"] = ps.warm_start;
  j["objective"] = {{"kind", problems::to_string(settings.objective.kind)}, {"label", objective_label(settings)}};
  j["montecarlo"] = {{"runs", settings.study.runs}, {"seed", settings.study.seed}};
  j["validation"] = {{"runs", settings.validation.runs}, {"seed", settings.validation.seed}};
  nlohmann::json pts = nlohmann::json::array();
  for (const auto& p : r.points) {
    nlohmann::json x = nlohmann::json::object();
    for (std::size_t i = 0; i < vars.size() && i < p.x.size(); ++i) x[vars[i].name] = p.x[i];
    pts.push_back({{"max_startup_time_s", p.epsilon},
                   {"problem_id", p.problem_id},
                   {"startup_time_s", p.startup_time_s},
                   {"x", x},
                   {"feasible", p.result.feasible},
                   {"dominated", p.dominated},
                   {"reason", to_string(p.result.reason)},
                   {"evaluations", p.evaluations},
                   {"starts", p.starts},
                   {"kept_start", p.warm_start_won ? "previous_best" : "x0"},
                   {"archive_hits", p.result.archive_hits},
                   {"in_sample", evaluation_json(in_sample_evaluation(p))},
                   {"out_of_sample", evaluation_json(p.out_of_sample)}});
  }
  j["points"] = pts;
  j["report_profile"] = {{"startup_time_s", r.report_startup_time_s},
                         {"in_sample", evaluation_json(r.report_in_sample)},
                         {"out_of_sample", evaluation_json(r.report_out_of_sample)}};
  j["interrupted"] = r.interrupted;
  j["files"] = {{"csv", (out / "pareto.csv").string()}, {"archive", (out / "archive.sqlite").string()}};
  j["plot"] = plot;
  write_file_atomic(out / "summary.json", j.dump(2) + "\n");
  log << "wrote " << (out / "pareto.csv").string() << ", " << (out / "summary.json").string() << "\n" << plot << "\n";
  if (a.json) std::cout << j.dump(2) << "\n";
  if (r.interrupted) {
    std::cerr << "abuopt: interrupted by " << stop_signal_name() << ": kept the " << r.points.size()
        << " points above (pareto.csv, summary.json) and every evaluation in the archive; rerun the same command to "
           "resume\n";
    return stop_exit_status();
  }
  for (const auto& p : r.points)
    if (p.result.feasible) return 0;
  return 3;
}

}  // namespace

void register_pareto(CLI::App& app) {
  auto args = std::make_shared<ParetoArgs>();
  CLI::App* sub = app.add_subcommand(
      "pareto",
      "Pareto front of startup time against the objective (mean |I_r|) by the epsilon-constraint method:\n"
      "for each bound in pareto.max_startup_time_s, the config's optimiser minimises the objective with\n"
      "startup time <= bound, from x0 and from the previous bound's best (the better is kept). Every evaluation is archived\n"
      "in OUT/archive.sqlite (a rerun resumes). Then each front point and the 2003 report's profile on\n"
      "fresh initial conditions (out of sample). Writes pareto.csv, summary.json, pareto.png/.pdf.\n"
      "pareto.method: nsga2 or moead instead: one run of pagmo's NSGA-II / MOEA/D on both objectives\n"
      "(pareto.max_evaluations, population, reference), archived in OUT/archive/, every front point out of\n"
      "sample; writes fronts.csv, hypervolume.csv, front_<config stem>.png, summary.json (docs/sweep.md).\n"
      "Exit status: 0 ok, 2 bad input, 3 no bound gave a feasible design, 4 a file could not be written,\n"
      "130 interrupted (Ctrl-C), 143 terminated (SIGTERM).");
  sub->add_option("config", args->config, "YAML config: the sections of `optimize` plus `pareto` (docs/sweep.md)")
      ->required();
  sub->add_option("--max-bounds", args->max_bounds,
                  "the most bounds (pareto.max_startup_time_s) one run accepts (default 100; each is an optimisation)");
  sub->add_option("--out", args->out, "output directory (default results/<config stem>)");
  sub->add_flag("--json", args->json, "print summary.json to stdout (progress goes to stderr)");
  sub->add_flag("--progress", args->progress,
                "show evaluations done, rate and ETA on stderr also when it is not a terminal (on a terminal: always)");
  sub->add_option("--threads", args->threads, "Monte Carlo worker threads (0 = all cores; overrides montecarlo.threads)");
  sub->callback([args] { set_exit_code(run_pareto_command(*args)); });
}

}  // namespace abuopt::app
