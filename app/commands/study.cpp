// abuopt study STUDY.yaml: a whole design study from one declarative file (docs/study.md): stages
// chained, every evaluation archived (a rerun resumes), and a report a designer reads. The work is
// in studies/study.hpp; this file parses options, owns the Ctrl-C hook and prints.
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/output_file.hpp"
#include "abuopt/common/progress.hpp"
#include "abuopt/common/stop.hpp"
#include "abuopt/studies/study.hpp"
#include "commands/commands.hpp"

namespace abuopt::app {

namespace {

struct StudyArgs {
  std::string file, out;
  std::optional<long> threads;
  bool progress = false;
  bool check = false;
};

int run_study_command(const StudyArgs& a) {
  const studies::StudyFile f = studies::read_study_file(a.file);
  if (a.threads && *a.threads < 0)
    throw ConfigError("--threads", std::to_string(*a.threads), "must be >= 0 (0 = all cores)");
  if (a.check) {  // the file read and validated as a run reads it; the plan, nothing simulated
    std::cout << studies::plan_text(f) << std::flush;
    return 0;
  }
  const std::string out = a.out.empty() ? "results/" + std::filesystem::path(a.file).stem().string() : a.out;
  const OutputDirLock lock(out);
  std::cout << "study " << a.file << " (" << f.title << "): " << f.ball_counts.size() << " choice(s), "
            << f.stages.size() << " stages, budget " << f.max_evaluations << " evaluations, " << f.base.runs
            << " runs per evaluation; output " << out << "\n"
            << std::flush;
  ProgressReporter bar("study", "evaluations", 0, a.progress ? ProgressMode::Always : ProgressMode::Auto);
  studies::StudyRunOptions o;
  o.out = out;
  if (a.threads) o.threads = static_cast<std::size_t>(*a.threads);
  o.log = [&](const std::string& line) { bar.message(line, stdout); };
  o.progress = [&](long done, long total) {
    bar.set_total(static_cast<std::size_t>(total));
    bar.update(static_cast<std::size_t>(done));
  };
  // SIGINT / SIGTERM (common/stop.hpp): the stages stop between evaluations, a running optimiser
  // at its next evaluation; a Monte Carlo cut short outside an optimiser ends the study here.
  o.stop_requested = [] { return stop_requested(); };
  studies::StudyResult r;
  {
    const StopScope stop_scope;
    try {
      r = studies::run_study(f, o);
    } catch (const Interrupted& e) {
      bar.finish();
      throw Interrupted(std::string(e.what()) + "; every finished evaluation is kept in " + out +
                        "/archive.sqlite: rerun the same command to resume");
    }
  }
  bar.finish();
  const auto files = studies::write_study_report(f, r, out);
  std::cout << "wrote " << out << "/report.html, report.md, summary.json and " << r.designs.size()
            << " designs in " << out << "/designs/ (" << r.wall_time_s << " s)\n";
  if (r.interrupted) {
    std::cerr << "abuopt: interrupted by " << stop_signal_name() << ": the partial report is written and every finished "
              << "evaluation is kept in " << out << "/archive.sqlite; rerun the same command to resume\n";
    return stop_signal() != 0 ? stop_exit_status() : 130;
  }
  if (!r.recommended) {
    std::cerr << "abuopt: the study recommends no design:";
    for (const auto& n : r.notes) std::cerr << " " << n << ".";
    std::cerr << "\n";
    return 3;
  }
  std::cout << "recommended: " << r.designs[*r.recommended].label << " (" << out << "/designs/"
            << r.designs[*r.recommended].label << ".yaml)\n";
  return 0;
}

}  // namespace

void register_study(CLI::App& app) {
  auto args = std::make_shared<StudyArgs>();
  CLI::App* sub = app.add_subcommand(
      "study",
      "Run a whole design study from one file (ABU, envelope, baseline, profile family, choices,\n"
      "objective, constraints, stages, budget; docs/study.md, configs/studies/quick.yaml) and write\n"
      "OUT/report.html, report.md, summary.json and designs/*.yaml (ready for abuopt montecarlo).\n"
      "Every evaluation is archived in OUT/archive.sqlite: rerunning the same command resumes.\n"
      "Exit status: 0 ok, 2 bad input, 3 no design recommended (the reason is printed), 4 an output\n"
      "file could not be written, 130 interrupted (Ctrl-C), 143 terminated (SIGTERM).");
  sub->add_option("study", args->file, "study file (YAML)")->required();
  sub->add_option("--out", args->out, "output directory (default results/<study file stem>)");
  sub->add_option("--threads", args->threads, "Monte Carlo worker threads (0 = all cores; results do not depend on it)");
  sub->add_flag("--check", args->check,
                "read and validate the file as a run would (exit 2 on bad input), print the plan (f_n, free\n"
                "variables with bounds in Hz, choices, stages, budget, estimated simulations) and exit 0\n"
                "without simulating anything");
  sub->add_flag("--progress", args->progress, "show evaluations done, rate and ETA also when stderr is not a terminal");
  sub->callback([args] { set_exit_code(run_study_command(*args)); });
}

}  // namespace abuopt::app
