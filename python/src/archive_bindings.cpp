// abuopt.Archive: an evaluation archive (OUT/archive.sqlite of optimize, sweep, pareto) read from
// Python, as `abuopt archive list|show|best|history` reads it (optimizer/archive_reader.hpp).
// Results are NumPy arrays, one entry per evaluation; units are those of the stored values (the
// objective and metrics in the units docs/optimize.md gives them, e.g. 1e-7 kg m for mean I_r).
#include <cmath>
#include <algorithm>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "abuopt/optimizer/archive_reader.hpp"
#include "bindings.hpp"

namespace py = pybind11;

namespace abuopt::python {

namespace {

using opt::ArchiveProblem;
using opt::ArchiveReader;
using Entry = opt::EvaluationArchive::Entry;

std::vector<opt::ArchiveFilter> filters_of(const std::vector<std::string>& where) {
  std::vector<opt::ArchiveFilter> f;
  for (const auto& w : where) f.push_back(opt::parse_archive_filter(w, "where"));
  return f;
}

py::dict entry_dict(const ArchiveReader& r, const ArchiveProblem& p, const Entry& e) {
  py::dict x, g, h, m;
  for (std::size_t i = 0; i < p.record.variables.size() && i < e.x.size(); ++i) x[py::str(p.record.variables[i])] = e.x[i];
  for (std::size_t i = 0; i < p.record.inequality.size() && i < e.evaluation.inequality.size(); ++i)
    g[py::str(p.record.inequality[i])] = e.evaluation.inequality[i];
  for (std::size_t i = 0; i < p.record.equality.size() && i < e.evaluation.equality.size(); ++i)
    h[py::str(p.record.equality[i])] = e.evaluation.equality[i];
  for (const auto& [k, v] : e.evaluation.metrics) m[py::str(k)] = v;
  py::dict d;
  d["problem_id"] = p.record.problem_id;
  d["id"] = e.id;
  d["timestamp"] = e.timestamp;
  d["runs"] = e.runs;
  d["ok"] = e.evaluation.ok;
  d["feasible"] = r.feasible(p, e);
  d["max_violation"] = ArchiveReader::max_violation(e);
  d["objective"] = e.evaluation.objective;
  d["x"] = x;
  d["inequality"] = g;
  d["equality"] = h;
  d["metrics"] = m;
  d["message"] = e.evaluation.message;
  d["wall_time_s"] = e.wall_time_s;
  return d;
}

// Columns of the evaluations `rows` (in order): arrays of length n; x (n, variables), inequality
// (n, constraints); metrics {name: array} (NaN where an evaluation lacks the metric).
py::dict columns(const ArchiveReader& r, const ArchiveProblem& p, const std::vector<const Entry*>& rows,
                 const std::vector<double>* best_so_far) {
  const std::size_t n = rows.size(), nv = p.record.variables.size(), ng = p.record.inequality.size();
  py::array_t<long> id(n), runs(n);
  py::array_t<bool> ok(n), feasible(n);
  py::array_t<double> objective(n), violation(n), wall(n);
  py::array_t<double> x({n, nv}), g({n, ng});
  std::vector<std::string> metric_names;
  for (const Entry* e : rows)
    for (const auto& [k, v] : e->evaluation.metrics)
      if (std::find(metric_names.begin(), metric_names.end(), k) == metric_names.end()) metric_names.push_back(k);
  std::sort(metric_names.begin(), metric_names.end());
  py::dict metrics;
  std::vector<py::array_t<double>> mcols;
  for (const auto& k : metric_names) {
    mcols.emplace_back(n);
    metrics[py::str(k)] = mcols.back();
  }
  py::list timestamps, messages;
  auto xv = x.mutable_unchecked<2>();
  auto gv = g.mutable_unchecked<2>();
  for (std::size_t i = 0; i < n; ++i) {
    const Entry& e = *rows[i];
    id.mutable_at(i) = e.id;
    runs.mutable_at(i) = e.runs;
    ok.mutable_at(i) = e.evaluation.ok;
    feasible.mutable_at(i) = r.feasible(p, e);
    objective.mutable_at(i) = e.evaluation.objective;
    violation.mutable_at(i) = ArchiveReader::max_violation(e);
    wall.mutable_at(i) = e.wall_time_s;
    for (std::size_t j = 0; j < nv; ++j) xv(i, j) = j < e.x.size() ? e.x[j] : NAN;
    for (std::size_t j = 0; j < ng; ++j) gv(i, j) = j < e.evaluation.inequality.size() ? e.evaluation.inequality[j] : NAN;
    for (std::size_t k = 0; k < metric_names.size(); ++k) {
      auto it = e.evaluation.metrics.find(metric_names[k]);
      mcols[k].mutable_at(i) = it == e.evaluation.metrics.end() ? NAN : it->second;
    }
    timestamps.append(e.timestamp);
    messages.append(e.evaluation.message);
  }
  py::dict d;
  d["problem_id"] = p.record.problem_id;
  d["variables"] = p.record.variables;
  d["constraints"] = p.record.inequality;
  d["id"] = id;
  d["runs"] = runs;
  d["ok"] = ok;
  d["feasible"] = feasible;
  d["objective"] = objective;
  d["max_violation"] = violation;
  d["x"] = x;
  d["inequality"] = g;
  d["metrics"] = metrics;
  d["wall_time_s"] = wall;
  d["timestamp"] = timestamps;
  d["message"] = messages;
  if (best_so_far) {
    py::array_t<double> b(n);
    for (std::size_t i = 0; i < n; ++i) b.mutable_at(i) = (*best_so_far)[i];
    d["best_feasible"] = b;
  }
  return d;
}

class PyArchive {
 public:
  PyArchive(const std::string& path, double tolerance) : reader_(check_path(path)) {
    if (!(std::isfinite(tolerance) && tolerance >= 0))
      throw py::value_error("tolerance = " + std::to_string(tolerance) + ": must be >= 0");
    reader_.set_tolerance(tolerance);
  }

