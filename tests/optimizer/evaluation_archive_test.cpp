// The SQLite evaluation archive: exact (bitwise) lookups, exact values, a caching problem that
// never evaluates a point twice, a study killed with SIGKILL that resumes without re-evaluating
// anything it had stored, and damage: a flipped byte in a stored value is detected by the row's
// checksum and recomputed, garbage in the file is an error naming it, a schema version is checked.
#include "abuopt/optimizer/evaluation_archive.hpp"
#include "abuopt/common/output_file.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <sqlite3.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <thread>

#include "abuopt/common/config_error.hpp"
#include "abuopt/optimizer/minimize.hpp"

namespace {

using namespace abuopt::opt;
namespace fs = std::filesystem;

// A fresh archive path per test (in the build tree's temp folder).
std::string archive_path(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("abuopt_archive_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path file = dir / (name + ".sqlite");
  for (const char* suffix : {"", "-wal", "-shm"}) fs::remove(file.string() + suffix);
  return file.string();
}

// Rosenbrock with a counter of real evaluations and a record of the points evaluated.
struct CountingRosenbrock : FunctionProblem {
  long calls = 0;
  std::vector<std::vector<double>> evaluated;
  int sleep_ms = 0;
  CountingRosenbrock()
      : FunctionProblem("rosenbrock", {{"x1", -2, 2, 1}, {"x2", -2, 2, 1}}, nullptr, {"disc"}) {}
  Evaluation evaluate(const std::vector<double>& x) override {
    ++calls;
    evaluated.push_back(x);
    if (sleep_ms) std::this_thread::sleep_for(std::chrono::milliseconds(sleep_ms));
    Evaluation e;
    e.objective = 100 * std::pow(x[1] - x[0] * x[0], 2) + std::pow(1 - x[0], 2);
    e.inequality = {x[0] * x[0] + x[1] * x[1] - 2};
    e.metrics["distance"] = std::hypot(x[0] - 1, x[1] - 1);
    return e;
  }
  std::vector<double> initial_point() const override { return {-1.2, 1.0}; }
};

OptimizerOptions cobyla(long budget) {
  OptimizerOptions o;
  o.algorithm = "cobyla";
  o.max_evaluations = budget;
  return o;
}

TEST(EvaluationArchive, FindsOnlyBitwiseRepeatsAndReturnsValuesExactly) {
  EvaluationArchive a(archive_path("exact"), "problem-A");
  const std::vector<double> x{0.1, 1.0 / 3.0};
  Evaluation e;
  e.objective = 2.0 / 7.0;
  e.inequality = {-1e-300, INFINITY};
  e.equality = {std::nextafter(1.0, 2.0)};
  e.metrics = {{"mean", 0.1 + 0.2}, {"bad", NAN}, {"huge", -INFINITY}};
  e.message = "note";
  a.store(x, e, 0.25);
  EXPECT_EQ(a.count(), 1);

  const auto hit = a.find(x);
  ASSERT_TRUE(hit.has_value());
  EXPECT_TRUE(hit->from_archive);
  EXPECT_EQ(hit->objective, e.objective);  // bit for bit
  EXPECT_EQ(hit->inequality, e.inequality);
  EXPECT_EQ(hit->equality, e.equality);
  EXPECT_EQ(hit->metrics.at("mean"), 0.1 + 0.2);
  EXPECT_TRUE(std::isnan(hit->metrics.at("bad")));
  EXPECT_EQ(hit->metrics.at("huge"), -INFINITY);
  EXPECT_EQ(hit->message, "note");
  EXPECT_TRUE(hit->ok);

  std::vector<double> y = x;
  y[1] = std::nextafter(y[1], 1.0);  // one ulp away: not the same design
  EXPECT_FALSE(a.find(y).has_value());
  EXPECT_FALSE(a.find({0.1}).has_value());

  EvaluationArchive other(a.path(), "problem-B");  // same file, other problem: no match
  EXPECT_FALSE(other.find(x).has_value());
  EXPECT_EQ(other.count(), 0);

  a.store(x, Evaluation::failed("second store of the same x is ignored"), 1.0);
  EXPECT_EQ(a.count(), 1);
  const auto entries = a.entries();
  ASSERT_EQ(entries.size(), 1u);
  EXPECT_EQ(entries[0].x, x);
  EXPECT_EQ(entries[0].wall_time_s, 0.25);
  EXPECT_EQ(entries[0].timestamp.size(), 24u);  // 2024-01-01T00:00:00.000Z
  EXPECT_EQ(EvaluationArchive::key_of({1.0}), "3ff0000000000000");
}

TEST(EvaluationArchive, FailedEvaluationsAreStoredWithTheirStatus) {
  EvaluationArchive a(archive_path("failed"), "p");
  a.store({1.0}, Evaluation::failed("did not converge"), 0.1);
  const auto hit = a.find({1.0});
  ASSERT_TRUE(hit);
  EXPECT_FALSE(hit->ok);
  EXPECT_EQ(hit->message, "did not converge");
  EXPECT_TRUE(std::isinf(hit->objective));
}

TEST(EvaluationArchive, ProblemIdReusedForAnotherProblemIsAnError) {
  const std::string path = archive_path("signature");
  EvaluationArchive a(path, "study-1");
  CountingRosenbrock p;
  ArchivedProblem ap(p, a);
  FunctionProblem other("other", {{"y1", 0, 1, 1}, {"y2", 0, 1, 1}}, [](const std::vector<double>&) {
    return Evaluation{};
  });
  try {
    ArchivedProblem bad(other, a);
    FAIL() << "no error";
  } catch (const abuopt::ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "evaluation archive '" + path +
                                         "': problem id 'study-1' was recorded with variables [\"x1\",\"x2\"], this "
                                         "problem has [\"y1\",\"y2\"] (use another problem id for a different problem)");
  }
}

TEST(EvaluationArchive, UncreatableFileIsAnOutputError) {
  // an archive that cannot be created is a failed write (exit 4, docs/security.md), like any output file
  EXPECT_THROW(EvaluationArchive("/nonexistent-dir/x/archive.sqlite", "p"), abuopt::OutputError);
}

TEST(ArchivedProblem, ARepeatedStudyIsAnsweredEntirelyFromTheArchive) {
  const std::string path = archive_path("repeat");
  OptimizationResult first, second;
  long first_calls = 0;
  {
    EvaluationArchive archive(path, "rosenbrock-disc");
    CountingRosenbrock p;
    ArchivedProblem ap(p, archive);
    first = minimize(ap, cobyla(400));
    first_calls = p.calls;
    EXPECT_EQ(first.archive_hits, 0);
    EXPECT_EQ(first_calls, first.evaluations);  // no point evaluated twice within the run
    EXPECT_EQ(archive.count(), first.evaluations);
  }
  {
    EvaluationArchive archive(path, "rosenbrock-disc");
    CountingRosenbrock p;
    ArchivedProblem ap(p, archive);
    second = minimize(ap, cobyla(400));
    EXPECT_EQ(p.calls, 0);  // nothing evaluated again
    EXPECT_EQ(ap.hits(), second.evaluations);
    EXPECT_EQ(ap.misses(), 0);
  }
  EXPECT_EQ(second.archive_hits, second.evaluations);
  EXPECT_EQ(second.evaluations, first.evaluations);
  EXPECT_EQ(second.x, first.x);  // the same run, bit for bit
  EXPECT_EQ(second.objective, first.objective);
  EXPECT_EQ(second.reason, first.reason);
  EXPECT_EQ(second.metrics, first.metrics);
}

TEST(ArchivedProblem, ALargerBudgetContinuesFromTheArchive) {
  const std::string path = archive_path("extend");
  {
    EvaluationArchive archive(path, "p");
    CountingRosenbrock p;
    ArchivedProblem ap(p, archive);
    minimize(ap, cobyla(50));
  }
  EvaluationArchive archive(path, "p");
  CountingRosenbrock p;
  ArchivedProblem ap(p, archive);
  const auto r = minimize(ap, cobyla(120));
  EXPECT_EQ(r.archive_hits, 50);
  EXPECT_EQ(p.calls, 70);
}

// The honest resume test: a child process runs a slow study with an archive and is killed with
// SIGKILL mid-run; the rerun evaluates none of the points the child stored, and ends exactly
// where an uninterrupted run (without archive) ends.
TEST(ArchivedProblem, StudyKilledWithSigkillResumesWithoutReevaluatingStoredPoints) {
  const std::string path = archive_path("killed");
  const long budget = 200;
  { EvaluationArchive create(path, "killed-study"); }  // the file exists before the child starts

  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    // Child: a slow study (5 ms per evaluation, ~1 s in all); never returns to GoogleTest.
    EvaluationArchive archive(path, "killed-study");
    CountingRosenbrock p;
    p.sleep_ms = 5;
    ArchivedProblem ap(p, archive);
    OptimizerOptions o = cobyla(budget);
    o.handle_sigint = false;
    minimize(ap, o);
    ::_exit(0);
  }
  // Parent: wait until the child has stored 30 evaluations, then kill it without warning.
  EvaluationArchive watcher(path, "killed-study");
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (watcher.count() < 30 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the child finished before it was killed";
  EXPECT_EQ(WTERMSIG(status), SIGKILL);

  const auto stored = watcher.entries();
  ASSERT_GE(stored.size(), 30u);
  ASSERT_LT(stored.size(), static_cast<std::size_t>(budget));
  std::set<std::string> stored_keys;
  for (const auto& e : stored) stored_keys.insert(EvaluationArchive::key_of(e.x));

  // Rerun the same study.
  EvaluationArchive archive(path, "killed-study");
  CountingRosenbrock p;
  ArchivedProblem ap(p, archive);
  const auto resumed = minimize(ap, cobyla(budget));
  for (const auto& x : p.evaluated)
    EXPECT_EQ(stored_keys.count(EvaluationArchive::key_of(x)), 0u) << "re-evaluated a stored point";
  EXPECT_EQ(resumed.archive_hits, static_cast<long>(stored.size()));  // every stored point was asked again
  EXPECT_EQ(p.calls, resumed.evaluations - resumed.archive_hits);

  // The resumed study ends where an uninterrupted one ends.
  CountingRosenbrock fresh;
  const auto reference = minimize(fresh, cobyla(budget));
  EXPECT_EQ(resumed.x, reference.x);
  EXPECT_EQ(resumed.objective, reference.objective);
  EXPECT_EQ(resumed.evaluations, reference.evaluations);
  EXPECT_EQ(resumed.reason, reference.reason);
}

TEST(ArchivedProblem, ConcurrentEvaluationsAreSafe) {
  EvaluationArchive archive(archive_path("threads"), "p");
  CountingRosenbrock inner;
  std::mutex inner_mutex;
  FunctionProblem locked("rosenbrock", inner.variables(), [&](const std::vector<double>& x) {
    std::lock_guard<std::mutex> lock(inner_mutex);
    return inner.evaluate(x);
  }, {"disc"});
  ArchivedProblem ap(locked, archive);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int i = 0; i < 50; ++i) ap.evaluate({0.01 * i, 0.001 * (t % 2)});  // threads 0/2 and 1/3 overlap
    });
  for (auto& th : threads) th.join();
  EXPECT_EQ(archive.count(), 100);
  EXPECT_EQ(ap.hits() + ap.misses(), 200);
  EXPECT_GE(ap.hits(), 0);
}

