// Reading an archive afterwards (archive_reader.hpp): problems and runs, the best feasible design,
// its history (best so far), filters on constraints, metrics and variables, problem id prefixes.
#include "abuopt/optimizer/archive_reader.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <sqlite3.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "abuopt/common/config_error.hpp"

namespace {

using namespace abuopt::opt;
namespace fs = std::filesystem;

std::string fresh_archive() {
  const fs::path dir = fs::temp_directory_path() / ("abuopt_archive_reader_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path file = dir / "a.sqlite";
  for (const char* suffix : {"", "-wal", "-shm"}) fs::remove(file.string() + suffix);
  return file.string();
}

// f = x1 + x2 subject to g = 1 - x1 <= 0 (x1 >= 1); metric m = 10 x2.
Evaluation linear(const std::vector<double>& x) {
  Evaluation e;
  e.objective = x[0] + x[1];
  e.inequality = {1 - x[0]};
  e.metrics["m"] = 10 * x[1];
  return e;
}

// Stores the points (in this order) under problem id `id`.
void store(const std::string& path, const std::string& id, const std::vector<std::vector<double>>& xs) {
  FunctionProblem p("linear", {{"x1", 0, 5, 1}, {"x2", 0, 5, 1}}, linear, {"g1"});
  EvaluationArchive a(path, id);
  a.record_metadata("optimize", "cfg.yaml", "fnv1a64:0");
  ArchivedProblem ap(p, a);
  for (const auto& x : xs) (void)ap.evaluate(x);
}

std::string bytes_of(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<std::string> listing(const fs::path& dir) {
  std::vector<std::string> v;
  for (const auto& e : fs::directory_iterator(dir)) v.push_back(e.path().filename().string());
  std::sort(v.begin(), v.end());
  return v;
}

TEST(ArchiveReader, ReadsWithoutWriting) {
  // A reader opens the file read-only: an archive in a read-only file and directory (0444 in 0555)
  // is read and left byte-identical, no file added beside it. Both journal modes: WAL (as written;
  // read as immutable when no -shm can be made) and rollback, where a reader setting
  // journal_mode=WAL (as the writer does) changes the header, caught even as root (whom the
  // permissions do not bind).
  for (const char* journal : {"DELETE", "WAL"}) {
    SCOPED_TRACE(journal);
    const std::string path = fresh_archive();
    const fs::path dir = fs::path(path).parent_path();
    store(path, "linear-aaaa", {{1, 3}, {2, 1.5}});
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(db, (std::string("PRAGMA journal_mode=") + journal).c_str(), nullptr, nullptr, nullptr),
              SQLITE_OK);
    sqlite3_close(db);
    const std::string before = bytes_of(path);
    const std::vector<std::string> files = listing(dir);
    fs::permissions(path, fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
    fs::permissions(dir, fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                             fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
    std::size_t problems = 0, evaluations = 0, runs = 0;
    std::string error;
    try {
      const ArchiveReader r(path);
      problems = r.problems().size();
      evaluations = r.problem("linear").evaluations.size();
      runs = r.problem("linear").runs.size();
    } catch (const std::exception& e) {
      error = e.what();
    }
    const std::vector<std::string> files_after = listing(dir);
    fs::permissions(dir, fs::perms::owner_all);
    fs::permissions(path, fs::perms::owner_read | fs::perms::owner_write);
    EXPECT_EQ(error, "");
    EXPECT_EQ(problems, 1u);
    EXPECT_EQ(evaluations, 2u);
    EXPECT_EQ(runs, 1u);
    EXPECT_TRUE(bytes_of(path) == before) << "the reader changed the archive";
    // Root may write the directory anyway: SQLite then makes the WAL's -wal and -shm files, which a
    // read-only connection cannot remove (empty; the next writer takes them). Nothing else is added.
    std::vector<std::string> added;
    for (const auto& f : files_after)
      if (std::find(files.begin(), files.end(), f) == files.end()) added.push_back(f);
    if (std::string(journal) == "WAL" && ::geteuid() == 0)
      std::erase_if(added, [](const std::string& f) { return f == "a.sqlite-wal" || f == "a.sqlite-shm"; });
    EXPECT_EQ(added, std::vector<std::string>{});
  }
}

TEST(ArchiveReader, MissingOrEmptyFileIsAnErrorAndNotCreated) {
  const std::string path = fresh_archive();
  try {
    ArchiveReader r(path);
    ADD_FAILURE() << "a missing file was read";
  } catch (const abuopt::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("no such file"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(path));
  { std::ofstream(path, std::ios::binary); }  // an empty file: not an archive, and left empty
  try {
    ArchiveReader r(path);
    ADD_FAILURE() << "an empty file was read as an archive";
  } catch (const abuopt::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("not an evaluation archive"), std::string::npos) << e.what();
  }
  EXPECT_EQ(fs::file_size(path), 0u);
}

TEST(ArchiveReader, BestFeasibleHistoryAndFilters) {
  const std::string path = fresh_archive();
  // objectives 3 (infeasible: x1 = 0.5), 4, 2.5 (infeasible), 3.5, 5
  store(path, "linear-aaaa", {{0.5, 2.5}, {1, 3}, {0.5, 2}, {2, 1.5}, {3, 2}});
  store(path, "linear-bbbb", {{1, 1}});
  const ArchiveReader r(path);
  ASSERT_EQ(r.problems().size(), 2u);
  const ArchiveProblem& p = r.problem("linear-a");  // a unique prefix
  EXPECT_EQ(p.record.problem_id, "linear-aaaa");
  ASSERT_EQ(p.evaluations.size(), 5u);
  ASSERT_EQ(p.runs.size(), 1u);
  EXPECT_EQ(p.runs[0].command, "optimize");

  const auto* best = r.best(p);
  ASSERT_NE(best, nullptr);
  EXPECT_EQ(best->evaluation.objective, 3.5);  // the infeasible 3 and 2.5 are not it
  EXPECT_EQ(best->x, (std::vector<double>{2, 1.5}));

  // Filters: metric m = 10 x2 >= 20 leaves {1, 3} (4) and {3, 2} (5); on a variable: x1 > 2.
  EXPECT_EQ(r.best(p, {parse_archive_filter("m>=20")})->evaluation.objective, 4.0);
  EXPECT_EQ(r.best(p, {parse_archive_filter("x1 > 2")})->evaluation.objective, 5.0);
  EXPECT_EQ(r.best(p, {parse_archive_filter("g_g1<=-1.5")})->evaluation.objective, 5.0);  // g = 1 - x1: only x1 = 3
  EXPECT_EQ(r.best(p, {parse_archive_filter("g1<-2")}), nullptr);

  const auto h = r.history(p);
  ASSERT_EQ(h.size(), 5u);
  EXPECT_TRUE(std::isnan(h[0].best_feasible));  // nothing feasible yet
  EXPECT_FALSE(h[0].feasible);
  EXPECT_DOUBLE_EQ(h[0].max_violation, 0.5);
  EXPECT_EQ(h[1].best_feasible, 4.0);
  EXPECT_EQ(h[2].best_feasible, 4.0);  // 2.5 is infeasible
  EXPECT_EQ(h[3].best_feasible, 3.5);
  EXPECT_EQ(h[4].best_feasible, 3.5);

  EXPECT_EQ(ArchiveReader::find(p, h[3].entry->id), h[3].entry);
  EXPECT_THROW(r.problem(""), abuopt::ConfigError);      // two problems: which one?
  EXPECT_THROW(r.problem("other"), abuopt::ConfigError);  // none
  EXPECT_THROW(r.best(p, {parse_archive_filter("pct_mi<=5")}), abuopt::ConfigError);  // no such name
  EXPECT_THROW(parse_archive_filter("m=5"), abuopt::ConfigError);
  EXPECT_THROW(parse_archive_filter("<=5"), abuopt::ConfigError);
  EXPECT_THROW(ArchiveReader("/nonexistent/archive.sqlite"), abuopt::ConfigError);
}

}  // namespace
