// Runs of an optimiser outside abuopt (examples/python/optuna_study.py) read into a comparison
// (benchmarking.hpp, SolverSpec::external_runs). One CSV per (problem, start):
//   evaluation,ok,objective,max_violation,<variable 1>,...,<variable n>
// one line per evaluation in the order the optimiser made them (evaluation 1, 2, ...); ok is 0/1;
// objective and max_violation as numbers (inf allowed for a failed evaluation); the variables in
// the problem's order and by its names.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "abuopt/common/config_error.hpp"
#include "abuopt/optimizer/benchmarking.hpp"

namespace abuopt::opt {

namespace {

std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream is(line);
  while (std::getline(is, cell, ',')) {
    if (!cell.empty() && cell.back() == '\r') cell.pop_back();
    out.push_back(cell);
  }
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

double parse_number(const std::string& text, const std::string& where) {
  const char* begin = text.c_str();
  char* end = nullptr;
  const double v = std::strtod(begin, &end);
  if (text.empty() || end != begin + text.size())
    throw ConfigError(where, text.empty() ? "\"\"" : text, "is not a number");
  return v;
}

}  // namespace

std::string external_run_path(const std::string& directory, const std::string& problem_label, int start) {
  std::string safe = problem_label;
  for (char& c : safe)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
  return (std::filesystem::path(directory) / safe / ("start" + std::to_string(start) + ".csv")).string();
}

OptimizationResult read_external_run(const std::string& path, const Problem& problem, double constraint_tolerance,
                                     long max_evaluations) {
  std::ifstream in(path);
  if (!in)
    throw ConfigError(path, "<missing>",
                      "an external run must exist (made by e.g. examples/python/optuna_study.py before compare)");
  const std::vector<Variable> vars = problem.variables();
  std::string line;
  std::getline(in, line);
  const std::vector<std::string> header = split_csv(line);
  std::vector<std::string> expected = {"evaluation", "ok", "objective", "max_violation"};
  for (const Variable& v : vars) expected.push_back(v.name);
  if (header != expected) {
    std::string want;
    for (const auto& h : expected) want += (want.empty() ? "" : ",") + h;
    throw ConfigError(path + ": header", line, "must be " + want);
  }
  OptimizationResult r;
  r.problem_name = problem.name();
  r.constraint_tolerance = constraint_tolerance;
  for (const Variable& v : vars) r.variable_names.push_back(v.name);
  r.inequality_names = problem.inequality_names();
  r.equality_names = problem.equality_names();
  long row = 1;
  std::optional<std::size_t> best;
  while (std::getline(in, line)) {
    if (line.empty() || line == "\r") continue;
    ++row;
    const std::string where = path + ": line " + std::to_string(row);
    const std::vector<std::string> cells = split_csv(line);
    if (cells.size() != expected.size())
      throw ConfigError(where, std::to_string(cells.size()) + " fields", "must have " + std::to_string(expected.size()));
    EvaluationRecord h;
    h.index = static_cast<long>(r.history.size());
    if (parse_number(cells[0], where + " evaluation") != static_cast<double>(h.index + 1))
      throw ConfigError(where + " evaluation", cells[0], "must be " + std::to_string(h.index + 1) + " (1, 2, ... in order)");
    h.ok = parse_number(cells[1], where + " ok") != 0.0;
    h.objective = parse_number(cells[2], where + " objective");
    h.max_violation = parse_number(cells[3], where + " max_violation");
    for (std::size_t i = 0; i < vars.size(); ++i) h.x.push_back(parse_number(cells[4 + i], where + " " + vars[i].name));
    check_design_vector(vars, h.x, where);
    if (!h.ok) {
      h.objective = std::numeric_limits<double>::infinity();
      h.max_violation = std::numeric_limits<double>::infinity();
      ++r.failed_evaluations;
    }
    h.feasible = h.ok && std::isfinite(h.objective) && h.max_violation <= constraint_tolerance;
    r.history.push_back(std::move(h));
    if (max_evaluations > 0 && static_cast<long>(r.history.size()) > max_evaluations)
      throw ConfigError(path, std::to_string(r.history.size()) + " evaluations",
                        "must be within the problem's budget max_evaluations = " + std::to_string(max_evaluations));
    const EvaluationRecord& n = r.history.back();
    if (!best) {
      best = r.history.size() - 1;
    } else {
      const EvaluationRecord& b = r.history[*best];
      const bool better = n.feasible ? (!b.feasible || n.objective < b.objective)
                                     : (!b.feasible && n.max_violation < b.max_violation);
      if (better) best = r.history.size() - 1;
    }
  }
  r.evaluations = static_cast<long>(r.history.size());
  if (best) {
    const EvaluationRecord& b = r.history[*best];
    r.x = b.x;
    r.objective = b.objective;
    r.feasible = b.feasible;
    r.max_violation = b.max_violation;
  }
  r.x0 = r.history.empty() ? std::vector<double>{} : r.history.front().x;
  r.reason = max_evaluations > 0 && r.evaluations >= max_evaluations ? TerminationReason::MaxEvaluations
                                                                      : TerminationReason::Converged;
  r.message = "external run read from " + path;
  return r;
}

}  // namespace abuopt::opt
