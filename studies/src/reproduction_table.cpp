#include "abuopt/studies/reproduction_table.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

#include "abuopt/common/config_error.hpp"
#include "abuopt/core/simulation_config.hpp"
#include "study_text.hpp"

namespace abuopt {

namespace fs = std::filesystem;
using namespace studies_detail;

namespace {

const char* const kSetupSections[] = {"abu", "profile", "motor", "simulation", "montecarlo"};

ConclusionCheck conclusion_check_from_string(const std::string& s, const std::string& path) {
  for (ConclusionCheck c : {ConclusionCheck::BeatsAll, ConclusionCheck::PctMiDecreasesWithValue,
                            ConclusionCheck::WorsensWithValue})
    if (to_string(c) == s) return c;
  throw ConfigError(path, s, "must be one of: beats_all, pct_mi_decreases_with_value, worsens_with_value");
}

PlotKind plot_kind_from_string(const std::string& s, const std::string& path) {
  for (PlotKind k : {PlotKind::Trend, PlotKind::FinalPositions, PlotKind::SettlingHistogram,
                     PlotKind::EquilibriumOverlay})
    if (to_string(k) == s) return k;
  throw ConfigError(path, s, "must be one of: trend, final_positions, settling_histogram, equilibrium_overlay");
}

PublishedRow read_reference(YamlReader r) {
  PublishedRow p;
  if (!r.present()) return p;
  auto get = [&r](const char* key) -> std::optional<double> {
    if (!r.has(key)) {
      r.get_string_or(key, "");  // marks the key as read
      return std::nullopt;
    }
    return r.get_double(key, Rule::non_negative());
  };
  p.mean_1e7 = get("mean");
  p.max_1e7 = get("max");
  p.pct_lc = get("pct_lc");
  p.pct_mi = get("pct_mi");
  p.note = r.get_string_or("note", "");
  r.finish();
  return p;
}

ReproductionTable read_table(YamlReader& root, const std::string& name) {
  ReproductionTable t;
  t.file = name;
  if (!root.has("table")) throw ConfigError("table", "<missing>", "is required (id, title, source, ...)");
  YamlReader tr = root.child("table");
  t.id = tr.get_string("id");
  t.title = tr.get_string_or("title", t.id);
  t.source = tr.get_string_or("source", "");
  t.expectation = tr.get_string_or("expectation", "");
  YamlReader par = tr.child("parameter");
  if (par.present()) {
    t.parameter_name = par.get_string("name");
    t.parameter_unit = par.get_string_or("unit", "");
    par.finish();
  }
  if (tr.has("contact_variant")) {
    const std::string v = tr.get_string("contact_variant");
    for (const auto& [e, name] : kBallContactNames)
      if (name == v) t.contact_variant = e;
    if (!t.contact_variant || *t.contact_variant == BallContact::None)
      throw ConfigError(tr.key_path("contact_variant"), v, "must be a ball contact other than the report's model: hard");
  }
  for (YamlReader& c : tr.children("conclusions")) {
    Conclusion k;
    k.id = c.get_string("id");
    k.claim = c.get_string("claim");
    k.check = conclusion_check_from_string(c.get_string("check"), c.key_path("check"));
    k.case_id = c.get_string_or("case", "");
    if (k.check == ConclusionCheck::BeatsAll && k.case_id.empty())
      throw ConfigError(c.key_path("case"), "<missing>", "is required by check beats_all");
    c.finish();
    t.conclusions.push_back(std::move(k));
  }
  for (YamlReader& p : tr.children("plots")) {
    PlotRequest req;
    req.kind = plot_kind_from_string(p.get_string("kind"), p.key_path("kind"));
    req.name = p.get_string_or("name", t.id + "_" + to_string(req.kind));
    req.case_ids = p.get_string_list_or("cases");
    p.finish();
    t.plots.push_back(std::move(req));
  }
  tr.finish();

  // The base setup: only the five setup sections.
  if (!root.has("base")) throw ConfigError("base", "<missing>", "is required (abu, profile, motor, simulation, montecarlo)");
  YamlReader base = root.child("base");
  for (const char* sec : kSetupSections) base.child(sec);
  base.finish();
  const YAML::Node base_node = base.node();

  std::set<std::string> ids;
  std::vector<YamlReader> cases = root.children("cases");
  if (cases.empty()) throw ConfigError("cases", "<missing>", "must list at least one case");
  for (std::size_t i = 0; i < cases.size(); ++i) {
    YamlReader& c = cases[i];
    ReproductionCase rc;
    rc.id = c.get_string("id");
    if (!ids.insert(rc.id).second) throw ConfigError(c.key_path("id"), rc.id, "must be unique within the table");
    if (c.has("value")) rc.value = c.get_double("value");
    else c.get_string_or("value", "");
    rc.label = c.get_string_or("label", "");
    if (rc.label.empty()) {
      if (rc.value && !t.parameter_name.empty())
        rc.label = t.parameter_name + " = " + short_num(*rc.value) + (t.parameter_unit.empty() ? "" : " " + t.parameter_unit);
      else
        rc.label = rc.id;
    }
    rc.reference = read_reference(c.child("reference"));
    YAML::Node overlay(YAML::NodeType::Map);
    for (const char* sec : kSetupSections) {
      YamlReader r = c.child(sec);
      if (r.present()) overlay[sec] = r.node();
    }
    c.finish();
    YamlReader merged(merge_yaml(base_node, overlay), "");
    try {
      SimulationSetup setup = read_simulation_setup(merged);
      MonteCarloConfig cfg = read_monte_carlo_config(merged, std::move(setup));
      merged.finish();
      rc.study = std::move(cfg.study);
      rc.threads = cfg.threads;
    } catch (const ConfigError& e) {
      throw ConfigError(c.path() + " (" + rc.id + "), base merged with the case: " + e.what());
    }
    t.cases.push_back(std::move(rc));
  }
  root.finish();

  for (const Conclusion& k : t.conclusions)
    if (!k.case_id.empty() && !t.find_case(k.case_id))
      throw ConfigError("table.conclusions (" + k.id + ").case", k.case_id, "must be the id of one of the cases");
  for (const PlotRequest& p : t.plots) {
    for (const std::string& id : p.case_ids)
      if (!t.find_case(id)) throw ConfigError("table.plots (" + p.name + ").cases", id, "must be the id of one of the cases");
    const bool needs_cases = p.kind != PlotKind::Trend;
    if (needs_cases && p.case_ids.empty())
      throw ConfigError("table.plots (" + p.name + ").cases", "<missing>", "is required by plot kind " + to_string(p.kind));
  }
  return t;
}

}  // namespace

std::string to_string(ConclusionCheck c) {
  switch (c) {
    case ConclusionCheck::BeatsAll: return "beats_all";
    case ConclusionCheck::PctMiDecreasesWithValue: return "pct_mi_decreases_with_value";
    case ConclusionCheck::WorsensWithValue: return "worsens_with_value";
  }
  return "?";
}

std::string to_string(PlotKind k) {
  switch (k) {
    case PlotKind::Trend: return "trend";
    case PlotKind::FinalPositions: return "final_positions";
    case PlotKind::SettlingHistogram: return "settling_histogram";
    case PlotKind::EquilibriumOverlay: return "equilibrium_overlay";
  }
  return "?";
}

const ReproductionCase* ReproductionTable::find_case(const std::string& case_id) const {
  for (const ReproductionCase& c : cases)
    if (c.id == case_id) return &c;
  return nullptr;
}

// --- reading -----------------------------------------------------------------------------------

ReproductionTable read_reproduction_table_string(const std::string& yaml_text, const std::string& name) {
  try {
    YamlReader root = YamlReader::load_string(yaml_text, name);
    return read_table(root, name);
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    if (what.rfind(name + ":", 0) == 0 || what.find("'" + name + "'") != std::string::npos) throw;
    throw ConfigError(name + ": " + what);
  }
}

ReproductionTable read_reproduction_table(const std::string& file) {
  try {
    YamlReader root = YamlReader::load_file(file);
    return read_table(root, file);
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    if (what.find("'" + file + "'") != std::string::npos) throw;  // load_file already names it
    throw ConfigError(file + ": " + what);
  }
}

const std::vector<std::string>& report_table_ids() {
  static const std::vector<std::string> ids = {"4.1", "4.2", "4.3", "4.4", "final", "mu"};
  return ids;
}

std::vector<ReproductionTable> read_reproduction_tables(const std::string& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw ConfigError("reproduction tables directory", dir, "must be a directory of table YAML files (configs/report)");
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.is_regular_file() && (e.path().extension() == ".yaml" || e.path().extension() == ".yml"))
      files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  std::vector<ReproductionTable> tables;
  std::map<std::string, std::string> seen;
  for (const std::string& f : files) {
    tables.push_back(read_reproduction_table(f));
    const std::string& id = tables.back().id;
    if (auto [it, fresh] = seen.emplace(id, f); !fresh)
      throw ConfigError(f + ": table.id", id, "is also the id of " + it->second + " (ids must be unique)");
  }
  if (tables.empty()) throw ConfigError("reproduction tables directory", dir, "has no *.yaml table files");
  auto rank = [](const std::string& id) {
    const auto& ids = report_table_ids();
    return static_cast<std::size_t>(std::find(ids.begin(), ids.end(), id) - ids.begin());
  };
  std::stable_sort(tables.begin(), tables.end(), [&](const ReproductionTable& a, const ReproductionTable& b) {
    const std::size_t ra = rank(a.id), rb = rank(b.id);
    return ra != rb ? ra < rb : a.id < b.id;
  });
  return tables;
}

