#include "abuopt/studies/reproduction.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/gnuplot.hpp"
#include "abuopt/core/equilibrium_set.hpp"
#include "abuopt/core/simulation_config.hpp"

namespace abuopt {

namespace fs = std::filesystem;

namespace {

constexpr double kZ95 = 1.959963984540054;
const char* const kSetupSections[] = {"abu", "profile", "motor", "simulation", "montecarlo"};

std::string num(double v, int digits) {
  if (!std::isfinite(v)) return "n/a";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

// Shortest readable form of a parameter value (1, 0.025, 19).
std::string short_num(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

std::string opt_num(const std::optional<double>& v, int digits) { return v ? num(*v, digits) : "-"; }

// Checks that a raw mapping only has the allowed keys (for entries read by hand).
void check_keys(const YAML::Node& n, const std::string& path, const std::set<std::string>& allowed) {
  if (!n.IsMap()) throw ConfigError(path, yaml_value_text(n), "must be a mapping of keys");
  for (auto it = n.begin(); it != n.end(); ++it) {
    const std::string k = it->first.Scalar();
    if (!allowed.count(k))
      throw ConfigError(path + "." + k, yaml_value_text(it->second), "unknown key (misspelt, or not valid here)");
  }
}

std::string scalar_string(const YAML::Node& n, const std::string& path) {
  if (!n || !n.IsScalar()) throw ConfigError(path, n ? yaml_value_text(n) : "<missing>", "must be a string");
  return n.Scalar();
}

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
  // Plot entries hold a list of strings, which the reader has no getter for: each entry is
  // checked and read by hand (children() marks the key as read).
  for (YamlReader& p : tr.children("plots")) {
    const YAML::Node& n = p.node();
    check_keys(n, p.path(), {"kind", "name", "cases"});
    PlotRequest req;
    req.kind = plot_kind_from_string(scalar_string(n["kind"], p.key_path("kind")), p.key_path("kind"));
    req.name = n["name"] ? scalar_string(n["name"], p.key_path("name")) : t.id + "_" + to_string(req.kind);
    if (const YAML::Node cs = n["cases"]) {
      if (!cs.IsSequence()) throw ConfigError(p.key_path("cases"), yaml_value_text(cs), "must be a list of case ids");
      for (std::size_t i = 0; i < cs.size(); ++i)
        req.case_ids.push_back(scalar_string(cs[i], p.key_path("cases") + "[" + std::to_string(i) + "]"));
    }
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

std::string table_dir_name(const std::string& id) {
  std::string s = id;
  for (char& ch : s)
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '.' || ch == '_' || ch == '-')) ch = '_';
  return s;
}

// --- statistics helpers -----------------------------------------------------------------------

bool mi_clearly_lower(const CaseSummary& a, const CaseSummary& b) { return a.ci_x[1] < b.ci_x[0]; }
bool mean_clearly_lower(const CaseSummary& a, const CaseSummary& b) {
  return b.mean_x - a.mean_x > kZ95 * std::hypot(a.sem_x, b.sem_x);
}

std::string mi_text(const CaseSummary& s) {
  return num(s.pct_mi_x, 2) + " [" + num(s.ci_x[0], 1) + ", " + num(s.ci_x[1], 1) + "]";
}
std::string mean_text(const CaseSummary& s) { return num(s.mean_x, 2) + " +- " + num(kZ95 * s.sem_x, 2); }

// The rows with a value, smallest and largest value.
std::optional<std::pair<const CaseSummary*, const CaseSummary*>> value_extremes(const std::vector<CaseSummary>& rows) {
  const CaseSummary *lo = nullptr, *hi = nullptr;
  for (const CaseSummary& r : rows) {
    if (!r.value || r.ok == 0) continue;
    if (!lo || *r.value < *lo->value) lo = &r;
    if (!hi || *r.value > *hi->value) hi = &r;
  }
  if (!lo || lo == hi) return std::nullopt;
  return std::make_pair(lo, hi);
}

std::string ref_mi(const CaseSummary& s) { return s.reference.pct_mi ? num(*s.reference.pct_mi, 2) : "-"; }

// --- files --------------------------------------------------------------------------------------

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string csv_num(double v) {
  if (!std::isfinite(v)) return "";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}
std::string csv_opt(const std::optional<double>& v) { return v ? csv_num(*v) : ""; }

void write_text_file(const fs::path& path, const std::string& text) {
  std::ofstream f(path);
  if (!f) throw ConfigError("output file", path.string(), "cannot be written");
  f << text;
}

std::string local_time_text() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  localtime_r(&now, &tm);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S", &tm);
  return buf;
}

std::string md_escape(const std::string& s) {
  std::string o;
  for (char c : s) o += c == '|' ? std::string("\\|") : std::string(1, c);
  return o;
}

}  // namespace

// --- names -------------------------------------------------------------------------------------

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

std::string to_string(VerdictOutcome v) {
  switch (v) {
    case VerdictOutcome::Confirmed: return "CONFIRMED";
    case VerdictOutcome::Weak: return "WEAK";
    case VerdictOutcome::NotReproduced: return "NOT REPRODUCED";
    case VerdictOutcome::NotTested: return "NOT TESTED";
  }
  return "?";
}

const ReproductionCase* ReproductionTable::find_case(const std::string& case_id) const {
  for (const ReproductionCase& c : cases)
    if (c.id == case_id) return &c;
  return nullptr;
}

// --- reading -----------------------------------------------------------------------------------

YAML::Node merge_yaml(const YAML::Node& base, const YAML::Node& overlay) {
  if (!overlay || overlay.IsNull()) return YAML::Clone(base);
  if (!base || !base.IsMap() || !overlay.IsMap()) return YAML::Clone(overlay);
  YAML::Node out = YAML::Clone(base);
  for (auto it = overlay.begin(); it != overlay.end(); ++it) {
    const std::string key = it->first.Scalar();
    const YAML::Node& cout_ = out;  // const lookup: does not insert
    const YAML::Node existing = cout_[key];
    if (existing && existing.IsMap() && it->second.IsMap())
      out[key] = merge_yaml(existing, it->second);
    else
      out[key] = YAML::Clone(it->second);
  }
  return out;
}

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

std::string override_runs(std::vector<ReproductionTable>& tables, std::size_t runs) {
  if (runs < 1) throw ConfigError("--runs", std::to_string(runs), "must be >= 1");
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
      validate(c.study, "--runs");
      std::string g = std::to_string(n);
      for (std::size_t b = 1; b < balls; ++b) g += " x " + std::to_string(n);
      grids.insert(g + " grid = " + std::to_string(total) + " runs");
    }
  std::string text = "--runs " + std::to_string(runs) + ": every case uses ";
  bool first = true;
  for (const std::string& g : grids) {
    text += (first ? "" : ", or ") + g;
    first = false;
  }
  text += " (n = round(N^(1/balls)) points per axis, so the grid is n^balls runs)";
  return text;
}

