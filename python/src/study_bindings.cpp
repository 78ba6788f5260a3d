// abuopt.optimize, abuopt.sweep, abuopt.pareto: the studies of `abuopt optimize`, `sweep` and
// `pareto` from Python, through the same library functions (studies/optimize_run.hpp, sweep.hpp,
// pareto.hpp) on a config read by the same readers. Results are dicts with attribute access (as
// scipy.optimize.OptimizeResult) holding NumPy arrays. The work runs on a worker thread with the
// GIL released; Ctrl-C stops it at the library's next safe point (within the current evaluation)
// and raises KeyboardInterrupt (what was evaluated stays in the archive when `out` is given).
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <csignal>
#include <exception>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <pybind11/eval.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <yaml-cpp/yaml.h>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/config_sections.hpp"
#include "abuopt/common/output_file.hpp"
#include "abuopt/common/provenance.hpp"
#include "abuopt/common/stop.hpp"
#include "abuopt/optimizer/evaluation_archive.hpp"
#include "abuopt/optimizer/optimizer_options.hpp"
#include "abuopt/problems/startup_profile_problem.hpp"
#include "abuopt/studies/optimize_run.hpp"
#include "abuopt/studies/pareto.hpp"
#include "abuopt/studies/sweep.hpp"
#include "bindings.hpp"
#include "convert.hpp"
#include "interruptible.hpp"

namespace py = pybind11;
namespace fs = std::filesystem;

