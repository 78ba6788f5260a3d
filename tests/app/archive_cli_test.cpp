// `abuopt archive list|show|best|history|export` on the archive of a short `abuopt optimize` run:
// the best feasible design is the lowest feasible objective of the history, filters select, the
// export's CSV has unique column names, no lock file or empty gnuplot log is left in the folder.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "abuopt_cli.hpp"

namespace {

namespace fs = std::filesystem;
using abuopt::test::run_abuopt;

std::vector<std::vector<std::string>> read_csv(const fs::path& p) {  // no quoted commas in these files
  std::vector<std::vector<std::string>> rows;
  std::ifstream in(p);
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> row;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) row.push_back(cell);
    rows.push_back(row);
  }
  return rows;
}

TEST(ArchiveCli, ListBestHistoryShowExport) {
  const fs::path out = fs::path(ABUOPT_BINARY_DIR) / "archive_cli_test";
  fs::remove_all(out);
  const std::string cfg = std::string(ABUOPT_SOURCE_DIR) + "/configs/optimize/quick.yaml";
  const auto opt = run_abuopt("optimize " + cfg + " --max-evaluations 5 --threads 2 --out " + (out / "opt").string());
  ASSERT_EQ(opt.status, 0) << opt.output;
  EXPECT_FALSE(fs::exists(out / "opt" / ".abuopt.lock"));
  for (const auto& e : fs::directory_iterator(out / "opt")) {
    if (e.path().extension() == ".log") {
      EXPECT_GT(fs::file_size(e.path()), 0u) << e.path();
    }
  }
  const std::string arc = (out / "opt" / "archive.sqlite").string();

  const auto list = run_abuopt("archive list " + arc);
  ASSERT_EQ(list.status, 0) << list.output;
  EXPECT_NE(list.output.find("5 evaluations: 5 ok"), std::string::npos) << list.output;
  EXPECT_NE(list.output.find("optimize " + cfg), std::string::npos) << list.output;

  // history --csv: the best feasible objective so far; its last value is `best`'s objective.
  const auto hist = run_abuopt("archive history " + arc + " --csv " + (out / "history.csv").string());
  ASSERT_EQ(hist.status, 0) << hist.output;
  const auto rows = read_csv(out / "history.csv");
  ASSERT_EQ(rows.size(), 6u);
  ASSERT_EQ(rows[0][4], "feasible");
  double lowest = std::numeric_limits<double>::infinity();
  std::string lowest_id;
  for (std::size_t i = 1; i < rows.size(); ++i)
    if (rows[i][4] == "1" && std::stod(rows[i][5]) < lowest) {
      lowest = std::stod(rows[i][5]);
      lowest_id = rows[i][0];
    }
  ASSERT_TRUE(std::isfinite(lowest)) << hist.output;
  EXPECT_EQ(std::stod(rows.back()[7]), lowest);
  const auto best = run_abuopt("archive best " + arc + " --json", "", false);
  ASSERT_EQ(best.status, 0) << best.output;
  const nlohmann::json b = nlohmann::json::parse(best.output);
  EXPECT_EQ(b["objective"].get<double>(), lowest);
  EXPECT_EQ(std::to_string(b["id"].get<long>()), lowest_id);
  EXPECT_TRUE(b["feasible"].get<bool>());

  // A filter no evaluation passes; a misspelt name.
  const auto none = run_abuopt("archive best " + arc + " --where 'objective<0'");
  EXPECT_EQ(none.status, 3) << none.output;
  const auto bad = run_abuopt("archive best " + arc + " --where 'pct_mx<=3'");
  EXPECT_EQ(bad.status, 2) << bad.output;
  EXPECT_NE(bad.output.find("did you mean 'pct_mi'?"), std::string::npos) << bad.output;
  const auto show = run_abuopt("archive show " + arc + " " + lowest_id + " --json", "", false);
  ASSERT_EQ(show.status, 0) << show.output;
  EXPECT_EQ(nlohmann::json::parse(show.output)["objective"].get<double>(), lowest);

  // export: every column name once (the metric `runs` beside the key column `runs`)
  const auto exp = run_abuopt("archive export " + arc + " " + (out / "export").string());
  ASSERT_EQ(exp.status, 0) << exp.output;
  for (const auto& e : fs::directory_iterator(out / "export")) {
    if (e.path().extension() != ".csv") continue;
    const auto header = read_csv(e.path()).front();
    const std::set<std::string> unique(header.begin(), header.end());
    EXPECT_EQ(unique.size(), header.size()) << e.path();
    EXPECT_TRUE(unique.count("runs") && unique.count("metric_runs")) << e.path();
  }
}

}  // namespace
