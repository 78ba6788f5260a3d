// Design sweeps (sweep.hpp, docs/sweep.md): settings, plans, the evaluation loop and the CSV.
#include "abuopt/studies/sweep.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "abuopt/common/stop.hpp"
#include "abuopt/common/config_error.hpp"
#include "abuopt/common/output_file.hpp"
#include "abuopt/common/text.hpp"
#include "abuopt/core/final_states.hpp"
#include "abuopt/core/initial_conditions.hpp"
#include "abuopt/surrogate/doe.hpp"

namespace abuopt {

namespace {

std::size_t index_of(const std::vector<opt::Variable>& vars, const std::string& name, const std::string& key,
                     const std::string& value) {
  for (std::size_t i = 0; i < vars.size(); ++i)
    if (vars[i].name == name) return i;
  std::string names;
  for (const auto& v : vars) names += (names.empty() ? "" : ", ") + v.name;
  throw ConfigError(key, value, "not a free variable of the design (free: " + names + ")");
}

}  // namespace

std::string to_string(SweepMethod m) {
  switch (m) {
    case SweepMethod::Grid: return "grid";
    case SweepMethod::Lhs: return "lhs";
    case SweepMethod::Sobol: return "sobol";
  }
  return "grid";
}

SweepSettings read_sweep_settings(YamlReader section, const std::vector<opt::Variable>& free) {
  SweepSettings s;
  if (!section.present()) throw ConfigError("sweep", "(absent)", "a sweep needs a `sweep` section (method, points)");
  const std::string method = section.get_choice_or("method", "grid", {"grid", "lhs", "sobol"});
  s.method = method == "lhs" ? SweepMethod::Lhs : method == "sobol" ? SweepMethod::Sobol : SweepMethod::Grid;
  s.variables = section.get_string_list_or("variables", {});
  std::set<std::string> seen;
  for (std::size_t i = 0; i < s.variables.size(); ++i) {
    const std::string key = section.key_path("variables") + "[" + std::to_string(i) + "]";
    index_of(free, s.variables[i], key, s.variables[i]);
    if (!seen.insert(s.variables[i]).second) throw ConfigError(key, s.variables[i], "listed twice");
  }
  if (section.has("points"))
    s.points = static_cast<std::size_t>(section.get_int("points", Rule::at_least(1)));
  YamlReader levels = section.child("levels");
  if (levels.present()) {
    if (s.method != SweepMethod::Grid)
      throw ConfigError(section.key_path("levels"), "(given)", "only with method: grid");
    if (!levels.node().IsMap()) throw ConfigError(section.key_path("levels"), yaml_value_text(levels.node()), "must be a mapping {variable: levels}");
    for (const auto& kv : levels.node()) {
      const std::string name = kv.first.as<std::string>();
      const std::string key = levels.key_path(name);
      index_of(free, name, key, name);
      const long n = levels.get_int(name, Rule::at_least(2));
      s.levels.emplace_back(name, static_cast<std::size_t>(n));
    }
    levels.finish();
  }
  if (s.method == SweepMethod::Lhs)
    s.seed = static_cast<std::uint64_t>(section.get_int_or("seed", 1, Rule::non_negative()));
  else if (section.has("seed"))
    throw ConfigError(section.key_path("seed"), yaml_value_text(section.node()["seed"]), "only with method: lhs");
  section.finish();
  return s;
}

std::vector<std::vector<double>> grid_unit_design(const std::vector<std::size_t>& levels) {
  std::size_t total = 1;
  for (std::size_t n : levels) {
    if (n < 2) throw std::invalid_argument("grid_unit_design: levels = " + std::to_string(n) + ": must be >= 2");
    total *= n;
  }
  std::vector<std::vector<double>> rows(total, std::vector<double>(levels.size()));
  for (std::size_t p = 0; p < total; ++p) {
    std::size_t rest = p;
    for (std::size_t k = levels.size(); k-- > 0;) {  // the last variable varies fastest
      const std::size_t j = rest % levels[k];
      rest /= levels[k];
      rows[p][k] = static_cast<double>(j) / static_cast<double>(levels[k] - 1);
    }
  }
  return rows;
}

std::vector<std::vector<double>> sobol_unit_design(std::size_t points, std::size_t dims) {
  std::vector<std::vector<double>> rows;
  rows.reserve(points);
  for (std::size_t i = 0; i < points; ++i) rows.push_back(sobol_unit_point(i, dims));
  return rows;
}

std::vector<std::vector<double>> lhs_unit_design(std::size_t points, std::size_t dims, std::uint64_t seed) {
  surrogate::LatinHypercubeOptions o;
  o.points = static_cast<int>(points);
  o.seed = seed;
  const Eigen::MatrixXd d = surrogate::latin_hypercube(static_cast<int>(dims), o);  // in [-1, 1]
  std::vector<std::vector<double>> rows(points, std::vector<double>(dims));
  for (std::size_t i = 0; i < points; ++i)
    for (std::size_t j = 0; j < dims; ++j)
      rows[i][j] = std::clamp((d(static_cast<long>(i), static_cast<long>(j)) + 1.0) / 2.0, 0.0, 1.0);
  return rows;
}

SweepPlan plan_sweep(const SweepSettings& s, const std::vector<opt::Variable>& vars, const std::vector<double>& x0) {
  SweepPlan plan;
  plan.method = s.method;
  if (s.variables.empty())
    for (std::size_t i = 0; i < vars.size(); ++i) plan.swept.push_back(i);
  else
    for (const auto& n : s.variables) plan.swept.push_back(index_of(vars, n, "sweep.variables", n));
  const std::size_t k = plan.swept.size();
  if (s.method == SweepMethod::Grid) {
    for (std::size_t i : plan.swept) {
      std::size_t n = s.points;
      for (const auto& [name, lv] : s.levels)
        if (name == vars[i].name) n = lv;
      if (n == 0)
        throw ConfigError("sweep.points", "(absent)", "a grid needs the levels per variable: sweep.points or sweep.levels." + vars[i].name);
      if (n < 2) throw ConfigError("sweep.points", std::to_string(n), "a grid needs >= 2 levels per variable");
      plan.levels.push_back(n);
    }
    for (const auto& [name, lv] : s.levels) {
      bool swept = false;
      for (std::size_t i : plan.swept) swept = swept || vars[i].name == name;
      if (!swept) throw ConfigError("sweep.levels." + name, std::to_string(lv), "this variable is not swept (sweep.variables)");
    }
    double total = 1;
    for (std::size_t n : plan.levels) total *= static_cast<double>(n);
    if (total > static_cast<double>(kMaxSweepPoints))
      throw ConfigError("sweep.points", format_number(total) + " grid points",
                        "must be <= " + std::to_string(kMaxSweepPoints));
    plan.unit = grid_unit_design(plan.levels);
  } else {
    if (s.points == 0) throw ConfigError("sweep.points", "(absent)", "lhs and sobol need the number of points");
    if (s.points > kMaxSweepPoints)
      throw ConfigError("sweep.points", std::to_string(s.points), "must be <= " + std::to_string(kMaxSweepPoints));
    if (s.method == SweepMethod::Sobol) {
      if (k > kSobolMaxDimension)
        throw ConfigError("sweep.variables", std::to_string(k) + " variables",
                          "sobol supports at most " + std::to_string(kSobolMaxDimension));
      plan.unit = sobol_unit_design(s.points, k);
    } else {
      if (s.points < 2) throw ConfigError("sweep.points", std::to_string(s.points), "lhs needs >= 2 points");
      plan.unit = lhs_unit_design(s.points, k, s.seed);
    }
  }
  for (const auto& u : plan.unit) {
    std::vector<double> x = x0;
    for (std::size_t j = 0; j < k; ++j) {
      const opt::Variable& v = vars[plan.swept[j]];
      double xi = u[j] <= 0.0 ? v.lower : u[j] >= 1.0 ? v.upper : v.lower + u[j] * (v.upper - v.lower);
      x[plan.swept[j]] = std::clamp(xi, v.lower, v.upper);
    }
    plan.x.push_back(std::move(x));
  }
  return plan;
}

const SweepPoint* best_feasible_point(const SweepResult& r) {
  const SweepPoint* best = nullptr;
  for (const auto& p : r.points)
    if (p.feasible && (!best || p.e.objective < best->e.objective)) best = &p;
  return best;
}

SweepResult run_sweep(opt::Problem& problem, opt::EvaluationArchive& archive, const SweepPlan& plan,
                      const SweepProgress& progress, const std::atomic<bool>* stop, double constraint_tolerance) {
  using clock = std::chrono::steady_clock;
  SweepResult r;
  r.plan = plan;
  const auto t0 = clock::now();
  const std::size_t n_ineq = problem.inequality_names().size(), n_eq = problem.equality_names().size();
  for (std::size_t i = 0; i < plan.x.size(); ++i) {
    if (stop && stop->load()) {
      r.interrupted = true;
      break;
    }
    SweepPoint p;
    p.index = i;
    p.x = plan.x[i];
    if (std::optional<opt::Evaluation> hit = archive.find(p.x)) {
      p.e = std::move(*hit);
      p.from_archive = true;
      ++r.archive_hits;
    } else {
      const auto t = clock::now();
      try {
        p.e = problem.evaluate(p.x);
      } catch (const Interrupted&) {  // the stop request ended the point's runs: not a point
        r.interrupted = true;
        break;
      }
      p.wall_time_s = std::chrono::duration<double>(clock::now() - t).count();
      p.e.from_archive = false;
      if (p.e.ok) opt::check_evaluation_shape(n_ineq, n_eq, p.e);
      archive.store(p.x, p.e, p.wall_time_s);
      ++r.computed;
    }
    if (!p.e.ok) ++r.failed;
    p.max_violation = opt::max_constraint_violation(p.e);
    p.feasible = opt::is_feasible(p.e, constraint_tolerance);
    r.points.push_back(std::move(p));
    if (progress)
      progress(r.points.back(), r.points.size(), plan.x.size(), std::chrono::duration<double>(clock::now() - t0).count());
  }
  r.wall_time_s = std::chrono::duration<double>(clock::now() - t0).count();
  return r;
}

std::string objective_label(const problems::StartupProfileSettings& s) {
  using problems::ObjectiveKind;
  const bool x = s.objective.definition == problems::ImbalanceDefinition::ReportX;
  const std::string ir = x ? "I_r,x" : "|I_r|";
  switch (s.objective.kind) {
    case ObjectiveKind::Mean: return "mean " + ir + " [1e-7 kg m]";
    case ObjectiveKind::PctMi: return "%MI (" + ir + ") [%]";
    case ObjectiveKind::Weighted: return "weighted objective (mean " + ir + ", %MI)";
    case ObjectiveKind::SmoothPctMi: return "smoothed %MI (" + ir + ") [%]";
    case ObjectiveKind::Quantile: return "quantile of " + ir + " [1e-7 kg m]";
    case ObjectiveKind::Cvar: return "CVaR of " + ir + " [1e-7 kg m]";
    case ObjectiveKind::StartupTime: return "startup time [s]";
  }
  return "objective";
}

std::string variable_label(const std::string& name) {
  if (name.rfind("dt", 0) == 0) return "duration " + name + " [s]";
  if (name.rfind("f", 0) == 0) return "end frequency " + name + " [Hz]";
  return name;
}

double objective_half_width(const problems::StartupProfileSettings& s, const opt::Evaluation& e) {
  if (s.objective.kind != problems::ObjectiveKind::Mean || !s.objective.robust_friction_mu.empty())
    return std::numeric_limits<double>::quiet_NaN();
  const bool x = s.objective.definition == problems::ImbalanceDefinition::ReportX;
  auto it = e.metrics.find(x ? "ir_x_mean_hw95" : "ir_magnitude_mean_hw95");
  return it == e.metrics.end() ? std::numeric_limits<double>::quiet_NaN() : it->second;
}

std::optional<double> sweep_lock_radius_kgm(const problems::StartupProfileSettings& s) {
  const UncertainParameters& u = s.study.uncertain;
  if (!u.deterministic() || !u.envelope.empty()) return std::nullopt;
  AbuParameters p = s.study.setup.abu;
  if (u.friction.sampling == FrictionSampling::Fixed) p.friction_mu = u.friction.value;
  return lock_radius_kgm(p);
}

void write_sweep_csv(const std::filesystem::path& path, const problems::StartupProfileProblem& problem,
                     const SweepResult& r) {
  const std::optional<double> r_lock = sweep_lock_radius_kgm(problem.settings());
  const auto vars = problem.variables();
  const auto g_names = problem.inequality_names();
  std::set<std::string> metric_names;
  for (const auto& p : r.points)
    for (const auto& [k, v] : p.e.metrics) metric_names.insert(k);
  AtomicFile f(path);
  f << "point,from_archive,ok,feasible,objective,objective_hw95,max_violation";
  for (const auto& v : vars) f << "," << csv_field(v.name);
  for (const auto& n : g_names) f << "," << csv_field("g_" + n);
  for (const auto& n : metric_names) f << "," << csv_field(n);
  f << ",wall_time_s,message,depth_mean\n";
  for (const auto& p : r.points) {
    const double hw = objective_half_width(problem.settings(), p.e);
    f << p.index + 1 << "," << p.from_archive << "," << p.e.ok << "," << p.feasible << ","
      << (p.e.ok ? csv_number(p.e.objective) : "") << "," << (std::isfinite(hw) ? csv_number(hw) : "") << ","
      << csv_number(p.max_violation);
    for (double xi : p.x) f << "," << csv_number(xi);
    for (std::size_t i = 0; i < g_names.size(); ++i)
      f << "," << (i < p.e.inequality.size() ? csv_number(p.e.inequality[i]) : "");
    for (const auto& n : metric_names) {
      auto it = p.e.metrics.find(n);
      f << "," << (it == p.e.metrics.end() ? "" : csv_number(it->second));
    }
    f << "," << csv_number(p.wall_time_s) << "," << csv_field(p.e.message) << ",";
    // mean |I_r| over r_lock (docs/equilibrium_sets.md section 4): empty with uncertain parameters
    const auto m = p.e.metrics.find("ir_magnitude_mean");
    if (r_lock && p.e.ok && m != p.e.metrics.end()) f << csv_number(m->second * 1e-7 / *r_lock);
    f << "\n";
  }
  f.commit();
}

}  // namespace abuopt
