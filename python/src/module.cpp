// The Python module `abuopt` (docs/python.md): the library functions the `abuopt` commands call,
// with configs read by the same C++ readers (a ConfigError becomes abuopt.ConfigError, a
// ValueError) and the GIL released while simulating.
#include <cmath>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/config_sections.hpp"
#include "bindings.hpp"  // register_module_extras, register_archive
#include "interruptible.hpp"  // run_interruptible: long calls that Ctrl-C stops
#include "abuopt/common/stop.hpp"
#include "abuopt/common/text.hpp"
#include "abuopt/core/batch_runner.hpp"
#include "abuopt/core/equilibrium_set.hpp"
#include "abuopt/core/monte_carlo.hpp"
#include "abuopt/core/monte_carlo_stats.hpp"
#include "abuopt/core/simulation_config.hpp"
#include "abuopt/core/simulator.hpp"
#include "abuopt/optimizer/optimizer_options.hpp"
#include "abuopt/problems/startup_profile_problem.hpp"
#include "convert.hpp"
#include "problem_bindings.hpp"

namespace py = pybind11;

namespace abuopt::python {

namespace {

using Array = py::array_t<double>;

// Initial angles and other per-call numbers from Python: finite, as the command line requires.
void require_finite(const std::vector<double>& v, const std::string& key) {
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i]))
      throw ConfigError(key + "[" + std::to_string(i) + "]", format_number(v[i]), "must be a finite angle in rad");
}

py::dict outcome_dict(const RunOutcome& o) {
  py::dict d;
  d["status"] = to_string(o.status);
  d["message"] = o.message;
  d["beta_final"] = Array(static_cast<py::ssize_t>(o.beta_final.size()), o.beta_final.data());
  d["residual_imbalance"] = o.residual_imbalance_kgm;
  d["residual_imbalance_x"] = o.residual_imbalance_x_kgm;
  d["settled"] = o.settled;
  d["settling_time"] = o.settling_time_s;
  d["max_amplitude_mm"] = o.max_amplitude_mm;
  d["end_time_s"] = o.end_time_s;
  d["events"] = o.events;
  d["steps"] = o.steps;
  d["rhs_evaluations"] = o.rhs_evaluations;
  d["wall_time_s"] = o.wall_time_s;
  return d;
}

// As `abuopt simulate`: the setup sections, a montecarlo section checked and not used.
py::dict simulate(const py::handle& config, const std::vector<double>& beta0) {
  YamlReader root = load_config(config);
  SimulationSetup setup = read_simulation_setup(root);
  if (root.has("montecarlo") || root.has("envelope")) (void)read_monte_carlo_config(root, setup);
  finish_config(root);
  const std::size_t n = setup.abu.balls.size();
  if (beta0.size() != n)
    throw ConfigError("beta0", std::to_string(beta0.size()) + " angles",
                      "must give " + std::to_string(n) + " angles (one per ball)");
  require_finite(beta0, "beta0");
  RunOutcome o;
  double I0 = 0;
  run_interruptible([&] {
    Simulator sim(setup);
    o = sim.run(beta0, {});
    I0 = setup.abu.imbalance_kgm();
  });
  py::dict d = outcome_dict(o);
  d["beta0"] = Array(static_cast<py::ssize_t>(beta0.size()), beta0.data());
  d["imbalance_without_balls"] = I0;
  return d;
}

// Sets montecarlo.<key> in the config document before it is read, so that the value is checked,
// and named in messages, exactly as the config file's own key.
template <typename T>
void override_key(YamlReader& root, const char* key, const std::optional<T>& value) {
  if (!value) return;
  YAML::Node n = root.node();
  n["montecarlo"][key] = *value;
}

