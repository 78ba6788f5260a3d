// The SQLite evaluation archive: exact (bitwise) lookups, exact values, a caching problem that
// never evaluates a point twice, and a study killed with SIGKILL that resumes without
// re-evaluating anything it had stored.
#include "abuopt/optimizer/evaluation_archive.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
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

TEST(EvaluationArchive, UnopenableFileIsAConfigError) {
  EXPECT_THROW(EvaluationArchive("/nonexistent-dir/x/archive.sqlite", "p"), abuopt::ConfigError);
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

}  // namespace
