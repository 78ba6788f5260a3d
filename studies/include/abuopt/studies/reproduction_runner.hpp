#pragma once
// Running the reproduction: every case of every table, into one output folder.
#include <vector>

#include "abuopt/studies/reproduction_report.hpp"
#include "abuopt/studies/reproduction_table.hpp"

namespace abuopt {

// Runs every case of every table into opt.out_dir:
//   runs/<table id>/<case id>.csv  the engine's per-run CSV, written as soon as the case ends
//   tables.csv                     one line per case (ours and the report's), appended per case
//   report.md                      tables, verdicts, settings, wall time (rewritten per table)
//   plots/<name>.csv, .gp, .png    the plots the tables ask for (gnuplot helper)
// Nothing already computed is lost if the study is interrupted; every file is written whole
// (write_file_atomic) and tables.csv is rewritten after each case. Throws OutputError when the
// output directory cannot be written.
ReproductionReport run_reproduction(const std::vector<ReproductionTable>& tables, const ReproductionOptions& opt);

}  // namespace abuopt