py::dict montecarlo(const py::handle& config, std::optional<long long> runs, std::optional<std::string> design,
                    std::optional<long long> seed, std::optional<long long> threads, long long max_runs) {
  YamlReader loaded = load_config(config);
  if (!loaded.node().IsMap()) throw ConfigError("<root>", "", "the config must be a mapping of sections");
  override_key(loaded, "design", design);
  override_key(loaded, "runs", runs);
  override_key(loaded, "seed", seed);
  override_key(loaded, "threads", threads);
  YamlReader root(loaded.node(), "");
  SimulationSetup setup = read_simulation_setup(root);
  MonteCarloConfig cfg = read_monte_carlo_config(root, std::move(setup));
  finish_config(root);
  // Every run's outcome is returned as arrays (about 0.5 kB per run with the study's own copy):
  // above max_runs the caller asks for it explicitly.
  if (max_runs < 1) throw ConfigError("max_runs", std::to_string(max_runs), "must be >= 1");
  if (cfg.study.runs > static_cast<std::size_t>(max_runs))
    throw ConfigError("montecarlo.runs", std::to_string(cfg.study.runs),
                      "is more than max_runs = " + std::to_string(max_runs) +
                          " (the default limit of one call: every run is kept in memory, about 0.5 kB each); pass "
                          "max_runs=N to allow more");

  MonteCarloResult result;
  MonteCarloStats stats;
  run_interruptible([&] {
    ThreadPoolRunner runner(cfg.threads);
    result = run_monte_carlo(cfg.study, runner);
    stats = compute_statistics(result);
  });
  const std::size_t n = result.samples.size();
  const std::size_t nb = cfg.study.setup.abu.balls.size();
  Array ir(n), irx(n), settling(n), amp(n), end(n), mu(n), imb(n), wall(n);
  Array beta0({n, nb}), beta_final({n, nb});
  py::array_t<bool> ok(n), settled(n), reused(n);
  py::array_t<long> events(n), steps(n), rhs(n);
  py::list status;
  auto b0 = beta0.mutable_unchecked<2>();
  auto bf = beta_final.mutable_unchecked<2>();
  for (std::size_t i = 0; i < n; ++i) {
    const MonteCarloSample& s = result.samples[i];
    const RunOutcome& o = s.outcome;
    ir.mutable_at(i) = o.residual_imbalance_kgm;
    irx.mutable_at(i) = o.residual_imbalance_x_kgm;
    settling.mutable_at(i) = o.settling_time_s;
    amp.mutable_at(i) = o.max_amplitude_mm;
    end.mutable_at(i) = o.end_time_s;
    mu.mutable_at(i) = s.friction_mu;
    imb.mutable_at(i) = s.imbalance_kgm;
    wall.mutable_at(i) = o.wall_time_s;
    ok.mutable_at(i) = o.ok();
    settled.mutable_at(i) = o.settled;
    reused.mutable_at(i) = s.reused;
    events.mutable_at(i) = o.events;
    steps.mutable_at(i) = o.steps;
    rhs.mutable_at(i) = o.rhs_evaluations;
    status.append(to_string(o.status));
    for (std::size_t b = 0; b < nb; ++b) {
      b0(i, b) = b < s.beta0.size() ? s.beta0[b] : NAN;
      bf(i, b) = b < o.beta_final.size() ? o.beta_final[b] : NAN;
    }
  }
  py::dict d;
  d["residual_imbalance"] = ir;
  d["residual_imbalance_x"] = irx;
  d["beta0"] = beta0;
  d["beta_final"] = beta_final;
  d["status"] = py::module_::import("numpy").attr("array")(status);
  d["ok"] = ok;
  d["settled"] = settled;
  d["settling_time"] = settling;
  d["max_amplitude_mm"] = amp;
  d["end_time_s"] = end;
  d["friction_mu"] = mu;
  d["imbalance_kgm"] = imb;
  d["reused"] = reused;
  d["events"] = events;
  d["steps"] = steps;
  d["rhs_evaluations"] = rhs;
  d["wall_time_s"] = wall;
  d["summary"] = to_python(to_json(stats, result, cfg.study));
  return d;
}

