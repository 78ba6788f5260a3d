// Two-objective problems of `abuopt compare`: reading and running (front_comparison.hpp).
#include "abuopt/studies/front_comparison.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <memory>
#include <mutex>
#include <set>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/stop.hpp"
#include "abuopt/common/text.hpp"
#include "abuopt/optimizer/evaluation_archive.hpp"
#include "abuopt/optimizer/evaluation_scheduler.hpp"
#include "abuopt/optimizer/multi_objective.hpp"
#include "abuopt/studies/pareto.hpp"

namespace abuopt {

namespace {

namespace fs = std::filesystem;

FrontMethod read_method(YamlReader& r, const FrontProblem& fp, std::size_t dimension) {
  FrontMethod m;
  const std::string algorithm = r.get_string("algorithm");
  m.label = r.get_string_or("label", algorithm);
  if (m.label.empty()) throw ConfigError(r.key_path("label"), "\"\"", "must not be empty");
  if (algorithm == "pagmo_nsga2" || algorithm == "pagmo_moead") {
    m.kind = algorithm == "pagmo_moead" ? FrontMethod::Kind::Moead : FrontMethod::Kind::Nsga2;
    YamlReader options = r.child("options");
    if (options.present()) {
      if (options.has("algorithm"))
        throw ConfigError(options.key_path("algorithm"), yaml_value_text(options.node()["algorithm"]),
                          "give the algorithm once, as " + r.key_path("algorithm"));
      m.options = opt::read_optimizer_options(options);
    }
    m.options.population = r.get_int_or("population", m.options.population > 0 ? m.options.population : 20,
                                        Rule::in_range(4, 100000));
    const char* name = m.kind == FrontMethod::Kind::Moead ? "MOEA/D" : "NSGA-II";
    if (m.kind == FrontMethod::Kind::Nsga2 && (m.options.population < 8 || m.options.population % 4 != 0))
      throw ConfigError(r.key_path("population"), std::to_string(m.options.population),
                        "NSGA-II needs a multiple of 4, at least 8");
    if (m.options.population > fp.max_evaluations)
      throw ConfigError(r.key_path("population"), std::to_string(m.options.population),
                        "must be <= max_evaluations (" + std::to_string(fp.max_evaluations) + "): " + name +
                            " needs at least one population");
  } else if (algorithm == "epsilon_constraint") {
    m.kind = FrontMethod::Kind::EpsilonConstraint;
    if (fp.second_objective != "startup_time_s")
      throw ConfigError(r.key_path("algorithm"), algorithm,
                        "bounds the startup time only: second_objective must be startup_time_s (it is " +
                            fp.second_objective + ")");
    m.bounds_s = r.get_double_list("bounds_s", Rule::positive());
    if (m.bounds_s.size() < 2)
      throw ConfigError(r.key_path("bounds_s"), std::to_string(m.bounds_s.size()) + " values", "a front needs >= 2 bounds");
    std::sort(m.bounds_s.begin(), m.bounds_s.end());
    for (std::size_t i = 1; i < m.bounds_s.size(); ++i)
      if (m.bounds_s[i] == m.bounds_s[i - 1])
        throw ConfigError(r.key_path("bounds_s"), format_number(m.bounds_s[i]), "listed twice");
    if (!(fp.reference.second >= m.bounds_s.back()))
      throw ConfigError(r.key_path("bounds_s"), format_number(m.bounds_s.back()),
                        "the loosest bound must not lie beyond reference.second (" + format_number(fp.reference.second) +
                            "): the fronts are compared inside the reference");
    m.warm_start = r.get_bool_or("warm_start", true);
    YamlReader inner = r.child("inner");
    if (inner.present()) {
      if (inner.has("then") || inner.has("external"))
        throw ConfigError(inner.key_path(inner.has("then") ? "then" : "external"), "<section>",
                          "the inner optimiser of an epsilon-constraint series is one algorithm");
      m.options = opt::read_solver_spec(inner).options;
    } else {
      m.options.algorithm = "cobyla";
    }
    const long inner_budget = epsilon_constraint_inner_budget(fp.max_evaluations, m.bounds_s.size(), m.warm_start);
    if (inner_budget < static_cast<long>(dimension) + 2)
      throw ConfigError(r.key_path("bounds_s"), std::to_string(m.bounds_s.size()) + " bounds",
                        "max_evaluations " + std::to_string(fp.max_evaluations) + " split over " +
                            std::to_string(epsilon_constraint_runs(m.bounds_s.size(), m.warm_start)) + " runs leaves " +
                            std::to_string(inner_budget) + " evaluations per run; needs >= dimension + 2 = " +
                            std::to_string(dimension + 2) + " (fewer bounds, warm_start: false or a larger budget)");
  } else {
    throw ConfigError(r.key_path("algorithm"), algorithm,
                      "a two-objective method is pagmo_nsga2, pagmo_moead or epsilon_constraint");
  }
  r.finish();
  return m;
}

}  // namespace

std::size_t epsilon_constraint_runs(std::size_t bounds, bool warm_start) {
  return bounds == 0 ? 0 : (warm_start ? 2 * bounds - 1 : bounds);
}

long epsilon_constraint_inner_budget(long budget, std::size_t bounds, bool warm_start) {
  const std::size_t runs = epsilon_constraint_runs(bounds, warm_start);
  return runs == 0 ? 0 : budget / static_cast<long>(runs);
}

FrontProblem pareto_front_problem(const problems::StartupProfileSettings& base, const opt::OptimizerOptions& options,
                                  const ParetoSettings& pareto, const std::string& label) {
  const bool moead = pareto.method == ParetoSettings::Method::Moead;
  if (pareto.method == ParetoSettings::Method::EpsilonConstraint)
    throw ConfigError("pareto.method", "epsilon_constraint", "is run_pareto's series, not a population method");
  const std::string method = to_string(pareto.method);
  if (base.constraints.max_startup_time_s)
    throw ConfigError("constraints.max_startup_time_s", format_number(*base.constraints.max_startup_time_s),
                      "must be absent for method " + method + ": the startup time is the front's second objective");
  if (base.constraints.penalty_weight > 0)
    throw ConfigError("constraints.penalty_weight", format_number(base.constraints.penalty_weight),
                      "must be 0 for method " + method + ": " + (moead ? "MOEA/D" : "NSGA-II") +
                          " sees the constraints itself (feasibility rules)");
  opt::check_two_objective_population(moead ? opt::TwoObjectiveMethod::Moead : opt::TwoObjectiveMethod::Nsga2,
                                      pareto.population, pareto.max_evaluations, "pareto.population",
                                      "pareto.max_evaluations");
  FrontProblem fp;
  fp.label = label;
  fp.settings = base;
  fp.second_objective = "startup_time_s";
  fp.max_evaluations = pareto.max_evaluations;
  fp.seeds = 1;
  fp.seed = options.seed;
  fp.constraint_tolerance = options.constraint_tolerance;
  fp.reference = pareto.reference;
  FrontMethod m;
  m.kind = moead ? FrontMethod::Kind::Moead : FrontMethod::Kind::Nsga2;
  m.label = moead ? "MOEA/D" : "NSGA-II";
  m.options = options;
  m.options.population = pareto.population;
  fp.methods.push_back(m);
  return fp;
}

FrontProblem read_front_problem(YamlReader& r) {
  FrontProblem fp;
  fp.label = r.get_string("label");
  if (fp.label.empty()) throw ConfigError(r.key_path("label"), "\"\"", "must not be empty");
  fp.second_objective = r.get_string_or("second_objective", fp.second_objective);
  if (fp.second_objective.empty())
    throw ConfigError(r.key_path("second_objective"), "\"\"", "must name a metric of the problem's evaluations");
  fp.max_evaluations = r.get_int_or("max_evaluations", fp.max_evaluations, Rule::positive());
  fp.seeds = static_cast<int>(r.get_int_or("seeds", 1, Rule::in_range(1, 1000)));
  fp.seed = static_cast<std::uint64_t>(r.get_int_or("seed", 1, Rule::non_negative()));
  fp.constraint_tolerance = r.get_double_or("constraint_tolerance", 1e-6, Rule::non_negative());
  YamlReader ref = r.child("reference");
  if (!ref.present())
    throw ConfigError(r.key_path("reference"), "<missing>",
                      "is required: {objective: F, second: S}, the hypervolume's reference point, beyond every front");
  fp.reference.first = ref.get_double("objective", Rule::positive());
  fp.reference.second = ref.get_double("second", Rule::positive());
  ref.finish();

  YamlReader section = r.child("startup_profile");
  if (!section.present())
    throw ConfigError(r.key_path("startup_profile"), "<missing>",
                      "is required: a two-objective problem is the startup-profile problem");
  fp.settings = problems::read_startup_profile_settings(section);
  section.finish();
  if (fp.second_objective == "startup_time_s" && fp.settings.constraints.max_startup_time_s)
    throw ConfigError(section.key_path("constraints") + ".max_startup_time_s",
                      format_number(*fp.settings.constraints.max_startup_time_s),
                      "must be absent: the startup time is an objective here (the epsilon-constraint bounds it per run)");
  if (fp.settings.constraints.penalty_weight > 0)
    throw ConfigError(section.key_path("constraints") + ".penalty_weight",
                      format_number(fp.settings.constraints.penalty_weight),
                      "must be 0 for a front: both methods see the constraints themselves");
  const problems::StartupProfileProblem check(fp.settings);  // a bad design is a ConfigError now
  const std::size_t dimension = check.variables().size();

  std::set<std::string> labels;
  for (YamlReader& m : r.children("methods")) {
    fp.methods.push_back(read_method(m, fp, dimension));
    if (!labels.insert(fp.methods.back().label).second)
      throw ConfigError(m.key_path("label"), fp.methods.back().label, "duplicate method label");
  }
  if (fp.methods.empty()) throw ConfigError(r.key_path("methods"), "<missing>", "must list at least one method");
  r.finish();
  return fp;
}

namespace {

// The run's in-sample points: sorted by objective, each marked non-dominated or not.
void finish_points(std::vector<FrontPoint>& points) {
  std::sort(points.begin(), points.end(), [](const FrontPoint& a, const FrontPoint& b) {
    return a.objective < b.objective || (a.objective == b.objective && a.second < b.second);
  });
  for (FrontPoint& p : points) {
    p.non_dominated = true;
    for (const FrontPoint& q : points)
      if (&q != &p && q.objective <= p.objective && q.second <= p.second &&
          (q.objective < p.objective || q.second < p.second))
        p.non_dominated = false;
  }
}

// The options of one run: the problem's budget share, seed + k, its tolerance; no SIGINT handler of
// its own (the command's StopScope ends every run); with runs at once, evaluations one at a time
// unless the method says otherwise (as the single-objective runs).
opt::OptimizerOptions run_options(const FrontProblem& fp, const FrontMethod& m, long budget, int k, int threads) {
  opt::OptimizerOptions o = m.options;
  o.max_evaluations = budget;
  o.seed = fp.seed + static_cast<unsigned long>(k);
  o.constraint_tolerance = fp.constraint_tolerance;
  o.handle_sigint = false;
  o.keep_history = true;
  if (threads > 1 && o.evaluation_threads == 0) o.evaluation_threads = 1;
  return o;
}

void run_pagmo(const FrontProblem& fp, const FrontMethod& m, const std::vector<double>& x0, int k, int threads,
               const std::string& archive_path, FrontRun& run) {
  problems::StartupProfileProblem problem(fp.settings);
  std::unique_ptr<opt::EvaluationArchive> archive;
  std::unique_ptr<opt::ArchivedProblem> archived;
  if (!archive_path.empty()) {
    archive = std::make_unique<opt::EvaluationArchive>(archive_path, problem.identity());
    archived = std::make_unique<opt::ArchivedProblem>(problem, *archive);
  }
  opt::Problem& target = archived ? static_cast<opt::Problem&>(*archived) : problem;
  const opt::OptimizerOptions o = run_options(fp, m, fp.max_evaluations, k, threads);
  const opt::TwoObjectiveResult r = opt::minimize_two_objectives(
      target, fp.second_objective, o, x0,
      m.kind == FrontMethod::Kind::Moead ? opt::TwoObjectiveMethod::Moead : opt::TwoObjectiveMethod::Nsga2);
  run.evaluations = r.run.evaluations;
  run.reason = opt::to_string(r.run.reason);
  for (std::size_t i : r.front) {
    const opt::EvaluationRecord& h = r.run.history[i];
    FrontPoint p;
    p.objective = h.objective;
    p.second = h.metrics.at(fp.second_objective);
    p.x = h.x;
    run.points.push_back(std::move(p));
  }
}

void run_epsilon_constraint(const FrontProblem& fp, const FrontMethod& m, const std::vector<double>& x0, int k,
                            int threads, const std::string& archive_path, FrontRun& run) {
  ParetoSettings ps;
  ps.max_startup_time_s = m.bounds_s;
  ps.warm_start = m.warm_start;
  run.inner_budget = epsilon_constraint_inner_budget(fp.max_evaluations, m.bounds_s.size(), m.warm_start);
  const opt::OptimizerOptions o = run_options(fp, m, run.inner_budget, k, threads);
  // without an archive file, a temporary one (run_pareto keeps its runs in one)
  fs::path path = archive_path;
  const bool temporary = path.empty();
  if (temporary)
    path = fs::temp_directory_path() /
           ("abuopt-front-" + std::to_string(std::hash<std::string>{}(fp.label + m.label)) + "-" + std::to_string(k) +
            "-" + std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()) + ".sqlite");
  const ParetoResult pr = run_pareto(fp.settings, o, ps, path.string(), "compare", "", {}, false, x0);
  if (temporary) {
    std::error_code ec;
    for (const char* suffix : {"", "-wal", "-shm", "-journal"}) fs::remove(path.string() + suffix, ec);
  }
  for (const ParetoPoint& p : pr.points) {
    run.evaluations += p.evaluations;
    run.reason = opt::to_string(p.result.reason);
    if (p.x.empty() || !p.result.feasible) continue;
    FrontPoint f;
    f.objective = p.result.objective;
    f.second = p.startup_time_s;
    f.x = p.x;
    run.points.push_back(std::move(f));
  }
}

}  // namespace

