// Evaluation concurrency (evaluation_scheduler.hpp, EvaluationDriver::evaluate_batch): the points
// of a design of experiments and finite-difference neighbours are evaluated at once, and the
// result, the history (order, values, counts) and the archive's rows are the same, bit for bit,
// with 1, 2 and 4 workers; the budget cuts a batch at the same point; an exception in the middle
// of a batch ends the run at that point; and the evaluations did overlap (else the test measures
// nothing).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "abuopt/optimizer/benchmarks/benchmark_factory.hpp"
#include "abuopt/optimizer/evaluation_archive.hpp"
#include "abuopt/optimizer/evaluation_scheduler.hpp"
#include "abuopt/optimizer/minimize.hpp"

namespace {

using namespace abuopt;

// A benchmark declared thread-safe (the analytic benchmarks are pure functions), which counts how
// many evaluations overlap in time and may throw at one chosen evaluation.
class Overlapping : public opt::Problem {
 public:
  explicit Overlapping(std::string name) : inner_(opt::benchmarks::make_benchmark(name)) {}
  std::string name() const override { return inner_->name(); }
  std::vector<opt::Variable> variables() const override { return inner_->variables(); }
  std::vector<std::string> inequality_names() const override { return inner_->inequality_names(); }
  std::vector<std::string> equality_names() const override { return inner_->equality_names(); }
  std::vector<double> initial_point() const override { return inner_->initial_point(); }
  bool thread_safe() const override { return true; }
  opt::Evaluation evaluate(const std::vector<double>& x) override {
    const int now = ++in_flight_;
    int seen = max_in_flight_.load();
    while (now > seen && !max_in_flight_.compare_exchange_weak(seen, now)) {
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));  // long enough to overlap
    --in_flight_;
    if (throw_at_ && x == *throw_at_) throw std::runtime_error("planted defect");
    return inner_->evaluate(x);
  }
  int max_in_flight() const { return max_in_flight_.load(); }
  std::optional<std::vector<double>> throw_at_;

 private:
  std::unique_ptr<opt::Problem> inner_;
  std::atomic<int> in_flight_{0};
  std::atomic<int> max_in_flight_{0};
};

void expect_same_runs(const opt::OptimizationResult& a, const opt::OptimizationResult& b, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(a.reason, b.reason);
  EXPECT_EQ(a.message, b.message);
  EXPECT_EQ(a.evaluations, b.evaluations);
  EXPECT_EQ(a.gradient_evaluations, b.gradient_evaluations);
  EXPECT_EQ(a.repeated_requests, b.repeated_requests);
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(a.x, b.x);  // bitwise: operator== on doubles
  EXPECT_EQ(a.objective, b.objective);
  ASSERT_EQ(a.history.size(), b.history.size());
  for (std::size_t i = 0; i < a.history.size(); ++i) {
    const auto &p = a.history[i], &q = b.history[i];
    EXPECT_EQ(p.index, q.index);
    EXPECT_EQ(p.x, q.x) << "evaluation " << i;
    EXPECT_EQ(p.objective, q.objective) << "evaluation " << i;
    EXPECT_EQ(p.inequality, q.inequality) << "evaluation " << i;
    EXPECT_EQ(p.equality, q.equality) << "evaluation " << i;
    EXPECT_EQ(p.for_gradient, q.for_gradient) << "evaluation " << i;
    EXPECT_EQ(p.from_archive, q.from_archive) << "evaluation " << i;
  }
}

opt::OptimizationResult run(const std::string& benchmark, opt::OptimizerOptions o, std::size_t workers,
                            int* overlap = nullptr) {
  Overlapping p(benchmark);
  o.evaluation_threads = workers;
  o.handle_sigint = false;
  opt::OptimizationResult r = opt::minimize(p, o);
  if (overlap) *overlap = p.max_in_flight();
  return r;
}

