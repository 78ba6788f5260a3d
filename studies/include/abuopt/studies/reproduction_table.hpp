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
//     contact_variant: hard              # optional: also run every case with this ball contact
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
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "abuopt/common/yaml_reader.hpp"
#include "abuopt/core/monte_carlo.hpp"

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
  // table.contact_variant (optional, e.g. `hard`): every case is run a second time with
  // abu.ball_contact set to this (same starts; docs/model.md 11.6 maps a grid onto the feasible
  // set), and reported as an extra column set beside the case's own columns.
  std::optional<BallContact> contact_variant;
  std::string file;    // where it was read from (or the name given to the string reader)

  const ReproductionCase* find_case(const std::string& case_id) const;  // nullptr if absent
};

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
// an id is unknown (the message lists the available ids; the app passes its flag's name). Empty
// `ids`: all tables.
std::vector<ReproductionTable> select_tables(const std::vector<ReproductionTable>& tables,
                                            const std::vector<std::string>& ids,
                                            const std::string& option = "table ids");

// Every case gets an n^balls grid with n = round(runs^(1/balls)) (n x n for two balls), so
// runs = n^balls. Returns a sentence for the output, starting with `name` and the number
// ("runs 1000: every case uses a 32 x 32 grid = 1024 runs ..."; the app passes its flag's name).
// Throws ConfigError naming `name` for runs < 1 or a study that breaks its limits.
std::string override_runs(std::vector<ReproductionTable>& tables, std::size_t runs, const std::string& name = "runs");

}  // namespace abuopt
