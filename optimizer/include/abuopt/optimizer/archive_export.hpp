#pragma once
// Export of an evaluation archive (evaluation_archive.hpp) to plain files, so that any tool
// (Python, pandas, a spreadsheet) reads every stored evaluation without SQLite: the idea of
// OpenMDAO's CaseReader, as files. docs/archive.md is the schema; kExportSchemaVersion its version
// (raised whenever a field changes meaning or disappears; adding a field does not raise it).
//
//   DIR/archive.json                    every problem, its metadata rows and its evaluations
//   DIR/evaluations-<problem_id>.csv    one line per evaluation of that problem
//
// Numbers are written shortest round-trip (text.hpp's format_number; nlohmann's JSON numbers the
// same), so reading them back (strtod, Python float) gives the stored doubles bit for bit.
// Non-finite values: "inf", "-inf", "nan" (JSON strings; CSV fields).
#include <string>
#include <vector>

namespace abuopt::opt {

inline constexpr int kExportSchemaVersion = 1;

struct ArchiveExportSummary {
  std::vector<std::string> files;  // written, archive.json first
  long problems = 0;
  long evaluations = 0;
};

// Reads the archive at `archive_path` (ConfigError naming it when it does not exist, is damaged or
// has another schema version) and writes the files into `dir` (created if needed; OutputError when a
// file cannot be written, nothing half-written is left).
ArchiveExportSummary export_archive(const std::string& archive_path, const std::string& dir);

}  // namespace abuopt::opt
