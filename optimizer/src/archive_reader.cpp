#include "abuopt/optimizer/archive_reader.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/suggest.hpp"

namespace abuopt::opt {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

std::size_t index_of(const std::vector<std::string>& names, const std::string& n) {
  return static_cast<std::size_t>(std::find(names.begin(), names.end(), n) - names.begin());
}

// Every name a filter may use for this problem.
std::vector<std::string> filter_names(const ArchiveProblem& p) {
  std::vector<std::string> out = {"objective"};
  for (const auto& v : p.record.variables) out.push_back(v);
  for (const auto& g : p.record.inequality) {
    out.push_back(g);
    out.push_back("g_" + g);
  }
  for (const auto& h : p.record.equality) out.push_back("h_" + h);
  for (const auto& e : p.evaluations)
    for (const auto& [k, v] : e.evaluation.metrics)
      if (std::find(out.begin(), out.end(), k) == out.end()) out.push_back(k);
  return out;
}

}  // namespace

ArchiveFilter parse_archive_filter(const std::string& text, const std::string& key) {
  static const std::pair<const char*, ArchiveFilter::Op> ops[] = {{"<=", ArchiveFilter::Op::Le},
                                                                  {">=", ArchiveFilter::Op::Ge},
                                                                  {"==", ArchiveFilter::Op::Eq},
                                                                  {"<", ArchiveFilter::Op::Lt},
                                                                  {">", ArchiveFilter::Op::Gt}};
  const std::string rule = "must be NAME OP VALUE with OP one of <=, <, >=, >, == (e.g. pct_mi<=5, g_amplitude<=0)";
  for (const auto& [sym, op] : ops) {
    const auto at = text.find(sym);
    if (at == std::string::npos) continue;
    ArchiveFilter f;
    f.name = trim(text.substr(0, at));
    f.op = op;
    f.text = text;
    const std::string v = trim(text.substr(at + std::string(sym).size()));
    char* end = nullptr;
    errno = 0;
    f.value = std::strtod(v.c_str(), &end);
    if (f.name.empty() || v.empty() || end == v.c_str() || *end != '\0' || errno == ERANGE || !std::isfinite(f.value))
      throw ConfigError(key, text, rule);
    return f;
  }
  throw ConfigError(key, text, rule);
}

ArchiveReader::ArchiveReader(const std::string& path) : path_(path) {
  if (!std::filesystem::is_regular_file(path))
    throw ConfigError("archive", path, "no such file (an archive.sqlite written by optimize, sweep or pareto)");
  std::vector<EvaluationArchive::ProblemRecord> records;
  {
    EvaluationArchive any(path, "", EvaluationArchive::OpenMode::ReadOnly);
    records = any.problems();
  }
  for (auto& rec : records) {
    EvaluationArchive a(path, rec.problem_id, EvaluationArchive::OpenMode::ReadOnly);
    a.set_warning_handler({});  // damaged rows are left out and counted
    ArchiveProblem p;
    p.evaluations = a.entries();
    p.runs = a.metadata();
    p.damaged_rows_left_out = a.damaged_rows();
    p.record = std::move(rec);
    problems_.push_back(std::move(p));
  }
}

const ArchiveProblem& ArchiveReader::problem(const std::string& id_or_prefix, const std::string& key) const {
  if (problems_.empty()) throw ConfigError("archive", path_, "holds no problem (nothing was evaluated into it)");
  std::vector<const ArchiveProblem*> hits;
  for (const auto& p : problems_) {
    if (p.record.problem_id == id_or_prefix) return p;
    if (p.record.problem_id.rfind(id_or_prefix, 0) == 0) hits.push_back(&p);
  }
  if (hits.size() == 1) return *hits.front();
  std::string ids;
  for (const auto& p : problems_) ids += (ids.empty() ? "" : ", ") + p.record.problem_id;
  if (hits.empty()) throw ConfigError(key, id_or_prefix, "is no problem id of " + path_ + " (it holds: " + ids + ")");
  throw ConfigError(key, id_or_prefix.empty() ? "<none>" : id_or_prefix,
                    "matches " + std::to_string(hits.size()) + " problems of " + path_ + ": give a longer prefix of one of " + ids);
}