opt::OptimizerOptions sao_with_designs() {
  opt::OptimizerOptions o;
  o.algorithm = "SAO";
  o.max_evaluations = 60;
  o.sao.doe = opt::DoeKind::CentralComposite;  // a design in every region: fill_region batches
  return o;
}

TEST(EvaluationBatch, SaoDesignsAreTheSameWithOneTwoAndFourWorkers) {
  const opt::OptimizerOptions o = sao_with_designs();
  int overlap1 = 0, overlap4 = 0;
  const opt::OptimizationResult r1 = run("hs071", o, 1, &overlap1);
  const opt::OptimizationResult r2 = run("hs071", o, 2);
  const opt::OptimizationResult r4 = run("hs071", o, 4, &overlap4);
  ASSERT_GT(r1.evaluations, 20);
  expect_same_runs(r1, r2, "SAO 1 vs 2 workers");
  expect_same_runs(r1, r4, "SAO 1 vs 4 workers");
  EXPECT_EQ(overlap1, 1);  // one worker: one evaluation at a time
  EXPECT_GE(overlap4, 2);  // the design's points did run at once
}

TEST(EvaluationBatch, FiniteDifferenceNeighboursAreTheSameWithOneTwoAndFourWorkers) {
  for (const char* fd : {"forward", "central"}) {
    opt::OptimizerOptions o;
    o.algorithm = "SLSQP";
    o.max_evaluations = 150;
    o.finite_difference = opt::finite_difference_from_string(fd);
    int overlap = 0;
    const opt::OptimizationResult r1 = run("hs071", o, 1);
    const opt::OptimizationResult r2 = run("hs071", o, 2);
    const opt::OptimizationResult r4 = run("hs071", o, 4, &overlap);
    ASSERT_GT(r1.gradient_evaluations, 8) << fd;
    expect_same_runs(r1, r2, std::string("SLSQP ") + fd + " 1 vs 2");
    expect_same_runs(r1, r4, std::string("SLSQP ") + fd + " 1 vs 4");
    EXPECT_GE(overlap, 2) << fd;
  }
}

TEST(EvaluationBatch, TheBudgetCutsABatchAtTheSamePoint) {
  // budgets that end inside designs and inside gradients
  for (long budget : {7L, 13L, 22L}) {
    opt::OptimizerOptions o = sao_with_designs();
    o.max_evaluations = budget;
    const opt::OptimizationResult r1 = run("hs071", o, 1);
    const opt::OptimizationResult r4 = run("hs071", o, 4);
    EXPECT_EQ(r1.evaluations, budget);
    EXPECT_EQ(r1.reason, opt::TerminationReason::MaxEvaluations);
    expect_same_runs(r1, r4, "SAO budget " + std::to_string(budget));
    opt::OptimizerOptions g;
    g.algorithm = "SLSQP";
    g.finite_difference = opt::FiniteDifference::Central;
    g.max_evaluations = budget;
    expect_same_runs(run("hs071", g, 1), run("hs071", g, 4), "SLSQP budget " + std::to_string(budget));
  }
}

TEST(EvaluationBatch, AnExceptionInsideABatchEndsTheRunAtThatPoint) {
  opt::OptimizerOptions o = sao_with_designs();
  o.handle_sigint = false;
  // the 9th point of the one-worker run throws
  const opt::OptimizationResult clean = run("hs071", o, 1);
  ASSERT_GT(clean.history.size(), 9u);
  const std::vector<double> bad = clean.history[8].x;
  std::vector<opt::OptimizationResult> rs;
  for (std::size_t w : {1u, 4u}) {
    Overlapping p("hs071");
    p.throw_at_ = bad;
    o.evaluation_threads = w;
    rs.push_back(opt::minimize(p, o));
  }
  EXPECT_EQ(rs[0].reason, opt::TerminationReason::EvaluationError);
  EXPECT_EQ(rs[0].evaluations, 9);
  EXPECT_NE(rs[0].message.find("planted defect"), std::string::npos) << rs[0].message;
  expect_same_runs(rs[0], rs[1], "exception, 1 vs 4 workers");
}