// ---- damage: every stored evaluation carries a checksum, the file a schema version ----

// The file's bytes (after the archive is closed, so the WAL is folded into it).
std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}
void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// One flipped byte in a stored value: the archive must not answer with it (the value would be
// wrong, and SQLite's own integrity check does not see it). The row is recomputed, and said.
TEST(EvaluationArchive, AFlippedByteInAStoredValueIsDetectedAndTheRowRecomputed) {
  const std::string path = archive_path("flipped");
  CountingRosenbrock p;
  const std::vector<double> x = {0.25, -0.5};
  const Evaluation truth = p.evaluate(x);
  {
    EvaluationArchive a(path, "p");
    ArchivedProblem ap(p, a);
    ap.evaluate(x);
  }
  // the objective's exact bits as the archive writes them (16 hex digits)
  std::string bytes = file_bytes(path);
  const std::string key = EvaluationArchive::key_of({truth.objective});
  const std::size_t at = bytes.find(key);
  ASSERT_NE(at, std::string::npos);
  bytes[at + 1] = bytes[at + 1] == '0' ? '8' : '0';  // a large change of the stored value
  write_bytes(path, bytes);

  EvaluationArchive a(path, "p");
  std::vector<std::string> said;
  a.set_warning_handler([&](const std::string& w) { said.push_back(w); });
  EXPECT_FALSE(a.find(x).has_value());  // not the damaged value
  ASSERT_EQ(said.size(), 1u);
  EXPECT_NE(said[0].find(path), std::string::npos) << said[0];
  EXPECT_NE(said[0].find("checksum"), std::string::npos) << said[0];
  EXPECT_EQ(a.damaged_rows(), 1);
  // recomputed through the archived problem, stored again, then answered correctly
  const long calls = p.calls;
  ArchivedProblem ap(p, a);
  const Evaluation e = ap.evaluate(x);
  EXPECT_EQ(p.calls, calls + 1);
  EXPECT_EQ(e.objective, truth.objective);
  const auto again = a.find(x);
  ASSERT_TRUE(again.has_value());
  EXPECT_EQ(again->objective, truth.objective);
  for (const auto& en : a.entries()) EXPECT_EQ(en.evaluation.objective, truth.objective);
}

