#pragma once
// The reproduction's results and how they are written: the per-table results, the report (Markdown
// and plain text) and tables.csv.
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "abuopt/core/monte_carlo.hpp"
#include "abuopt/studies/reproduction_table.hpp"
#include "abuopt/studies/verdicts.hpp"

namespace abuopt {

// --- Running and reporting ----------------------------------------------------------------------

// One case run again with the table's contact_variant (same starts, mapped onto the feasible set).
struct ContactRow {
  CaseSummary summary;                  // the case with contact on
  std::size_t overlapping_without = 0;  // final states of the no-contact runs that overlap
  std::size_t overlapping_with = 0;     // the same with contact on (the model says 0)
};

// A final state overlaps when min_contact_clearance < -kOverlapTolerance_rad (the simulator closes
// rounding-level negative gaps; docs/model.md 11.5 measured >= -6e-15 rad).
inline constexpr double kOverlapTolerance_rad = 1e-9;
std::size_t count_overlapping_final_states(const AbuParameters& p, const MonteCarloResult& r);

struct TableResult {
  ReproductionTable table;
  std::vector<CaseSummary> rows;            // one per case, in case order
  std::vector<ContactRow> contact_rows;     // one per case when table.contact_variant is set
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
  // Where every case's Monte Carlo runs (e.g. MPI ranks: abuopt::parallel); null: a
  // ThreadPoolRunner of `threads`. Results do not depend on it.
  std::shared_ptr<BatchRunner> runner;
  // How many of a table's Monte Carlo studies (cases, contact variants) run at once: > 1 only for
  // a runner that takes studies from several threads (MPI ranks: their runs then share one pool,
  // docs/cluster.md). Results, files and log lines are the same, in case order; progress is then
  // reported per case.
  std::size_t cases_at_once = 1;
  bool plots = true;
  std::string command_line;      // for the report's settings section
  std::string runs_note;         // from override_runs, for the report ("" = report's run counts)
  // One progress line per finished case (and a few more); the app prints them on stderr.
  std::function<void(const std::string& line)> log;
  // Runs done of all cases (with the contact variants) so far, and their total; called from a
  // worker thread (at most one at a time), so keep it cheap.
  std::function<void(std::size_t done, std::size_t total)> progress;
};

struct ReproductionReport {
  std::vector<TableResult> tables;
  std::vector<PlotNote> plots;
  double wall_time_s = 0;
  std::size_t concurrency = 1;
  std::string markdown_path, tables_csv_path;
  std::string tables_contact_csv_path;  // empty when no table has a contact_variant
  std::vector<Verdict> verdicts() const;  // of every table, in order
};

// The table side by side with the report's values, as plain text (for the terminal).
std::string format_table_text(const TableResult& t);
// The same as a Markdown table (with the table's heading and verdicts).
std::string format_table_markdown(const TableResult& t);
// The whole Markdown report.
std::string format_report_markdown(const ReproductionReport& r, const ReproductionOptions& opt);

// tables.csv: the header line, and one line per case.
std::string tables_csv_header();
std::string tables_csv_line(const CaseSummary& s);
// tables_contact.csv (tables with a contact_variant): tables.csv's columns, then the contact model
// and the overlapping final states without and with contact.
std::string tables_contact_csv_header();
std::string tables_contact_csv_line(const ContactRow& r, BallContact contact);

}  // namespace abuopt