py::dict equilibrium_set(const py::handle& config, double freq, std::size_t grid,
                         const std::vector<double>& other_angles) {
  if (!(std::isfinite(freq) && freq > 0 && freq <= kMaxEquilibriumFrequencyHz))
    throw ConfigError("freq", format_number(freq),
                      "must be a frequency in (0, 1e6] Hz (above it the steady amplitude overflows double precision)");
  if (grid < 2 || grid > 4096) throw ConfigError("grid", std::to_string(grid), "must be in [2, 4096] (points per axis)");
  YamlReader root = load_config(config);
  const SimulationSetup setup = read_simulation_setup(root);
  finish_config(root);
  const std::size_t nb = setup.abu.balls.size();
  if (nb < 2) throw ConfigError("abu.balls", std::to_string(nb) + " balls", "the equilibrium-set grid needs at least 2 balls");
  if (other_angles.size() != nb - 2)
    throw ConfigError("other_angles", std::to_string(other_angles.size()) + " angles",
                      "must give the fixed angles of balls 3.." + std::to_string(nb) + " (" + std::to_string(nb - 2) +
                          " values)");
  require_finite(other_angles, "other_angles");
  std::optional<EquilibriumSet> set;
  EquilibriumGrid g;
  {
    py::gil_scoped_release release;
    set.emplace(setup.abu);
    g = set->grid(freq, grid, other_angles);
  }
  Array beta(grid), amplitude({grid, grid}), margins({grid, grid, nb});
  py::array_t<bool> in_set({grid, grid});
  auto a = amplitude.mutable_unchecked<2>();
  auto s = in_set.mutable_unchecked<2>();
  auto m = margins.mutable_unchecked<3>();
  for (std::size_t i = 0; i < grid; ++i) {
    beta.mutable_at(i) = g.beta(i);
    for (std::size_t j = 0; j < grid; ++j) {
      const std::size_t k = g.index(i, j);
      a(i, j) = g.amplitude_mm[k];
      s(i, j) = g.in_set[k] != 0;
      for (std::size_t b = 0; b < nb; ++b) m(i, j, b) = g.margins[k * nb + b];
    }
  }
  py::dict d;
  d["frequency_hz"] = freq;
  d["speed_ratio"] = set->speed_ratio(freq);
  d["natural_frequency_hz"] = set->natural_frequency_hz();
  d["mu"] = set->mu();
  d["beta"] = beta;
  d["amplitude_mm"] = amplitude;
  d["in_set"] = in_set;
  d["margins"] = margins;
  d["coverage"] = g.coverage();
  d["full_coverage_closed_form"] = set->full_coverage_margin(freq) >= 0;
  return d;
}

// The startup-profile problem as `abuopt optimize` builds it (its optimizer/sao sections are
// checked and not used). evaluate(x) remembers the last x, so that an optimiser asking for the
// objective and then the constraints at the same x pays for one Monte Carlo.
class PyStartupProfileProblem {
 public:
  PyStartupProfileProblem(const py::handle& config, std::optional<long long> runs, std::optional<std::string> design,
                          std::optional<long long> seed, std::optional<long long> threads) {
    YamlReader loaded = load_config(config);
    if (!loaded.node().IsMap()) throw ConfigError("<root>", "", "the config must be a mapping of sections");
    override_key(loaded, "design", design);
    override_key(loaded, "runs", runs);
    override_key(loaded, "seed", seed);
    override_key(loaded, "threads", threads);
    YamlReader root(loaded.node(), "");
    problems::StartupProfileSettings settings = problems::read_startup_profile_settings(root);
    YamlReader optimizer = root.child("optimizer");
    YamlReader sao = root.child("sao");
    (void)opt::read_optimizer_options(optimizer, &sao);
    finish_config(root);
    problem_ = std::make_unique<problems::StartupProfileProblem>(std::move(settings));
    vars_ = problem_->variables();
  }