// Damage in any field that is read back (a metric here) is detected too.
TEST(EvaluationArchive, ADamagedMetricIsDetected) {
  const std::string path = archive_path("metric");
  CountingRosenbrock p;
  const std::vector<double> x = {0.75, 0.5};
  {
    EvaluationArchive a(path, "p");
    ArchivedProblem ap(p, a);
    ap.evaluate(x);
  }
  std::string bytes = file_bytes(path);
  const std::size_t at = bytes.find("\"distance\":");
  ASSERT_NE(at, std::string::npos);
  const std::size_t digit = bytes.find_first_of("123456789", at + 11);
  ASSERT_NE(digit, std::string::npos);
  bytes[digit] = bytes[digit] == '9' ? '1' : static_cast<char>(bytes[digit] + 1);
  write_bytes(path, bytes);
  EvaluationArchive a(path, "p");
  a.set_warning_handler([](const std::string&) {});
  EXPECT_FALSE(a.find(x).has_value());
  EXPECT_TRUE(a.entries().empty());  // the damaged row informs nobody
  EXPECT_EQ(a.damaged_rows(), 1);
}

// Garbage in the middle of the file: the archive is not trusted at all; the error names the file.
TEST(EvaluationArchive, GarbageInTheMiddleOfTheFileIsAnErrorNamingTheFile) {
  const std::string path = archive_path("garbage");
  {
    CountingRosenbrock p;
    EvaluationArchive a(path, "p");
    ArchivedProblem ap(p, a);
    for (int i = 0; i < 400; ++i) ap.evaluate({-1.5 + 0.007 * i, 0.3});
  }
  std::string bytes = file_bytes(path);
  ASSERT_GT(bytes.size(), 40000u);  // several pages
  std::uint64_t state = 12345;
  for (std::size_t i = bytes.size() / 2; i < bytes.size() / 2 + 3000; ++i) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    bytes[i] = static_cast<char>(state >> 56);
  }
  write_bytes(path, bytes);
  try {
    EvaluationArchive a(path, "p");
    CountingRosenbrock p;
    ArchivedProblem ap(p, a);
    for (int i = 0; i < 400; ++i) ap.evaluate({-1.5 + 0.007 * i, 0.3});
    a.entries();
    ADD_FAILURE() << "a damaged archive was used";
  } catch (const abuopt::ConfigError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(path), std::string::npos) << m;
    EXPECT_NE(m.find("damaged"), std::string::npos) << m;
  }
}

