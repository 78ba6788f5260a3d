// SAO options: validation and the `sao:` YAML section (see sao_options.hpp, docs/sao.md).
#include "abuopt/optimizer/sao_options.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/config_fields.hpp"
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

// A finite value in an interval; `interval` is one of "[]", "(]", "()", "[)" (closed or open at
// each end). The rule reads "must be in [lo, hi]" and then `note`, if any.
void require_in(const std::string& prefix, const std::string& key, double value, const char* interval, double lo,
                double hi, const std::string& note = "") {
  const bool lo_ok = interval[0] == '[' ? value >= lo : value > lo;
  const bool hi_ok = interval[1] == ']' ? value <= hi : value < hi;
  require(std::isfinite(value) && lo_ok && hi_ok, prefix, key, value,
          std::string("must be in ") + interval[0] + format_number(lo) + ", " + format_number(hi) + interval[1] +
              (note.empty() ? "" : " " + note));
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

const std::vector<std::string>& global_phase_mode_names() {
  static const std::vector<std::string> c = {"auto", "always", "never"};
  return c;
}
std::string to_string(GlobalPhaseMode mode) { return enum_to_string(mode, global_phase_mode_names()); }

namespace {
// The automatic size of the global phase: 4 (n + 1) points, a sixth of the budget at most, 2 at
// least (docs/sao.md, "Global phase": 20 + 20 on hs071, n = 4, was the measured setting).
int automatic_global_size(int n, long max_evaluations) {
  long k = 4L * (n + 1);
  if (max_evaluations > 0) k = std::min(k, max_evaluations / 6);
  return static_cast<int>(std::max(2L, k));
}
}  // namespace

int SaoGlobalPhase::design_points(int n, long max_evaluations) const {
  return points > 0 ? points : automatic_global_size(n, max_evaluations);
}
int SaoGlobalPhase::infill_points(int n, long max_evaluations) const {
  return points > 0 ? iterations : automatic_global_size(n, max_evaluations);
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
  require_in(p, "doe_points_factor", doe_points_factor, "[]", 1, 10);
  require_in(p, "reuse_distance", reuse_distance, "(]", 0, 1);
  require_in(p, "neighbourhood", neighbourhood, "[]", 1, 10);
  require_in(p, "geometry_spread", geometry_spread, "()", 0, 1);
  require_in(p, "initial_radius", initial_radius, "(]", 0, 1);
  require(std::isfinite(min_radius) && min_radius > 0 && min_radius <= initial_radius, p, "min_radius", min_radius,
          "must be in (0, initial_radius = " + format_number(initial_radius) + "]");
  require(std::isfinite(max_radius) && max_radius >= initial_radius && max_radius <= 1, p, "max_radius", max_radius,
          "must be in [initial_radius = " + format_number(initial_radius) + ", 1]");
  require_in(p, "shrink_factor", shrink_factor, "()", 0, 1);
  require_in(p, "expand_factor", expand_factor, "[]", 1, 100);
  require_in(p, "rho_shrink", rho_shrink, "[)", 0, 1);
  require(std::isfinite(rho_expand_low) && rho_expand_low > rho_shrink, p, "rho_expand_low", rho_expand_low,
          "must be > rho_shrink = " + format_number(rho_shrink));
  require(std::isfinite(rho_expand_high) && rho_expand_high >= rho_expand_low, p, "rho_expand_high",
          rho_expand_high, "must be >= rho_expand_low = " + format_number(rho_expand_low));
  require_in(p, "short_step", short_step, "[)", 0, 1, "(0: off)");
  require_in(p, "noise_tolerance", noise_tolerance, "[]", 0, 100, "(0: off)");
  require_in(p, "noise_stop", noise_stop, "[]", 0, 100, "(0: off)");
  require(noise_stop_window >= 0, p, "noise_stop_window", noise_stop_window, "must be >= 0 (0: automatic, 10 (n + 1))");
  require(std::isfinite(penalty_initial) && penalty_initial >= 0, p, "penalty_initial", penalty_initial,
          "must be >= 0 (0: automatic)");
  require(std::isfinite(penalty_multiplier_factor) && penalty_multiplier_factor >= 1, p, "penalty_multiplier_factor",
          penalty_multiplier_factor, "must be >= 1");
  require(stall_iterations >= 1, p, "stall_iterations", stall_iterations, "must be >= 1");
  require(std::isfinite(stall_tolerance) && stall_tolerance >= 0, p, "stall_tolerance", stall_tolerance,
          "must be >= 0");
  require(subproblem_max_evaluations >= 10, p, "subproblem_max_evaluations", subproblem_max_evaluations,
          "must be >= 10");
  require_in(p, "kriging_nugget", kriging_nugget, "()", 0, 1);
  require(global_phase.points == 0 || global_phase.points >= 2, p + ".global_phase", "points", global_phase.points,
          "must be 0 (automatic size) or >= 2");
  require(global_phase.iterations == 0 || global_phase.points > 0, p + ".global_phase", "iterations",
          global_phase.iterations, "needs global_phase.points > 0 (the design the infill starts from)");
  require(samples.initial >= 0, p + ".samples", "initial", samples.initial, "must be 0 (off) or >= 1");
  require(samples.max == 0 || (samples.initial > 0 && samples.max >= samples.initial), p + ".samples", "max",
          samples.max,
          samples.initial > 0 ? "must be 0 (the problem's largest) or >= samples.initial = " + std::to_string(samples.initial)
                              : std::string("needs samples.initial >= 1 (the schedule is off)"));
  require_in(p + ".samples", "exponent", samples.exponent, "[]", 0, 8);
  if (surrogate == SurrogateKind::Quadratic && doe == DoeKind::Koshal)
    throw ConfigError(p + ".doe", to_string(doe), "koshal (n+1 points) cannot determine a quadratic surrogate; use auto, axial, "
                                       "central_composite or lhs");
}

namespace {

// EnumNames (config_fields.hpp) from a spelling list in declaration order.
template <class E>
EnumNames<E> enum_names(const std::vector<std::string>& names) {
  EnumNames<E> out;
  for (std::size_t i = 0; i < names.size(); ++i) out.emplace_back(static_cast<E>(i), names[i]);
  return out;
}

// An override that is absent unless given (written only when set).
void optional_intervening(FieldArchive& a, const char* key, std::optional<InterveningKind>& v,
                          InterveningKind fallback) {
  static const EnumNames<InterveningKind> names = enum_names<InterveningKind>(intervening_kind_names());
  InterveningKind k = v.value_or(fallback);
  FieldOptions o;
  o.enabled = a.reading() || v.has_value();
  const bool given = a.reading() && a.has(key);
  a.field(key, k, names, o);
  if (given) v = k;
}

}  // namespace

// The keys of a `sao:` section, once (reading, writing, validation of single values). The rules
// that relate keys (min_radius <= initial_radius, ...) and the friendlier texts are in validate().
void describe_fields(FieldArchive& a, SaoOptions& o) {
  static const EnumNames<SurrogateKind> surrogates = enum_names<SurrogateKind>(surrogate_kind_names());
  static const EnumNames<DoeKind> does = enum_names<DoeKind>(doe_kind_names());
  static const EnumNames<InterveningKind> forms = enum_names<InterveningKind>(intervening_kind_names());
  static const EnumNames<SubproblemSolver> solvers = enum_names<SubproblemSolver>(subproblem_solver_names());
  a.field("surrogate", o.surrogate, surrogates);
  a.field("doe", o.doe, does);
  a.field("doe_points", o.doe_points, Rule::in_range(0, 100000));
  a.field("doe_points_factor", o.doe_points_factor);
  a.field("reuse_distance", o.reuse_distance);
  a.field("neighbourhood", o.neighbourhood);
  a.field("geometry_spread", o.geometry_spread);
  a.field("initial_radius", o.initial_radius);
  a.field("min_radius", o.min_radius);
  a.field("max_radius", o.max_radius);
  a.field("shrink_factor", o.shrink_factor);
  a.field("expand_factor", o.expand_factor);
  a.field("rho_shrink", o.rho_shrink);
  a.field("rho_expand_low", o.rho_expand_low);
  a.field("rho_expand_high", o.rho_expand_high);
  a.field("intervening", o.intervening, forms);
  optional_intervening(a, "intervening_objective", o.intervening_objective, o.intervening);
  optional_intervening(a, "intervening_constraints", o.intervening_constraints, o.intervening);
  a.field("correction", o.correction);
  a.field("short_step", o.short_step);
  a.field("noise_tolerance", o.noise_tolerance);
  a.field("noise_detection", o.noise_detection);
  a.field("noise_stop", o.noise_stop);
  a.field("noise_stop_window", o.noise_stop_window, Rule::in_range(0, 1e9));
  a.field("penalty_initial", o.penalty_initial);
  a.field("penalty_multiplier_factor", o.penalty_multiplier_factor);
  a.field("stall_iterations", o.stall_iterations, Rule::in_range(1, 1e6));
  a.field("stall_tolerance", o.stall_tolerance);
  a.field("subproblem_solver", o.subproblem_solver, solvers);
  a.field("subproblem_max_evaluations", o.subproblem_max_evaluations, Rule::in_range(10, 1e7));
  a.field("kriging_nugget", o.kriging_nugget);
  a.nested("global_phase", o.global_phase);
  FieldOptions sampling;
  sampling.enabled = a.reading() || o.samples.enabled();  // written only when on (older outputs unchanged)
  a.nested("samples", o.samples, sampling);
}

void describe_fields(FieldArchive& a, SaoSampling& o) {
  a.field("initial", o.initial, Rule::in_range(0, 1 << 30));
  a.field("max", o.max, Rule::in_range(0, 1 << 30));
  a.field("exponent", o.exponent);
}

void describe_fields(FieldArchive& a, SaoGlobalPhase& o) {
  static const EnumNames<GlobalPhaseMode> modes = enum_names<GlobalPhaseMode>(global_phase_mode_names());
  a.field("mode", o.mode, modes);
  a.field("points", o.points, Rule::in_range(0, 100000));
  a.field("iterations", o.iterations, Rule::in_range(0, 100000));
  a.field("restart", o.restart);
  a.field("polish", o.polish);
}

SaoOptions read_sao_options(YamlReader& r) {
  SaoOptions o;
  read_fields(r, o);  // absent keys keep their defaults; unknown keys are errors (finish())
  o.validate(r.path().empty() ? "sao" : r.path());
  return o;
}

std::string to_yaml(const SaoOptions& o) { return write_fields(o); }

}  // namespace abuopt::opt