  py::dict evaluate(const std::vector<double>& x) {
    if (x.size() != vars_.size())
      throw std::invalid_argument("x has " + std::to_string(x.size()) + " entries; the problem has " +
                                  std::to_string(vars_.size()) + " variables");
    if (!(has_last_ && x == last_x_)) {
      run_interruptible([&] { last_ = problem_->evaluate(x); });
      last_x_ = x;
      has_last_ = true;
      ++evaluations_;
    }
    const std::size_t nc = problem_->inequality_names().size();
    Array g(nc);
    for (std::size_t i = 0; i < nc; ++i)
      g.mutable_at(i) = (last_.ok && i < last_.inequality.size()) ? last_.inequality[i] : INFINITY;
    py::dict d;
    d["objective"] = last_.objective;
    d["constraints"] = g;
    d["metrics"] = last_.metrics;
    d["ok"] = last_.ok;
    d["message"] = last_.message;
    return d;
  }

  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const auto& v : vars_) out.push_back(v.name);
    return out;
  }
  std::vector<std::pair<double, double>> bounds() const {
    std::vector<std::pair<double, double>> out;
    for (const auto& v : vars_) out.emplace_back(v.lower, v.upper);
    return out;
  }
  std::vector<double> scales() const {
    std::vector<double> out;
    for (const auto& v : vars_) out.push_back(v.scale);
    return out;
  }
  std::vector<double> x0() const { return problem_->initial_point(); }
  std::vector<std::string> constraint_names() const { return problem_->inequality_names(); }
  std::string identity() const { return problem_->identity(); }
  std::size_t evaluations() const { return evaluations_; }
  double startup_time_s(const std::vector<double>& x) const { return problem_->startup_time_s(x); }

 private:
  std::unique_ptr<problems::StartupProfileProblem> problem_;
  std::vector<opt::Variable> vars_;
  std::vector<double> last_x_;
  opt::Evaluation last_;
  bool has_last_ = false;
  std::size_t evaluations_ = 0;
};

}  // namespace

}  // namespace abuopt::python