// The schema version: written on creation, checked on opening, with a clear message.
TEST(EvaluationArchive, SchemaVersionIsWrittenAndCheckedWithAClearMessage) {
  const std::string path = archive_path("version");
  { EvaluationArchive a(path, "p"); }
  { EvaluationArchive a(path, "p"); }  // its own version opens again
  EXPECT_EQ(EvaluationArchive::schema_version(), 2);
  // an archive of the first layout (no version, no checksums)
  const std::string old = archive_path("version_old");
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(old.c_str(), &db), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(db,
                           "CREATE TABLE evaluations (id INTEGER PRIMARY KEY AUTOINCREMENT, problem_id TEXT NOT NULL,"
                           " x_key TEXT NOT NULL, x TEXT NOT NULL, objective REAL, values_hex TEXT NOT NULL,"
                           " n_inequality INTEGER NOT NULL, inequality TEXT NOT NULL, equality TEXT NOT NULL,"
                           " metrics TEXT NOT NULL, ok INTEGER NOT NULL, message TEXT NOT NULL, wall_time_s REAL,"
                           " timestamp TEXT NOT NULL, UNIQUE(problem_id, x_key))",
                           nullptr, nullptr, nullptr),
              SQLITE_OK);
    sqlite3_close(db);
  }
  try {
    EvaluationArchive a(old, "p");
    ADD_FAILURE() << "an archive of another schema version was opened";
  } catch (const abuopt::ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "evaluation archive '" + old +
                                         "' has schema version 0; this abuopt reads version 2 (checksums and "
                                         "run counts per evaluation): move it away or delete it (its evaluations "
                                         "are recomputed)");
  }
}

