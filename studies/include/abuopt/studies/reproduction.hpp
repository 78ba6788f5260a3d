#pragma once
// Reproducing the 2003 report's published studies (spec section 7; docs/validation.md).
//
// A *reproduction table* is one YAML file (configs/report/*.yaml) describing one of the report's
// tables: a `base` setup (sections abu, profile, motor, simulation, montecarlo, as in any config)
// and a list of `cases`, each a full Monte Carlo study obtained by deep-merging the case's own
// sections over the base (mappings merge key by key; scalars and sequences replace). Each case
// carries the report's published row (`reference`, in the report's units: mean and max I_r,x in
// 1e-7 kg m, %LC and %MI in percent). The table names the published conclusions it tests and the
// plots it wants:
//
//   table:
//     id: "4.1"                          # 4.1, 4.2, 4.3, 4.4, final, mu (--only uses these)
//     title: "..."; source: "report table 4.1 (1024 runs)"
//     parameter: {name: dt, unit: s}     # the varied quantity (optional)
//     expectation: "..."                 # a published trend without numbers (optional)
//     conclusions:                       # optional
//       - {id: b, check: pct_mi_decreases_with_value, claim: "..."}
//       - {id: a, check: beats_all, case: three_step, claim: "..."}
//       - {id: c, check: worsens_with_value, claim: "..."}
//     plots:                             # optional; kinds below
//       - {kind: trend | final_positions | settling_histogram | equilibrium_overlay,
//          name: file_stem, cases: [case ids]}
//   base: {abu: ..., profile: ..., motor: ..., simulation: ..., montecarlo: ...}
//   cases:
//     - {id: dt1, label: "dt = 1 s", value: 1, profile: {...},
//        reference: {mean: 11.54, max: 44.65, pct_lc: 0, pct_mi: 15.43, note: "..."}}
//
// Unknown keys are errors (strict YamlReader); messages name the file and the case.
//
// The published tables use the report's I_r,x (spec section 5), so every comparison here is on
// I_r,x; the magnitude |I_r| is reported beside it as extra columns.
#include <array>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "abuopt/common/yaml_reader.hpp"
#include "abuopt/core/monte_carlo.hpp"
#include "abuopt/core/monte_carlo_stats.hpp"

namespace abuopt {

// --- The study files ----------------------------------------------------------------------------

// One published row, in the report's units; an absent value was not published.
struct PublishedRow {
  std::optional<double> mean_1e7;  // mean I_r,x [1e-7 kg m]
  std::optional<double> max_1e7;   // max I_r,x [1e-7 kg m]
  std::optional<double> pct_lc;    // %LC [%]
  std::optional<double> pct_mi;    // %MI [%]
  std::string note;                // e.g. "max quoted as 'about 2.4e-6 kg m'"
  bool empty() const { return !mean_1e7 && !max_1e7 && !pct_lc && !pct_mi; }
};

struct ReproductionCase {
  std::string id;     // unique within its table; used in file names
  std::string label;  // for tables ("dt = 1 s"); default "<parameter> = <value> <unit>" or the id
  std::optional<double> value;  // the table's varied parameter
  MonteCarloStudy study;        // the case's full study (base merged with the case)
  std::size_t threads = 0;      // montecarlo.threads of the merged config (the CLI overrides it)
  PublishedRow reference;
};

enum class ConclusionCheck {
  BeatsAll,                  // case `case_id` has lower mean I_r,x AND lower %MI than every other case
  PctMiDecreasesWithValue,   // %MI of the largest-value case is below that of the smallest-value case
  WorsensWithValue,          // mean I_r,x and %MI of the largest-value case exceed the smallest's
};
std::string to_string(ConclusionCheck c);  // "beats_all", "pct_mi_decreases_with_value", "worsens_with_value"

struct Conclusion {
  std::string id;     // the brief's letter: a, b, c
  std::string claim;  // the published conclusion, in words
  ConclusionCheck check = ConclusionCheck::BeatsAll;
  std::string case_id;  // BeatsAll: the case that must beat all others
};

enum class PlotKind {
  Trend,               // mean I_r,x and %MI (with Wilson interval) against the case value
  FinalPositions,      // final (beta_1, beta_2) of each listed case (report fig 4.7)
  SettlingHistogram,   // histogram of the settling time of the listed case
  EquilibriumOverlay,  // final positions over the equilibrium set at the profile's final speed
};
std::string to_string(PlotKind k);  // "trend", "final_positions", "settling_histogram", "equilibrium_overlay"

struct PlotRequest {
  PlotKind kind = PlotKind::Trend;
  std::string name;                  // file stem of the CSV/PNG
  std::vector<std::string> case_ids;
};

struct ReproductionTable {
  std::string id;      // "4.1", "4.2", "4.3", "4.4", "final", "mu"
  std::string title;
  std::string source;  // where the published values come from
  std::string parameter_name, parameter_unit;
  std::string expectation;
  std::vector<Conclusion> conclusions;
  std::vector<PlotRequest> plots;
  std::vector<ReproductionCase> cases;
  std::string file;    // where it was read from (or the name given to the string reader)