// --- summaries and conclusions -------------------------------------------------------------------

CaseSummary summarize_case(const ReproductionTable& table, const ReproductionCase& c, const MonteCarloResult& result) {
  const MonteCarloStats st = compute_statistics(result);
  CaseSummary s;
  s.table_id = table.id;
  s.case_id = c.id;
  s.label = c.label;
  s.value = c.value;
  s.reference = c.reference;
  s.runs = st.runs;
  s.ok = st.ok;
  s.failed = st.failed;
  s.mean_x = st.report_x.mean * 1e7;
  s.max_x = st.report_x.max * 1e7;
  s.pct_mi_x = st.report_x.pct_mi;
  s.ci_x = st.report_x.pct_mi_ci95;
  s.mean_mag = st.magnitude.mean * 1e7;
  s.max_mag = st.magnitude.max * 1e7;
  s.pct_mi_mag = st.magnitude.pct_mi;
  s.ci_mag = st.magnitude.pct_mi_ci95;
  s.pct_lc = st.pct_lc;
  s.settling_mean_s = st.settling_mean_s;
  s.settling_median_s = st.settling_median_s;
  s.settling_max_s = st.settling_max_s;
  s.amplitude_max_mm = st.amplitude_max_mm;
  s.wall_time_s = result.wall_time_s;
  // Standard error of the mean I_r,x over the ok runs: sample standard deviation / sqrt(n_eff),
  // n_eff = the distinct runs (exchanged starts of identical balls repeat a run: no new
  // information, as for the Wilson interval of %MI).
  double sum = 0, sum2 = 0;
  std::size_t n = 0;
  for (const MonteCarloSample& m : result.samples)
    if (m.outcome.ok()) {
      const double v = m.outcome.residual_imbalance_x_kgm * 1e7;
      sum += v;
      sum2 += v * v;
      ++n;
    }
  const std::size_t n_eff = st.distinct;
  if (n >= 2 && n_eff >= 2) {
    const double mean = sum / static_cast<double>(n);
    const double var = std::max(0.0, (sum2 - static_cast<double>(n) * mean * mean) / static_cast<double>(n - 1));
    s.sem_x = std::sqrt(var / static_cast<double>(n_eff));
  } else {
    s.sem_x = std::numeric_limits<double>::quiet_NaN();
  }
  return s;
}

std::optional<bool> reference_pct_mi_inside(const CaseSummary& s) {
  if (!s.reference.pct_mi || s.ok == 0) return std::nullopt;
  // Half a printed digit of slack: the report prints %MI with two decimals.
  const double r = *s.reference.pct_mi;
  return r >= s.ci_x[0] - 0.005 && r <= s.ci_x[1] + 0.005;
}

std::string Verdict::one_line() const {
  return "(" + conclusion_id + ") [table " + table_id + "] " + to_string(outcome) + ": " + claim +
         (evidence.empty() ? "" : " -- " + evidence);
}

