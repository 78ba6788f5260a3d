// Comparison of optimisers: runs, solve matrix, data and performance profiles, CSV and gnuplot.
#include "abuopt/optimizer/benchmarking.hpp"

#include "abuopt/optimizer/evaluation_scheduler.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <mutex>
#include <random>
#include <set>
#include <sstream>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/gnuplot.hpp"
#include "abuopt/common/plot_style.hpp"
#include "abuopt/common/output_file.hpp"
#include "abuopt/common/text.hpp"
#include "abuopt/optimizer/algorithms.hpp"
#include "abuopt/optimizer/evaluation_archive.hpp"
#include "abuopt/optimizer/minimize.hpp"
#include "abuopt/optimizer/two_stage.hpp"

namespace abuopt::opt {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double true_objective(const EvaluationRecord& r, const std::string& metric) {
  if (!metric.empty())
    if (auto it = r.metrics.find(metric); it != r.metrics.end()) return it->second;
  return r.objective;
}

double solved_threshold(double f_star, double tau) { return tau * std::max(std::fabs(f_star), 1.0); }

using abuopt::csv_number;
std::string csv_text(const std::string& s) { return abuopt::csv_field(s); }

using abuopt::file_safe;

}  // namespace

SolverSpec solver_spec(const std::string& label, const std::string& algorithm) {
  SolverSpec s;
  s.label = label;
  find_algorithm(algorithm, "solver " + label + ": algorithm");
  s.options.algorithm = algorithm;
  return s;
}

SolverSpec read_solver_spec(YamlReader& r) {
  SolverSpec s;
  if (r.has("external")) {
    s.external_runs = r.get_string("external");
    if (s.external_runs.empty()) throw ConfigError(r.key_path("external"), "\"\"", "must name a directory");
    s.label = r.get_string("label");
    if (s.label.empty()) throw ConfigError(r.key_path("label"), "\"\"", "must not be empty");
    r.finish();  // an external solver has no algorithm, options or stages
    return s;
  }
  const std::string algorithm = r.get_string("algorithm");
  find_algorithm(algorithm, r.key_path("algorithm"));
  s.label = r.get_string_or("label", algorithm);
  if (s.label.empty()) throw ConfigError(r.key_path("label"), "\"\"", "must not be empty");
  YamlReader options = r.child("options");
  if (options.present()) {
    if (options.has("algorithm"))
      throw ConfigError(options.key_path("algorithm"), yaml_value_text(options.node()["algorithm"]),
                        "give the algorithm once, as " + r.key_path("algorithm"));
    if (options.has("sao"))
      throw ConfigError(options.key_path("sao"), "<section>", "give the SAO settings as " + r.key_path("sao"));
    s.options = read_optimizer_options(options);
  }
  s.options.algorithm = algorithm;
  YamlReader sao = r.child("sao");
  if (sao.present()) {
    if (find_algorithm(algorithm, r.key_path("algorithm")).name != "SAO")
      throw ConfigError(r.key_path("sao"), "<section>", "only for algorithm sao (this solver is " + algorithm + ")");
    s.options.sao = read_sao_options(sao);
  }
  YamlReader then = r.child("then");
  if (then.present()) {
    if (then.has("then")) throw ConfigError(then.key_path("then"), "<section>", "two stages at most");
    SolverSpec second = read_solver_spec(then);
    s.then = second.options;
    s.first_fraction = r.get_double_or("first_fraction", s.first_fraction, Rule::in_range(1e-6, 1 - 1e-6));
    s.penalty_weight = r.get_double_or("penalty_weight", s.penalty_weight, Rule::positive());
  }
  r.finish();
  return s;
}

std::vector<std::vector<double>> starting_points(const Problem& problem, int starts, std::uint64_t seed) {
  std::vector<std::vector<double>> out = {problem.initial_point()};
  const std::vector<Variable> vars = problem.variables();
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 1; k < starts; ++k) {
    std::vector<double> x(vars.size());
    for (std::size_t i = 0; i < vars.size(); ++i) x[i] = vars[i].lower + u(rng) * (vars[i].upper - vars[i].lower);
    out.push_back(std::move(x));
  }
  return out;
}

bool counts_as_problem_value(const EvaluationRecord& h, std::size_t full_sample_size, const std::string& metric) {
  if (full_sample_size == 0 || (!metric.empty() && h.metrics.count(metric))) return true;
  const auto runs = h.metrics.find("runs");
  return runs == h.metrics.end() || runs->second >= static_cast<double>(full_sample_size);
}