  const ReproductionCase* find_case(const std::string& case_id) const;  // nullptr if absent
};

// Deep merge: a copy of `base` with `overlay` applied (maps merge recursively, anything else
// replaces). Neither argument is modified.
YAML::Node merge_yaml(const YAML::Node& base, const YAML::Node& overlay);

// Reads one table file; throws ConfigError ("<file>: cases[3] (dt4): profile.segments[0]... ").
ReproductionTable read_reproduction_table(const std::string& file);
// The same from YAML text (tests); `name` stands in for the file name in messages.
ReproductionTable read_reproduction_table_string(const std::string& yaml_text, const std::string& name);

// Every *.yaml of `dir`, ordered as the report (4.1, 4.2, 4.3, 4.4, final, mu, then others by id).
// Throws ConfigError when the directory is missing, has no table, or two tables share an id.
std::vector<ReproductionTable> read_reproduction_tables(const std::string& dir);

// The report's table ids in the report's order.
const std::vector<std::string>& report_table_ids();

// The tables whose id is in `ids` (in the tables' order). Throws ConfigError naming `option` when
// an id is unknown (the message lists the available ids). Empty `ids`: all tables.
std::vector<ReproductionTable> select_tables(const std::vector<ReproductionTable>& tables,
                                            const std::vector<std::string>& ids,
                                            const std::string& option = "--only");

// --runs N: every case gets an n^balls grid with n = round(N^(1/balls)) (n x n for two balls),
// runs = n^balls. Returns a sentence for the output ("--runs 1000: every case uses a 32 x 32 grid
// = 1024 runs"). Throws ConfigError for N < 1.
std::string override_runs(std::vector<ReproductionTable>& tables, std::size_t runs);

// --- Results and conclusions ----------------------------------------------------------------------

// One case's figures, in the report's units (1e-7 kg m, percent). Built from the engine's
// statistics plus the standard error of the mean I_r,x (for the conclusion checks).
struct CaseSummary {
  std::string table_id, case_id, label;
  std::optional<double> value;
  std::size_t runs = 0, ok = 0, failed = 0;
  // I_r,x (report eq 4.2): what the report's tables show.
  double mean_x = 0, sem_x = 0, max_x = 0, pct_mi_x = 0;
  std::array<double, 2> ci_x{0, 0};  // 95 % Wilson interval of %MI
  // |I_r| (magnitude): extra columns.
  double mean_mag = 0, max_mag = 0, pct_mi_mag = 0;
  std::array<double, 2> ci_mag{0, 0};
  double pct_lc = 0;
  double settling_mean_s = 0, settling_median_s = 0, settling_max_s = 0;
  double amplitude_max_mm = 0;
  double wall_time_s = 0;
  PublishedRow reference;
};

CaseSummary summarize_case(const ReproductionTable& table, const ReproductionCase& c, const MonteCarloResult& result);

// Is the published %MI inside our Wilson interval? (nullopt when not published.)
std::optional<bool> reference_pct_mi_inside(const CaseSummary& s);

enum class VerdictOutcome {
  Confirmed,      // the claimed direction holds and is statistically clear (see below)
  Weak,           // the direction holds on the point estimates, but intervals overlap
  NotReproduced,  // the direction does not hold
  NotTested,      // the cases needed are missing
};
std::string to_string(VerdictOutcome v);  // "CONFIRMED", "WEAK", "NOT REPRODUCED", "NOT TESTED"

struct Verdict {
  std::string table_id, conclusion_id, claim;
  VerdictOutcome outcome = VerdictOutcome::NotTested;
  std::string evidence;  // the numbers behind the outcome, one line
  std::string one_line() const;  // "(b) [table 4.1] CONFIRMED: <claim> -- <evidence>"
};

// "Statistically clear": for %MI the two Wilson intervals do not overlap; for the mean the gap
// exceeds 1.96 sqrt(sem_a^2 + sem_b^2). A comparison is "better" when lower.
// beats_all: `best` against each of `others`, on mean_x and on pct_mi_x: Confirmed when every
// comparison is lower and clear, Weak when every one is lower, NotReproduced otherwise.
Verdict check_beats_all(const CaseSummary& best, const std::vector<CaseSummary>& others);
// pct_mi_decreases_with_value: the smallest-value row against the largest-value row.
Verdict check_pct_mi_decreases(const std::vector<CaseSummary>& rows);
// worsens_with_value: mean_x AND pct_mi_x of the largest-value row above the smallest-value row;
// the evidence also counts the monotone steps along the value.
Verdict check_worsens_with_value(const std::vector<CaseSummary>& rows);
// Every conclusion of the table on its rows (claim, ids filled in).
std::vector<Verdict> check_conclusions(const ReproductionTable& table, const std::vector<CaseSummary>& rows);

// --- Running and reporting ----------------------------------------------------------------------

struct TableResult {
  ReproductionTable table;
  std::vector<CaseSummary> rows;            // one per case, in case order
  std::vector<MonteCarloResult> results;    // the samples (for the plots)
  std::vector<Verdict> verdicts;
  double wall_time_s = 0;
};

struct PlotNote {
  std::string name;     // file stem
  std::string png;      // path of the PNG (if made)
  std::string csv;      // its data
  bool made = false;
  std::string message;  // "ok", or why it was skipped
};

struct ReproductionOptions {
  std::string out_dir;           // required: everything goes here
  std::size_t threads = 0;       // 0: all cores
  bool plots = true;
  std::string command_line;      // for the report's settings section
  std::string runs_note;         // from override_runs, for the report ("" = report's run counts)
  // One progress line per finished case (and a few more); the app prints them on stderr.
  std::function<void(const std::string& line)> log;
};

struct ReproductionReport {
  std::vector<TableResult> tables;
  std::vector<PlotNote> plots;
  double wall_time_s = 0;
  std::size_t concurrency = 1;
  std::string markdown_path, tables_csv_path;
  std::vector<Verdict> verdicts() const;  // of every table, in order
};

// Runs every case of every table into opt.out_dir:
//   runs/<table id>/<case id>.csv  the engine's per-run CSV, written as soon as the case ends
//   tables.csv                     one line per case (ours and the report's), appended per case
//   report.md                      tables, verdicts, settings, wall time (rewritten per table)
//   plots/<name>.csv, .gp, .png    the plots the tables ask for (gnuplot helper)
// Nothing already computed is lost if the study is interrupted. Throws ConfigError when the
// output directory cannot be written.
ReproductionReport run_reproduction(const std::vector<ReproductionTable>& tables, const ReproductionOptions& opt);

// The table side by side with the report's values, as plain text (for the terminal).
std::string format_table_text(const TableResult& t);
// The same as a Markdown table (with the table's heading and verdicts).
std::string format_table_markdown(const TableResult& t);
// The whole Markdown report.
std::string format_report_markdown(const ReproductionReport& r, const ReproductionOptions& opt);

// tables.csv: the header line, and one line per case.
std::string tables_csv_header();
std::string tables_csv_line(const CaseSummary& s);

}  // namespace abuopt