Verdict check_beats_all(const CaseSummary& best, const std::vector<CaseSummary>& others) {
  Verdict v;
  v.table_id = best.table_id;
  if (others.empty() || best.ok == 0) {
    v.outcome = VerdictOutcome::NotTested;
    v.evidence = "no other case to compare with";
    return v;
  }
  bool all_lower = true, all_clear = true;
  const CaseSummary *near_mean = nullptr, *near_mi = nullptr;
  std::size_t clear = 0, total = 0;
  for (const CaseSummary& o : others) {
    if (o.ok == 0) continue;
    const bool lower_mean = best.mean_x < o.mean_x, lower_mi = best.pct_mi_x < o.pct_mi_x;
    const bool clear_mean = mean_clearly_lower(best, o), clear_mi = mi_clearly_lower(best, o);
    all_lower = all_lower && lower_mean && lower_mi;
    all_clear = all_clear && clear_mean && clear_mi;
    clear += static_cast<std::size_t>(clear_mean) + static_cast<std::size_t>(clear_mi);
    total += 2;
    if (!near_mean || o.mean_x < near_mean->mean_x) near_mean = &o;
    if (!near_mi || o.pct_mi_x < near_mi->pct_mi_x) near_mi = &o;
  }
  if (!near_mean) {
    v.outcome = VerdictOutcome::NotTested;
    v.evidence = "every other case failed";
    return v;
  }
  v.outcome = all_clear ? VerdictOutcome::Confirmed : all_lower ? VerdictOutcome::Weak : VerdictOutcome::NotReproduced;
  v.evidence = best.label + ": mean " + mean_text(best) + ", %MI " + mi_text(best) + "; best other on mean: " +
               near_mean->label + " " + mean_text(*near_mean) + "; on %MI: " + near_mi->label + " " + mi_text(*near_mi) +
               "; " + std::to_string(clear) + " of " + std::to_string(total) + " comparisons statistically clear";
  return v;
}

Verdict check_pct_mi_decreases(const std::vector<CaseSummary>& rows) {
  Verdict v;
  if (!rows.empty()) v.table_id = rows.front().table_id;
  const auto ext = value_extremes(rows);
  if (!ext) {
    v.outcome = VerdictOutcome::NotTested;
    v.evidence = "needs two cases with different values";
    return v;
  }
  const CaseSummary& fast = *ext->first;  // smallest duration
  const CaseSummary& slow = *ext->second;
  v.outcome = mi_clearly_lower(slow, fast)     ? VerdictOutcome::Confirmed
              : slow.pct_mi_x < fast.pct_mi_x ? VerdictOutcome::Weak
                                              : VerdictOutcome::NotReproduced;
  v.evidence = "%MI " + fast.label + ": " + mi_text(fast) + " -> " + slow.label + ": " + mi_text(slow) + " (report " +
               ref_mi(fast) + " -> " + ref_mi(slow) + ")";
  return v;
}

Verdict check_worsens_with_value(const std::vector<CaseSummary>& rows) {
  Verdict v;
  if (!rows.empty()) v.table_id = rows.front().table_id;
  const auto ext = value_extremes(rows);
  if (!ext) {
    v.outcome = VerdictOutcome::NotTested;
    v.evidence = "needs two cases with different values";
    return v;
  }
  const CaseSummary& lo = *ext->first;
  const CaseSummary& hi = *ext->second;
  const bool up = hi.mean_x > lo.mean_x && hi.pct_mi_x > lo.pct_mi_x;
  const bool clear = mean_clearly_lower(lo, hi) && mi_clearly_lower(lo, hi);
  v.outcome = clear ? VerdictOutcome::Confirmed : up ? VerdictOutcome::Weak : VerdictOutcome::NotReproduced;
  // Monotone steps along the value.
  std::vector<const CaseSummary*> sorted;
  for (const CaseSummary& r : rows)
    if (r.value && r.ok > 0) sorted.push_back(&r);
  std::sort(sorted.begin(), sorted.end(), [](const CaseSummary* a, const CaseSummary* b) { return *a->value < *b->value; });
  std::size_t mean_up = 0, mi_up = 0;
  for (std::size_t i = 1; i < sorted.size(); ++i) {
    mean_up += sorted[i]->mean_x > sorted[i - 1]->mean_x;
    mi_up += sorted[i]->pct_mi_x > sorted[i - 1]->pct_mi_x;
  }
  const std::size_t steps = sorted.size() - 1;
  v.evidence = lo.label + " -> " + hi.label + ": mean " + mean_text(lo) + " -> " + mean_text(hi) + ", %MI " +
               mi_text(lo) + " -> " + mi_text(hi) + "; mean rises in " + std::to_string(mean_up) + " of " +
               std::to_string(steps) + " steps, %MI in " + std::to_string(mi_up) + " of " + std::to_string(steps);
  return v;
}

std::vector<Verdict> check_conclusions(const ReproductionTable& table, const std::vector<CaseSummary>& rows) {
  std::vector<Verdict> out;
  for (const Conclusion& k : table.conclusions) {
    Verdict v;
    switch (k.check) {
      case ConclusionCheck::BeatsAll: {
        const CaseSummary* best = nullptr;
        std::vector<CaseSummary> others;
        for (const CaseSummary& r : rows) {
          if (r.case_id == k.case_id) best = &r;
          else others.push_back(r);
        }
        if (best) {
          v = check_beats_all(*best, others);
        } else {
          v.outcome = VerdictOutcome::NotTested;
          v.evidence = "case " + k.case_id + " was not run";
        }
        break;
      }
      case ConclusionCheck::PctMiDecreasesWithValue: v = check_pct_mi_decreases(rows); break;
      case ConclusionCheck::WorsensWithValue: v = check_worsens_with_value(rows); break;
    }
    v.table_id = table.id;
    v.conclusion_id = k.id;
    v.claim = k.claim;
    out.push_back(std::move(v));
  }
  return out;
}

std::vector<Verdict> ReproductionReport::verdicts() const {
  std::vector<Verdict> out;
  for (const TableResult& t : tables) out.insert(out.end(), t.verdicts.begin(), t.verdicts.end());
  return out;
}

// --- formatting ---------------------------------------------------------------------------------