FrontComparison run_front_comparison(
    const std::vector<FrontProblem>& problems, const std::string& archive_directory, int threads,
    const std::function<void(const FrontRun&, std::size_t, std::size_t)>& on_run_ended) {
  FrontComparison out;
  out.problems = problems;
  std::set<std::string> labels;
  std::size_t total = 0, ended = 0;
  for (const FrontProblem& fp : problems) {
    if (!labels.insert(fp.label).second) throw ConfigError("fronts", fp.label, "duplicate front label");
    total += static_cast<std::size_t>(fp.seeds) * fp.methods.size();
  }
  std::mutex ended_mutex;
  for (const FrontProblem& fp : problems) {
    const auto validator = std::make_shared<const problems::StartupProfileProblem>(fp.settings);
    const auto starts = opt::starting_points(*validator, fp.seeds, fp.seed);
    const fs::path dir = archive_directory.empty() ? fs::path() : fs::path(archive_directory) / file_safe(fp.label);
    std::unique_ptr<opt::EvaluationArchive> validation_archive;
    if (!archive_directory.empty()) {
      std::error_code ec;
      fs::create_directories(dir, ec);
      if (ec) throw ConfigError("archive directory '" + dir.string() + "' cannot be created: " + ec.message());
      if (fp.settings.validation.enabled)
        validation_archive = std::make_unique<opt::EvaluationArchive>(
            (dir / "validation.sqlite").string(),
            validator->identity() + "/validation/" + validator->validation_identity());
    }
    const std::size_t first = out.runs.size();
    const std::size_t tasks = static_cast<std::size_t>(fp.seeds) * fp.methods.size();
    out.runs.resize(first + tasks);
    auto task = [&](std::size_t t) {
      const int k = static_cast<int>(t / fp.methods.size());
      const FrontMethod& m = fp.methods[t % fp.methods.size()];
      FrontRun run;
      run.problem = fp.label;
      run.method = m.label;
      run.run = k;
      run.budget = fp.max_evaluations;
      const std::string archive_path =
          dir.empty() ? std::string() : (dir / ("run" + std::to_string(k) + "-" + file_safe(m.label) + ".sqlite")).string();
      const auto started = std::chrono::steady_clock::now();
      try {
        if (m.kind != FrontMethod::Kind::EpsilonConstraint) run_pagmo(fp, m, starts[k], k, threads, archive_path, run);
        else run_epsilon_constraint(fp, m, starts[k], k, threads, archive_path, run);
      } catch (const std::exception& e) {  // recorded, never fatal to the other runs
        run.points.clear();
        run.reason = std::string("failure: ") + e.what();
      }
      finish_points(run.points);
      // every front point out of sample (unless the comparison is being stopped)
      if (fp.settings.validation.enabled && !stop_requested()) {
        run.validated = true;
        for (FrontPoint& p : run.points) {
          if (validation_archive) p.validation = validation_archive->find(p.x);
          if (!p.validation) {
            const auto t0 = std::chrono::steady_clock::now();
            try {
              p.validation = validator->evaluate_out_of_sample_at(p.x);
              if (validation_archive)
                validation_archive->store(p.x, *p.validation,
                                          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
            } catch (const std::exception& e) {
              p.validation = opt::Evaluation::failed(std::string("validation threw: ") + e.what());
            }
          }
          const auto it = p.validation->metrics.find(fp.second_objective);
          p.validated_second = it != p.validation->metrics.end() ? it->second : p.second;
          p.validated_feasible = p.validation->ok && std::isfinite(p.validation->objective) &&
                                 std::isfinite(p.validated_second) &&
                                 opt::is_feasible(*p.validation, fp.constraint_tolerance);
        }
      }
      std::vector<std::pair<double, double>> in, valid;
      for (const FrontPoint& p : run.points) {
        in.emplace_back(p.objective, p.second);
        if (p.validated_feasible) valid.emplace_back(p.validation->objective, p.validated_second);
      }
      run.hv_in = opt::hypervolume_2d(in, fp.reference);
      run.hv_out = opt::hypervolume_2d(valid, fp.reference);
      run.points_out = valid.size();
      run.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      out.runs[first + t] = std::move(run);
      if (on_run_ended) {
        const std::lock_guard<std::mutex> lock(ended_mutex);
        on_run_ended(out.runs[first + t], ++ended, total);
      }
    };
    opt::ThreadScheduler(static_cast<std::size_t>(std::max(1, threads))).run(tasks, task);
  }
  return out;
}

}  // namespace abuopt