long evaluations_to_solve(const OptimizationResult& result, double f_star, double tau, const std::string& metric,
                          std::size_t full_sample_size) {
  const double threshold = solved_threshold(f_star, tau);
  for (const EvaluationRecord& h : result.history)
    if (h.feasible && counts_as_problem_value(h, full_sample_size, metric) && true_objective(h, metric) - f_star <= threshold)
      return h.index + 1;
  return -1;
}

std::vector<std::vector<double>> ComparisonResult::solve_matrix() const {
  std::map<std::pair<std::string, int>, std::size_t> row_of;
  std::vector<std::vector<double>> t;
  std::map<std::string, std::size_t> col;
  for (std::size_t s = 0; s < solvers.size(); ++s) col[solvers[s]] = s;
  for (const RunRecord& r : runs) {
    auto key = std::make_pair(r.problem, r.start);
    auto it = row_of.find(key);
    if (it == row_of.end()) {
      it = row_of.emplace(key, t.size()).first;
      t.emplace_back(solvers.size(), kInf);
    }
    t[it->second][col.at(r.solver)] = r.evaluations_to_solve > 0 ? static_cast<double>(r.evaluations_to_solve) : kInf;
  }
  return t;
}

std::vector<std::size_t> ComparisonResult::instance_dimensions() const {
  std::set<std::pair<std::string, int>> seen;
  std::vector<std::size_t> dims;
  for (const RunRecord& r : runs)
    if (seen.insert({r.problem, r.start}).second) dims.push_back(r.dimension);
  return dims;
}

std::vector<double> data_profile(const std::vector<std::vector<double>>& t, const std::vector<std::size_t>& dims,
                                 std::size_t solver, const std::vector<double>& alphas) {
  std::vector<double> d;
  for (double alpha : alphas) {
    std::size_t solved = 0;
    for (std::size_t p = 0; p < t.size(); ++p)
      if (t[p][solver] <= alpha * static_cast<double>(dims[p] + 1)) ++solved;
    d.push_back(t.empty() ? 0.0 : static_cast<double>(solved) / static_cast<double>(t.size()));
  }
  return d;
}

std::vector<std::vector<double>> performance_ratios(const std::vector<std::vector<double>>& t) {
  std::vector<std::vector<double>> r = t;
  for (std::size_t p = 0; p < t.size(); ++p) {
    const double best = *std::min_element(t[p].begin(), t[p].end());
    for (std::size_t s = 0; s < t[p].size(); ++s) r[p][s] = std::isfinite(best) && std::isfinite(t[p][s]) ? t[p][s] / best : kInf;
  }
  return r;
}

std::vector<double> performance_profile(const std::vector<std::vector<double>>& t, std::size_t solver,
                                        const std::vector<double>& taus) {
  const auto r = performance_ratios(t);
  std::vector<double> rho;
  for (double tau : taus) {
    std::size_t count = 0;
    for (const auto& row : r)
      if (row[solver] <= tau) ++count;
    rho.push_back(r.empty() ? 0.0 : static_cast<double>(count) / static_cast<double>(r.size()));
  }
  return rho;
}