// An archive killed (SIGKILL) while it is being created opens again: its schema (the tables and
// the version) is written in one transaction, so a kill leaves either no schema or all of it.
// Before, a kill between the first table and the version left "schema version 0" behind, and the
// resumed study refused its own archive (seen in CI: CompareCli.KilledComparisonResumesFromItsArchives).
// A child creates fresh archives in a loop and reports each one through a pipe; the parent times
// the child's second archive (c), then kills it after a random 0 - 2c (fixed seed), 100 times. The
// delay scales with the machine (a sanitizer build is several times slower), so the kills land
// inside creations on any machine; before the fix this found 3 - 8 such files per run (four runs).
TEST(EvaluationArchive, AnArchiveKilledWhileItIsCreatedOpensAgain) {
  const fs::path dir = fs::path(archive_path("creation")).parent_path() / "creation";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::uint32_t lcg = 12345;
  const int rounds = 100;
  for (int round = 0; round < rounds; ++round) {
    int fds[2];
    ASSERT_EQ(pipe(fds), 0);
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      close(fds[0]);
      try {  // never back into gtest in the forked copy
        for (int i = 0;; ++i) {
          char name[64];
          std::snprintf(name, sizeof name, "r%d_%d.sqlite", round, i);
          { EvaluationArchive a((dir / name).string(), "p"); }
          if (write(fds[1], "x", 1) != 1) _exit(1);
        }
      } catch (...) {
        _exit(2);
      }
    }
    close(fds[1]);
    char byte = 0;
    const bool first = read(fds[0], &byte, 1) == 1;  // the first archive is complete
    const auto t0 = std::chrono::steady_clock::now();
    const bool second = first && read(fds[0], &byte, 1) == 1;  // and the second: its time is one creation
    const double c_us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
    lcg = lcg * 1664525u + 1013904223u;
    const double frac = static_cast<double>(lcg >> 8) / static_cast<double>(1u << 24);  // [0, 1)
    if (second) std::this_thread::sleep_for(std::chrono::microseconds(static_cast<long>(2.0 * c_us * frac)));
    kill(pid, SIGKILL);  // on every path: the child never ends by itself
    int status = 0;
    waitpid(pid, &status, 0);
    close(fds[0]);
    ASSERT_TRUE(second) << "the child did not report two archives";
    ASSERT_TRUE(WIFSIGNALED(status));
  }
  int opened = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() != ".sqlite") continue;
    try {
      EvaluationArchive a(entry.path().string(), "p");
      ++opened;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "an archive killed while it was created does not open: " << e.what();
    }
  }
  EXPECT_GE(opened, 2 * rounds);  // every child completed two archives before it was killed
  fs::remove_all(dir);
}

// The Monte Carlo run count is part of the key: a value computed with 16 runs never answers a
// request for 32 (nothing stale is reused), and both are kept.
TEST(EvaluationArchive, RunCountIsPartOfTheKey) {
  const std::string path = archive_path("runs");
  EvaluationArchive a(path, "p");
  Evaluation e16, e32;
  e16.objective = 1.5;
  e32.objective = 1.25;
  const std::vector<double> x = {0.5, 0.5};
  a.store(x, e16, 0.0, 16);
  EXPECT_FALSE(a.find(x, 32).has_value());
  EXPECT_FALSE(a.find(x).has_value());  // 0: no run count
  a.store(x, e32, 0.0, 32);
  EXPECT_EQ(a.find(x, 16)->objective, 1.5);
  EXPECT_EQ(a.find(x, 32)->objective, 1.25);
  const auto entries = a.entries();
  ASSERT_EQ(entries.size(), 2u);
  EXPECT_EQ(entries[0].runs, 16);
  EXPECT_EQ(entries[1].runs, 32);
}

}  // namespace
