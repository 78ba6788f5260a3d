// abuopt.BatchProblem: a design problem as a batch function for Python optimisers (Optuna, SciPy,
// pymoo, ...): an (n, d) array of designs in, objectives and constraints out, evaluated through
// Problem::evaluate_batch (the points at once on `threads` threads when the problem allows it, each
// Monte Carlo sharing the cores), with the GIL released. The startup-profile problem of
// `abuopt optimize` and the analytic benchmarks (fast, with known optima) behind one interface.
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "abuopt/common/config_error.hpp"
#include "abuopt/optimizer/benchmarks/benchmark_factory.hpp"
#include "abuopt/optimizer/evaluation_scheduler.hpp"
#include "abuopt/optimizer/optimizer_options.hpp"
#include "abuopt/problems/startup_profile_problem.hpp"
#include "convert.hpp"
#include "problem_bindings.hpp"

namespace py = pybind11;

namespace abuopt::python {

namespace {

using Array = py::array_t<double>;

class PyBatchProblem {
 public:
  // The startup-profile problem from a config (path or dict) as `abuopt optimize` reads it; runs,
  // seed and threads override montecarlo.runs / .seed / .threads.
  PyBatchProblem(const py::handle& config, std::optional<long long> runs, std::optional<long long> seed,
                 std::optional<long long> threads, std::size_t batch_threads)
      : threads_(batch_threads) {
    YamlReader loaded = load_config(config);
    if (!loaded.node().IsMap()) throw ConfigError("<root>", "", "the config must be a mapping of sections");
    YAML::Node node = loaded.node();
    if (runs) node["montecarlo"]["runs"] = *runs;
    if (seed) node["montecarlo"]["seed"] = *seed;
    if (threads) node["montecarlo"]["threads"] = *threads;
    YamlReader root(node, "");
    settings_ = problems::read_startup_profile_settings(root);
    for (const char* ignored : {"optimizer", "sao", "sweep", "pareto"}) root.mark_read(ignored);
    root.finish();
    auto p = std::make_unique<problems::StartupProfileProblem>(*settings_);
    identity_ = p->identity();
    problem_ = std::move(p);
  }
  // An analytic benchmark of make_benchmark (hs071, cantilever, two_bar_truss, rosenbrock, noisy_*).
  PyBatchProblem(const std::string& name, std::size_t batch_threads) : threads_(batch_threads) {
    problem_ = opt::benchmarks::make_benchmark(name);
    identity_ = name;
  }

  // X: (n, d) -> objective (n,), inequality (n, m_i), equality (n, m_e), ok (n,), max_violation (n,)
  py::dict evaluate(const py::array_t<double, py::array::c_style | py::array::forcecast>& X) {
    const std::size_t d = problem_->dimension();
    if (X.ndim() != 2 || static_cast<std::size_t>(X.shape(1)) != d)
      throw ConfigError("X", "shape " + shape_text(X), "must be (n, " + std::to_string(d) + "): one design per row");
    const std::size_t n = static_cast<std::size_t>(X.shape(0));
    std::vector<std::vector<double>> xs(n, std::vector<double>(d));
    auto x = X.unchecked<2>();
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = 0; j < d; ++j) xs[i][j] = x(i, j);
    const std::vector<opt::Variable> vars = problem_->variables();
    for (std::size_t i = 0; i < n; ++i) opt::check_design_vector(vars, xs[i], "X[" + std::to_string(i) + "]");
    std::vector<opt::BatchEvaluation> out;
    {
      py::gil_scoped_release release;
      opt::ThreadScheduler scheduler(threads_);
      out = problem_->evaluate_batch(xs, scheduler);
    }
    evaluations_ += n;
    const std::size_t mi = problem_->inequality_names().size(), me = problem_->equality_names().size();
    Array objective(n), violation(n), g({n, mi}), h({n, me});
    py::array_t<bool> ok(n);
    auto gm = g.mutable_unchecked<2>();
    auto hm = h.mutable_unchecked<2>();
    py::list messages;
    for (std::size_t i = 0; i < n; ++i) {
      if (out[i].error) std::rethrow_exception(out[i].error);
      const opt::Evaluation& e = out[i].evaluation;
      const bool good = e.ok && e.inequality.size() == mi && e.equality.size() == me;
      objective.mutable_at(i) = good ? e.objective : INFINITY;
      violation.mutable_at(i) = good ? opt::max_constraint_violation(e) : INFINITY;
      ok.mutable_at(i) = good;
      for (std::size_t k = 0; k < mi; ++k) gm(i, k) = good ? e.inequality[k] : INFINITY;
      for (std::size_t k = 0; k < me; ++k) hm(i, k) = good ? e.equality[k] : INFINITY;
      messages.append(e.message);
    }
    py::dict r;
    r["objective"] = objective;
    r["inequality"] = g;
    r["equality"] = h;
    r["max_violation"] = violation;
    r["ok"] = ok;
    r["message"] = messages;
    return r;
  }

