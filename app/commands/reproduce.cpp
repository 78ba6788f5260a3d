// abuopt reproduce: runs the 2003 report's studies (configs/report/*.yaml) and prints every table
// side by side with the published values, plus a verdict per published conclusion. The work is in
// studies/reproduction.hpp; this file parses options, finds the study files and prints.
#include <unistd.h>

#include <chrono>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "abuopt/common/stop.hpp"
#include "abuopt/common/config_error.hpp"
#include "abuopt/common/output_file.hpp"
#include "abuopt/common/progress.hpp"
#include "abuopt/studies/reproduction.hpp"
#include "abuopt/parallel/parallel.hpp"
#include "abuopt/studies/terms.hpp"
#include "commands/commands.hpp"

namespace abuopt::app {

namespace {

namespace fs = std::filesystem;

struct ReproduceArgs {
  std::optional<long> runs, threads;
  long long max_total_runs = 10000000;  // the runs of every case together: more is asked for explicitly
  std::vector<std::string> only;
  std::string out, configs;
  bool no_plots = false, progress = false;
};

// The study files: --configs, else configs/report below the working directory, else beside the
// source tree of this binary (<build>/app/abuopt -> <source>/configs/report).
std::string find_configs(const std::string& given) {
  if (!given.empty()) return given;
  std::error_code ec;
  if (fs::is_directory("configs/report", ec)) return "configs/report";
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    for (fs::path dir = exe.parent_path(); !dir.empty() && dir != dir.root_path(); dir = dir.parent_path()) {
      if (fs::is_directory(dir / "configs" / "report", ec)) return (dir / "configs" / "report").string();
      if (fs::is_directory(dir / "share" / "abuopt" / "configs" / "report", ec))
        return (dir / "share" / "abuopt" / "configs" / "report").string();
    }
  }
  throw ConfigError("--configs", "<not given>",
                    "configs/report was not found below the working directory nor above the binary; pass "
                    "--configs DIR");
}

std::string default_out_dir() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  localtime_r(&now, &tm);
  char buf[64];
  std::strftime(buf, sizeof buf, "results/reproduce-%Y%m%d-%H%M%S", &tm);
  return buf;
}

std::string command_line(const ReproduceArgs& a, const std::string& out) {
  std::string c = "abuopt reproduce";
  if (a.runs) c += " --runs " + std::to_string(*a.runs);
  if (!a.only.empty()) {
    c += " --only ";
    for (std::size_t i = 0; i < a.only.size(); ++i) c += (i ? "," : "") + a.only[i];
  }
  if (a.threads) c += " --threads " + std::to_string(*a.threads);
  if (!a.configs.empty()) c += " --configs " + a.configs;
  if (a.no_plots) c += " --no-plots";
  return c + " --out " + out;
}

