// SAO options: validation and the `sao:` YAML section (see sao_options.hpp, docs/sao.md).
#include "abuopt/optimizer/sao_options.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "abuopt/common/config_error.hpp"
#include "abuopt/optimizer/problem.hpp"

namespace abuopt::opt {

// ---------------------------------------------------------------------------------------------
// Options

namespace {

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

// The enumerator whose spelling is `text` (names in declaration order).
template <class E>
E enum_from_string(const std::string& text, const std::string& key, const std::vector<std::string>& names) {
  const auto it = std::find(names.begin(), names.end(), text);
  if (it == names.end())
    throw ConfigError(key, text.empty() ? "\"\"" : text, "must be one of: " + join(names));
  return static_cast<E>(it - names.begin());
}
template <class E>
const std::string& enum_to_string(E value, const std::vector<std::string>& names) {
  return names.at(static_cast<std::size_t>(value));
}

void require(bool ok, const std::string& prefix, const std::string& key, double value, const std::string& rule) {
  if (!ok) throw ConfigError(prefix + "." + key, format_number(value), rule);
}

}  // namespace

const std::vector<std::string>& surrogate_kind_names() {
  static const std::vector<std::string> c = {"auto", "linear", "interactions", "pure_quadratic", "quadratic",
                                             "kriging"};
  return c;
}
const std::vector<std::string>& doe_kind_names() {
  static const std::vector<std::string> c = {"auto", "koshal", "axial", "central_composite", "lhs"};
  return c;
}
const std::vector<std::string>& intervening_kind_names() {
  static const std::vector<std::string> c = {"auto", "linear", "reciprocal", "exponential"};
  return c;
}
const std::vector<std::string>& subproblem_solver_names() {
  static const std::vector<std::string> c = {"slsqp", "cobyla"};
  return c;
}

std::string to_string(SurrogateKind kind) { return enum_to_string(kind, surrogate_kind_names()); }
std::string to_string(DoeKind kind) { return enum_to_string(kind, doe_kind_names()); }
std::string to_string(InterveningKind kind) { return enum_to_string(kind, intervening_kind_names()); }
std::string to_string(SubproblemSolver solver) { return enum_to_string(solver, subproblem_solver_names()); }

SurrogateKind surrogate_kind_from_string(const std::string& text, const std::string& key) {
  return enum_from_string<SurrogateKind>(text, key, surrogate_kind_names());
}
DoeKind doe_kind_from_string(const std::string& text, const std::string& key) {
  return enum_from_string<DoeKind>(text, key, doe_kind_names());
}
InterveningKind intervening_kind_from_string(const std::string& text, const std::string& key) {
  return enum_from_string<InterveningKind>(text, key, intervening_kind_names());
}
SubproblemSolver subproblem_solver_from_string(const std::string& text, const std::string& key) {
  return enum_from_string<SubproblemSolver>(text, key, subproblem_solver_names());
}

void SaoOptions::validate(const std::string& p) const {
  require(doe_points >= 0, p, "doe_points", doe_points, "must be >= 0 (0: automatic)");
  require(std::isfinite(doe_points_factor) && doe_points_factor >= 1 && doe_points_factor <= 10, p,
          "doe_points_factor", doe_points_factor, "must be in [1, 10]");
  require(std::isfinite(reuse_distance) && reuse_distance > 0 && reuse_distance <= 1, p, "reuse_distance",
          reuse_distance, "must be in (0, 1]");
  require(std::isfinite(neighbourhood) && neighbourhood >= 1 && neighbourhood <= 10, p, "neighbourhood",
          neighbourhood, "must be in [1, 10]");
  require(std::isfinite(geometry_spread) && geometry_spread > 0 && geometry_spread < 1, p, "geometry_spread",
          geometry_spread, "must be in (0, 1)");
  require(std::isfinite(initial_radius) && initial_radius > 0 && initial_radius <= 1, p, "initial_radius",
          initial_radius, "must be in (0, 1]");
  require(std::isfinite(min_radius) && min_radius > 0 && min_radius <= initial_radius, p, "min_radius", min_radius,
          "must be in (0, initial_radius = " + format_number(initial_radius) + "]");
  require(std::isfinite(max_radius) && max_radius >= initial_radius && max_radius <= 1, p, "max_radius", max_radius,
          "must be in [initial_radius = " + format_number(initial_radius) + ", 1]");
  require(std::isfinite(shrink_factor) && shrink_factor > 0 && shrink_factor < 1, p, "shrink_factor", shrink_factor,
          "must be in (0, 1)");
  require(std::isfinite(expand_factor) && expand_factor >= 1 && expand_factor <= 100, p, "expand_factor",
          expand_factor, "must be in [1, 100]");
  require(std::isfinite(rho_shrink) && rho_shrink >= 0 && rho_shrink < 1, p, "rho_shrink", rho_shrink,
          "must be in [0, 1)");
  require(std::isfinite(rho_expand_low) && rho_expand_low > rho_shrink, p, "rho_expand_low", rho_expand_low,
          "must be > rho_shrink = " + format_number(rho_shrink));
  require(std::isfinite(rho_expand_high) && rho_expand_high >= rho_expand_low, p, "rho_expand_high",
          rho_expand_high, "must be >= rho_expand_low = " + format_number(rho_expand_low));
  require(std::isfinite(short_step) && short_step >= 0 && short_step < 1, p, "short_step", short_step,
          "must be in [0, 1) (0: off)");
  require(std::isfinite(noise_tolerance) && noise_tolerance >= 0 && noise_tolerance <= 100, p, "noise_tolerance",
          noise_tolerance, "must be in [0, 100] (0: off)");
  require(std::isfinite(penalty_initial) && penalty_initial >= 0, p, "penalty_initial", penalty_initial,
          "must be >= 0 (0: automatic)");
  require(std::isfinite(penalty_multiplier_factor) && penalty_multiplier_factor >= 1, p, "penalty_multiplier_factor",
          penalty_multiplier_factor, "must be >= 1");
  require(stall_iterations >= 1, p, "stall_iterations", stall_iterations, "must be >= 1");
  require(std::isfinite(stall_tolerance) && stall_tolerance >= 0, p, "stall_tolerance", stall_tolerance,
          "must be >= 0");
  require(subproblem_max_evaluations >= 10, p, "subproblem_max_evaluations", subproblem_max_evaluations,
          "must be >= 10");
  require(std::isfinite(kriging_nugget) && kriging_nugget > 0 && kriging_nugget < 1, p, "kriging_nugget",
          kriging_nugget, "must be in (0, 1)");
  if (surrogate == SurrogateKind::Quadratic && doe == DoeKind::Koshal)
    throw ConfigError(p + ".doe", to_string(doe), "koshal (n+1 points) cannot determine a quadratic surrogate; use auto, axial, "
                                       "central_composite or lhs");
}

SaoOptions read_sao_options(YamlReader& r) {
  SaoOptions o;
  // the choices: read as text (the reader checks the spelling), parsed once into their enums
  auto choice = [&r](const std::string& key, const std::string& fallback, const std::vector<std::string>& names) {
    return r.get_choice_or(key, fallback, names);
  };
  o.surrogate = surrogate_kind_from_string(choice("surrogate", to_string(o.surrogate), surrogate_kind_names()),
                                           r.key_path("surrogate"));
  o.doe = doe_kind_from_string(choice("doe", to_string(o.doe), doe_kind_names()), r.key_path("doe"));
  o.doe_points = static_cast<int>(r.get_int_or("doe_points", o.doe_points, Rule::in_range(0, 100000)));
  o.doe_points_factor = r.get_double_or("doe_points_factor", o.doe_points_factor);
  o.reuse_distance = r.get_double_or("reuse_distance", o.reuse_distance);
  o.neighbourhood = r.get_double_or("neighbourhood", o.neighbourhood);
  o.geometry_spread = r.get_double_or("geometry_spread", o.geometry_spread);
  o.initial_radius = r.get_double_or("initial_radius", o.initial_radius);
  o.min_radius = r.get_double_or("min_radius", o.min_radius);
  o.max_radius = r.get_double_or("max_radius", o.max_radius);
  o.shrink_factor = r.get_double_or("shrink_factor", o.shrink_factor);
  o.expand_factor = r.get_double_or("expand_factor", o.expand_factor);
  o.rho_shrink = r.get_double_or("rho_shrink", o.rho_shrink);
  o.rho_expand_low = r.get_double_or("rho_expand_low", o.rho_expand_low);
  o.rho_expand_high = r.get_double_or("rho_expand_high", o.rho_expand_high);
  o.intervening = intervening_kind_from_string(
      choice("intervening", to_string(o.intervening), intervening_kind_names()), r.key_path("intervening"));
  for (const char* key : {"intervening_objective", "intervening_constraints"}) {
    if (!r.has(key)) continue;
    const InterveningKind k = intervening_kind_from_string(
        choice(key, to_string(o.intervening), intervening_kind_names()), r.key_path(key));
    (std::string(key) == "intervening_objective" ? o.intervening_objective : o.intervening_constraints) = k;
  }
  o.correction = r.get_bool_or("correction", o.correction);
  o.short_step = r.get_double_or("short_step", o.short_step);
  o.noise_tolerance = r.get_double_or("noise_tolerance", o.noise_tolerance);
  o.penalty_initial = r.get_double_or("penalty_initial", o.penalty_initial);
  o.penalty_multiplier_factor = r.get_double_or("penalty_multiplier_factor", o.penalty_multiplier_factor);
  o.stall_iterations = static_cast<int>(r.get_int_or("stall_iterations", o.stall_iterations, Rule::in_range(1, 1e6)));
  o.stall_tolerance = r.get_double_or("stall_tolerance", o.stall_tolerance);
  o.subproblem_solver = subproblem_solver_from_string(
      choice("subproblem_solver", to_string(o.subproblem_solver), subproblem_solver_names()),
      r.key_path("subproblem_solver"));
  o.subproblem_max_evaluations = static_cast<int>(
      r.get_int_or("subproblem_max_evaluations", o.subproblem_max_evaluations, Rule::in_range(10, 1e7)));
  o.kriging_nugget = r.get_double_or("kriging_nugget", o.kriging_nugget);
  r.finish();
  o.validate(r.path().empty() ? "sao" : r.path());
  return o;
}


}  // namespace abuopt::opt