std::string tables_csv_header() {
  return "table,case,label,value,runs,ok,failed,mean_x_1e7,sem_x_1e7,ref_mean_1e7,max_x_1e7,ref_max_1e7,pct_lc,"
         "ref_pct_lc,pct_mi_x,pct_mi_x_ci_lo,pct_mi_x_ci_hi,ref_pct_mi,ref_pct_mi_inside_ci,mean_mag_1e7,"
         "max_mag_1e7,pct_mi_mag,pct_mi_mag_ci_lo,pct_mi_mag_ci_hi,settling_mean_s,settling_median_s,"
         "settling_max_s,amplitude_max_mm,wall_time_s";
}

std::string tables_csv_line(const CaseSummary& s) {
  const auto inside = reference_pct_mi_inside(s);
  std::ostringstream os;
  os << csv_field(s.table_id) << ',' << csv_field(s.case_id) << ',' << csv_field(s.label) << ',' << csv_opt(s.value)
     << ',' << s.runs << ',' << s.ok << ',' << s.failed << ',' << csv_num(s.mean_x) << ',' << csv_num(s.sem_x) << ','
     << csv_opt(s.reference.mean_1e7) << ',' << csv_num(s.max_x) << ',' << csv_opt(s.reference.max_1e7) << ','
     << csv_num(s.pct_lc) << ',' << csv_opt(s.reference.pct_lc) << ',' << csv_num(s.pct_mi_x) << ','
     << csv_num(s.ci_x[0]) << ',' << csv_num(s.ci_x[1]) << ',' << csv_opt(s.reference.pct_mi) << ','
     << (inside ? (*inside ? "yes" : "no") : "") << ',' << csv_num(s.mean_mag) << ',' << csv_num(s.max_mag) << ','
     << csv_num(s.pct_mi_mag) << ',' << csv_num(s.ci_mag[0]) << ',' << csv_num(s.ci_mag[1]) << ','
     << csv_num(s.settling_mean_s) << ',' << csv_num(s.settling_median_s) << ',' << csv_num(s.settling_max_s) << ','
     << csv_num(s.amplitude_max_mm) << ',' << csv_num(s.wall_time_s);
  return os.str();
}

namespace {

std::string pair_text(double ours, const std::optional<double>& ref, int digits) {
  return num(ours, digits) + " / " + opt_num(ref, digits);
}

std::string table_heading(const ReproductionTable& t) {
  const std::string name = (t.id == "final" || t.id == "mu") ? t.title : "Table " + t.id + ": " + t.title;
  return name;
}

std::size_t table_runs(const TableResult& t) {
  std::size_t runs = 0;
  for (const CaseSummary& r : t.rows) runs = std::max(runs, r.runs);
  return runs;
}

}  // namespace

std::string format_table_text(const TableResult& t) {
  std::ostringstream os;
  os << table_heading(t.table) << "\n  source: " << t.table.source << "; ours: " << table_runs(t)
     << " runs per case\n"
     << "  I_r,x (report's definition) in 1e-7 kg m, as \"ours / report\"; %MI with our 95 % Wilson interval;\n"
     << "  in = the report's %MI lies inside that interval; |I_r| = magnitude (extra, not in the report)\n";
  char line[512];
  std::snprintf(line, sizeof line, "  %-20s %5s  %-15s %-15s %-13s %-28s %-3s  %-7s %-20s %s\n", "case", "runs",
                "mean I_r,x", "max I_r,x", "%LC", "%MI [95% CI] / report", "in", "|I_r|", "|I_r| %MI [CI]", "wall");
  os << line;
  for (const CaseSummary& s : t.rows) {
    const auto inside = reference_pct_mi_inside(s);
    const std::string mi = mi_text(s) + " / " + opt_num(s.reference.pct_mi, 2);
    const std::string mag_mi = num(s.pct_mi_mag, 1) + " [" + num(s.ci_mag[0], 1) + ", " + num(s.ci_mag[1], 1) + "]";
    std::snprintf(line, sizeof line, "  %-20s %5zu  %-15s %-15s %-13s %-28s %-3s  %-7s %-20s %.1f s%s\n",
                  s.label.c_str(), s.runs, pair_text(s.mean_x, s.reference.mean_1e7, 2).c_str(),
                  pair_text(s.max_x, s.reference.max_1e7, 2).c_str(), pair_text(s.pct_lc, s.reference.pct_lc, 2).c_str(),
                  mi.c_str(), inside ? (*inside ? "yes" : "no") : "-", num(s.mean_mag, 2).c_str(), mag_mi.c_str(),
                  s.wall_time_s, s.failed ? (" (" + std::to_string(s.failed) + " failed)").c_str() : "");
    os << line;
  }
  for (const CaseSummary& s : t.rows)
    if (!s.reference.note.empty()) os << "  note (" << s.label << "): " << s.reference.note << "\n";
  if (!t.table.expectation.empty()) os << "  expected (report): " << t.table.expectation << "\n";
  for (const Verdict& v : t.verdicts) os << "  " << v.one_line() << "\n";
  return os.str();
}

