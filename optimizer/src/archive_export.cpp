#include "abuopt/optimizer/archive_export.hpp"

#include <cctype>
#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/output_file.hpp"
#include "abuopt/common/provenance.hpp"
#include "abuopt/common/text.hpp"
#include "abuopt/optimizer/evaluation_archive.hpp"

namespace abuopt::opt {

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

// Finite doubles as JSON numbers (nlohmann writes them shortest round-trip), the others as text.
json number_json(double v) {
  if (std::isfinite(v)) return v;
  return format_number(v);  // "inf", "-inf", "nan"
}

json named_values(const std::vector<std::string>& names, const std::vector<double>& values) {
  json o = json::object();
  for (std::size_t i = 0; i < names.size() && i < values.size(); ++i) o[names[i]] = number_json(values[i]);
  return o;
}

// "evaluations-<id>.csv" with every character outside [A-Za-z0-9._-] as '_' (ids are
// "<name>-<hex>" in practice; the JSON holds the exact id).
std::string csv_name(const std::string& problem_id) {
  std::string s = problem_id;
  for (char& c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-')) c = '_';
  return "evaluations-" + s + ".csv";
}

std::string value_at(const std::vector<double>& v, std::size_t i) { return i < v.size() ? csv_number(v[i]) : ""; }

}  // namespace

ArchiveExportSummary export_archive(const std::string& archive_path, const std::string& dir) {
  if (!fs::is_regular_file(archive_path))
    throw ConfigError("archive", archive_path, "no such file (an archive.sqlite written by optimize or sweep)");
  const fs::path out(dir);
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec) throw OutputError("cannot create the export directory '" + dir + "': " + ec.message());

  std::vector<EvaluationArchive::ProblemRecord> problems;
  {
    EvaluationArchive any(archive_path, "");
    problems = any.problems();
  }
  ArchiveExportSummary summary;
  json root = {{"schema", "abuopt-archive-export"},
               {"schema_version", kExportSchemaVersion},
               {"archive", archive_path},
               {"archive_schema_version", EvaluationArchive::schema_version()},
               {"exported_by", {{"abuopt_version", abuopt_version()}, {"git_commit", abuopt_git_commit()}}}};
  json jproblems = json::array();
  std::vector<std::pair<fs::path, std::string>> csvs;
  for (const auto& p : problems) {
    EvaluationArchive archive(archive_path, p.problem_id);
    archive.set_warning_handler({});  // damaged rows are left out (and counted below)
    const std::vector<EvaluationArchive::Entry> entries = archive.entries();
    std::set<std::string> metric_names;
    for (const auto& en : entries)
      for (const auto& [k, v] : en.evaluation.metrics) metric_names.insert(k);

    json jmeta = json::array();
    for (const auto& m : archive.metadata())
      jmeta.push_back({{"timestamp", m.timestamp},
                       {"abuopt_version", m.abuopt_version},
                       {"git_commit", m.git_commit},
                       {"command", m.command},
                       {"config", m.config},
                       {"config_hash", m.config_hash}});

    // A metric named like a fixed column (the metric `runs`, the Monte Carlo's run count, beside the
    // archive key `runs`) is written as metric_<name>: every column name is unique.
    std::set<std::string> fixed = {"id", "timestamp", "runs", "ok", "objective", "wall_time_s", "message"};
    for (const auto& n : p.variables) fixed.insert(n);
    for (const auto& n : p.inequality) fixed.insert("g_" + n);
    for (const auto& n : p.equality) fixed.insert("h_" + n);
    std::ostringstream csv;
    csv << "id,timestamp,runs,ok,objective";
    for (const auto& n : p.variables) csv << ',' << csv_field(n);
    for (const auto& n : p.inequality) csv << ',' << csv_field("g_" + n);
    for (const auto& n : p.equality) csv << ',' << csv_field("h_" + n);
    for (const auto& n : metric_names) csv << ',' << csv_field(fixed.count(n) ? "metric_" + n : n);
    csv << ",wall_time_s,message\n";

    json jevals = json::array();
    for (const auto& en : entries) {
      const Evaluation& e = en.evaluation;
      json metrics = json::object();
      for (const auto& [k, v] : e.metrics) metrics[k] = number_json(v);
      jevals.push_back({{"id", en.id},
                        {"timestamp", en.timestamp},
                        {"runs", en.runs},
                        {"x", named_values(p.variables, en.x)},
                        {"ok", e.ok},
                        {"objective", number_json(e.objective)},
                        {"inequality", named_values(p.inequality, e.inequality)},
                        {"equality", named_values(p.equality, e.equality)},
                        {"metrics", metrics},
                        {"message", e.message},
                        {"wall_time_s", number_json(en.wall_time_s)}});
      csv << en.id << ',' << csv_field(en.timestamp) << ',' << en.runs << ',' << (e.ok ? 1 : 0) << ','
          << csv_number(e.objective);
      for (std::size_t i = 0; i < p.variables.size(); ++i) csv << ',' << value_at(en.x, i);
      for (std::size_t i = 0; i < p.inequality.size(); ++i) csv << ',' << value_at(e.inequality, i);
      for (std::size_t i = 0; i < p.equality.size(); ++i) csv << ',' << value_at(e.equality, i);
      for (const auto& n : metric_names) {
        auto it = e.metrics.find(n);
        csv << ',' << (it == e.metrics.end() ? std::string() : csv_number(it->second));
      }
      csv << ',' << csv_number(en.wall_time_s) << ',' << csv_field(e.message) << '\n';
    }
    const std::string file = csv_name(p.problem_id);
    jproblems.push_back({{"problem_id", p.problem_id},
                         {"name", p.name},
                         {"variables", p.variables},
                         {"inequality", p.inequality},
                         {"equality", p.equality},
                         {"created", p.created},
                         {"csv", file},
                         {"damaged_rows_left_out", archive.damaged_rows()},
                         {"metadata", jmeta},
                         {"evaluations", jevals}});
    csvs.emplace_back(out / file, csv.str());
    ++summary.problems;
    summary.evaluations += static_cast<long>(entries.size());
  }
  root["problems"] = jproblems;
  write_file_atomic(out / "archive.json", root.dump(2) + "\n");
  summary.files.push_back((out / "archive.json").string());
  for (const auto& [path, text] : csvs) {
    write_file_atomic(path, text);
    summary.files.push_back(path.string());
  }
  return summary;
}

}  // namespace abuopt::opt