namespace abuopt::python {

namespace {

using Array = py::array_t<double>;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

template <typename T>
void set_key(YAML::Node root, const char* section, const char* key, const std::optional<T>& value) {
  if (value) root[section][key] = *value;
}

struct Loaded {
  YAML::Node node;
  std::string config;  // the path as given, or "<dict>"
  std::string hash;    // of the file's bytes, or of the dict's YAML text
};

// The config (path or dict) with the keyword arguments written into its keys, so that they are
// checked, and named in messages, as the config file's own keys.
Loaded load(const py::handle& config, std::optional<long long> runs, std::optional<long long> seed,
            std::optional<long long> threads, std::optional<long long> max_evaluations) {
  YamlReader r = load_config(config);
  if (!r.node().IsMap()) throw ConfigError("<root>", "", "the config must be a mapping of sections");
  Loaded l;
  if (py::isinstance<py::dict>(config)) {
    l.config = "<dict>";
    l.hash = content_hash(YAML::Dump(r.node()));
  } else {
    l.config = py::module_::import("os").attr("fspath")(config).cast<std::string>();
    l.hash = config_hash(l.config);
  }
  l.node = r.node();
  set_key(l.node, "montecarlo", "runs", runs);
  set_key(l.node, "montecarlo", "seed", seed);
  set_key(l.node, "montecarlo", "threads", threads);
  set_key(l.node, "optimizer", "max_evaluations", max_evaluations);
  return l;
}

// The output folder (created, locked for the call) and its archive; none: an archive in memory.
struct Output {
  std::optional<OutputDirLock> lock;
  std::string dir, archive;
  explicit Output(const std::optional<py::object>& out) {
    if (!out || out->is_none()) {
      archive = ":memory:";
      return;
    }
    dir = py::module_::import("os").attr("fspath")(*out).cast<std::string>();
    lock.emplace(fs::path(dir));
    archive = (fs::path(dir) / "archive.sqlite").string();
  }
  py::object archive_path() const { return dir.empty() ? py::object(py::none()) : py::object(py::str(archive)); }
  py::object out_dir() const { return dir.empty() ? py::object(py::none()) : py::object(py::str(dir)); }
};

py::object result_object(const char* type, py::dict d) {
  return py::module_::import("abuopt").attr(type)(d);
}

Array vec(const std::vector<double>& v) { return Array(static_cast<py::ssize_t>(v.size()), v.data()); }

Array matrix(const std::vector<std::vector<double>>& rows, std::size_t cols) {
  Array a({rows.size(), cols});
  auto m = a.mutable_unchecked<2>();
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (std::size_t j = 0; j < cols; ++j) m(i, j) = j < rows[i].size() ? rows[i][j] : kNaN;
  return a;
}

// Metrics of several evaluations as {name: array} (NaN where one lacks it).
py::dict metric_columns(const std::vector<const std::map<std::string, double>*>& rows) {
  std::map<std::string, std::vector<double>> cols;
  for (const auto* r : rows)
    for (const auto& [k, v] : *r) cols.emplace(k, std::vector<double>());
  for (auto& [k, c] : cols)
    for (const auto* r : rows) {
      auto it = r->find(k);
      c.push_back(it == r->end() ? kNaN : it->second);
    }
  py::dict d;
  for (const auto& [k, c] : cols) d[py::str(k)] = vec(c);
  return d;
}

std::vector<std::string> variable_names(const std::vector<opt::Variable>& vars) {
  std::vector<std::string> n;
  for (const auto& v : vars) n.push_back(v.name);
  return n;
}

py::dict profile_dict(const StartupProfile& p) {
  py::list segs;
  for (const auto& s : p.segments()) {
    py::dict d;
    d["end_frequency_hz"] = s.end_frequency_hz;
    d["duration_s"] = s.duration_s;
    segs.append(d);
  }
  py::dict d;
  d["start_frequency_hz"] = p.start_frequency_hz();
  d["segments"] = segs;
  d["duration_s"] = p.duration_s();
  return d;
}

py::dict evaluation_dict(const opt::Evaluation& e) {
  py::dict d;
  d["ok"] = e.ok;
  d["objective"] = e.ok ? e.objective : kNaN;
  d["constraints"] = vec(e.inequality);
  d["max_violation"] = e.ok ? opt::max_constraint_violation(e) : kNaN;
  d["metrics"] = e.metrics;
  d["message"] = e.message;
  return d;
}

// ---- optimize ----------------------------------------------------------------------------------

py::object optimize(const py::handle& config, std::optional<long long> max_evaluations,
                    const std::optional<py::object>& out, std::optional<long long> threads,
                    std::optional<long long> seed, std::optional<long long> runs, bool validate) {
  const Loaded l = load(config, runs, seed, threads, max_evaluations);
  YamlReader root(l.node, "");
  problems::StartupProfileSettings settings = problems::read_startup_profile_settings(root);
  YamlReader optimizer = root.child("optimizer");
  YamlReader sao = root.child("sao");
  opt::OptimizerOptions options = opt::read_optimizer_options(optimizer, &sao);
  finish_config(root);
  options.validate();
  options.handle_sigint = false;  // Python's own handler sees Ctrl-C (run_interruptible)

  OptimizeRun run(std::move(settings), std::move(options));
  const Output output(out);
  run.open_archive(output.archive, "optimize (python)", l.config, l.hash);
  const auto& st = run.problem().settings();
  const std::vector<opt::Variable> vars = run.problem().variables();

  std::atomic<bool> stop{false};
  opt::OptimizationResult r;
  std::optional<OutOfSampleComparison> cmp;
  run_interruptible([&] {
    r = run.minimize([&](const opt::Progress&) { return !stop.load(); });
    if (validate && !r.x.empty() && st.validation.enabled && !stop.load()) cmp = run.compare_out_of_sample(r);
  }, &stop);

  py::dict d;
  d["x"] = vec(r.x);
  d["fun"] = r.x.empty() ? kNaN : r.objective;
  d["names"] = variable_names(vars);
  d["constraints"] = vec(r.inequality);
  d["constraint_names"] = r.inequality_names;
  d["feasible"] = r.has_feasible_point();
  d["maxcv"] = r.x.empty() ? kNaN : r.max_violation;
  d["metrics"] = r.metrics;
  d["success"] = r.success();
  d["reason"] = to_string(r.reason);
  d["message"] = r.message;
  d["nfev"] = r.evaluations;
  d["archive_hits"] = r.archive_hits;
  d["failed_evaluations"] = r.failed_evaluations;
  d["gradient_evaluations"] = r.gradient_evaluations;
  d["wall_time_s"] = r.wall_time_s;
  d["algorithm"] = r.algorithm;
  d["problem_id"] = run.problem().identity();
  d["objective_label"] = objective_label(st);
  d["x0"] = vec(run.problem().initial_point());
  d["profile"] = r.x.empty() ? py::object(py::none()) : py::object(profile_dict(run.problem().profile_at(r.x)));
  d["archive"] = output.archive_path();
  d["out"] = output.out_dir();

  // history: one row per evaluation, in order (archive hits included)
  const std::size_t n = r.history.size();
  std::vector<std::vector<double>> hx;
  std::vector<const std::map<std::string, double>*> hm;
  Array obj(n), viol(n), best(n);
  py::array_t<bool> ok(n), feas(n), from_archive(n), for_gradient(n);
  double b = kNaN;
  for (std::size_t i = 0; i < n; ++i) {
    const auto& h = r.history[i];
    hx.push_back(h.x);
    hm.push_back(&h.metrics);
    obj.mutable_at(i) = h.ok ? h.objective : kNaN;
    viol.mutable_at(i) = h.ok ? h.max_violation : kNaN;
    if (h.feasible && !(h.objective >= b)) b = h.objective;
    best.mutable_at(i) = b;
    ok.mutable_at(i) = h.ok;
    feas.mutable_at(i) = h.feasible;
    from_archive.mutable_at(i) = h.from_archive;
    for_gradient.mutable_at(i) = h.for_gradient;
  }
  py::dict hist;
  hist["x"] = matrix(hx, vars.size());
  hist["objective"] = obj;
  hist["max_violation"] = viol;
  hist["best_feasible"] = best;
  hist["ok"] = ok;
  hist["feasible"] = feas;
  hist["from_archive"] = from_archive;
  hist["for_gradient"] = for_gradient;
  hist["metrics"] = metric_columns(hm);
  d["history"] = hist;

  if (cmp) {
    const auto& rows = cmp->rows;
    const OutOfSampleVerdict verdict = out_of_sample_verdict(rows);
    py::dict v;
    v["runs"] = st.validation.runs;
    v["seed"] = st.validation.seed;
    v["best_in_sample"] = evaluation_dict(rows[0].e);
    v["best_out_of_sample"] = evaluation_dict(rows[1].e);
    v["report_in_sample"] = evaluation_dict(rows[2].e);
    v["report_out_of_sample"] = evaluation_dict(rows[3].e);
    v["report_profile"] = profile_dict(cmp->report);
    v["worse_than_report_profile"] = verdict.worse;
    d["validation"] = v;
  } else {
    d["validation"] = py::none();
  }
  return result_object("OptimizeResult", d);
}

// ---- sweep -------------------------------------------------------------------------------------

py::object sweep(const py::handle& config, const std::optional<py::object>& out, std::optional<long long> threads,
                 std::optional<long long> seed, std::optional<long long> runs) {
  const Loaded l = load(config, runs, seed, threads, std::nullopt);
  YamlReader root(l.node, "");
  problems::StartupProfileSettings settings = problems::read_startup_profile_settings(root);
  YamlReader optimizer = root.child("optimizer");
  YamlReader sao = root.child("sao");
  const opt::OptimizerOptions options = opt::read_optimizer_options(optimizer, &sao);  // constraint_tolerance
  YamlReader sweep_section = root.child("sweep");
  problems::StartupProfileProblem problem(settings);
  const auto vars = problem.variables();
  const SweepSettings ss = read_sweep_settings(sweep_section, vars);
  finish_config(root);
  const SweepPlan plan = plan_sweep(ss, vars, problem.initial_point());

  const Output output(out);
  opt::EvaluationArchive archive(output.archive, problem.identity());
  archive.check_signature(problem);
  archive.record_metadata("sweep (python)", l.config, l.hash);

  std::atomic<bool> stop{false};
  SweepResult r;
  run_interruptible([&] { r = run_sweep(problem, archive, plan, {}, &stop, options.constraint_tolerance); }, &stop);

  const std::size_t n = r.points.size(), ng = problem.inequality_names().size();
  std::vector<std::vector<double>> xs, gs, unit;
  std::vector<const std::map<std::string, double>*> ms;
  Array obj(n), hw(n), viol(n), wall(n);
  py::array_t<bool> ok(n), feas(n), from_archive(n);
  py::list messages;
  for (std::size_t i = 0; i < n; ++i) {
    const SweepPoint& p = r.points[i];
    xs.push_back(p.x);
    gs.push_back(p.e.ok ? p.e.inequality : std::vector<double>(ng, kNaN));
    unit.push_back(plan.unit[p.index]);
    ms.push_back(&p.e.metrics);
    obj.mutable_at(i) = p.e.ok ? p.e.objective : kNaN;
    hw.mutable_at(i) = p.e.ok ? objective_half_width(problem.settings(), p.e) : kNaN;
    viol.mutable_at(i) = p.e.ok ? p.max_violation : kNaN;
    wall.mutable_at(i) = p.wall_time_s;
    ok.mutable_at(i) = p.e.ok;
    feas.mutable_at(i) = p.feasible;
    from_archive.mutable_at(i) = p.from_archive;
    messages.append(p.e.message);
  }
  std::vector<std::string> swept;
  for (std::size_t k : plan.swept) swept.push_back(vars[k].name);
  py::dict d;
  d["method"] = to_string(plan.method);
  d["names"] = variable_names(vars);
  d["swept"] = swept;
  d["x"] = matrix(xs, vars.size());
  d["unit"] = matrix(unit, plan.swept.size());
  d["objective"] = obj;
  d["objective_hw95"] = hw;
  d["objective_label"] = objective_label(problem.settings());
  d["constraints"] = matrix(gs, ng);
  d["constraint_names"] = problem.inequality_names();
  d["max_violation"] = viol;
  d["ok"] = ok;
  d["feasible"] = feas;
  d["from_archive"] = from_archive;
  d["metrics"] = metric_columns(ms);
  d["wall_time_s"] = wall;
  d["message"] = messages;
  const SweepPoint* best = best_feasible_point(r);
  d["best"] = best ? py::object(py::int_(best - r.points.data())) : py::object(py::none());
  d["computed"] = r.computed;
  d["archive_hits"] = r.archive_hits;
  d["failed"] = r.failed;
  d["problem_id"] = problem.identity();
  d["archive"] = output.archive_path();
  d["out"] = output.out_dir();
  return result_object("SweepResult", d);
}

// ---- pareto ------------------------------------------------------------------------------------

double metric_or_nan(const opt::Evaluation& e, const char* k) {
  auto it = e.metrics.find(k);
  return it == e.metrics.end() ? kNaN : it->second;
}

py::object pareto(const py::handle& config, const std::optional<py::object>& out, std::optional<long long> threads,
                  std::optional<long long> seed, std::optional<long long> runs,
                  std::optional<long long> max_evaluations, bool validate) {
  const Loaded l = load(config, runs, seed, threads, max_evaluations);
  YamlReader root(l.node, "");
  problems::StartupProfileSettings settings = problems::read_startup_profile_settings(root);
  YamlReader optimizer = root.child("optimizer");
  YamlReader sao = root.child("sao");
  opt::OptimizerOptions options = opt::read_optimizer_options(optimizer, &sao);
  const ParetoSettings ps = read_pareto_settings(root.child("pareto"));
  finish_config(root);
  options.validate();
  options.handle_sigint = false;  // Python's own handler sees Ctrl-C (run_interruptible)
  const problems::StartupProfileProblem shape(settings);  // validates; names and labels
  const auto vars = shape.variables();

  const Output output(out);
  std::atomic<bool> stop{false};
  ParetoResult r;
  run_interruptible([&] {
    r = run_pareto(settings, options, ps, output.archive, l.config, l.hash,
                   [&](std::size_t, std::size_t, const opt::Progress&) { return !stop.load(); }, validate);
  }, &stop);

  const std::size_t n = r.points.size();
  std::vector<std::vector<double>> xs;
  Array eps(n), t(n), obj(n), hw(n), oos(n), oos_hw(n), pmi(n), oos_pmi(n);
  py::array_t<bool> feas(n), dominated(n), front(n);
  py::array_t<long> evals(n), starts(n);
  py::list reasons, ids, kept;
  for (std::size_t i = 0; i < n; ++i) {
    const ParetoPoint& p = r.points[i];
    const opt::Evaluation in = in_sample_evaluation(p);
    xs.push_back(p.x);
    eps.mutable_at(i) = p.epsilon;
    t.mutable_at(i) = p.x.empty() ? kNaN : p.startup_time_s;
    obj.mutable_at(i) = in.ok ? in.objective : kNaN;
    hw.mutable_at(i) = in.ok ? objective_half_width(settings, in) : kNaN;
    oos.mutable_at(i) = p.out_of_sample.ok ? p.out_of_sample.objective : kNaN;
    oos_hw.mutable_at(i) = p.out_of_sample.ok ? objective_half_width(settings, p.out_of_sample) : kNaN;
    pmi.mutable_at(i) = metric_or_nan(in, "pct_mi");
    oos_pmi.mutable_at(i) = metric_or_nan(p.out_of_sample, "pct_mi");
    feas.mutable_at(i) = p.result.feasible && !p.x.empty();
    dominated.mutable_at(i) = p.dominated;
    front.mutable_at(i) = p.result.feasible && !p.x.empty() && !p.dominated;
    evals.mutable_at(i) = p.evaluations;
    starts.mutable_at(i) = p.starts;
    reasons.append(to_string(p.result.reason));
    ids.append(p.problem_id);
    kept.append(p.warm_start_won ? "previous_best" : "x0");
  }
  py::dict d;
  d["max_startup_time_s"] = eps;
  d["startup_time_s"] = t;
  d["names"] = variable_names(vars);
  d["x"] = matrix(xs, vars.size());
  d["objective"] = obj;
  d["objective_hw95"] = hw;
  d["objective_label"] = objective_label(settings);
  d["out_of_sample_objective"] = oos;
  d["out_of_sample_hw95"] = oos_hw;
  d["pct_mi"] = pmi;
  d["out_of_sample_pct_mi"] = oos_pmi;
  d["feasible"] = feas;
  d["dominated"] = dominated;
  d["front"] = front;
  d["evaluations"] = evals;
  d["starts"] = starts;
  d["kept_start"] = kept;
  d["reason"] = reasons;
  d["problem_ids"] = ids;
  py::dict rep;
  rep["startup_time_s"] = r.report_startup_time_s;
  rep["in_sample"] = evaluation_dict(r.report_in_sample);
  rep["out_of_sample"] = evaluation_dict(r.report_out_of_sample);
  d["report_profile"] = rep;
  d["archive"] = output.archive_path();
  d["out"] = output.out_dir();
  return result_object("ParetoResult", d);
}

// The result types: dicts with attribute access and a readable repr, as scipy.optimize's.
constexpr const char* kResultTypes = R"PY(
class _Result(dict):
    """A dict whose keys are also attributes (r.x == r["x"]), as scipy.optimize.OptimizeResult."""

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError as e:
            raise AttributeError(name) from e