  py::list problems() const {
    py::list out;
    for (const ArchiveProblem& p : reader_.problems()) {
      py::list runs;
      for (const auto& m : p.runs) {
        py::dict r;
        r["timestamp"] = m.timestamp;
        r["command"] = m.command;
        r["config"] = m.config;
        r["config_hash"] = m.config_hash;
        r["abuopt_version"] = m.abuopt_version;
        r["git_commit"] = m.git_commit;
        runs.append(r);
      }
      py::dict d;
      d["problem_id"] = p.record.problem_id;
      d["name"] = p.record.name;
      d["created"] = p.record.created;
      d["variables"] = p.record.variables;
      d["inequality"] = p.record.inequality;
      d["equality"] = p.record.equality;
      d["evaluations"] = p.evaluations.size();
      d["runs"] = runs;
      out.append(d);
    }
    return out;
  }

  py::dict evaluations(const std::string& problem, const std::vector<std::string>& where) const {
    const ArchiveProblem& p = reader_.problem(problem);
    const auto f = filters_of(where);
    ArchiveReader::check_filters(p, f);
    std::vector<const Entry*> rows;
    for (const Entry& e : p.evaluations)
      if (ArchiveReader::passes(p, e, f)) rows.push_back(&e);
    return columns(reader_, p, rows, nullptr);
  }

  py::dict history(const std::string& problem, const std::vector<std::string>& where) const {
    const ArchiveProblem& p = reader_.problem(problem);
    const auto h = reader_.history(p, filters_of(where));
    std::vector<const Entry*> rows;
    std::vector<double> best;
    for (const auto& pt : h) {
      rows.push_back(pt.entry);
      best.push_back(pt.best_feasible);
    }
    return columns(reader_, p, rows, &best);
  }

  py::object best(const std::string& problem, const std::vector<std::string>& where) const {
    const ArchiveProblem& p = reader_.problem(problem);
    const Entry* e = reader_.best(p, filters_of(where));
    if (!e) return py::none();
    return entry_dict(reader_, p, *e);
  }

  py::dict evaluation(long id, const std::string& problem) const {
    const ArchiveProblem& p = reader_.problem(problem);
    const Entry* e = ArchiveReader::find(p, id);
    if (!e) throw py::key_error("no evaluation with id " + std::to_string(id) + " in " + p.record.problem_id);
    return entry_dict(reader_, p, *e);
  }

  const std::string& path() const { return reader_.path(); }

 private:
  static const std::string& check_path(const std::string& path) {
    if (!py::module_::import("os").attr("path").attr("isfile")(path).cast<bool>()) {
      PyErr_SetObject(PyExc_FileNotFoundError, py::make_tuple(2, "No such archive file", path).ptr());
      throw py::error_already_set();
    }
    return path;
  }
  ArchiveReader reader_;
};

}  // namespace

void register_archive(py::module_& m) {
  py::class_<PyArchive>(m, "Archive",
                        "An evaluation archive (OUT/archive.sqlite of `abuopt optimize`, `sweep`, `pareto`), read as\n"
                        "`abuopt archive` reads it (docs/archive.md). `problem` is a problem id or a unique prefix\n"
                        "(default \"\": the only problem); `where` a list of filters \"NAME OP VALUE\" (OP <=, <, >=,\n"
                        "  >, ==; NAME a variable, a constraint, g_/h_<name>, a metric or objective). Feasible: ok\n"
                        "and every g <= tolerance. Values are as stored: the objective and metrics in the units of\n"
                        "docs/optimize.md (mean I_r in 1e-7 kg m), variables in Hz and s.")
      .def(py::init<const std::string&, double>(), py::arg("path"), py::kw_only(), py::arg("tolerance") = 1e-6,
           "Reads the file; FileNotFoundError when it does not exist, ConfigError when it is damaged.")
      .def_property_readonly("path", &PyArchive::path)
      .def("problems", &PyArchive::problems,
           "One dict per problem: problem_id, name, created, variables, inequality, equality, evaluations\n"
           "(count) and runs (the commands that wrote it: timestamp, command, config, config_hash, ...).")
      .def("evaluations", &PyArchive::evaluations, py::arg("problem") = "", py::kw_only(),
           py::arg("where") = std::vector<std::string>{},
           "Every evaluation passing `where`, in storing order, as columns: id, runs, ok, feasible,\n"
           "objective, max_violation, wall_time_s (arrays, n), x (n x variables), inequality (n x\n"
           "constraints), metrics {name: array} (NaN where missing), timestamp and message (lists),\n"
           "variables and constraints (the column names).")
      .def("history", &PyArchive::history, py::arg("problem") = "", py::kw_only(),
           py::arg("where") = std::vector<std::string>{},
           "As evaluations(), plus best_feasible: the lowest feasible objective up to each evaluation\n"
           "(NaN before the first feasible one).")
      .def("best", &PyArchive::best, py::arg("problem") = "", py::kw_only(), py::arg("where") = std::vector<std::string>{},
           "The feasible evaluation with the lowest objective among those passing `where` (a dict: id,\n"
           "objective, x {name: value}, inequality, equality, metrics, feasible, max_violation, ...), or None.")
      .def("evaluation", &PyArchive::evaluation, py::arg("id"), py::arg("problem") = "",
           "One evaluation by its id (a dict as best() returns); KeyError when there is none.");
}

}  // namespace abuopt::python