TEST(EvaluationBatch, ArchiveRowsFollowInputOrder) {
  const opt::OptimizerOptions o = sao_with_designs();
  std::vector<std::vector<std::vector<double>>> rows;
  for (std::size_t w : {1u, 4u}) {
    const std::string path = ::testing::TempDir() + "batch_archive_" + std::to_string(w) + ".sqlite";
    std::remove(path.c_str());
    Overlapping p("hs071");
    opt::EvaluationArchive archive(path, "hs071_batch");
    opt::ArchivedProblem ap(p, archive);
    opt::OptimizerOptions ow = o;
    ow.evaluation_threads = w;
    ow.handle_sigint = false;
    const opt::OptimizationResult r = opt::minimize(ap, ow);
    EXPECT_EQ(ap.misses(), r.evaluations);
    std::vector<std::vector<double>> xs;
    for (const auto& e : archive.entries()) xs.push_back(e.x);
    // the archive's rows are the history's points, in the history's order
    ASSERT_EQ(xs.size(), r.history.size());
    for (std::size_t i = 0; i < xs.size(); ++i) EXPECT_EQ(xs[i], r.history[i].x) << i;
    rows.push_back(xs);
    // a rerun on the archive is answered from it entirely, with the same result
    Overlapping p2("hs071");
    opt::ArchivedProblem ap2(p2, archive);
    const opt::OptimizationResult again = opt::minimize(ap2, ow);
    EXPECT_EQ(again.archive_hits, again.evaluations);
    EXPECT_EQ(again.x, r.x);
    std::remove(path.c_str());
  }
  EXPECT_EQ(rows[0], rows[1]);
}

TEST(EvaluationBatch, ThreadSchedulerCallsEveryTaskOnceAndRethrows) {
  opt::ThreadScheduler s(3);
  EXPECT_EQ(s.concurrency(), 3u);
  std::vector<std::atomic<int>> hits(100);
  s.run(hits.size(), [&](std::size_t i) { ++hits[i]; });
  for (const auto& h : hits) EXPECT_EQ(h.load(), 1);
  EXPECT_THROW(s.run(10, [](std::size_t i) {
    if (i == 5) throw std::runtime_error("x");
  }),
               std::runtime_error);
  EXPECT_GE(opt::ThreadScheduler(0).concurrency(), 1u);
}

TEST(EvaluationBatch, ProblemsThatAreNotThreadSafeRunOneAtATime) {
  // a FunctionProblem is not thread-safe unless declared so
  std::atomic<int> in_flight{0}, most{0};
  std::atomic<bool> wait_for_company{false};
  opt::FunctionProblem f("sphere", {{"a", -1, 1}, {"b", -1, 1}}, [&](const std::vector<double>& x) {
    const int now = ++in_flight;
    most = std::max(most.load(), now);
    // Thread-safe case: stay until a second evaluation is in flight too (at most 10 s; once an
    // overlap was seen nobody waits), so the overlap is shown without depending on how the threads
    // are scheduled (a 1 ms sleep was not enough under ThreadSanitizer on a loaded machine).
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (wait_for_company.load() && most.load() < 2 && in_flight.load() < 2 &&
           std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    most = std::max(most.load(), in_flight.load());
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    --in_flight;
    opt::Evaluation e;
    e.objective = x[0] * x[0] + x[1] * x[1];
    return e;
  });
  opt::ThreadScheduler s(4);
  const auto out = f.evaluate_batch({{0, 0}, {0.5, 0}, {0, 0.5}, {1, 1}}, s);
  ASSERT_EQ(out.size(), 4u);
  EXPECT_EQ(out[3].evaluation.objective, 2.0);
  EXPECT_EQ(most.load(), 1);
  f.set_thread_safe(true);
  most = 0;
  wait_for_company = true;
  f.evaluate_batch({{0, 0}, {0.5, 0}, {0, 0.5}, {1, 1}}, s);
  EXPECT_GE(most.load(), 2);
}

}  // namespace