  // Out of sample (the startup problem's validation section: fresh runs no optimiser saw), one
  // design per row: objective (n,), max_violation (n,), ok (n,).
  py::dict validate(const py::array_t<double, py::array::c_style | py::array::forcecast>& X) {
    if (!settings_) throw ConfigError("validate", name(), "only the startup-profile problem has a validation sample");
    const std::size_t d = problem_->dimension();
    if (X.ndim() != 2 || static_cast<std::size_t>(X.shape(1)) != d)
      throw ConfigError("X", "shape " + shape_text(X), "must be (n, " + std::to_string(d) + ")");
    const std::size_t n = static_cast<std::size_t>(X.shape(0));
    auto x = X.unchecked<2>();
    Array objective(n), violation(n);
    py::array_t<bool> ok(n);
    const auto& p = static_cast<const problems::StartupProfileProblem&>(*problem_);
    for (std::size_t i = 0; i < n; ++i) {
      std::vector<double> xi(d);
      for (std::size_t j = 0; j < d; ++j) xi[j] = x(i, j);
      opt::check_design_vector(p.variables(), xi, "X[" + std::to_string(i) + "]");
      opt::Evaluation e;
      {
        py::gil_scoped_release release;
        e = p.evaluate_out_of_sample_at(xi);  // the profile and, with design.ball_count, the balls at x
      }
      objective.mutable_at(i) = e.ok ? e.objective : INFINITY;
      violation.mutable_at(i) = opt::max_constraint_violation(e);
      ok.mutable_at(i) = e.ok;
    }
    py::dict r;
    r["objective"] = objective;
    r["max_violation"] = violation;
    r["ok"] = ok;
    return r;
  }

  std::string name() const { return problem_->name(); }
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const auto& v : problem_->variables()) out.push_back(v.name);
    return out;
  }
  Array lower() const { return bound(true); }
  Array upper() const { return bound(false); }
  std::vector<double> x0() const { return problem_->initial_point(); }
  std::vector<std::string> inequality_names() const { return problem_->inequality_names(); }
  std::vector<std::string> equality_names() const { return problem_->equality_names(); }
  std::optional<double> best_known() const {
    auto b = problem_->best_known();
    return b ? std::optional<double>(b->objective) : std::nullopt;
  }
  std::string identity() const { return identity_; }
  std::size_t evaluations() const { return evaluations_; }

 private:
  static std::string shape_text(const py::array& X) {
    std::string s = "(";
    for (py::ssize_t i = 0; i < X.ndim(); ++i) s += (i ? ", " : "") + std::to_string(X.shape(i));
    return s + ")";
  }
  Array bound(bool lower) const {
    const auto vars = problem_->variables();
    Array a(vars.size());
    for (std::size_t i = 0; i < vars.size(); ++i) a.mutable_at(i) = lower ? vars[i].lower : vars[i].upper;
    return a;
  }

  std::unique_ptr<opt::Problem> problem_;
  std::optional<problems::StartupProfileSettings> settings_;
  std::string identity_;
  std::size_t threads_ = 1;
  std::size_t evaluations_ = 0;
};

}  // namespace

void register_problem_bindings(py::module_& m) {
  py::class_<PyBatchProblem>(m, "BatchProblem",
                             "A design problem as a batch function: evaluate(X) with X an (n, d) array of designs.\n"
                             "BatchProblem(config, runs=, seed=, threads=, batch_threads=1): the startup-profile\n"
                             "problem of `abuopt optimize` (config: YAML path or dict); BatchProblem.benchmark(name):\n"
                             "an analytic benchmark (hs071, cantilever, two_bar_truss, rosenbrock, noisy_*).")
      .def(py::init<const py::handle&, std::optional<long long>, std::optional<long long>, std::optional<long long>,
                    std::size_t>(),
           py::arg("config"), py::kw_only(), py::arg("runs") = py::none(), py::arg("seed") = py::none(),
           py::arg("threads") = py::none(), py::arg("batch_threads") = 1,
           "runs/seed/threads override montecarlo.runs/.seed/.threads; batch_threads: designs of one batch\n"
           "evaluated at once (each Monte Carlo then uses about threads / batch_threads threads).")
      .def_static(
          "benchmark", [](const std::string& name) { return PyBatchProblem(name, 1); }, py::arg("name"))
      .def("evaluate", &PyBatchProblem::evaluate, py::arg("X"),
           "X (n, d) -> dict: objective (n,), inequality (n, m_i) feasible when <= 0, equality (n, m_e),\n"
           "max_violation (n,), ok (n,) (False: the evaluation failed; its values are +inf), message (list).")
      .def("__call__", &PyBatchProblem::evaluate, py::arg("X"))
      .def("validate", &PyBatchProblem::validate, py::arg("X"),
           "Out of sample on the validation section's fresh runs (startup problem only): objective,\n"
           "max_violation, ok per row.")
      .def_property_readonly("name", &PyBatchProblem::name)
      .def_property_readonly("names", &PyBatchProblem::names)
      .def_property_readonly("lower", &PyBatchProblem::lower)
      .def_property_readonly("upper", &PyBatchProblem::upper)
      .def_property_readonly("x0", &PyBatchProblem::x0)
      .def_property_readonly("inequality_names", &PyBatchProblem::inequality_names)
      .def_property_readonly("equality_names", &PyBatchProblem::equality_names)
      .def_property_readonly("best_known", &PyBatchProblem::best_known, "f* of a benchmark, None otherwise")
      .def_property_readonly("identity", &PyBatchProblem::identity)
      .def_property_readonly("evaluations", &PyBatchProblem::evaluations, "designs evaluated so far");
}

}  // namespace abuopt::python
