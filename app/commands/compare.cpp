// abuopt compare CONFIG: runs several optimisers (NLopt algorithms, Ipopt, SAO variants) on several
// problems from several starts, prints a table, and writes runs/convergence/profile CSVs and plots.
//
// Config (see configs/compare/benchmarks.yaml):
//   tau: 0.01                        # solved: feasible and f - f* <= tau max(|f*|, 1)
//   problems:
//     - benchmark: rosenbrock        # a name of make_benchmark (noisy_<name> too)
//       label: rosenbrock2           # optional (default: the benchmark name)
//       dimension: 2                 # rosenbrock only
//       noise_amplitude: 1e-3        # noisy_* only
//       noise_seed: 1                # noisy_* only
//       noise_samples: 0             # noisy_* only: N > 0, a mean of N runs (sample size for SAO's adaptive schedule)
//       max_evaluations: 300         # budget of every run
//       starts: 3                    # initial point + 2 seeded random points
//       seed: 1
//       constraint_tolerance: 1e-6
//       f_star: 0                    # optional reference (default: best_known)
//     - startup_profile: {abu: ..., profile: ..., montecarlo: ..., design: ..., objective: ...,
//                         constraints: ...}   # the sections of an `abuopt optimize` config
//       label: startup_profile       # optional; max_evaluations, starts, seed, ... as above
//                                    # (see configs/compare/startup_profile.yaml)
//       validation_checkpoints: 20   # optional: also validate each run's incumbent at 20 evenly spaced
//                                    # evaluations (OUT/validated_convergence.csv; docs/benchmarks.md)
//   solvers:
//     - {label: SAO, algorithm: sao, sao: {...}}
//     - {label: COBYLA, algorithm: cobyla, options: {...}}   # options: the optimizer: keys
//     - {label: CMA-ES, algorithm: pagmo_cmaes}             # pagmo2: pagmo_cmaes/xnes/sade/pso
//     - {label: Optuna-TPE, external: DIR}    # runs made elsewhere: DIR/<problem>/start<k>.csv
//                                             # (examples/python/optuna_study.py; docs/benchmarks.md)
//   fronts:                                   # two-objective problems (studies/front_comparison.hpp):
//     - label: time_vs_imbalance              # NSGA-II against the epsilon-constraint series at equal
//       reference: {objective: 25, second: 23}  # evaluations, by hypervolume in and out of sample;
//       methods: [...]                        # fronts.csv, hypervolume.csv, front_<label>.png
//   (problems and solvers may be left out when fronts are given)
//
// Resumable: every run keeps its evaluations in OUT/archive/<problem>/start<k>-<solver>.sqlite (and
// the validations in OUT/archive/<problem>/validation.sqlite); the same command with the same --out
// after a Ctrl-C or a kill answers them bit for bit, so finished runs cost no simulation and the
// interrupted ones go on where they stopped. One progress line per run on stderr, with an ETA.
#include <algorithm>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "abuopt/common/stop.hpp"
#include "abuopt/common/config_error.hpp"
#include "abuopt/common/output_file.hpp"
#include "abuopt/common/progress.hpp"
#include "abuopt/optimizer/benchmarking.hpp"
#include "abuopt/optimizer/benchmarks/benchmark_factory.hpp"
#include "abuopt/problems/startup_profile_problem.hpp"
#include "abuopt/studies/front_comparison.hpp"
#include "abuopt/parallel/parallel.hpp"
#include "commands/commands.hpp"