std::string format_table_markdown(const TableResult& t) {
  std::ostringstream os;
  os << "### " << table_heading(t.table) << "\n\n"
     << "Source: " << t.table.source << ". Ours: " << table_runs(t) << " runs per case, wall time "
     << num(t.wall_time_s, 1) << " s.";
  if (!t.table.expectation.empty()) os << " Expected (report): " << t.table.expectation << ".";
  os << "\n\n"
     << "| case | runs | mean I_r,x | report | max I_r,x | report | %LC | report | %MI | 95 % CI | report | in CI | "
        "mean \\|I_r\\| | %MI \\|I_r\\| (95 % CI) | failed | wall [s] |\n"
     << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|:-:|---:|---|---:|---:|\n";
  for (const CaseSummary& s : t.rows) {
    const auto inside = reference_pct_mi_inside(s);
    os << "| " << md_escape(s.label) << " | " << s.runs << " | " << num(s.mean_x, 2) << " | "
       << opt_num(s.reference.mean_1e7, 2) << " | " << num(s.max_x, 2) << " | " << opt_num(s.reference.max_1e7, 2)
       << " | " << num(s.pct_lc, 2) << " | " << opt_num(s.reference.pct_lc, 2) << " | " << num(s.pct_mi_x, 2) << " | "
       << num(s.ci_x[0], 2) << " .. " << num(s.ci_x[1], 2) << " | " << opt_num(s.reference.pct_mi, 2) << " | "
       << (inside ? (*inside ? "yes" : "**no**") : "-") << " | " << num(s.mean_mag, 2) << " | "
       << num(s.pct_mi_mag, 2) << " (" << num(s.ci_mag[0], 1) << " .. " << num(s.ci_mag[1], 1) << ") | " << s.failed
       << " | " << num(s.wall_time_s, 1) << " |\n";
  }
  os << "\n";
  for (const CaseSummary& s : t.rows)
    if (!s.reference.note.empty()) os << "Note (" << s.label << "): " << s.reference.note << ".\n\n";
  for (const Verdict& v : t.verdicts) os << "- " << md_escape(v.one_line()) << "\n";
  if (!t.verdicts.empty()) os << "\n";
  return os.str();
}

std::string format_report_markdown(const ReproductionReport& r, const ReproductionOptions& opt) {
  std::ostringstream os;
  os << "# Reproduction of the 2003 report's tables\n\n"
     << "Generated by `abuopt reproduce` on " << local_time_text() << ".\n\n"
     << "- command: `" << (opt.command_line.empty() ? "abuopt reproduce" : opt.command_line) << "`\n"
     << "- wall time: " << num(r.wall_time_s, 1) << " s on " << r.concurrency << " thread"
     << (r.concurrency == 1 ? "" : "s") << "\n";
  if (!opt.runs_note.empty()) os << "- " << opt.runs_note << "\n";
  os << "- I_r,x is the report's definition (eq 4.2), in 1e-7 kg m; %MI is the share of runs with I_r,x >= m_I e "
        "= 2.072e-6 kg m, with our 95 % Wilson score interval; \"in CI\" says whether the report's %MI lies inside it.\n"
     << "- |I_r| (the magnitude of the residual imbalance vector) is not in the report: extra columns.\n\n";
  const std::vector<Verdict> verdicts = r.verdicts();
  os << "## Verdicts on the report's conclusions\n\n";
  if (verdicts.empty()) os << "(no conclusion was tested: the tables that carry them were not run)\n";
  for (const Verdict& v : verdicts) os << "- " << md_escape(v.one_line()) << "\n";
  os << "\nCONFIRMED: the claimed direction holds and the intervals separate (Wilson intervals of %MI do not "
        "overlap; means differ by more than 1.96 combined standard errors). WEAK: the direction holds on the "
        "point estimates only. NOT REPRODUCED: it does not hold.\n\n";
  os << "## Tables\n\n";
  for (const TableResult& t : r.tables) os << format_table_markdown(t);
  os << "## Plots\n\n";
  if (r.plots.empty()) os << "(none yet)\n";
  for (const PlotNote& p : r.plots) {
    if (p.made)
      os << "- " << p.name << ": ![" << p.name << "](" << fs::path(p.png).lexically_relative(opt.out_dir).string()
         << ") (data: `" << fs::path(p.csv).lexically_relative(opt.out_dir).string() << "`)\n";
    else
      os << "- " << p.name << ": " << p.message << "\n";
  }
  os << "\n## Settings\n\n";
  if (!r.tables.empty() && !r.tables.front().table.cases.empty()) {
    const MonteCarloStudy& s = r.tables.front().table.cases.front().study;
    const AbuParameters& a = s.setup.abu;
    const SimulationOptions& o = s.setup.options;
    os << "- ABU (first case; a table may vary one of these): M_T " << a.table_mass_kg << " kg, b "
       << a.damping_Ns_per_m << " N s/m, k " << a.stiffness_N_per_m << " N/m, L " << a.ball_track_radius_m
       << " m, m_I " << a.imbalance_mass_kg << " kg, e " << a.eccentricity_m << " m, mu " << a.friction_mu << ", "
       << a.balls.size() << " balls of " << (a.balls.empty() ? 0.0 : a.balls.front().mass_kg) << " kg, natural frequency "
       << num(a.natural_frequency_hz(), 2) << " Hz\n"
       << "- simulation: " << to_string(o.method) << ", integrator " << to_string(o.backend) << " (" << o.erk_table
       << "), rtol " << o.rtol << ", atol " << o.atol << ", end time "
       << (o.end_time_s > 0 ? num(o.end_time_s, 1) + " s" : std::string("twice the profile duration")) << "\n"
       << "- motor: " << (s.setup.motor.kind == MotorKind::Ideal ? "ideal" : "PI") << "\n";
  }
  for (const TableResult& t : r.tables) {
    if (t.table.cases.empty()) continue;
    const InitialConditionDesign d = study_design(t.table.cases.front().study);
    os << "- " << table_heading(t.table) << " (`" << t.table.file << "`): design " << to_string(d.kind);
    if (d.kind == InitialConditionKind::Grid) os << " " << d.grid_points_per_axis << "^" << d.balls;
    os << ", " << t.table.cases.front().study.runs << " runs per case, " << t.table.cases.size() << (t.table.cases.size() == 1 ? " case\n" : " cases\n");
  }
  os << "\nPer-run data: `runs/<table>/<case>.csv` (one line per run); all rows: `tables.csv`.\n";
  return os.str();
}