std::vector<ReproductionTable> select_tables(const std::vector<ReproductionTable>& tables,
                                            const std::vector<std::string>& ids, const std::string& option) {
  if (ids.empty()) return tables;
  for (const std::string& id : ids) {
    const bool known = std::any_of(tables.begin(), tables.end(), [&](const ReproductionTable& t) { return t.id == id; });
    if (!known) {
      std::string list;
      for (const ReproductionTable& t : tables) list += (list.empty() ? "" : ", ") + t.id;
      throw ConfigError(option, id, "must be one of the table ids: " + list);
    }
  }
  std::vector<ReproductionTable> out;
  for (const ReproductionTable& t : tables)
    if (std::find(ids.begin(), ids.end(), t.id) != ids.end()) out.push_back(t);
  return out;
}

std::string override_runs(std::vector<ReproductionTable>& tables, std::size_t runs, const std::string& name) {
  if (runs < 1) throw ConfigError(name, std::to_string(runs), "must be >= 1");
  std::set<std::string> grids;
  for (ReproductionTable& t : tables)
    for (ReproductionCase& c : t.cases) {
      const std::size_t balls = c.study.setup.abu.balls.size();
      const double root = std::pow(static_cast<double>(runs), 1.0 / static_cast<double>(balls));
      const std::size_t n = std::max<std::size_t>(1, static_cast<std::size_t>(std::llround(root)));
      std::size_t total = 1;
      for (std::size_t b = 0; b < balls; ++b) total *= n;
      c.study.design.kind = InitialConditionKind::Grid;
      c.study.design.grid_points_per_axis = n;
      c.study.runs = total;
      validate(c.study, name);
      std::string g = std::to_string(n);
      for (std::size_t b = 1; b < balls; ++b) g += " x " + std::to_string(n);
      grids.insert(g + " grid = " + std::to_string(total) + " runs");
    }
  std::string text = name + " " + std::to_string(runs) + ": every case uses ";
  bool first = true;
  for (const std::string& g : grids) {
    text += (first ? "" : ", or ") + g;
    first = false;
  }
  text += " (n = round(N^(1/balls)) points per axis, so the grid is n^balls runs)";
  return text;
}

}  // namespace abuopt