namespace abuopt::app {

namespace {

struct CompareArgs {
  std::string config;
  std::string out;
  bool json = false, progress = false;
};

// The budget, starts, seed, tolerance and reference value of any problem entry.
void read_run_settings(YamlReader& r, opt::ProblemSpec& spec) {
  spec.max_evaluations = r.get_int_or("max_evaluations", 200, Rule::positive());
  spec.starts = static_cast<int>(r.get_int_or("starts", 1, Rule::in_range(1, 1000)));
  spec.seed = static_cast<std::uint64_t>(r.get_int_or("seed", 1, Rule::non_negative()));
  spec.constraint_tolerance = r.get_double_or("constraint_tolerance", 1e-6, Rule::non_negative());
  if (r.has("f_star")) spec.f_star = r.get_double("f_star");
}

// A `startup_profile:` entry: the sections of an `abuopt optimize` config (abu, profile, motor,
// simulation, montecarlo, design, objective, constraints, validation) read by the problem's own
// reader, so a comparison and an optimisation of the same design problem mean the same thing.
opt::ProblemSpec read_startup_profile_problem(YamlReader& r) {
  opt::ProblemSpec spec;
  YamlReader section = r.child("startup_profile");
  const problems::StartupProfileSettings settings = problems::read_startup_profile_settings(section);
  section.finish();
  problems::StartupProfileProblem check(settings);  // a bad design is a ConfigError now, before any run
  spec.label = r.get_string_or("label", "startup_profile");
  spec.identity = check.identity();  // the archive id of `optimize` on the same sections
  spec.validation_identity = check.validation_identity();  // a changed validation is computed anew
  // under mpirun every evaluation's Monte Carlo is spread over the ranks; the comparison's runs
  // (starts x solvers, `threads` at once) share them: their studies go into one pool of runs
  std::shared_ptr<BatchRunner> runner;
  const bool concurrent = parallel::session() && parallel::session()->concurrent_studies();
  if (parallel::session() && parallel::session()->size() > 1) runner = parallel::make_runner(settings.threads);
  spec.make = [settings, runner, concurrent] {
    return problems::make_startup_profile_problem(settings, runner, concurrent);
  };
  // every run's result checked out of sample, on the validation section's fresh runs (as optimize
  // does; validation.enabled: false turns it off): the constrained problem, whatever the penalty
  if (settings.validation.enabled) {
    auto validator = std::make_shared<const problems::StartupProfileProblem>(settings);
    spec.validate = [validator](const std::vector<double>& x) {
      return validator->evaluate_out_of_sample_at(x);  // the profile and, with design.ball_count, the balls at x
    };
  }
  read_run_settings(r, spec);
  spec.validation_checkpoints = static_cast<int>(
      r.get_int_or("validation_checkpoints", 0, Rule::in_range(0, std::min<long>(1000, spec.max_evaluations))));
  if (spec.validation_checkpoints > 0 && !spec.validate)
    throw ConfigError(r.key_path("validation_checkpoints"), std::to_string(spec.validation_checkpoints),
                      "needs the problem's validation (startup_profile.validation.enabled: true)");
  r.finish();
  return spec;
}

opt::ProblemSpec read_problem(YamlReader& r) {
  if (r.has("startup_profile")) {
    if (r.has("benchmark"))
      throw ConfigError(r.key_path("startup_profile"), "<section>", "give either benchmark or startup_profile, not both");
    return read_startup_profile_problem(r);
  }
  opt::ProblemSpec spec;
  const std::string name = r.get_string("benchmark");
  opt::benchmarks::BenchmarkSettings settings;
  settings.dimension = static_cast<int>(r.get_int_or("dimension", settings.dimension, Rule::in_range(2, 10)));
  settings.noise_amplitude = r.get_double_or("noise_amplitude", settings.noise_amplitude, Rule::in_range(0, 0.999));
  settings.noise_seed =
      static_cast<std::uint64_t>(r.get_int_or("noise_seed", static_cast<long>(settings.noise_seed), Rule::non_negative()));
  settings.noise_samples = static_cast<std::size_t>(
      r.get_int_or("noise_samples", static_cast<long>(settings.noise_samples), Rule::in_range(0, 1 << 24)));
  opt::benchmarks::make_benchmark(name, settings);  // an unknown name is a ConfigError now, listing the valid ones
  spec.label = r.get_string_or("label", name == "rosenbrock" || name == "noisy_rosenbrock"
                                            ? name + std::to_string(settings.dimension)
                                            : name);
  spec.make = [name, settings] { return opt::benchmarks::make_benchmark(name, settings); };
  // everything that fixes the benchmark's values, as the archive's problem id
  spec.identity = name + "/d" + std::to_string(settings.dimension) + "/a" + opt::format_number(settings.noise_amplitude) +
                  "/s" + std::to_string(settings.noise_seed) + "/n" + std::to_string(settings.noise_samples);
  read_run_settings(r, spec);
  r.finish();
  return spec;
}

// The default output folder: results/compare-<config stem>, the same for every run of the same
// config, so that a plain rerun after an interruption resumes from OUT/archive/.
std::string default_out(const std::string& config) {
  return "results/compare-" + std::filesystem::path(config).stem().string();
}

nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

int run_compare(const CompareArgs& a) {
  YamlReader root = YamlReader::load_file(a.config);
  opt::ComparisonSetup setup;
  setup.tau = root.get_double_or("tau", setup.tau, Rule::in_range(1e-12, 0.999));
  setup.threads = static_cast<int>(root.get_int_or("threads", setup.threads, Rule::in_range(1, 256)));
  for (YamlReader& p : root.children("problems")) setup.problems.push_back(read_problem(p));
  for (YamlReader& s : root.children("solvers")) setup.solvers.push_back(opt::read_solver_spec(s));
  std::vector<FrontProblem> fronts;
  for (YamlReader& f : root.children("fronts")) fronts.push_back(read_front_problem(f));
  root.finish();
  // under mpirun the runs go `threads` at once only if the ranks take studies from several threads;
  // then each run's batches of evaluations are spread too (as in `optimize`)
  if (parallel::session() && parallel::session()->size() > 1) {
    if (!parallel::session()->concurrent_studies()) setup.threads = 1;
    for (opt::SolverSpec& s : setup.solvers) s.options.scheduler = parallel::make_evaluation_scheduler();
  }
  if (setup.problems.empty() && fronts.empty())
    throw ConfigError("problems", "<missing>", "must list at least one problem (or a two-objective one under fronts)");
  if (setup.solvers.empty() && !setup.problems.empty())
    throw ConfigError("solvers", "<missing>", "must list at least one solver");
  const bool single = !setup.problems.empty();

  std::size_t total = 0;
  for (const auto& p : setup.problems) total += static_cast<std::size_t>(p.starts) * setup.solvers.size();
  const std::string out = a.out.empty() ? default_out(a.config) : a.out;
  const OutputDirLock lock(out);  // one run per output directory (created here)
  // every run keeps its evaluations in OUT/archive/: a rerun of a killed comparison resumes
  setup.archive_directory = (std::filesystem::path(out) / "archive").string();
  ProgressReporter bar("compare", "runs", total, a.progress ? ProgressMode::Always : ProgressMode::Auto);
  // ETA from the runs that computed something (replayed runs take no time): the wall time so far per
  // such run, times the runs still to go
  const auto started = std::chrono::steady_clock::now();
  std::size_t computed_runs = 0;
  long computed_evaluations = 0, archived_evaluations = 0;
  setup.on_run_ended = [&](const opt::RunRecord& r, std::size_t ended, std::size_t all) {
    const long computed = r.result.evaluations - r.result.archive_hits;
    computed_evaluations += computed;
    archived_evaluations += r.result.archive_hits;
    if (computed > 0) ++computed_runs;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    std::ostringstream line;
    line << "[" << ended << "/" << all << "] " << r.problem << " start " << r.start << " " << r.solver << ": "
         << r.result.brief_report();
    if (r.result.samples > 0) line << "; " << r.result.samples << " simulations";
    if (r.validation)
      line << "; out of sample f = " << opt::format_number(r.validation->objective)
           << (r.validation_feasible ? " feasible" : " infeasible (violation " +
                                                         opt::format_number(opt::max_constraint_violation(*r.validation)) + ")")
           << (r.validation_from_archive ? " [archive]" : "");
    line << "; elapsed " << format_duration(elapsed);
    if (ended < all && computed_runs > 0)
      line << ", ETA " << format_duration(elapsed / static_cast<double>(computed_runs) * static_cast<double>(all - ended));
    bar.message(line.str());
    bar.update(ended);
  };
  const StopScope stop_scope;  // SIGINT / SIGTERM end every run after its current evaluation
  const opt::ComparisonResult result = single ? opt::run_comparison(setup) : opt::ComparisonResult{};
  bar.finish();
  // the two-objective problems: after the single-objective ones, their runs archived under
  // OUT/archive/fronts/ (resumable alike)
  FrontComparison front_result;
  if (!fronts.empty() && !stop_requested()) {
    std::size_t front_runs = 0;
    for (const auto& f : fronts) front_runs += static_cast<std::size_t>(f.seeds) * f.methods.size();
    ProgressReporter front_bar("compare fronts", "runs", front_runs,
                               a.progress ? ProgressMode::Always : ProgressMode::Auto);
    const auto front_started = std::chrono::steady_clock::now();
    front_result = run_front_comparison(
        fronts, (std::filesystem::path(setup.archive_directory) / "fronts").string(), setup.threads,
        [&](const FrontRun& r, std::size_t ended, std::size_t all) {
          const double elapsed =
              std::chrono::duration<double>(std::chrono::steady_clock::now() - front_started).count();
          std::ostringstream line;
          line << "[front " << ended << "/" << all << "] " << r.problem << " run " << r.run << " " << r.method << ": "
               << r.evaluations << " evaluations, " << r.points.size() << " front points, hypervolume "
               << opt::format_number(r.hv_in) << " in sample";
          if (r.validated)
            line << ", " << opt::format_number(r.hv_out) << " out of sample (" << r.points_out << " points feasible)";
          line << "; " << r.reason << "; elapsed " << format_duration(elapsed);
          if (ended < all)
            line << ", ETA " << format_duration(elapsed / static_cast<double>(ended) * static_cast<double>(all - ended));
          front_bar.message(line.str());
          front_bar.update(ended);
        });
    front_bar.finish();
  }
  if (stop_requested())  // the tables and profiles need every run: none is written
    throw Interrupted("interrupted by " + stop_signal_name() + ": kept " + std::to_string(computed_evaluations) +
                      " computed evaluations in " + setup.archive_directory +
                      "; no result file is written (the comparison needs every run); rerun the same command "
                      "with --out " + out + " to resume");
  if (single)
    std::cerr << "compare: " << computed_evaluations << " evaluations computed, " << archived_evaluations
              << " answered from the archive (" << setup.archive_directory << ")\n";

  opt::WrittenFiles files;
  if (single) files = opt::write_comparison(result, out);
  if (!fronts.empty()) write_front_outputs(front_result, out, files);

  if (a.json) {
    nlohmann::json j;
    j["config"] = a.config;
    j["tau"] = result.tau;
    j["out"] = out;
    j["problems"] = nlohmann::json::array();
    for (std::size_t p = 0; p < result.problems.size(); ++p)
      j["problems"].push_back({{"label", result.problems[p]},
                               {"f_star", number(result.f_star[p])},
                               {"f_star_source", result.f_star_source[p]}});
    j["solvers"] = result.solvers;
    j["runs"] = nlohmann::json::array();
    for (const auto& r : result.runs)
      j["runs"].push_back({{"problem", r.problem},
                           {"start", r.start},
                           {"solver", r.solver},
                           {"algorithm", r.result.algorithm},
                           {"reason", opt::to_string(r.result.reason)},
                           {"best_true_objective", number(r.best_true_objective)},
                           {"feasible", r.feasible},
                           {"evaluations", r.result.evaluations},
                           {"evaluations_to_tau", r.evaluations_to_solve},
                           {"samples", r.result.samples},
                           {"archive_hits", r.result.archive_hits},
                           {"computed_evaluations", r.result.evaluations - r.result.archive_hits},
                           {"validated_objective", r.validation ? number(r.validation->objective) : nlohmann::json()},
                           {"validated_feasible", r.validation ? nlohmann::json(r.validation_feasible) : nlohmann::json()},
                           {"wall_time_s", r.result.wall_time_s}});
    j["fronts"] = nlohmann::json::array();
    for (const auto& r : front_result.runs)
      j["fronts"].push_back({{"problem", r.problem},
                             {"method", r.method},
                             {"run", r.run},
                             {"evaluations", r.evaluations},
                             {"budget", r.budget},
                             {"points", r.points.size()},
                             {"hv_in", number(r.hv_in)},
                             {"hv_out", r.validated ? number(r.hv_out) : nlohmann::json()},
                             {"points_out", r.validated ? nlohmann::json(r.points_out) : nlohmann::json()},
                             {"reason", r.reason}});
    j["files"] = files.files;
    j["skipped_plots"] = files.skipped_plots;
    std::cout << j.dump(2) << "\n";
  } else {
    if (single) std::cout << opt::format_table(result);
    if (!fronts.empty()) std::cout << format_front_table(front_result);
    std::cout << "\nwritten to " << out << "/: "
              << (single ? "runs.csv, convergence.csv, data_profile.csv, performance_profile.csv, plots.gp" : "")
              << (single && !fronts.empty() ? ", " : "")
              << (fronts.empty() ? "" : "fronts.csv, hypervolume.csv, front_<problem>.gp");
    if (files.skipped_plots.empty()) std::cout << " and the PNG plots (gnuplot " << files.gnuplot << ")\n";
    else std::cout << "\n";
  }
  if (!files.skipped_plots.empty()) {
    std::cerr << "plots skipped (" << (files.gnuplot.empty() ? "gnuplot not found" : "gnuplot failed, see gnuplot.log")
              << "):";
    for (const auto& s : files.skipped_plots) std::cerr << " " << s;
    std::cerr << "\n";
  }
  // A solver that evaluated no point in any run (it refused every start, or failed before
  // evaluating) has no place in the profiles: the comparison is then no usable result (exit 3).
  std::vector<std::string> idle;
  for (const std::string& solver : result.solvers) {
    const opt::RunRecord* example = nullptr;
    bool evaluated = false;
    for (const auto& r : result.runs)
      if (r.solver == solver) {
        evaluated = evaluated || r.result.evaluations > 0;
        if (!example) example = &r;
      }
    if (!evaluated && example) {
      idle.push_back(solver);
      std::cerr << "abuopt: solver " << solver << " evaluated no point in any run: "
                << opt::to_string(example->result.reason)
                << (example->result.message.empty() ? std::string() : " (" + example->result.message + ")") << "\n";
    }
  }
  if (!idle.empty()) {
    std::cerr << "abuopt: the comparison is incomplete (" << idle.size() << " of " << result.solvers.size()
              << " solvers evaluated nothing)\n";
    return 3;
  }
  return 0;
}

}  // namespace

void register_compare(CLI::App& app) {
  auto args = std::make_shared<CompareArgs>();
  CLI::App* sub = app.add_subcommand(
      "compare",
      "Compare optimisers (NLopt algorithms, IPOPT, SAO) on benchmark problems from several starts, each\n"
      "with an evaluation budget: a table (solved runs, evaluations to reach tau, best value, feasibility,\n"
      "time), convergence curves, data profiles and performance profiles (CSV, and PNG + PDF with gnuplot).\n"
      "Two-objective problems (fronts:): NSGA-II against the epsilon-constraint series at equal evaluations,\n"
      "by hypervolume in and out of sample (fronts.csv, hypervolume.csv, front_<problem>.png).\n"
      "Every evaluation is archived in OUT/archive/: rerunning the same command (same config, same --out or\n"
      "none) after an interruption resumes (stored evaluations are answered from the archive, bit for bit).\n"
      "Exit status: 0 ok, 2 bad input, 3 a solver evaluated no point in any run, 4 an output file could not be written,\n"
      "130 interrupted (Ctrl-C), 143 terminated (SIGTERM): the archive keeps every finished evaluation.");
  sub->add_option("config", args->config, "YAML config (tau, problems, solvers; see configs/compare/)")->required();
  sub->add_option("--out", args->out,
                  "output directory (default results/compare-<config stem>/: a rerun of the same config resumes there)");
  sub->add_flag("--json", args->json, "print one JSON object (runs and files) instead of the table");
  sub->add_flag("--progress", args->progress, "show runs done, rate and ETA on stderr also when it is not a terminal");
  sub->callback([args] { set_exit_code(run_compare(*args)); });
}

}  // namespace abuopt::app
