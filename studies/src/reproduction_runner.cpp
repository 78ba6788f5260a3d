#include "abuopt/studies/reproduction_runner.hpp"

#include <chrono>
#include <deque>
#include <filesystem>
#include <future>
#include <sstream>
#include <stdexcept>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/gnuplot.hpp"
#include "abuopt/common/output_file.hpp"
#include "output_dir.hpp"
#include "reproduction_plots.hpp"
#include "study_text.hpp"

namespace abuopt {

namespace fs = std::filesystem;
using namespace studies_detail;

ReproductionReport run_reproduction(const std::vector<ReproductionTable>& tables, const ReproductionOptions& opt) {
  using clock = std::chrono::steady_clock;
  if (opt.out_dir.empty()) throw std::invalid_argument("run_reproduction: ReproductionOptions::out_dir is empty");
  const fs::path out(opt.out_dir);
  std::error_code ec;
  fs::create_directories(out / "runs", ec);
  if (!ec) fs::create_directories(out / "plots", ec);
  if (ec) throw OutputError("cannot create the output directory " + opt.out_dir + " (" + ec.message() + ")");
  auto log = [&opt](const std::string& line) {
    if (opt.log) opt.log(line);
  };

  ReproductionReport report;
  report.markdown_path = (out / "report.md").string();
  report.tables_csv_path = (out / "tables.csv").string();
  // tables.csv is rewritten whole after every case (a few dozen lines): an interrupted study keeps
  // every finished case, and a failed write never leaves a truncated file under the name.
  std::string tables_csv = tables_csv_header() + "\n";
  write_text_file(report.tables_csv_path, tables_csv);
  std::string tables_contact_csv;

  const std::shared_ptr<BatchRunner> runner_owner =
      opt.runner ? opt.runner : std::make_shared<ThreadPoolRunner>(opt.threads);
  BatchRunner& runner = *runner_owner;
  report.concurrency = runner.concurrency();
  std::size_t total_cases = 0, done_cases = 0, total_runs = 0, runs_before = 0;
  for (const ReproductionTable& t : tables) {
    total_cases += t.cases.size();
    for (const ReproductionCase& c : t.cases) total_runs += c.study.runs * (t.contact_variant ? 2 : 1);
  }
  // Progress of one Monte Carlo, counted from the runs of the cases before it.
  auto run_case = [&](const MonteCarloStudy& study) {
    ProgressCallback cb;
    if (opt.progress)
      cb = [&opt, &runs_before, total_runs](std::size_t done, std::size_t, double) { opt.progress(runs_before + done, total_runs); };
    MonteCarloResult r = run_monte_carlo(study, runner, cb);
    runs_before += study.runs;
    return r;
  };
  // With cases_at_once > 1 a table's studies (each case, then its contact variant) start ahead, up
  // to cases_at_once running, and are taken in order: files and tables as one after another.
  // (declared before `ahead`: a future of std::async waits for its study when destroyed, e.g.
  // after an exception, and the study must still be there)
  std::deque<MonteCarloStudy> contact_studies;  // a deque: push_back keeps the pointers valid
  std::deque<const MonteCarloStudy*> to_start;
  std::deque<std::future<MonteCarloResult>> ahead;
  auto start_ahead = [&] {
    while (!to_start.empty() && ahead.size() < opt.cases_at_once) {
      const MonteCarloStudy* st = to_start.front();
      to_start.pop_front();
      ahead.push_back(std::async(std::launch::async, [&runner, st] { return run_monte_carlo(*st, runner); }));
    }
  };
  auto next_result = [&](const MonteCarloStudy& study) {
    if (opt.cases_at_once <= 1) return run_case(study);
    start_ahead();
    std::future<MonteCarloResult> f = std::move(ahead.front());
    ahead.pop_front();
    MonteCarloResult r = f.get();
    runs_before += study.runs;
    if (opt.progress) opt.progress(runs_before, total_runs);
    start_ahead();
    return r;
  };
  const auto t_start = clock::now();

  for (const ReproductionTable& table : tables) {
    TableResult tr;
    tr.table = table;
    const auto t_table = clock::now();
    const fs::path run_dir = out / "runs" / table_dir_name(table.id);
    fs::create_directories(run_dir, ec);
    if (ec) throw OutputError("cannot create " + run_dir.string() + " (" + ec.message() + ")");
    if (opt.cases_at_once > 1) {
      contact_studies.clear();  // the previous table's studies are all taken
      for (const ReproductionCase& c : table.cases) {
        to_start.push_back(&c.study);
        if (!table.contact_variant) continue;
        MonteCarloStudy cs = c.study;
        cs.setup.abu.ball_contact = *table.contact_variant;
        contact_studies.push_back(std::move(cs));
        to_start.push_back(&contact_studies.back());
      }
    }
    for (std::size_t k = 0; k < table.cases.size(); ++k) {
      const ReproductionCase& c = table.cases[k];
      MonteCarloResult result = next_result(c.study);
      const fs::path csv_path = run_dir / (c.id + ".csv");
      {
        std::ostringstream f;
        write_runs_csv(f, result.samples);
        write_text_file(csv_path, f.str());
      }
      CaseSummary s = summarize_case(table, c, result);
      tables_csv += tables_csv_line(s) + "\n";
      write_text_file(report.tables_csv_path, tables_csv);
      ++done_cases;
      const double elapsed = std::chrono::duration<double>(clock::now() - t_start).count();
      // (built piece by piece: GCC 12 warns -Wrestrict on one long "..." + std::string chain here)
      std::string line = "[";
      line += std::to_string(done_cases) + "/" + std::to_string(total_cases) + "] " + table.id + " " + c.label;
      line += ": " + std::to_string(s.runs) + " runs in " + num(s.wall_time_s, 1) + " s (mean I_r,x " + num(s.mean_x, 2);
      line += " vs " + opt_num(c.reference.mean_1e7, 2) + ", %MI " + num(s.pct_mi_x, 2) + " vs ";
      line += opt_num(c.reference.pct_mi, 2) + (s.failed ? ", " + std::to_string(s.failed) + " failed" : "");
      line += "); total " + num(elapsed, 0) + " s";
      // ETA from the rate of runs so far (cases differ in size: 256 or 1024 runs)
      if (runs_before > 0 && runs_before < total_runs)
        line += ", ETA " + num(elapsed / static_cast<double>(runs_before) * static_cast<double>(total_runs - runs_before), 0) + " s";
      log(line);
      if (table.contact_variant) {
        MonteCarloStudy cs = c.study;
        cs.setup.abu.ball_contact = *table.contact_variant;
        MonteCarloResult cr = next_result(cs);
        {
          std::ostringstream f;
          write_runs_csv(f, cr.samples);
          write_text_file(run_dir / (c.id + "_contact_" + to_string(*table.contact_variant) + ".csv"), f.str());
        }
        ContactRow row;
        row.summary = summarize_case(table, c, cr);
        row.overlapping_without = count_overlapping_final_states(c.study.setup.abu, result);
        row.overlapping_with = count_overlapping_final_states(cs.setup.abu, cr);
        if (report.tables_contact_csv_path.empty()) {
          report.tables_contact_csv_path = (out / "tables_contact.csv").string();
          tables_contact_csv = tables_contact_csv_header() + "\n";
        }
        tables_contact_csv += tables_contact_csv_line(row, *table.contact_variant) + "\n";
        write_text_file(report.tables_contact_csv_path, tables_contact_csv);
        std::string cl = "  with ball_contact " + to_string(*table.contact_variant) + ": " + num(row.summary.wall_time_s, 1);
        cl += " s (mean I_r,x " + num(row.summary.mean_x, 2) + ", %MI " + num(row.summary.pct_mi_x, 2) + ", overlapping final states ";
        cl += std::to_string(row.overlapping_with) + " vs " + std::to_string(row.overlapping_without) + " without contact)";
        log(cl);
        tr.contact_rows.push_back(std::move(row));
      }
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
