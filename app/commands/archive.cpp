// abuopt archive list|show|best|history|export: reading an evaluation archive afterwards
// (optimizer/archive_reader.hpp, optimizer/archive_export.hpp; docs/archive.md).
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/output_file.hpp"
#include "abuopt/common/text.hpp"
#include "abuopt/optimizer/archive_export.hpp"
#include "abuopt/optimizer/archive_reader.hpp"
#include "commands/commands.hpp"

namespace abuopt::app {

namespace {

using opt::ArchiveProblem;
using opt::ArchiveReader;
using Entry = opt::EvaluationArchive::Entry;
using json = nlohmann::json;

struct ExportArgs {
  std::string archive;
  std::string dir;
};

struct ReadArgs {
  std::string archive;
  std::string problem;             // id or unique prefix; "" = the only one
  std::vector<std::string> where;  // filters
  double tolerance = 1e-6;
  long id = -1;                    // show: one evaluation
  bool json = false;
  std::string csv;                 // history: also write this CSV
};

int run_export(const ExportArgs& a) {
  const opt::ArchiveExportSummary s = opt::export_archive(a.archive, a.dir);
  std::cout << "archive " << a.archive << ": " << s.problems << " problem" << (s.problems == 1 ? "" : "s") << ", "
            << s.evaluations << " evaluation" << (s.evaluations == 1 ? "" : "s") << " (export schema version "
            << opt::kExportSchemaVersion << ", docs/archive.md)\n";
  for (const auto& f : s.files) std::cout << "wrote " << f << "\n";
  return 0;
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s.empty() ? "none" : s;
}

json number_json(double v) {
  if (std::isfinite(v)) return v;
  return format_number(v);
}

json entry_json(const ArchiveReader& r, const ArchiveProblem& p, const Entry& e) {
  json x = json::object(), g = json::object(), h = json::object(), m = json::object();
  for (std::size_t i = 0; i < p.record.variables.size() && i < e.x.size(); ++i) x[p.record.variables[i]] = number_json(e.x[i]);
  for (std::size_t i = 0; i < p.record.inequality.size() && i < e.evaluation.inequality.size(); ++i)
    g[p.record.inequality[i]] = number_json(e.evaluation.inequality[i]);
  for (std::size_t i = 0; i < p.record.equality.size() && i < e.evaluation.equality.size(); ++i)
    h[p.record.equality[i]] = number_json(e.evaluation.equality[i]);
  for (const auto& [k, v] : e.evaluation.metrics) m[k] = number_json(v);
  return {{"problem_id", p.record.problem_id}, {"id", e.id},           {"timestamp", e.timestamp},
          {"runs", e.runs},                    {"ok", e.evaluation.ok}, {"feasible", r.feasible(p, e)},
          {"max_violation", number_json(ArchiveReader::max_violation(e))},
          {"objective", number_json(e.evaluation.objective)},
          {"x", x},                            {"inequality", g},       {"equality", h},
          {"metrics", m},                      {"message", e.evaluation.message},
          {"wall_time_s", number_json(e.wall_time_s)}};
}

void print_entry(const ArchiveReader& r, const ArchiveProblem& p, const Entry& e) {
  std::cout << "evaluation " << e.id << " of " << p.record.problem_id << " (stored " << e.timestamp
            << (e.runs ? ", at " + std::to_string(e.runs) + " Monte Carlo runs" : std::string()) << ")\n"
            << "  " << (e.evaluation.ok ? (r.feasible(p, e) ? "feasible" : "NOT feasible") : "FAILED: " + e.evaluation.message)
            << ", objective " << format_number(e.evaluation.objective) << "\n  x:";
  for (std::size_t i = 0; i < p.record.variables.size() && i < e.x.size(); ++i)
    std::cout << " " << p.record.variables[i] << " = " << format_number(e.x[i]);
  if (!p.record.inequality.empty()) {
    std::cout << "\n  constraints (feasible when g <= " << format_number(r.tolerance()) << "):";
    for (std::size_t i = 0; i < p.record.inequality.size() && i < e.evaluation.inequality.size(); ++i)
      std::cout << " " << p.record.inequality[i] << " " << format_significant(e.evaluation.inequality[i], 4);
  }
  for (std::size_t i = 0; i < p.record.equality.size() && i < e.evaluation.equality.size(); ++i)
    std::cout << " h_" << p.record.equality[i] << " " << format_significant(e.evaluation.equality[i], 4);
  std::cout << "\n  metrics:";
  int k = 0;
  for (const auto& [name, v] : e.evaluation.metrics) {
    if (k++ % 4 == 0) std::cout << "\n   ";
    std::cout << " " << name << " " << format_significant(v, 6);
  }
  std::cout << "\n  wall time " << format_significant(e.wall_time_s, 3) << " s\n";
}

std::vector<opt::ArchiveFilter> filters_of(const ReadArgs& a) {
  std::vector<opt::ArchiveFilter> f;
  for (const auto& w : a.where) f.push_back(opt::parse_archive_filter(w, "--where"));
  return f;
}

ArchiveReader open_reader(const ReadArgs& a) {
  if (!(std::isfinite(a.tolerance) && a.tolerance >= 0))
    throw ConfigError("--tolerance", format_number(a.tolerance), "must be >= 0");
  ArchiveReader r(a.archive);
  r.set_tolerance(a.tolerance);
  return r;
}

int run_list(const ReadArgs& a) {
  const ArchiveReader r = open_reader(a);
  json jp = json::array();
  if (!a.json)
    std::cout << "archive " << a.archive << ": " << r.problems().size() << " problem"
              << (r.problems().size() == 1 ? "" : "s") << "\n";
  for (const ArchiveProblem& p : r.problems()) {
    long ok = 0, feasible = 0;
    for (const Entry& e : p.evaluations) {
      ok += e.evaluation.ok;
      feasible += r.feasible(p, e);
    }
    const Entry* best = r.best(p);
    if (a.json) {
      json runs = json::array();
      for (const auto& m : p.runs)
        runs.push_back({{"timestamp", m.timestamp}, {"command", m.command}, {"config", m.config},
                        {"config_hash", m.config_hash}, {"abuopt_version", m.abuopt_version}, {"git_commit", m.git_commit}});
      jp.push_back({{"problem_id", p.record.problem_id}, {"name", p.record.name}, {"created", p.record.created},
                    {"variables", p.record.variables}, {"inequality", p.record.inequality},
                    {"equality", p.record.equality}, {"evaluations", p.evaluations.size()}, {"ok", ok},
                    {"feasible", feasible}, {"runs", runs},
                    {"best_feasible", best ? entry_json(r, p, *best) : json(nullptr)}});
      continue;
    }
    std::cout << "  " << p.record.problem_id << "  (" << p.record.name << ", created " << p.record.created << ")\n"
              << "    " << p.evaluations.size() << " evaluations: " << ok << " ok, " << feasible << " feasible";
    if (best) std::cout << "; best feasible objective " << format_number(best->evaluation.objective) << " (evaluation " << best->id << ")";
    std::cout << "\n    variables " << join(p.record.variables) << "; constraints " << join(p.record.inequality) << "\n";
    if (p.damaged_rows_left_out) std::cout << "    " << p.damaged_rows_left_out << " damaged rows left out\n";
    for (const auto& m : p.runs)
      std::cout << "    run " << m.timestamp << "  " << m.command << " " << m.config << "  (abuopt " << m.abuopt_version
                << ", " << m.git_commit << ")\n";
  }
  if (a.json) std::cout << json{{"archive", a.archive}, {"problems", jp}}.dump(2) << "\n";
  return 0;
}

int run_show(const ReadArgs& a) {
  const ArchiveReader r = open_reader(a);
  const ArchiveProblem& p = r.problem(a.problem, "--problem");
  const Entry* e = ArchiveReader::find(p, a.id);
  if (!e) throw ConfigError("id", std::to_string(a.id), "is no evaluation of " + p.record.problem_id + " (abuopt archive history lists them)");
  if (a.json)
    std::cout << entry_json(r, p, *e).dump(2) << "\n";
  else
    print_entry(r, p, *e);
  return 0;
}

int run_best(const ReadArgs& a) {
  const ArchiveReader r = open_reader(a);
  const ArchiveProblem& p = r.problem(a.problem, "--problem");
  const std::vector<opt::ArchiveFilter> f = filters_of(a);
  const Entry* e = r.best(p, f);
  if (!e) {
    std::cerr << "abuopt: no feasible evaluation of " << p.record.problem_id
              << (f.empty() ? std::string() : " passes the --where filters") << " (of " << p.evaluations.size() << ")\n";
    return 3;
  }
  if (a.json)
    std::cout << entry_json(r, p, *e).dump(2) << "\n";
  else {
    std::cout << "best feasible of " << p.evaluations.size() << " evaluations";
    for (const auto& x : f) std::cout << (&x == &f.front() ? " with " : ", ") << x.text;
    std::cout << ":\n";
    print_entry(r, p, *e);
  }
  return 0;
}

int run_history(const ReadArgs& a) {
  const ArchiveReader r = open_reader(a);
  const ArchiveProblem& p = r.problem(a.problem, "--problem");
  const auto hist = r.history(p, filters_of(a));
  std::ostringstream csv;
  csv << "id,timestamp,runs,ok,feasible,objective,max_violation,best_feasible_objective";
  for (const auto& v : p.record.variables) csv << ',' << csv_field(v);
  csv << '\n';
  std::cout << "    id  feasible      objective  max violation   best feasible so far\n";
  for (const auto& h : hist) {
    const Entry& e = *h.entry;
    std::cout << std::setw(6) << e.id << "  " << std::setw(8) << (e.evaluation.ok ? (h.feasible ? "yes" : "no") : "failed")
              << std::setw(15) << format_significant(e.evaluation.objective, 6) << std::setw(15)
              << format_significant(h.max_violation, 3) << std::setw(23) << format_significant(h.best_feasible, 6) << "\n";
    csv << e.id << ',' << csv_field(e.timestamp) << ',' << e.runs << ',' << (e.evaluation.ok ? 1 : 0) << ','
        << (h.feasible ? 1 : 0) << ',' << csv_number(e.evaluation.objective) << ',' << csv_number(h.max_violation) << ','
        << csv_number(h.best_feasible);
    for (std::size_t i = 0; i < p.record.variables.size(); ++i) csv << ',' << (i < e.x.size() ? csv_number(e.x[i]) : "");
    csv << '\n';
  }
  std::cout << hist.size() << " of " << p.evaluations.size() << " evaluations of " << p.record.problem_id
            << (a.where.empty() ? std::string() : " pass the --where filters") << "\n";
  if (!a.csv.empty()) {
    write_file_atomic(a.csv, csv.str());
    std::cout << "wrote " << a.csv << "\n";
  }
  return 0;
}

CLI::App* reader_command(CLI::App* sub, const char* name, const char* help, std::shared_ptr<ReadArgs> args,
                         bool problem_option) {
  CLI::App* c = sub->add_subcommand(name, help);
  c->add_option("archive", args->archive, "the archive file (e.g. results/cobyla/archive.sqlite)")->required();
  if (problem_option)
    c->add_option("--problem", args->problem, "problem id or a unique prefix of it (default: the only problem)");
  c->add_option("--tolerance", args->tolerance, "feasible when every g <= this and every |h| <= this (default 1e-6)");
  return c;
}

}  // namespace

void register_archive(CLI::App& app) {
  CLI::App* sub = app.add_subcommand(
      "archive",
      "Read an evaluation archive (OUT/archive.sqlite of optimize, sweep and pareto): list its problems\n"
      "and runs, show one evaluation, the best feasible design, the history; export it (docs/archive.md).");
  sub->require_subcommand(1);
  auto ex = std::make_shared<ExportArgs>();
  CLI::App* exp = sub->add_subcommand(
      "export",
      "Write every stored evaluation of ARCHIVE into DIR: archive.json (problems, provenance metadata,\n"
      "evaluations) and one evaluations-<problem id>.csv per problem. Numbers are shortest round-trip:\n"
      "they read back bit for bit. The schema and its version: docs/archive.md.\n"
      "Exit status: 0 ok, 2 no such archive / damaged / other schema version, 4 a file could not be written.");
  exp->add_option("archive", ex->archive, "the archive file (e.g. results/cobyla/archive.sqlite)")->required();
  exp->add_option("dir", ex->dir, "output directory (created if needed)")->required();
  exp->callback([ex] { set_exit_code(run_export(*ex)); });

  auto la = std::make_shared<ReadArgs>();
  CLI::App* list = reader_command(sub, "list",
                                  "The problems ARCHIVE holds: evaluations (ok, feasible), the best feasible objective,\n"
                                  "variables, constraints and the runs (commands) that wrote it.",
                                  la, false);
  list->add_flag("--json", la->json, "print JSON instead of text");
  list->callback([la] { set_exit_code(run_list(*la)); });

  auto sa = std::make_shared<ReadArgs>();
  CLI::App* show = reader_command(sub, "show", "One evaluation by its id (the id column of history and export).", sa, true);
  show->add_option("id", sa->id, "evaluation id")->required();
  show->add_flag("--json", sa->json, "print JSON instead of text");
  show->callback([sa] { set_exit_code(run_show(*sa)); });

  auto ba = std::make_shared<ReadArgs>();
  CLI::App* best = reader_command(sub, "best",
                                  "The feasible evaluation with the lowest objective, optionally among those passing\n"
                                  "--where filters. Exit status 3 when there is none.",
                                  ba, true);
  best->add_option("--where", ba->where,
                   "keep evaluations with NAME OP VALUE (OP <=, <, >=, >, ==; NAME a variable, a constraint, g_/h_<name>,\n"
                   "a metric or objective), e.g. --where 'pct_mi_x<=5' --where 'dt3>=6'; repeatable");
  best->add_flag("--json", ba->json, "print JSON instead of text");
  best->callback([ba] { set_exit_code(run_best(*ba)); });

  auto ha = std::make_shared<ReadArgs>();
  CLI::App* hist = reader_command(sub, "history",
                                  "Every evaluation in storing order with its feasibility, largest constraint violation\n"
                                  "and the best feasible objective so far.",
                                  ha, true);
  hist->add_option("--where", ha->where, "keep evaluations with NAME OP VALUE (as for best); repeatable");
  hist->add_option("--csv", ha->csv, "also write the history (with the variables) to this CSV file");
  hist->callback([ha] { set_exit_code(run_history(*ha)); });
}

}  // namespace abuopt::app