// --- plots --------------------------------------------------------------------------------------

namespace {

const MonteCarloResult* find_result(const TableResult& t, const std::string& case_id) {
  for (std::size_t i = 0; i < t.table.cases.size() && i < t.results.size(); ++i)
    if (t.table.cases[i].id == case_id) return &t.results[i];
  return nullptr;
}

PlotNote finish_note(PlotNote n, const PlotStatus& st) {
  n.made = st.ran();
  n.png = st.png_path;
  n.message = st.message;
  return n;
}

PlotNote plot_trend(const Gnuplot& gp, const TableResult& t, const PlotRequest& req, const fs::path& dir) {
  PlotNote note;
  note.name = req.name;
  note.csv = (dir / (req.name + ".csv")).string();
  std::ostringstream csv;
  csv << "value,mean_x_1e7,pct_mi_x,pct_mi_x_ci_lo,pct_mi_x_ci_hi,ref_mean_1e7,ref_pct_mi,mean_mag_1e7,pct_mi_mag\n";
  std::size_t points = 0;
  for (const CaseSummary& s : t.rows) {
    if (!s.value || s.ok == 0) continue;
    ++points;
    csv << csv_num(*s.value) << ',' << csv_num(s.mean_x) << ',' << csv_num(s.pct_mi_x) << ',' << csv_num(s.ci_x[0])
        << ',' << csv_num(s.ci_x[1]) << ',' << csv_opt(s.reference.mean_1e7) << ',' << csv_opt(s.reference.pct_mi)
        << ',' << csv_num(s.mean_mag) << ',' << csv_num(s.pct_mi_mag) << '\n';
  }
  write_text_file(note.csv, csv.str());
  if (points == 0) {
    note.message = "skipped: no case with a value";
    return note;
  }
  const std::string data = Gnuplot::quote(note.csv);
  const std::string xl = t.table.parameter_name + (t.table.parameter_unit.empty() ? "" : " [" + t.table.parameter_unit + "]");
  std::ostringstream b;
  b << "set datafile separator ','\n"
    << "set datafile missing ''\n"
    << "set title " << Gnuplot::quote(table_heading(t.table) + ": ours (I_r,x) and the report") << "\n"
    << "set xlabel " << Gnuplot::quote(xl) << "\n"
    << "set ylabel 'mean I_r,x [1e-7 kg m]'\n"
    << "set y2label '%MI [%]'\n"
    << "set ytics nomirror\nset y2tics\nset grid\nset key outside below\nset offsets graph 0.03, graph 0.03, 0, 0\n"
    << "plot " << data << " skip 1 using 1:2 with linespoints pt 7 lc rgb '#1f77b4' title 'mean I_r,x (ours)', \\\n"
    << "     " << data << " skip 1 using 1:6 with points pt 6 ps 1.5 lc rgb '#1f77b4' title 'mean (report)', \\\n"
    << "     " << data
    << " skip 1 using 1:3:4:5 axes x1y2 with yerrorlines pt 5 lc rgb '#d62728' title '%MI (ours, 95 % CI)', \\\n"
    << "     " << data << " skip 1 using 1:7 axes x1y2 with points pt 4 ps 1.5 lc rgb '#d62728' title '%MI (report)'\n";
  const std::string png = (dir / (req.name + ".png")).string();
  return finish_note(note, gp.run(b.str(), (dir / (req.name + ".gp")).string(), png, 900, 650));
}

PlotNote plot_final_positions(const Gnuplot& gp, const TableResult& t, const PlotRequest& req, const fs::path& dir) {
  PlotNote note;
  note.name = req.name;
  note.csv = (dir / (req.name + ".csv")).string();
  std::vector<const MonteCarloResult*> res;
  std::vector<std::string> labels;
  std::size_t rows = 0;
  for (const std::string& id : req.case_ids) {
    const MonteCarloResult* r = find_result(t, id);
    if (!r) continue;
    res.push_back(r);
    labels.push_back(t.table.find_case(id)->label);
    rows = std::max(rows, r->samples.size());
  }
  std::ostringstream csv;
  for (std::size_t k = 0; k < res.size(); ++k)
    csv << (k ? "," : "") << "beta1_" << req.case_ids[k] << "_rad,beta2_" << req.case_ids[k] << "_rad";
  csv << '\n';
  for (std::size_t i = 0; i < rows; ++i) {
    for (std::size_t k = 0; k < res.size(); ++k) {
      if (k) csv << ',';
      const auto& smp = res[k]->samples;
      if (i < smp.size() && smp[i].outcome.ok() && smp[i].outcome.beta_final.size() >= 2)
        csv << csv_num(smp[i].outcome.beta_final[0]) << ',' << csv_num(smp[i].outcome.beta_final[1]);
      else
        csv << ',';
    }
    csv << '\n';
  }
  write_text_file(note.csv, csv.str());
  XYLinesPlot p;
  p.csv_path = note.csv;
  p.png_path = (dir / (req.name + ".png")).string();
  p.width_px = 800;
  p.height_px = 800;
  p.labels = {"Final ball positions (cf. report fig 4.7)", "beta_1 [rad]", "beta_2 [rad]"};
  for (std::size_t k = 0; k < res.size(); ++k)
    p.series.push_back({static_cast<int>(2 * k + 1), static_cast<int>(2 * k + 2), labels[k], "points"});
  return finish_note(note, gp.xy_lines(p));
}

PlotNote plot_settling(const Gnuplot& gp, const TableResult& t, const PlotRequest& req, const fs::path& dir) {
  PlotNote note;
  note.name = req.name;
  note.csv = (dir / (req.name + ".csv")).string();
  const MonteCarloResult* r = find_result(t, req.case_ids.front());
  std::ostringstream csv;
  csv << "settling_time_s\n";
  std::size_t n = 0;
  if (r)
    for (const MonteCarloSample& s : r->samples)
      if (s.outcome.ok() && s.outcome.settled) {
        csv << csv_num(s.outcome.settling_time_s) << '\n';
        ++n;
      }
  write_text_file(note.csv, csv.str());
  if (n < 2) {
    note.message = "skipped: fewer than two settled runs";
    return note;
  }
  HistogramPlot p;
  p.csv_path = note.csv;
  p.png_path = (dir / (req.name + ".png")).string();
  p.labels = {"Settling time, " + t.table.find_case(req.case_ids.front())->label + " (" + std::to_string(n) +
                  " settled runs)",
              "settling time [s]", "runs"};
  p.bins = 40;
  return finish_note(note, gp.histogram(p));
}

PlotNote plot_equilibrium(const Gnuplot& gp, const TableResult& t, const PlotRequest& req, const fs::path& dir) {
  PlotNote note;
  note.name = req.name;
  note.csv = (dir / (req.name + ".csv")).string();
  const ReproductionCase* c = t.table.find_case(req.case_ids.front());
  const MonteCarloResult* r = find_result(t, req.case_ids.front());
  if (!c || !r || c->study.setup.abu.balls.size() != 2) {
    note.message = "skipped: needs a two-ball case that ran";
    return note;
  }
  const double f = c->study.setup.profile.final_frequency_hz();
  const EquilibriumSet set(c->study.setup.abu);
  const std::size_t n = 96;
  const EquilibriumGrid g = set.grid(f, n);
  // Grid data for gnuplot's image style: one scan per beta_1, blank line between scans.
  const std::string grid_csv = (dir / (req.name + ".grid.csv")).string();
  {
    std::ostringstream os;
    os << "beta1_rad,beta2_rad,in_set,steady_amplitude_mm\n";
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = 0; j < n; ++j)
        os << csv_num(g.beta(i)) << ',' << csv_num(g.beta(j)) << ',' << int(g.in_set[g.index(i, j)]) << ','
           << csv_num(g.amplitude_mm[g.index(i, j)]) << '\n';
      os << '\n';
    }
    write_text_file(grid_csv, os.str());
  }
  {
    std::ostringstream os;
    os << "beta1_final_rad,beta2_final_rad,ir_x_1e7\n";
    for (const MonteCarloSample& s : r->samples)
      if (s.outcome.ok() && s.outcome.beta_final.size() == 2)
        os << csv_num(s.outcome.beta_final[0]) << ',' << csv_num(s.outcome.beta_final[1]) << ','
           << csv_num(s.outcome.residual_imbalance_x_kgm * 1e7) << '\n';
    write_text_file(note.csv, os.str());
  }
  // Frictionless balancing positions: beta = +- arccos(-m_I e / (2 m L)).
  const AbuParameters& a = c->study.setup.abu;
  const double ratio = a.imbalance_kgm() / (2.0 * a.balls[0].mass_kg * a.ball_track_radius_m);
  std::ostringstream b;
  b << "set datafile separator ','\n"
    << "set title " << Gnuplot::quote("Final positions over the equilibrium set at " + num(f, 1) + " Hz (mu = " +
                                      short_num(a.friction_mu) + "; coverage " + num(100.0 * g.coverage(), 1) + " %)")
    << "\n"
    << "set xlabel 'beta_1 [rad]'\nset ylabel 'beta_2 [rad]'\nset size square\n"
    << "set xrange [0:2*pi]\nset yrange [0:2*pi]\n"
    << "set palette defined (0 '#ffffff', 1 '#c6dbef', 2 '#6baed6', 3 '#2171b5')\n"
    << "set cblabel 'steady amplitude with the balls stuck there [mm]'\n"
    << "set key outside below\n";
  if (ratio < 1.0) {
    const double bb = std::acos(-ratio);
    b << "set label 1 '' at " << bb << "," << 2 * M_PI - bb << " point pt 3 ps 3 lw 2 lc rgb '#d62728' front\n"
      << "set label 2 '' at " << 2 * M_PI - bb << "," << bb << " point pt 3 ps 3 lw 2 lc rgb '#d62728' front\n";
  }
  b << "plot " << Gnuplot::quote(grid_csv)
    << " skip 1 using 1:2:4 with image title 'steady amplitude (background)', \\\n"
    << "     " << Gnuplot::quote(grid_csv)
    << " skip 1 using 1:(column(3) < 0.5 ? column(2) : NaN) with points pt 1 ps 0.4 lc rgb '#888888' "
       "title 'outside the equilibrium set', \\\n"
    << "     " << Gnuplot::quote(note.csv)
    << " skip 1 using 1:2 with points pt 7 ps 0.6 lc rgb '#000000' title 'final positions (red stars: frictionless "
       "balancing positions)'\n";
  const std::string png = (dir / (req.name + ".png")).string();
  return finish_note(note, gp.run(b.str(), (dir / (req.name + ".gp")).string(), png, 820, 860));
}

}  // namespace