int run_reproduce(const ReproduceArgs& a) {
  if (a.threads && *a.threads < 0)
    throw ConfigError("--threads", std::to_string(*a.threads), "must be >= 0 (0 = all cores)");
  if (a.runs && *a.runs < 1) throw ConfigError("--runs", std::to_string(*a.runs), "must be >= 1");

  const std::string dir = find_configs(a.configs);
  std::vector<ReproductionTable> tables = select_tables(read_reproduction_tables(dir), a.only, "--only");

  ReproductionOptions opt;
  opt.out_dir = a.out.empty() ? default_out_dir() : a.out;
  opt.threads = a.threads ? static_cast<std::size_t>(*a.threads) : 0;
  // under mpirun every case's Monte Carlo is spread over the ranks, a table's cases at once when the
  // ranks take concurrent studies (their runs share one pool)
  if (parallel::session() && parallel::session()->size() > 1) {
    opt.runner = parallel::make_runner(opt.threads);
    if (parallel::session()->concurrent_studies()) opt.cases_at_once = parallel::kEvaluationsAtOnce;
  }
  opt.plots = !a.no_plots;
  opt.command_line = command_line(a, opt.out_dir);
  if (a.runs) opt.runs_note = override_runs(tables, static_cast<std::size_t>(*a.runs), "--runs");
  std::size_t cases = 0, runs = 0, all_runs = 0;  // all_runs: with the contact variants
  for (const ReproductionTable& t : tables)
    for (const ReproductionCase& c : t.cases) {
      ++cases;
      runs += c.study.runs;
      all_runs += c.study.runs * (t.contact_variant ? 2 : 1);
    }
  if (a.max_total_runs < 1) throw ConfigError("--max-total-runs", std::to_string(a.max_total_runs), "must be >= 1");
  if (all_runs > static_cast<std::size_t>(a.max_total_runs))
    throw ConfigError(a.runs ? "--runs" : "--only", a.runs ? std::to_string(*a.runs) : std::to_string(tables.size()) + " tables",
                      "gives " + std::to_string(all_runs) + " runs over " + std::to_string(cases) +
                          " cases: at most " + std::to_string(a.max_total_runs) +
                          " in one reproduce (hours of work; a case keeps its runs in memory, about 0.5 kB each); "
                          "pass --max-total-runs N to allow more");
  ProgressReporter bar("reproduce", "runs", all_runs, a.progress ? ProgressMode::Always : ProgressMode::Auto);
  opt.log = [&bar](const std::string& line) { bar.message(line); };
  opt.progress = [&bar](std::size_t done, std::size_t) { bar.update(done); };
  std::cout << "Reproducing the 2003 report: " << tables.size() << " table" << (tables.size() == 1 ? "" : "s") << ", "
            << cases << " cases, " << runs << " runs (study files: " << dir << ")\n";
  if (!opt.runs_note.empty()) std::cout << opt.runs_note << "\n";
  else std::cout << "run counts as in the report (1024 or 256 per case); --runs N for a quicker look\n";
  std::cout << "output: " << opt.out_dir << "\n" << std::flush;

  const OutputDirLock lock(opt.out_dir);  // one run per output directory
  const StopScope stop_scope;  // SIGINT / SIGTERM stop the current case's runs (abuopt/common/stop.hpp)
  ReproductionReport r;
  try {
    r = run_reproduction(tables, opt);
  } catch (const Interrupted& e) {
    bar.finish();
    throw Interrupted(std::string(e.what()) + "; kept in " + opt.out_dir +
                      ": the per-case run CSVs and tables.csv of the cases that ended; a rerun computes every case "
                      "again (the same seeds, the same result)");
  }
  bar.finish();

  std::cout << "\n";
  for (const TableResult& t : r.tables) std::cout << format_table_text(t) << "\n";
  const std::vector<Verdict> verdicts = r.verdicts();
  std::cout << "Verdicts on the report's conclusions (CONFIRMED: direction holds and intervals separate; WEAK: "
               "direction holds on the point estimates only):\n";
  if (verdicts.empty()) std::cout << "  (none: the tables that carry them were not run)\n";
  for (const Verdict& v : verdicts) std::cout << "  " << v.one_line() << "\n";
  std::cout << terms_pointer() << "\n";
  if (!r.plots.empty()) {
    std::cout << "Plots (PNG; a PDF and the gnuplot script beside each):\n";
    for (const PlotNote& p : r.plots) std::cout << "  " << p.name << ": " << (p.made ? p.png : p.message) << "\n";
  }
  std::cout << "Wall time " << static_cast<long>(r.wall_time_s * 10) / 10.0 << " s on " << r.concurrency << " thread"
            << (r.concurrency == 1 ? "" : "s") << ". Wrote " << r.markdown_path << ", " << r.tables_csv_path << " and "
            << opt.out_dir << "/runs/\n";

  bool all_failed_somewhere = false;
  for (const TableResult& t : r.tables)
    for (const CaseSummary& s : t.rows) all_failed_somewhere = all_failed_somewhere || s.ok == 0;
  if (all_failed_somewhere) {
    std::cerr << "abuopt: every run of at least one case failed (see the failed column of its table)\n";
    return 3;
  }
  return 0;
}

}  // namespace

void register_reproduce(CLI::App& app) {
  auto args = std::make_shared<ReproduceArgs>();
  CLI::App* sub = app.add_subcommand(
      "reproduce",
      "Run the 2003 report's studies (tables 4.1-4.4, the final profile, the friction sensitivity) from\n"
      "configs/report/*.yaml and print each table side by side with the published values (report's I_r,x:\n"
      "mean, max, %LC, %MI; our 95 % Wilson interval of %MI; the magnitude |I_r| as extra columns), with a\n"
      "verdict per published conclusion. Writes per-case run CSVs (as each case ends), tables.csv,\n"
      "report.md and plots into --out. Exit status: 0 ok, 2 bad input, 3 every run of some case failed,\n"
      "4 an output file could not be written.");
  sub->footer("\n" + terms_pointer());
  sub->add_option("--runs", args->runs,
                  "runs per case for every case: an n x n grid with n = round(sqrt(N)) (default: the report's counts)");
  sub->add_option("--only", args->only, "comma-separated table ids: 4.1, 4.2, 4.3, 4.4, final, mu (default: all)")
      ->delimiter(',');
  sub->add_option("--threads", args->threads, "worker threads (0 = all cores; results do not depend on it)");
  sub->add_option("--max-total-runs", args->max_total_runs,
                  "the most runs of all cases together one reproduce accepts (default 10^7)");
  sub->add_option("--out", args->out, "output directory (default results/reproduce-<timestamp>)");
  sub->add_option("--configs", args->configs, "directory of the study files (default: configs/report)");
  sub->add_flag("--no-plots", args->no_plots, "skip the plots");
  sub->add_flag("--progress", args->progress,
                "show runs done, rate and ETA on stderr also when it is not a terminal (on a terminal: always)");
  sub->callback([args] { set_exit_code(run_reproduce(*args)); });
}

}  // namespace abuopt::app