ComparisonResult run_comparison(const ComparisonSetup& setup) {
  if (setup.problems.empty()) throw ConfigError("compare.problems", "[]", "must list at least one problem");
  if (setup.solvers.empty()) throw ConfigError("compare.solvers", "[]", "must list at least one solver");
  if (!(setup.tau > 0 && setup.tau < 1)) throw ConfigError("compare.tau", format_number(setup.tau), "must be in (0, 1)");
  std::set<std::string> labels;
  for (const ProblemSpec& p : setup.problems) {
    if (!labels.insert(p.label).second) throw ConfigError("compare.problems", p.label, "duplicate problem label");
    if (!p.make) throw ConfigError("compare.problems", p.label, "has no factory");
    if (p.max_evaluations <= 0)
      throw ConfigError("compare.problems[" + p.label + "].max_evaluations", std::to_string(p.max_evaluations), "must be > 0");
    if (p.starts < 1) throw ConfigError("compare.problems[" + p.label + "].starts", std::to_string(p.starts), "must be >= 1");
  }
  labels.clear();
  for (const SolverSpec& s : setup.solvers) {
    if (!labels.insert(s.label).second) throw ConfigError("compare.solvers", s.label, "duplicate solver label");
    if (find_algorithm(s.options.algorithm).name == "SAO") s.options.sao.validate("compare.solvers[" + s.label + "].sao");
    s.options.validate();
    if (s.then) s.then->validate();
    if (!s.external_runs.empty())  // every external run exists before anything runs
      for (const ProblemSpec& p : setup.problems)
        for (int k = 0; k < p.starts; ++k)
          if (!std::filesystem::exists(external_run_path(s.external_runs, p.label, k)))
            throw ConfigError("compare.solvers[" + s.label + "].external", external_run_path(s.external_runs, p.label, k),
                              "no such file: every problem and start needs its external run (made e.g. by "
                              "examples/python/optuna_study.py)");
  }

  ComparisonResult out;
  out.tau = setup.tau;
  for (const SolverSpec& s : setup.solvers) out.solvers.push_back(s.label);
  std::size_t total_runs = 0, ended = 0;
  for (const ProblemSpec& p : setup.problems) total_runs += static_cast<std::size_t>(p.starts) * setup.solvers.size();
  std::mutex ended_mutex;
  for (const ProblemSpec& spec : setup.problems) {
    out.problems.push_back(spec.label);
    std::unique_ptr<Problem> probe = spec.make();
    const auto starts = starting_points(*probe, spec.starts, spec.seed);
    const std::size_t first_run = out.runs.size();
    // the runs of this problem are independent: each has its own problem instance, start and seed,
    // and lands in its own slot, so the results do not depend on how many run at once
    const std::size_t tasks = static_cast<std::size_t>(spec.starts) * setup.solvers.size();
    out.runs.resize(first_run + tasks);
    // resumable: one archive per run, and one of the validations of this problem
    const bool archived = !setup.archive_directory.empty();
    const std::string identity = spec.identity.empty() ? spec.label : spec.identity;
    const std::filesystem::path archive_dir = std::filesystem::path(setup.archive_directory) / file_safe(spec.label);
    std::unique_ptr<EvaluationArchive> validation_archive;
    if (archived) {
      std::error_code ec;
      std::filesystem::create_directories(archive_dir, ec);
      if (ec) throw ConfigError("archive directory '" + archive_dir.string() + "' cannot be created: " + ec.message());
      if (spec.validate)
        validation_archive = std::make_unique<EvaluationArchive>(
            (archive_dir / "validation.sqlite").string(),
            identity + "/validation" + (spec.validation_identity.empty() ? "" : "/" + spec.validation_identity));
    }
    auto run_task = [&](std::size_t t) {
      const int k = static_cast<int>(t / setup.solvers.size());
      const SolverSpec& solver = setup.solvers[t % setup.solvers.size()];
      {
        std::unique_ptr<Problem> fresh = spec.make();
        std::unique_ptr<EvaluationArchive> archive;
        std::unique_ptr<ArchivedProblem> archived_problem;
        if (archived) {
          const std::string file = "start" + std::to_string(k) + "-" + file_safe(solver.label) + ".sqlite";
          archive = std::make_unique<EvaluationArchive>((archive_dir / file).string(), identity);
          archived_problem = std::make_unique<ArchivedProblem>(*fresh, *archive);
        }
        Problem* problem = archived ? static_cast<Problem*>(archived_problem.get()) : fresh.get();
        OptimizerOptions o = solver.options;
        o.max_evaluations = spec.max_evaluations;
        o.constraint_tolerance = spec.constraint_tolerance;
        o.seed = spec.seed + static_cast<unsigned long>(k);
        o.keep_history = true;
        // one handler owner at a time; with archives Ctrl-C ends the whole comparison (what is
        // stored stays), not one run that the comparison would then record as finished
        o.handle_sigint = o.handle_sigint && setup.threads <= 1 && !archived;
        // runs already go at once: their evaluations go one at a time unless the solver says otherwise
        if (setup.threads > 1 && o.evaluation_threads == 0) o.evaluation_threads = 1;
        RunRecord rec;
        rec.problem = spec.label;
        rec.solver = solver.label;
        rec.start = k;
        rec.dimension = problem->dimension();
        rec.sample_size = problem->sample_size();
        rec.x0 = starts[k];
        try {
          if (!solver.external_runs.empty()) {
            rec.result = read_external_run(external_run_path(solver.external_runs, spec.label, k), *problem,
                                           spec.constraint_tolerance, spec.max_evaluations);
            rec.result.algorithm = "external";
          } else if (solver.then) {
            TwoStageOptions two;
            two.first = o;
            two.then = *solver.then;
            two.then.constraint_tolerance = o.constraint_tolerance;
            two.then.seed = o.seed;
            two.then.handle_sigint = o.handle_sigint;
            if (setup.threads > 1 && two.then.evaluation_threads == 0) two.then.evaluation_threads = 1;
            two.first_fraction = solver.first_fraction;
            two.penalty_weight = solver.penalty_weight;
            rec.result = minimize_two_stage(*problem, two, spec.max_evaluations, starts[k]);
          } else {
            rec.result = minimize(*problem, o, starts[k]);
          }
        } catch (const ConfigError& e) {
          // e.g. a bound-only global algorithm on a constrained problem: recorded as a failed run
          rec.result.problem_name = problem->name();
          rec.result.algorithm = o.algorithm;
          rec.result.reason = TerminationReason::Failure;
          rec.result.message = e.what();
        }
        double best = kInf;
        for (const EvaluationRecord& h : rec.result.history) {
          if (!h.feasible || !counts_as_problem_value(h, rec.sample_size, setup.true_objective_metric)) continue;
          const double f = true_objective(h, setup.true_objective_metric);
          if (f < best) {
            best = f;
            rec.convergence.push_back({h.index + 1, f});
          }
        }
        rec.best_true_objective = best;
        rec.feasible = std::isfinite(best);
        // out of sample: stored validations answer again (bit for bit), a point is validated once per run
        std::map<std::vector<double>, std::pair<Evaluation, bool>> validated;  // x -> (value, from archive)
        auto validate_at = [&](const std::vector<double>& x) -> const std::pair<Evaluation, bool>& {
          auto it = validated.find(x);
          if (it != validated.end()) return it->second;
          std::optional<Evaluation> e;
          if (validation_archive) e = validation_archive->find(x);
          const bool stored = e.has_value();
          if (!e) {
            const auto started = std::chrono::steady_clock::now();
            try {
              e = spec.validate(x);
              if (validation_archive)
                validation_archive->store(x, *e,
                                          std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
            } catch (const std::exception& ex) {
              e = Evaluation::failed(std::string("validation threw: ") + ex.what());
            }
          }
          return validated.emplace(x, std::make_pair(std::move(*e), stored)).first->second;
        };
        if (spec.validate && spec.validation_checkpoints > 0) {
          // the incumbent (as the convergence curve counts it) at each checkpoint
          const long budget = spec.max_evaluations, c = spec.validation_checkpoints;
          const EvaluationRecord* incumbent = nullptr;
          double incumbent_f = kInf;
          std::size_t i = 0;
          for (long j = 1; j <= c; ++j) {
            const long at = (j * budget + c - 1) / c;
            for (; i < rec.result.history.size() && rec.result.history[i].index < at; ++i) {
              const EvaluationRecord& h = rec.result.history[i];
              if (!h.feasible || !counts_as_problem_value(h, rec.sample_size, setup.true_objective_metric)) continue;
              const double f = true_objective(h, setup.true_objective_metric);
              if (f < incumbent_f) incumbent_f = f, incumbent = &h;
            }
            if (!incumbent) continue;
            const Evaluation& e = validate_at(incumbent->x).first;
            rec.validated_convergence.push_back(
                {at, e.objective, max_constraint_violation(e), e.ok && is_feasible(e, spec.constraint_tolerance)});
          }
        }
        if (spec.validate && !rec.result.x.empty()) {
          const auto& v = validate_at(rec.result.x);
          rec.validation = v.first;
          rec.validation_from_archive = v.second;
          rec.validation_feasible = is_feasible(*rec.validation, spec.constraint_tolerance);
        }
        out.runs[first_run + t] = std::move(rec);
      }
      if (setup.on_run_ended) {
        const std::lock_guard<std::mutex> lock(ended_mutex);
        setup.on_run_ended(out.runs[first_run + t], ++ended, total_runs);
      }
    };
    // the runs are one batch of independent tasks on the evaluation scheduler's threads
    ThreadScheduler(static_cast<std::size_t>(std::max(1, setup.threads))).run(tasks, run_task);
    // the reference value f*
    double f_star = kInf;
    std::string source = "none";
    if (spec.f_star) {
      f_star = *spec.f_star;
      source = "given";
    } else if (auto bk = probe->best_known()) {
      f_star = bk->objective;
      source = "best_known";
    } else {
      for (std::size_t i = first_run; i < out.runs.size(); ++i) f_star = std::min(f_star, out.runs[i].best_true_objective);
      if (std::isfinite(f_star)) source = "best_found";
    }
    out.f_star.push_back(f_star);
    out.f_star_source.push_back(source);
    for (std::size_t i = first_run; i < out.runs.size(); ++i) {
      RunRecord& rec = out.runs[i];
      rec.evaluations_to_solve =
          std::isfinite(f_star) ? evaluations_to_solve(rec.result, f_star, setup.tau, setup.true_objective_metric,
                                                      rec.sample_size)
                               : -1;
      if (setup.on_run) setup.on_run(rec);
    }
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Reports

std::string format_table(const ComparisonResult& r) {
  std::ostringstream os;
  os << "tau = " << format_number(r.tau) << ": solved = feasible and f - f* <= tau max(|f*|, 1)\n";
  os << std::left << std::setw(22) << "problem" << std::setw(16) << "solver" << std::right << std::setw(8) << "solved"
     << std::setw(12) << "evals@tau" << std::setw(16) << "best f" << std::setw(10) << "feasible" << std::setw(10)
     << "evals" << std::setw(11) << "time [s]" << "\n";
  for (std::size_t p = 0; p < r.problems.size(); ++p) {
    for (const std::string& solver : r.solvers) {
      std::vector<long> solved;
      int runs = 0, feasible = 0;
      double best = kInf, evals = 0, time = 0;
      for (const RunRecord& run : r.runs) {
        if (run.problem != r.problems[p] || run.solver != solver) continue;
        ++runs;
        if (run.evaluations_to_solve > 0) solved.push_back(run.evaluations_to_solve);
        if (run.feasible) ++feasible;
        best = std::min(best, run.best_true_objective);
        evals += static_cast<double>(run.result.evaluations);
        time += run.result.wall_time_s;
      }
      if (runs == 0) continue;
      std::string median = "-";
      if (!solved.empty()) {
        std::sort(solved.begin(), solved.end());
        const std::size_t m = solved.size();
        const double med = m % 2 ? static_cast<double>(solved[m / 2]) : 0.5 * static_cast<double>(solved[m / 2 - 1] + solved[m / 2]);
        median = format_number(med);
      }
      std::ostringstream bestf;
      if (std::isfinite(best)) bestf << std::setprecision(8) << best;
      else bestf << "-";
      std::ostringstream t;
      t << std::fixed << std::setprecision(3) << time / runs;
      os << std::left << std::setw(22) << r.problems[p] << std::setw(16) << solver << std::right << std::setw(8)
         << (std::to_string(solved.size()) + "/" + std::to_string(runs)) << std::setw(12) << median << std::setw(16)
         << bestf.str() << std::setw(10) << (std::to_string(feasible) + "/" + std::to_string(runs)) << std::setw(10)
         << static_cast<long>(std::lround(evals / runs)) << std::setw(11) << t.str() << "\n";
    }
    os << std::left << std::setw(22) << "" << "f* = " << std::setprecision(10) << r.f_star[p] << " ("
       << r.f_star_source[p] << ")\n";
  }
  return os.str();
}

std::string find_gnuplot() { return Gnuplot::find(); }

namespace {

// A result file: collected, then written whole under its name by commit() (OutputError when the
// write fails: nothing half-written is left under the final name).
class OutFile {
 public:
  OutFile(const std::filesystem::path& path, WrittenFiles& written) : file_(path), written_(written) {}
  template <class T>
  OutFile& operator<<(const T& v) {
    file_.stream() << v;
    return *this;
  }
  void commit() {
    file_.commit();
    written_.files.push_back(file_.path().string());
  }

 private:
  AtomicFile file_;
  WrittenFiles& written_;
};

// Abscissae of the profiles: alpha in [0, max budget / (n_p + 1)], tau in [1, max finite ratio].
std::vector<double> alpha_grid(const ComparisonResult& r) {
  double top = 1;
  for (const RunRecord& run : r.runs)
    top = std::max(top, static_cast<double>(run.result.evaluations) / static_cast<double>(run.dimension + 1));
  std::vector<double> a;
  const int steps = 200;
  for (int i = 0; i <= steps; ++i) a.push_back(top * i / steps);
  return a;
}

std::vector<double> tau_grid(const std::vector<std::vector<double>>& t) {
  double top = 2;
  for (const auto& row : performance_ratios(t))
    for (double v : row)
      if (std::isfinite(v)) top = std::max(top, v * 1.1);
  std::vector<double> taus;
  const int steps = 200;
  for (int i = 0; i <= steps; ++i) taus.push_back(std::pow(top, static_cast<double>(i) / steps));
  return taus;
}

}  // namespace

WrittenFiles write_comparison(const ComparisonResult& r, const std::string& directory, bool make_plots) {
  namespace fs = std::filesystem;
  WrittenFiles written;
  std::error_code ec;
  fs::create_directories(directory, ec);
  if (ec) throw ConfigError("output directory '" + directory + "' cannot be created: " + ec.message());
  const fs::path dir(directory);

  {
    OutFile f(dir / "runs.csv", written);
    f << "problem,start,solver,algorithm,dimension,x0,reason,best_true_objective,feasible,objective,max_violation,"
         "evaluations,evaluations_to_tau,f_star,wall_time_s,samples,validated_objective,validated_max_violation,"
         "validated_feasible,message,x\n";
    for (const RunRecord& run : r.runs) {
      std::string x0;
      for (double v : run.x0) x0 += (x0.empty() ? "" : " ") + format_number(v);
      const std::size_t p = static_cast<std::size_t>(
          std::find(r.problems.begin(), r.problems.end(), run.problem) - r.problems.begin());
      f << csv_text(run.problem) << "," << run.start << "," << csv_text(run.solver) << ","
        << csv_text(run.result.algorithm) << "," << run.dimension << "," << x0 << "," << to_string(run.result.reason)
        << "," << csv_number(run.best_true_objective) << "," << (run.feasible ? 1 : 0) << ","
        << csv_number(run.result.objective) << "," << csv_number(run.result.max_violation) << ","
        << run.result.evaluations << "," << run.evaluations_to_solve << "," << csv_number(r.f_star[p]) << ","
        << csv_number(run.result.wall_time_s) << "," << run.result.samples << ",";
      if (run.validation)
        f << csv_number(run.validation->objective) << "," << csv_number(max_constraint_violation(*run.validation)) << ","
          << (run.validation_feasible ? 1 : 0) << ",";
      else
        f << ",,,";
      std::string x;  // the run's best point (what was validated)
      for (double v : run.result.x) x += (x.empty() ? "" : " ") + format_number(v);
      f << csv_text(run.result.message) << "," << x << "\n";
    }
    f.commit();
  }
  {
    OutFile f(dir / "convergence.csv", written);
    f << "problem,start,solver,evaluation,best_feasible_true_objective,relative_gap\n";
    for (const RunRecord& run : r.runs) {
      const std::size_t p = static_cast<std::size_t>(
          std::find(r.problems.begin(), r.problems.end(), run.problem) - r.problems.begin());
      for (const ConvergencePoint& c : run.convergence) {
        const double gap = (c.best - r.f_star[p]) / std::max(std::fabs(r.f_star[p]), 1.0);
        f << csv_text(run.problem) << "," << run.start << "," << csv_text(run.solver) << "," << c.evaluation << ","
          << csv_number(c.best) << "," << csv_number(gap) << "\n";
      }
    }
    f.commit();
  }
  if (std::any_of(r.runs.begin(), r.runs.end(), [](const RunRecord& run) { return !run.validated_convergence.empty(); })) {
    OutFile f(dir / "validated_convergence.csv", written);
    f << "problem,start,solver,evaluation,validated_objective,validated_max_violation,validated_feasible\n";
    for (const RunRecord& run : r.runs)
      for (const ValidatedCheckpoint& c : run.validated_convergence)
        f << csv_text(run.problem) << "," << run.start << "," << csv_text(run.solver) << "," << c.evaluation << ","
          << csv_number(c.objective) << "," << csv_number(c.max_violation) << "," << (c.feasible ? 1 : 0) << "\n";
    f.commit();
  }
  const auto t = r.solve_matrix();
  const auto dims = r.instance_dimensions();
  {
    OutFile f(dir / "data_profile.csv", written);
    const auto alphas = alpha_grid(r);
    std::vector<std::vector<double>> d;
    for (std::size_t s = 0; s < r.solvers.size(); ++s) d.push_back(data_profile(t, dims, s, alphas));
    f << "alpha";
    for (const auto& s : r.solvers) f << "," << csv_text(s);
    f << "\n";
    for (std::size_t i = 0; i < alphas.size(); ++i) {
      f << format_number(alphas[i]);
      for (std::size_t s = 0; s < r.solvers.size(); ++s) f << "," << format_number(d[s][i]);
      f << "\n";
    }
    f.commit();
  }
  {
    OutFile f(dir / "performance_profile.csv", written);
    const auto taus = tau_grid(t);
    std::vector<std::vector<double>> rho;
    for (std::size_t s = 0; s < r.solvers.size(); ++s) rho.push_back(performance_profile(t, s, taus));
    f << "tau";
    for (const auto& s : r.solvers) f << "," << csv_text(s);
    f << "\n";
    for (std::size_t i = 0; i < taus.size(); ++i) {
      f << format_number(taus[i]);
      for (std::size_t s = 0; s < r.solvers.size(); ++s) f << "," << format_number(rho[s][i]);
      f << "\n";
    }
    f.commit();
  }

  // Convergence curves of start 0: one data block per solver that has a curve, per problem. A
  // solver without a feasible point has no block (gnuplot's `index` counts the blocks that are
  // there, so an empty block would shift every later curve onto the wrong name); it is named in
  // the key instead. A gap of 0 (f* reached) cannot be drawn on the log axis: it is drawn on a floor
  // line (a tenth of the smallest positive gap of the problem's curves), labelled "f* reached", so
  // a solver that reaches f* keeps a visible curve to the end of its run.
  struct Curve {
    std::string solver;
    long index = -1;            // data block; -1: no feasible point
    long reached_at = -1;       // evaluation at which the gap became <= 0; -1: never
  };
  std::vector<std::string> pngs = {"data_profile.png", "performance_profile.png"};
  std::vector<std::string> conv_files;
  std::vector<std::vector<Curve>> curves(r.problems.size());
  std::vector<double> floors(r.problems.size(), 1e-12);
  for (std::size_t p = 0; p < r.problems.size(); ++p) {
    const std::string name = "convergence_" + file_safe(r.problems[p]) + ".dat";
    OutFile f(dir / name, written);
    const double scale = std::max(std::fabs(r.f_star[p]), 1.0);
    double smallest = std::numeric_limits<double>::infinity();
    for (const RunRecord& run : r.runs)
      if (run.problem == r.problems[p] && run.start == 0)
        for (const ConvergencePoint& c : run.convergence) {
          const double gap = (c.best - r.f_star[p]) / scale;
          if (gap > 0 && std::isfinite(gap)) smallest = std::min(smallest, gap);
        }
    const double floor_gap = std::isfinite(smallest) ? std::max(smallest / 10, 1e-300) : 1e-12;
    floors[p] = floor_gap;
    long blocks = 0;
    for (const std::string& solver : r.solvers) {
      Curve curve;
      curve.solver = solver;
      std::ostringstream block;
      for (const RunRecord& run : r.runs) {
        if (run.problem != r.problems[p] || run.solver != solver || run.start != 0) continue;
        for (std::size_t i = 0; i < run.convergence.size(); ++i) {
          double gap = (run.convergence[i].best - r.f_star[p]) / scale;
          if (std::isnan(gap)) continue;
          if (!(gap > 0)) {
            if (curve.reached_at < 0) curve.reached_at = run.convergence[i].evaluation;
            gap = floor_gap;  // drawn on the "f* reached" line
          }
          block << run.convergence[i].evaluation << " " << format_number(gap) << "\n";
          const long next = i + 1 < run.convergence.size() ? run.convergence[i + 1].evaluation : run.result.evaluations;
          if (next > run.convergence[i].evaluation) block << next << " " << format_number(gap) << "\n";  // staircase
        }
      }
      if (!block.str().empty()) {
        f << "# " << solver << "\n" << block.str() << "\n\n";
        curve.index = blocks++;
      }
      curves[p].push_back(curve);
    }
    conv_files.push_back(name);
    pngs.push_back("convergence_" + file_safe(r.problems[p]) + ".png");
    f.commit();
  }

  {
    // Every text from the setup (solver and problem labels) goes through Gnuplot::quote (with
    // noenhanced: shown literally, see plot_style.hpp): a label cannot end the string and add a
    // command. Each figure is drawn as PNG, then replotted as PDF (plot_style.hpp).
    OutFile f(dir / "plots.gp", written);
    const std::size_t ns = r.solvers.size();
    const Gnuplot probe;
    const std::string png_terminal = make_plots && probe.available() ? probe.terminal() : std::string("pngcairo");
    const int w = ns > 6 ? 1200 : 900, h = 600;  // many methods: the key goes beside the plot (below)
    auto begin_figure = [&](const std::string& png) {
      f << plot_style::png_terminal_line(png_terminal, w, h) << "set output " << Gnuplot::quote(png) << "\n";
    };
    auto end_figure = [&](const std::string& png) {
      f << plot_style::pdf_terminal_line(w, h) << "set output "
        << Gnuplot::quote(fs::path(png).replace_extension(".pdf").string()) << "\nreplot\nunset output\n";
    };
    f << "# gnuplot script written by abuopt compare; run in this folder: gnuplot plots.gp (PNG and PDF of each figure)\n";
    begin_figure("data_profile.png");
    // with many methods the key would cover the curves: it goes beside the plot
    const std::string key_inside_at = ns > 6 ? "outside right top" : "";
    f << plot_style::preamble() << "set datafile separator ','\nset key "
      << (key_inside_at.empty() ? "bottom right" : key_inside_at) << "\nset grid\nset yrange [0:1.05]\n";
    f << "set title 'Data profile (τ = " << format_number(r.tau)
      << "): fraction of problems solved within α (n_p + 1) evaluations'\n"
      << "set xlabel 'α = evaluations / (n_p + 1)'\nset ylabel 'd_s(α)'\nplot ";
    for (std::size_t s = 0; s < ns; ++s)
      f << (s ? ", " : "") << "'data_profile.csv' using 1:" << s + 2 << " with steps lt " << s + 1 << " title "
        << plot_style::literal(r.solvers[s]);
    f << "\n";
    end_figure("data_profile.png");
    begin_figure("performance_profile.png");
    f << "set title 'Performance profile (τ = " << format_number(r.tau)
      << "): evaluations relative to the best solver'\nset logscale x 2\n"
      << "set xlabel 'ratio r to the best solver'\nset ylabel 'ρ_s(r)'\nplot ";
    for (std::size_t s = 0; s < ns; ++s)
      f << (s ? ", " : "") << "'performance_profile.csv' using 1:" << s + 2 << " with steps lt " << s + 1 << " title "
        << plot_style::literal(r.solvers[s]);
    f << "\n";
    end_figure("performance_profile.png");
    f << "unset logscale x\nset datafile separator whitespace\nset autoscale y\nset logscale y\nset key "
      << (key_inside_at.empty() ? "top right" : key_inside_at) << "\n"
      << "set format y '10^{%L}'\n";
    for (std::size_t p = 0; p < r.problems.size(); ++p) {
      begin_figure(pngs[2 + p]);
      f << "set title " << plot_style::typeset("Convergence on " + plot_style::escape(r.problems[p]) +
                                               " (first start): best feasible (f - f^*) / max(|f^*|, 1)")
        << "\nset xlabel 'evaluations'\n"
        << "set ylabel 'relative gap to f^*'\nset yrange [" << format_number(floors[p] / 3) << ":*]\n"
        << "plot " << format_number(floors[p]) << " with lines lc rgb '#7f7f7f' dt 2 lw 1 title "
        << plot_style::literal("f* reached (gap 0, drawn at " + abuopt::format_significant(floors[p], 2) + ")") << ", ";
      for (std::size_t s = 0; s < curves[p].size(); ++s) {
        const Curve& c = curves[p][s];
        f << (s ? ", " : "");
        const std::string title =
            c.solver + (c.reached_at < 0 ? "" : " (reaches f* at evaluation " + std::to_string(c.reached_at) + ")");
        // The solver's colour is its column in the setup, whether or not it has a curve.
        if (c.index < 0) {  // nothing to draw: no feasible point, or a gap of 0 from the first one
          f << "NaN with lines lt " << s + 1 << " title "
            << plot_style::literal(c.reached_at < 0 ? c.solver + " (no feasible point)" : title);
          continue;
        }
        f << Gnuplot::quote(conv_files[p]) << " index " << c.index << " using 1:2 with lines lt " << s + 1 << " title "
          << plot_style::literal(title);
      }
      f << "\n";
      end_figure(pngs[2 + p]);
    }
    f.commit();
  }

  const Gnuplot gp;
  written.gnuplot = make_plots ? gp.executable() : "";
  if (written.gnuplot.empty()) {
    written.skipped_plots = pngs;
  } else {
    // No shell: gnuplot runs with an argument vector, in the output directory.
    std::error_code ec;
    auto pdf_of = [](const std::string& png) { return fs::path(png).replace_extension(".pdf").string(); };
    for (const std::string& png : pngs) {
      fs::remove(dir / png, ec);
      fs::remove(dir / pdf_of(png), ec);
    }
    const fs::path abs = fs::absolute(dir);
    const int rc = gp.run_script("plots.gp", abs.string(), (abs / "gnuplot.log").string());
    auto made = [&](const std::string& file) { return fs::exists(dir / file, ec) && fs::file_size(dir / file, ec) > 0; };
    for (const std::string& png : pngs) {
      if (rc == 0 && made(png) && made(pdf_of(png))) {
        written.files.push_back((dir / png).string());
        written.files.push_back((dir / pdf_of(png)).string());
      } else {
        written.skipped_plots.push_back(png);
      }
    }
  }
  return written;
}

}  // namespace abuopt::opt
