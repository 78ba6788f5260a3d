// abuopt sweep CONFIG: the design's free variables (or a subset) over a grid, Latin hypercube or
// Sobol' design, each point a Monte Carlo through the evaluation archive (a rerun evaluates only
// the missing points); sweep.csv, summary.json and plots. The logic is studies/sweep; this file
// parses, prints and writes summary.json. docs/sweep.md describes every key and output.
#include <atomic>
#include <csignal>
#include <cmath>
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
#include "abuopt/common/provenance.hpp"
#include "abuopt/common/text.hpp"
#include "abuopt/optimizer/evaluation_archive.hpp"
#include "abuopt/optimizer/optimizer_options.hpp"
#include "abuopt/problems/startup_profile_problem.hpp"
#include "abuopt/studies/sweep.hpp"
#include "commands/commands.hpp"

namespace abuopt::app {

namespace {

namespace fs = std::filesystem;

struct SweepArgs {
  std::string config;
  std::string out;
  bool json = false;
  std::optional<long> threads;
};

std::string point_text(const std::vector<opt::Variable>& vars, const std::vector<std::size_t>& swept,
                       const std::vector<double>& x) {
  std::ostringstream os;
  os << std::setprecision(5);
  for (std::size_t k = 0; k < swept.size(); ++k) os << (k ? " " : "") << vars[swept[k]].name << "=" << x[swept[k]];
  return os.str();
}

int run_sweep_command(const SweepArgs& a) {
  YamlReader root = YamlReader::load_file(a.config);
  problems::StartupProfileSettings settings = problems::read_startup_profile_settings(root);
  YamlReader optimizer = root.child("optimizer");
  YamlReader sao = root.child("sao");
  const opt::OptimizerOptions options = opt::read_optimizer_options(optimizer, &sao);  // constraint_tolerance
  YamlReader sweep_section = root.child("sweep");
  if (a.threads) {
    if (*a.threads < 0) throw ConfigError("--threads", std::to_string(*a.threads), "must be >= 0 (0 = all cores)");
    settings.threads = static_cast<std::size_t>(*a.threads);
  }
  problems::StartupProfileProblem problem(settings);
  const auto vars = problem.variables();
  const SweepSettings ss = read_sweep_settings(sweep_section, vars);
  finish_config(root);  // the file may also configure `abuopt optimize` and `abuopt pareto`
  const SweepPlan plan = plan_sweep(ss, vars, problem.initial_point());

  const fs::path out = a.out.empty() ? fs::path("results") / fs::path(a.config).stem() : fs::path(a.out);
  const OutputDirLock lock(out);
  const std::string id = problem.identity();
  opt::EvaluationArchive archive((out / "archive.sqlite").string(), id);
  archive.check_signature(problem);
  const Provenance prov = provenance_of(a.config);
  archive.record_metadata("sweep", a.config, prov.config_hash);

  std::ostream& log = a.json ? std::cerr : std::cout;
  const auto& st = problem.settings();
  log << "sweep " << a.config << ": problem " << id << ", " << to_string(plan.method) << " design, "
      << plan.x.size() << " points over";
  for (std::size_t k = 0; k < plan.swept.size(); ++k) {
    const auto& v = vars[plan.swept[k]];
    log << (k ? "," : "") << " " << v.name << " in [" << format_number(v.lower) << ", " << format_number(v.upper)
        << "]" << (plan.method == SweepMethod::Grid ? " (" + std::to_string(plan.levels[k]) + " levels)" : "");
  }
  log << "\n  Monte Carlo: " << st.study.runs << " runs per point, design " << to_string(st.study.design.kind)
      << ", seed " << st.study.seed << " (same for every point)\n";
  for (std::size_t i = 0; i < vars.size(); ++i) {
    bool swept = false;
    for (std::size_t k : plan.swept) swept = swept || k == i;
    if (!swept) log << "  " << vars[i].name << " fixed at x0 = " << format_number(problem.initial_point()[i]) << "\n";
  }
  log << "  archive " << (out / "archive.sqlite").string() << ": " << archive.count()
      << " stored evaluations of this problem (stored points are not recomputed)\n"
      << std::flush;

  const SweepProgress progress = [&](const SweepPoint& p, std::size_t done, std::size_t total, double elapsed) {
    std::ostringstream os;
    os << "point " << std::setw(4) << done << "/" << total << "  " << point_text(vars, plan.swept, p.x) << "  f=";
    if (p.e.ok)
      os << std::setprecision(6) << p.e.objective;
    else
      os << "FAILED (" << p.e.message << ")";
    os << "  viol=";
    if (p.e.ok)
      os << std::setprecision(3) << p.max_violation;
    else
      os << "-";
    os << (p.from_archive ? "  [archive]" : "  [computed " + format_number(std::round(p.wall_time_s * 10) / 10) + " s]");
    const double rate = elapsed > 0 ? static_cast<double>(done) / elapsed : 0;
    if (rate > 0) os << "  " << std::setprecision(3) << rate << " points/s";
    if (done < total && rate > 0) os << "  ETA " << std::llround(static_cast<double>(total - done) / rate) << " s";
    log << os.str() << "\n" << std::flush;
  };

  SweepResult r;
  {
    const StopScope stop_scope;  // SIGINT / SIGTERM stop after the current point (abuopt/common/stop.hpp)
    r = run_sweep(problem, archive, plan, progress, &stop_flag(), options.constraint_tolerance);
  }

  write_sweep_csv(out / "sweep.csv", problem, r);
  const std::vector<std::string> plots = write_sweep_plots(out, problem, r);

  const SweepPoint* best = best_feasible_point(r);

  nlohmann::json j;
  j["config"] = a.config;
  j["problem_id"] = id;
  j["provenance"] = {{"abuopt_version", prov.abuopt_version},
                     {"git_commit", prov.git_commit},
                     {"config_hash", prov.config_hash}};
  j["method"] = to_string(plan.method);
  nlohmann::json jv = nlohmann::json::array();
  for (std::size_t k = 0; k < plan.swept.size(); ++k) {
    const auto& v = vars[plan.swept[k]];
    nlohmann::json e = {{"name", v.name}, {"lower", v.lower}, {"upper", v.upper}};
    if (plan.method == SweepMethod::Grid) e["levels"] = plan.levels[k];
    jv.push_back(e);
  }
  j["swept"] = jv;
  if (plan.method == SweepMethod::Lhs) j["seed"] = ss.seed;
  j["points_planned"] = plan.x.size();
  j["points_evaluated"] = r.points.size();
  j["computed"] = r.computed;
  j["archive_hits"] = r.archive_hits;
  j["failed"] = r.failed;
  j["interrupted"] = r.interrupted;
  j["wall_time_s"] = r.wall_time_s;
  j["montecarlo"] = {{"runs", st.study.runs}, {"design", to_string(st.study.design.kind)}, {"seed", st.study.seed}};
  j["objective"] = {{"kind", problems::to_string(st.objective.kind)},
                    {"definition", problems::to_string(st.objective.definition)},
                    {"label", objective_label(st)}};
  j["constraints"] = problem.inequality_names();
  const auto r_lock = sweep_lock_radius_kgm(st);
  j["r_lock_kgm"] = r_lock ? nlohmann::json(*r_lock) : nlohmann::json(nullptr);  // depth_mean = mean |I_r| / r_lock
  if (best) {
    nlohmann::json bx = nlohmann::json::object();
    for (std::size_t i = 0; i < vars.size(); ++i) bx[vars[i].name] = best->x[i];
    j["best_feasible"] = {{"point", best->index + 1}, {"x", bx}, {"objective", best->e.objective}, {"metrics", best->e.metrics}};
  }
  j["files"] = {{"csv", (out / "sweep.csv").string()}, {"archive", (out / "archive.sqlite").string()}};
  j["plots"] = plots;
  write_file_atomic(out / "summary.json", j.dump(2) + "\n");

  log << "\n" << r.points.size() << " of " << plan.x.size() << " points (" << r.computed << " computed, "
      << r.archive_hits << " from the archive, " << r.failed << " failed) in " << std::fixed << std::setprecision(1)
      << r.wall_time_s << " s\n" << std::defaultfloat;
  if (best)
    log << "best feasible point: " << point_text(vars, plan.swept, best->x) << "  objective "
        << format_number(best->e.objective) << "\n";
  else
    log << "no feasible point in the sweep\n";
  log << "wrote " << (out / "sweep.csv").string() << ", " << (out / "summary.json").string() << "\n";
  for (const auto& m : plots) log << m << "\n";
  if (a.json) std::cout << j.dump(2) << "\n";
  if (r.interrupted) {
    std::cerr << "abuopt: interrupted by " << stop_signal_name() << ": kept the " << r.points.size()
        << " points above (sweep.csv, summary.json, the archive); rerun the same command to evaluate the remaining "
           "points (stored ones come from the archive)\n";
    return stop_exit_status();
  }
  return !r.points.empty() && r.failed == static_cast<long>(r.points.size()) ? 3 : 0;
}

}  // namespace

void register_sweep(CLI::App& app) {
  auto args = std::make_shared<SweepArgs>();
  CLI::App* sub = app.add_subcommand(
      "sweep",
      "Design sweep of a startup profile: the `design` section's free variables (or those listed in\n"
      "sweep.variables; the others stay at x0) over a grid, Latin hypercube or Sobol' design, each point\n"
      "a Monte Carlo over the same initial ball angles. Every evaluation is archived in OUT/archive.sqlite\n"
      "(shared with `optimize` on the same config): rerunning resumes. Writes sweep.csv (every point,\n"
      "every metric), summary.json and plots (1 variable: curve with 95 % error bars; 2: maps).\n"
      "Exit status: 0 ok, 2 bad input, 3 every point failed, 4 an output file could not be written,\n"
      "130 interrupted (Ctrl-C), 143 terminated (SIGTERM): the points so far are written.");
  sub->add_option("config", args->config, "YAML config: the sections of `optimize` plus `sweep` (docs/sweep.md)")
      ->required();
  sub->add_option("--out", args->out, "output directory (default results/<config stem>)");
  sub->add_flag("--json", args->json, "print summary.json to stdout (progress goes to stderr)");
  sub->add_option("--threads", args->threads, "Monte Carlo worker threads (0 = all cores; overrides montecarlo.threads)");
  sub->callback([args] { set_exit_code(run_sweep_command(*args)); });
}

}  // namespace abuopt::app