// --- running --------------------------------------------------------------------------------------

ReproductionReport run_reproduction(const std::vector<ReproductionTable>& tables, const ReproductionOptions& opt) {
  using clock = std::chrono::steady_clock;
  if (opt.out_dir.empty()) throw ConfigError("--out", "<empty>", "must name an output directory");
  const fs::path out(opt.out_dir);
  std::error_code ec;
  fs::create_directories(out / "runs", ec);
  if (!ec) fs::create_directories(out / "plots", ec);
  if (ec) throw ConfigError("--out", opt.out_dir, "cannot be created (" + ec.message() + ")");
  auto log = [&opt](const std::string& line) {
    if (opt.log) opt.log(line);
  };

  ReproductionReport report;
  report.markdown_path = (out / "report.md").string();
  report.tables_csv_path = (out / "tables.csv").string();
  std::ofstream tables_csv(report.tables_csv_path);
  if (!tables_csv) throw ConfigError("--out", opt.out_dir, "cannot write " + report.tables_csv_path);
  tables_csv << tables_csv_header() << '\n' << std::flush;

  ThreadPoolRunner runner(opt.threads);
  report.concurrency = runner.concurrency();
  std::size_t total_cases = 0, done_cases = 0;
  for (const ReproductionTable& t : tables) total_cases += t.cases.size();
  const auto t_start = clock::now();

  for (const ReproductionTable& table : tables) {
    TableResult tr;
    tr.table = table;
    const auto t_table = clock::now();
    const fs::path run_dir = out / "runs" / table_dir_name(table.id);
    fs::create_directories(run_dir, ec);
    if (ec) throw ConfigError("--out", opt.out_dir, "cannot create " + run_dir.string());
    for (std::size_t k = 0; k < table.cases.size(); ++k) {
      const ReproductionCase& c = table.cases[k];
      MonteCarloResult result = run_monte_carlo(c.study, runner);
      const fs::path csv_path = run_dir / (c.id + ".csv");
      {
        std::ofstream f(csv_path);
        if (!f) throw ConfigError("--out", opt.out_dir, "cannot write " + csv_path.string());
        write_runs_csv(f, result.samples);
      }
      CaseSummary s = summarize_case(table, c, result);
      tables_csv << tables_csv_line(s) << '\n' << std::flush;
      ++done_cases;
      const double elapsed = std::chrono::duration<double>(clock::now() - t_start).count();
      log("[" + std::to_string(done_cases) + "/" + std::to_string(total_cases) + "] " + table.id + " " + c.label +
          ": " + std::to_string(s.runs) + " runs in " + num(s.wall_time_s, 1) + " s (mean I_r,x " + num(s.mean_x, 2) +
          " vs " + opt_num(c.reference.mean_1e7, 2) + ", %MI " + num(s.pct_mi_x, 2) + " vs " +
          opt_num(c.reference.pct_mi, 2) + (s.failed ? ", " + std::to_string(s.failed) + " failed" : "") +
          "); total " + num(elapsed, 0) + " s");
      tr.rows.push_back(std::move(s));
      tr.results.push_back(std::move(result));
    }
    tr.verdicts = check_conclusions(table, tr.rows);
    tr.wall_time_s = std::chrono::duration<double>(clock::now() - t_table).count();
    report.tables.push_back(std::move(tr));
    report.wall_time_s = std::chrono::duration<double>(clock::now() - t_start).count();
    write_text_file(report.markdown_path, format_report_markdown(report, opt));  // partial report
  }

  if (opt.plots) {
    const Gnuplot gp;
    if (!gp.available()) log("gnuplot not found: writing the plot data and scripts, skipping the PNGs");
    const fs::path plot_dir = out / "plots";
    for (const TableResult& t : report.tables)
      for (const PlotRequest& req : t.table.plots) {
        PlotNote note;
        switch (req.kind) {
          case PlotKind::Trend: note = plot_trend(gp, t, req, plot_dir); break;
          case PlotKind::FinalPositions: note = plot_final_positions(gp, t, req, plot_dir); break;
          case PlotKind::SettlingHistogram: note = plot_settling(gp, t, req, plot_dir); break;
          case PlotKind::EquilibriumOverlay: note = plot_equilibrium(gp, t, req, plot_dir); break;
        }
        log("plot " + note.name + ": " + (note.made ? note.png : note.message));
        report.plots.push_back(std::move(note));
      }
  }
  report.wall_time_s = std::chrono::duration<double>(clock::now() - t_start).count();
  write_text_file(report.markdown_path, format_report_markdown(report, opt));
  return report;
}

}  // namespace abuopt
