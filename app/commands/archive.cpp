// abuopt archive export ARCHIVE DIR: every stored evaluation of an evaluation archive as CSV and
// JSON (optimizer/archive_export.hpp; the schema is docs/archive.md).
#include <iostream>
#include <memory>
#include <string>

#include "abuopt/optimizer/archive_export.hpp"
#include "commands/commands.hpp"

namespace abuopt::app {

namespace {

struct ExportArgs {
  std::string archive;
  std::string dir;
};

int run_export(const ExportArgs& a) {
  const opt::ArchiveExportSummary s = opt::export_archive(a.archive, a.dir);
  std::cout << "archive " << a.archive << ": " << s.problems << " problem" << (s.problems == 1 ? "" : "s") << ", "
            << s.evaluations << " evaluation" << (s.evaluations == 1 ? "" : "s") << " (export schema version "
            << opt::kExportSchemaVersion << ", docs/archive.md)\n";
  for (const auto& f : s.files) std::cout << "wrote " << f << "\n";
  return 0;
}

}  // namespace

void register_archive(CLI::App& app) {
  CLI::App* sub = app.add_subcommand("archive", "Work with an evaluation archive (OUT/archive.sqlite of optimize and sweep).");
  sub->require_subcommand(1);
  auto args = std::make_shared<ExportArgs>();
  CLI::App* exp = sub->add_subcommand(
      "export",
      "Write every stored evaluation of ARCHIVE into DIR: archive.json (problems, provenance metadata,\n"
      "evaluations) and one evaluations-<problem id>.csv per problem. Numbers are shortest round-trip:\n"
      "they read back bit for bit. The schema and its version: docs/archive.md.\n"
      "Exit status: 0 ok, 2 no such archive / damaged / other schema version, 4 a file could not be written.");
  exp->add_option("archive", args->archive, "the archive file (e.g. results/cobyla/archive.sqlite)")->required();
  exp->add_option("dir", args->dir, "output directory (created if needed)")->required();
  exp->callback([args] { set_exit_code(run_export(*args)); });
}

}  // namespace abuopt::app
