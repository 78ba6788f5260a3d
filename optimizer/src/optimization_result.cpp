#include "abuopt/optimizer/optimization_result.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <utility>

#include "abuopt/common/config_error.hpp"

namespace abuopt::opt {

namespace {
const std::vector<std::pair<TerminationReason, const char*>>& reason_names() {
  using R = TerminationReason;
  static const std::vector<std::pair<R, const char*>> names = {
      {R::Converged, "converged"},
      {R::ConvergedFtol, "converged_ftol"},
      {R::ConvergedXtol, "converged_xtol"},
      {R::TargetReached, "target_reached"},
      {R::MaxEvaluations, "max_evaluations"},
      {R::MaxIterations, "max_iterations"},
      {R::MaxTime, "max_time"},
      {R::StoppedByCallback, "stopped_by_callback"},
      {R::Interrupted, "interrupted"},
      {R::EvaluationError, "evaluation_error"},
      {R::Infeasible, "infeasible"},
      {R::RoundoffLimited, "roundoff_limited"},
      {R::Failure, "failure"},
  };
  return names;
}

std::string fixed(double v, int digits = 6) {
  if (!std::isfinite(v)) return format_number(v);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}
}  // namespace

std::string to_string(TerminationReason reason) {
  for (const auto& [r, n] : reason_names())
    if (r == reason) return n;
  return "unknown";
}

TerminationReason termination_reason_from_string(const std::string& text) {
  std::string valid;
  for (const auto& [r, n] : reason_names()) {
    if (text == n) return r;
    valid += (valid.empty() ? "" : ", ") + std::string(n);
  }
  throw ConfigError("termination reason", text, "unknown; valid: " + valid);
}

std::string to_string(IterationStep step) {
  switch (step) {
    case IterationStep::Accepted: return "accepted";
    case IterationStep::Rejected: return "rejected";
    case IterationStep::NoPredictedReduction: return "no_predicted_reduction";
    case IterationStep::NoModel: return "no_model";
  }
  return "unknown";
}

bool is_convergence(TerminationReason r) {
  return r == TerminationReason::Converged || r == TerminationReason::ConvergedFtol ||
         r == TerminationReason::ConvergedXtol || r == TerminationReason::TargetReached;
}

bool OptimizationResult::success() const { return is_convergence(reason) && has_feasible_point(); }

std::string OptimizationResult::brief_report() const {
  std::ostringstream os;
  os << algorithm << " on " << problem_name << ": " << to_string(reason);
  if (x.empty()) {
    os << ", no point evaluated";
  } else {
    os << ", f = " << fixed(objective, 8);
    if (feasible) os << " (feasible)";
    else os << " (INFEASIBLE, max violation " << fixed(max_violation, 3) << ")";
  }
  os << ", " << evaluations << " evaluations (" << archive_hits << " from archive), " << fixed(wall_time_s, 3)
     << " s";
  return os.str();
}

std::string OptimizationResult::full_report() const {
  std::ostringstream os;
  os << "Optimisation of '" << problem_name << "' with " << algorithm << "\n";
  os << "  termination:        " << to_string(reason) << (success() ? " (success)" : "") << "\n";
  if (!message.empty()) os << "  message:            " << message << "\n";
  os << "  evaluations:        " << evaluations << " (" << archive_hits << " from archive, " << failed_evaluations
     << " failed, " << gradient_evaluations << " for finite-difference gradients)\n";
  os << "  repeats from memory " << repeated_requests << ", requests clipped into bounds " << clipped_requests;
  if (iterations > 0) os << ", iterations " << iterations;
  os << "\n";
  os << "  wall time:          " << fixed(wall_time_s, 4) << " s\n";
  if (x.empty()) {
    os << "  no point was evaluated\n";
    return os.str();
  }
  os << "  best point:         f = " << format_number(objective) << ", "
     << (feasible ? "feasible" : "INFEASIBLE") << " (max violation " << fixed(max_violation, 3) << ", tolerance "
     << fixed(constraint_tolerance, 3) << ")\n";
  std::size_t width = 4;
  for (const auto& n : variable_names) width = std::max(width, n.size());
  for (const auto& n : inequality_names) width = std::max(width, n.size());
  for (const auto& n : equality_names) width = std::max(width, n.size());
  for (const auto& [n, v] : metrics) width = std::max(width, n.size());
  auto line = [&](const std::string& name, const std::string& value, const std::string& note) {
    os << "    " << name << std::string(width + 2 - std::min(width + 1, name.size()), ' ') << value << note << "\n";
  };
  os << "  variables (start -> best):\n";
  for (std::size_t i = 0; i < x.size(); ++i) {
    const std::string name = i < variable_names.size() ? variable_names[i] : "x[" + std::to_string(i) + "]";
    const std::string start = i < x0.size() ? format_number(x0[i]) + " -> " : "";
    line(name, start + format_number(x[i]), "");
  }
  if (!inequality.empty()) {
    os << "  inequality constraints g <= 0:\n";
    for (std::size_t i = 0; i < inequality.size(); ++i)
      line(i < inequality_names.size() ? inequality_names[i] : "g[" + std::to_string(i) + "]",
           fixed(inequality[i], 8), inequality[i] > constraint_tolerance ? "  VIOLATED" : "");
  }
  if (!equality.empty()) {
    os << "  equality constraints h = 0:\n";
    for (std::size_t i = 0; i < equality.size(); ++i)
      line(i < equality_names.size() ? equality_names[i] : "h[" + std::to_string(i) + "]", fixed(equality[i], 8),
           std::fabs(equality[i]) > constraint_tolerance ? "  VIOLATED" : "");
  }
  if (!metrics.empty()) {
    os << "  metrics:\n";
    for (const auto& [n, v] : metrics) line(n, fixed(v, 8), "");
  }
  return os.str();
}

}  // namespace abuopt::opt