double ArchiveReader::max_violation(const EvaluationArchive::Entry& e) {
  if (!e.evaluation.ok) return std::numeric_limits<double>::infinity();
  double v = 0.0;
  for (double g : e.evaluation.inequality) v = std::max(v, std::isnan(g) ? std::numeric_limits<double>::infinity() : g);
  for (double h : e.evaluation.equality) v = std::max(v, std::isnan(h) ? std::numeric_limits<double>::infinity() : std::fabs(h));
  return v;
}

bool ArchiveReader::feasible(const ArchiveProblem& p, const EvaluationArchive::Entry& e) const {
  return e.evaluation.ok && std::isfinite(e.evaluation.objective) &&
         e.evaluation.inequality.size() == p.record.inequality.size() && max_violation(e) <= tolerance_;
}

double ArchiveReader::value_of(const ArchiveProblem& p, const EvaluationArchive::Entry& e, const std::string& name) {
  const Evaluation& ev = e.evaluation;
  if (name == "objective") return ev.objective;
  if (auto i = index_of(p.record.variables, name); i < p.record.variables.size()) return i < e.x.size() ? e.x[i] : kNaN;
  const std::string g = name.rfind("g_", 0) == 0 ? name.substr(2) : name;
  if (auto i = index_of(p.record.inequality, g); i < p.record.inequality.size())
    return i < ev.inequality.size() ? ev.inequality[i] : kNaN;
  if (name.rfind("h_", 0) == 0)
    if (auto i = index_of(p.record.equality, name.substr(2)); i < p.record.equality.size())
      return i < ev.equality.size() ? ev.equality[i] : kNaN;
  auto it = ev.metrics.find(name);
  return it == ev.metrics.end() ? kNaN : it->second;
}

void ArchiveReader::check_filters(const ArchiveProblem& p, const std::vector<ArchiveFilter>& filters) {
  if (filters.empty()) return;
  const std::vector<std::string> names = filter_names(p);
  for (const auto& f : filters)
    if (std::find(names.begin(), names.end(), f.name) == names.end())
      throw ConfigError("filter", f.text,
                        "'" + f.name + "' is no variable, constraint or metric of " + p.record.problem_id +
                            did_you_mean(f.name, names));
}

bool ArchiveReader::passes(const ArchiveProblem& p, const EvaluationArchive::Entry& e,
                           const std::vector<ArchiveFilter>& filters) {
  for (const auto& f : filters) {
    const double v = value_of(p, e, f.name);
    if (std::isnan(v)) return false;
    bool ok = false;
    switch (f.op) {
      case ArchiveFilter::Op::Le: ok = v <= f.value; break;
      case ArchiveFilter::Op::Lt: ok = v < f.value; break;
      case ArchiveFilter::Op::Ge: ok = v >= f.value; break;
      case ArchiveFilter::Op::Gt: ok = v > f.value; break;
      case ArchiveFilter::Op::Eq: ok = v == f.value; break;
    }
    if (!ok) return false;
  }
  return true;
}

const EvaluationArchive::Entry* ArchiveReader::best(const ArchiveProblem& p, const std::vector<ArchiveFilter>& filters) const {
  check_filters(p, filters);
  const EvaluationArchive::Entry* b = nullptr;
  for (const auto& e : p.evaluations)
    if (feasible(p, e) && passes(p, e, filters) && (!b || e.evaluation.objective < b->evaluation.objective)) b = &e;
  return b;
}

std::vector<ArchiveHistoryPoint> ArchiveReader::history(const ArchiveProblem& p,
                                                        const std::vector<ArchiveFilter>& filters) const {
  check_filters(p, filters);
  std::vector<ArchiveHistoryPoint> out;
  double best_so_far = kNaN;
  for (const auto& e : p.evaluations) {
    if (!passes(p, e, filters)) continue;
    ArchiveHistoryPoint h;
    h.entry = &e;
    h.feasible = feasible(p, e);
    h.max_violation = max_violation(e);
    if (h.feasible && !(e.evaluation.objective >= best_so_far)) best_so_far = e.evaluation.objective;
    h.best_feasible = best_so_far;
    out.push_back(h);
  }
  return out;
}

const EvaluationArchive::Entry* ArchiveReader::find(const ArchiveProblem& p, long id) {
  for (const auto& e : p.evaluations)
    if (e.id == id) return &e;
  return nullptr;
}

}  // namespace abuopt::opt