PYBIND11_MODULE(abuopt, m) {
  using namespace abuopt::python;
  register_module_extras(m);  // first: the NumPy check (bindings.hpp)
  m.doc() =
      "abuopt: simulate an automatic balancing unit's startup, run Monte Carlo studies over the initial\n"
      "ball angles, compute equilibrium sets and evaluate the startup-profile design problem.\n"
      "Configs are YAML paths or dicts with the command line's sections (docs/python.md).\n"
      "Units: SI. Imbalances (I_r, I_r,x, I) in kg m, angles in rad, frequencies in Hz, times in s,\n"
      "amplitudes in mm (keys ending _mm). The optimisation problem's objective and metrics and the\n"
      "archive's values are the optimiser's numbers, as `abuopt optimize` prints them (mean I_r in\n"
      "1e-7 kg m; docs/optimize.md). Per-run results are NumPy arrays.";
  py::register_exception<abuopt::ConfigError>(m, "ConfigError", PyExc_ValueError);
  register_archive(m);  // abuopt.Archive (archive_bindings.cpp)
  register_studies(m);  // abuopt.optimize, sweep, pareto (study_bindings.cpp)

  m.def("simulate", &simulate, py::arg("config"), py::kw_only(), py::arg("beta0"),
        "One startup from the initial ball angles beta0 [rad] (one per ball), as `abuopt simulate`.\n"
        "Returns a dict: status, message, beta0 and beta_final (arrays [rad]), residual_imbalance (|I_r|,\n"
        "kg m), residual_imbalance_x (I_r,x, kg m), imbalance_without_balls (I, kg m), settled,\n"
        "settling_time [s], max_amplitude_mm, end_time_s, events, steps, rhs_evaluations, wall_time_s.\n"
        "Units: SI (imbalances in kg m), as in every function of this module.");
  m.def("montecarlo", &montecarlo, py::arg("config"), py::kw_only(), py::arg("runs") = py::none(),
        py::arg("design") = py::none(), py::arg("seed") = py::none(), py::arg("threads") = py::none(),
        py::arg("max_runs") = 1000000,
        "Monte Carlo over initial ball angles, as `abuopt montecarlo`. runs/design/seed/threads override\n"
        "the config's montecarlo.runs/.design/.seed/.threads (checked as those keys); more runs than\n"
        "max_runs (default 10^6: every run is kept in memory) is an error unless max_runs is raised.\n"
        "Ctrl-C stops the runs within about a second and raises KeyboardInterrupt. Returns a dict of\n"
        "NumPy arrays, one entry per run: residual_imbalance and residual_imbalance_x [kg m], beta0 and\n"
        "beta_final (runs x balls) [rad], status (str), ok, settled, settling_time [s], max_amplitude_mm,\n"
        "end_time_s, friction_mu, imbalance_kgm [kg m], reused, events, steps, rhs_evaluations,\n"
        "wall_time_s; and 'summary': the statistics as `abuopt montecarlo --json` prints them (kg m).\n"
        "Units: SI (imbalances in kg m), as in every function of this module.");
  m.def("equilibrium_set", &equilibrium_set, py::arg("config"), py::arg("freq"), py::kw_only(),
        py::arg("grid") = 128, py::arg("other_angles") = std::vector<double>{},
        "The equilibrium set at constant speed freq [Hz] on a grid x grid over (beta_1, beta_2), as\n"
        "`abuopt eqset --freq`. Returns beta (grid), amplitude_mm and in_set (grid x grid, [i, j] at\n"
        "beta_1 = beta[i], beta_2 = beta[j]), margins (grid x grid x balls), coverage, speed_ratio,\n"
        "natural_frequency_hz, mu, full_coverage_closed_form. Units: beta in rad, amplitude in mm.");

  py::class_<PyStartupProfileProblem>(m, "StartupProfileProblem",
                                      "The startup-profile design problem of `abuopt optimize` (docs/optimize.md).")
      .def(py::init<const py::handle&, std::optional<long long>, std::optional<std::string>,
                    std::optional<long long>, std::optional<long long>>(),
           py::arg("config"), py::kw_only(), py::arg("runs") = py::none(), py::arg("design") = py::none(),
           py::arg("seed") = py::none(), py::arg("threads") = py::none(),
           "runs/design/seed/threads override montecarlo.runs/.design/.seed/.threads of the config\n"
           "(checked as those keys): the in-sample initial conditions of every evaluation.")
      .def("evaluate", &PyStartupProfileProblem::evaluate, py::arg("x"),
           "objective (minimised), constraints (array, feasible when <= 0; +inf when the evaluation\n"
           "failed), metrics (dict), ok, message. The last x is remembered (no second Monte Carlo).\n"
           "Units: the optimiser's numbers, as `abuopt optimize` prints and archives them (mean I_r in\n"
           "1e-7 kg m, %MI in %; docs/optimize.md); x in Hz and s.")
      .def_property_readonly("names", &PyStartupProfileProblem::names,
                             "variable names: f<k> end frequency of segment k [Hz], dt<k> its duration [s]")
      .def_property_readonly("bounds", &PyStartupProfileProblem::bounds, "[(lower, upper)] per variable (Hz and s)")
      .def_property_readonly("scales", [](const PyStartupProfileProblem& p) {
        const std::vector<double> x = p.scales();
        return Array(static_cast<py::ssize_t>(x.size()), x.data());
      })
      .def_property_readonly("x0", [](const PyStartupProfileProblem& p) {
        const std::vector<double> x = p.x0();
        return Array(static_cast<py::ssize_t>(x.size()), x.data());
      }, "the initial point (array; Hz and s)")
      .def_property_readonly("constraint_names", &PyStartupProfileProblem::constraint_names)
      .def_property_readonly("identity", &PyStartupProfileProblem::identity)
      .def_property_readonly("evaluations", &PyStartupProfileProblem::evaluations,
                             "Monte Carlo evaluations done (repeats of the last x not counted)")
      .def("startup_time_s", &PyStartupProfileProblem::startup_time_s, py::arg("x"));

  register_problem_bindings(m);  // BatchProblem (problem_bindings.cpp)
}