    __setattr__ = dict.__setitem__
    __delattr__ = dict.__delitem__

    def __dir__(self):
        return list(self.keys())

    def __repr__(self):
        if not self:
            return self.__class__.__name__ + "()"
        w = max(map(len, self.keys())) + 1
        return "\n".join(k.rjust(w) + ": " + repr(v).replace("\n", "\n" + " " * (w + 2)) for k, v in self.items())


class OptimizeResult(_Result):
    """Result of abuopt.optimize (help(abuopt.optimize) lists the keys)."""


class SweepResult(_Result):
    """Result of abuopt.sweep (help(abuopt.sweep) lists the keys)."""


class ParetoResult(_Result):
    """Result of abuopt.pareto (help(abuopt.pareto) lists the keys)."""
)PY";

}  // namespace

void register_studies(py::module_& m) {
  py::dict scope;
  scope["__name__"] = "abuopt";
  scope["__builtins__"] = py::module_::import("builtins");
  py::exec(kResultTypes, scope);
  for (const char* name : {"OptimizeResult", "SweepResult", "ParetoResult"}) m.attr(name) = scope[name];

  m.def("optimize", &optimize, py::arg("config"), py::kw_only(), py::arg("max_evaluations") = py::none(),
        py::arg("out") = py::none(), py::arg("threads") = py::none(), py::arg("seed") = py::none(),
        py::arg("runs") = py::none(), py::arg("validate") = true,
        "Optimise the startup profile as `abuopt optimize CONFIG` does (docs/optimize.md): the config's\n"
        "optimiser on its design problem, every evaluation a Monte Carlo on the same initial conditions,\n"
        "then (validate and the config's validation section) the best design and the report's final\n"
        "profile out of sample. max_evaluations, threads, seed, runs override optimizer.max_evaluations,\n"
        "montecarlo.threads, .seed, .runs (checked as those keys). out: a folder for the evaluation\n"
        "archive out/archive.sqlite (shared with `abuopt optimize --out out`: a rerun resumes from it;\n"
        "abuopt.Archive reads it); None: the archive in memory, nothing written.\n"
        "Returns an OptimizeResult (a dict with attribute access, as SciPy's): x (array, the best design:\n"
        "names, in Hz and s), fun (its objective), constraints (array g(x), feasible when <= 0;\n"
        "constraint_names), feasible, maxcv (largest violation), metrics, success (converged and\n"
        "feasible), reason, message, nfev (evaluations, archive hits included), archive_hits,\n"
        "failed_evaluations, gradient_evaluations, wall_time_s, algorithm, problem_id, x0, profile,\n"
        "objective_label, archive (path or None), out, history (x (nfev, d), objective, max_violation,\n"
        "best_feasible, ok, feasible, from_archive, for_gradient: arrays, metrics {name: array}), and\n"
        "validation (None, or best_in_sample, best_out_of_sample, report_in_sample,\n"
        "report_out_of_sample: {ok, objective, constraints, max_violation, metrics}, report_profile,\n"
        "worse_than_report_profile, runs, seed).\n"
        "Units: the optimiser's numbers, as `abuopt optimize` prints and archives them: objective and\n"
        "metrics per docs/optimize.md (mean I_r in 1e-7 kg m, %MI in %; objective_label says which),\n"
        "x in Hz and s. Ctrl-C stops within the current evaluation (not recorded; those before stay in\n"
        "the archive) and raises KeyboardInterrupt.");
  m.def("sweep", &sweep, py::arg("config"), py::kw_only(), py::arg("out") = py::none(),
        py::arg("threads") = py::none(), py::arg("seed") = py::none(), py::arg("runs") = py::none(),
        "The design sweep of `abuopt sweep CONFIG` (the config's `sweep` section; docs/sweep.md): every\n"
        "point a Monte Carlo on the same initial conditions, through the archive (out: as optimize).\n"
        "threads, seed, runs override montecarlo.threads, .seed, .runs. Returns a SweepResult, one row\n"
        "per point in plan order: x (n, d; names), unit (n, swept: the design in [0, 1]), objective,\n"
        "objective_hw95 (95 % half-width), constraints (n, m; constraint_names), max_violation, ok,\n"
        "feasible, from_archive, wall_time_s (arrays), metrics {name: array}, message (list); method,\n"
        "swept, best (row of the lowest feasible objective, or None), computed, archive_hits, failed,\n"
        "objective_label, problem_id, archive, out.\n"
        "Units: the optimiser's numbers (mean I_r in 1e-7 kg m; docs/optimize.md), x in Hz and s.\n"
        "Ctrl-C stops within the current point (not recorded) and raises KeyboardInterrupt.");
  m.def("pareto", &pareto, py::arg("config"), py::kw_only(), py::arg("out") = py::none(),
        py::arg("threads") = py::none(), py::arg("seed") = py::none(), py::arg("runs") = py::none(),
        py::arg("max_evaluations") = py::none(), py::arg("validate") = true,
        "The Pareto front of startup time against the objective, as `abuopt pareto CONFIG` (the\n"
        "epsilon-constraint method over pareto.max_startup_time_s; docs/sweep.md). Overrides as optimize;\n"
        "validate=False skips the out-of-sample evaluations. Returns a ParetoResult, one row per bound\n"
        "(ascending): max_startup_time_s, startup_time_s [s], x (n, d; names), objective and\n"
        "objective_hw95 (in sample), out_of_sample_objective and out_of_sample_hw95 (NaN when not\n"
        "validated), pct_mi and out_of_sample_pct_mi [%], feasible, dominated, front (feasible and not\n"
        "dominated), evaluations, starts (arrays), kept_start, reason, problem_ids (lists),\n"
        "report_profile {startup_time_s, in_sample, out_of_sample}, objective_label, archive, out.\n"
        "Units: the optimiser's numbers (mean I_r in 1e-7 kg m; docs/optimize.md), x in Hz and s.\n"
        "Ctrl-C stops within the current evaluation and raises KeyboardInterrupt.");
}

}  // namespace abuopt::python
