// SAO (sequential approximate optimisation): reaches best_known on the analytic benchmarks and
// their noisy variants, needs fewer evaluations than COBYLA on the smooth constrained ones,
// handles an infeasible start, returns the best feasible point when the budget stops it, and
// rejects bad options with messages naming key, value and rule.
// Each convergence case prints "[measure]" with its evaluations to 1 % of best_known (the
// numbers of docs/sao.md).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <iostream>
#include <string>

#include "abuopt/common/config_error.hpp"
#include "abuopt/optimizer/evaluation_archive.hpp"
#include "abuopt/optimizer/minimize.hpp"
#include "abuopt/optimizer/sao.hpp"
#include "abuopt/optimizer/benchmarks/benchmark_factory.hpp"

namespace {

using namespace abuopt;

double true_objective(const opt::EvaluationRecord& r) {
  auto it = r.metrics.find("noise_free_objective");
  return it == r.metrics.end() ? r.objective : it->second;
}

// Evaluations until the first feasible point within 1 % of best_known (-1: never).
long evaluations_to_one_percent(const opt::OptimizationResult& r, double f_star) {
  const double scale = std::max(1.0, std::fabs(f_star));
  for (const auto& h : r.history)
    if (h.feasible && true_objective(h) - f_star <= 0.01 * scale) return h.index + 1;
  return -1;
}

struct Case {
  std::string problem;
  long budget;
  double f_tol;               // |f - f*| <= f_tol * max(1, |f*|), f noise-free
  double constraint_tol = 1e-6;
  bool noisy_settings = false;  // doe_points_factor = 2: least squares over about twice the terms
};

std::string case_name(const testing::TestParamInfo<Case>& info) { return info.param.problem; }

class SaoConvergence : public testing::TestWithParam<Case> {};

TEST_P(SaoConvergence, ReachesBestKnown) {
  const Case& c = GetParam();
  auto problem = opt::benchmarks::make_benchmark(c.problem);
  const opt::BestKnown best = *problem->best_known();
  opt::OptimizerOptions o;
  o.max_evaluations = c.budget;
  o.constraint_tolerance = c.constraint_tol;
  opt::SaoOptions sao;
  if (c.noisy_settings) sao.doe_points_factor = 2;
  const opt::OptimizationResult r = opt::minimize_sao(*problem, o, sao);
  std::cout << "[measure] " << c.problem << ": " << r.brief_report()
            << "; evaluations to 1%: " << evaluations_to_one_percent(r, best.objective) << "\n";
  ASSERT_TRUE(r.has_feasible_point()) << r.full_report();
  double f = r.objective;
  if (auto it = r.metrics.find("noise_free_objective"); it != r.metrics.end()) f = it->second;
  EXPECT_LE(std::fabs(f - best.objective), c.f_tol * std::max(1.0, std::fabs(best.objective))) << r.full_report();
  EXPECT_LE(r.evaluations, c.budget);
}

const double kTight = 1e-3;  // smooth problems
const double kLoose = 2e-2;  // noisy problems (relative noise 1e-3 on every output)

INSTANTIATE_TEST_SUITE_P(Smooth, SaoConvergence,
                         testing::Values(Case{"rosenbrock", 400, kTight}, Case{"hs071", 300, kTight},
                                         Case{"cantilever", 300, kTight}, Case{"two_bar_truss", 200, kTight}),
                         case_name);
INSTANTIATE_TEST_SUITE_P(Noisy, SaoConvergence,
                         testing::Values(Case{"noisy_rosenbrock", 400, kLoose, 1e-6, true},
                                         Case{"noisy_hs071", 400, kLoose, 1e-2, true},
                                         Case{"noisy_cantilever", 400, kLoose, 1e-2, true},
                                         Case{"noisy_two_bar_truss", 200, kLoose, 1e-2, true}),
                         case_name);

}  // namespace

// Evaluations to reach 1 % of best_known, SAO against COBYLA (both from the problem's starting
// point, constraint tolerance 1e-6), asserted on each. Measured with the default intervening
// variables (auto): cantilever SAO 15 / COBYLA 27 (the constraint sum a/x^3 is modelled in fitted
// exponents; with intervening: linear SAO needed 44), two_bar_truss 6 / 12, hs071 18 / 74.
class SaoVersusCobyla : public testing::TestWithParam<std::string> {};

TEST_P(SaoVersusCobyla, EvaluationsToOnePercent) {
  auto problem = opt::benchmarks::make_benchmark(GetParam());
  const double f_star = problem->best_known()->objective;
  opt::OptimizerOptions o;
  o.max_evaluations = 1000;
  const opt::OptimizationResult sao = opt::minimize_sao(*problem, o, opt::SaoOptions{});
  o.algorithm = "COBYLA";
  const opt::OptimizationResult cobyla = opt::minimize(*problem, o);
  const long n_sao = evaluations_to_one_percent(sao, f_star);
  const long n_cobyla = evaluations_to_one_percent(cobyla, f_star);
  std::cout << "[measure] " << GetParam() << ": evaluations to 1%: SAO " << n_sao << ", COBYLA " << n_cobyla << "\n";
  ASSERT_GT(n_sao, 0);
  ASSERT_GT(n_cobyla, 0);
  EXPECT_LT(n_sao, n_cobyla);
}

INSTANTIATE_TEST_SUITE_P(Constrained, SaoVersusCobyla, testing::Values("cantilever", "two_bar_truss", "hs071"));

// An infeasible start: the feasibility phase (minimise the predicted violation) leads to the
// feasible region, then to the optimum.
TEST(Sao, InfeasibleStartReachesFeasibleOptimum) {
  struct Start {
    std::string problem;
    std::vector<double> x0;
  };
  for (const Start& st : {Start{"cantilever", {2, 2, 2, 2, 2}}, Start{"hs071", {1, 1, 1, 1}},
                          Start{"two_bar_truss", {0.3, 1.5}}}) {
    auto problem = opt::benchmarks::make_benchmark(st.problem);
    const opt::Evaluation e0 = problem->evaluate(st.x0);
    ASSERT_GT(opt::max_constraint_violation(e0), 0.1) << st.problem << ": the start must be infeasible";
    opt::OptimizerOptions o;
    o.max_evaluations = 400;
    const opt::OptimizationResult r = opt::minimize_sao(*problem, o, opt::SaoOptions{}, st.x0);
    const double f_star = problem->best_known()->objective;
    std::cout << "[measure] infeasible start " << st.problem << ": " << r.brief_report() << "\n";
    EXPECT_TRUE(r.success()) << r.full_report();
    EXPECT_TRUE(r.feasible);
    EXPECT_NEAR(r.objective, f_star, 1e-3 * std::max(1.0, std::fabs(f_star))) << r.full_report();
    EXPECT_FALSE(r.history.front().feasible);
  }
}

// Stopped by the evaluation budget: the best FEASIBLE point of the history is returned (not the
// last iterate, not an infeasible point with a lower objective), and the run is not a success.
TEST(Sao, BudgetStopReturnsBestFeasiblePoint) {
  auto problem = opt::benchmarks::make_benchmark("cantilever");
  opt::OptimizerOptions o;
  o.max_evaluations = 30;
  const opt::OptimizationResult r = opt::minimize_sao(*problem, o, opt::SaoOptions{});
  EXPECT_EQ(r.reason, opt::TerminationReason::MaxEvaluations);
  EXPECT_EQ(r.evaluations, 30);
  EXPECT_FALSE(r.success());
  ASSERT_TRUE(r.has_feasible_point());
  double best = std::numeric_limits<double>::infinity();
  bool some_infeasible_lower = false;
  for (const auto& h : r.history) {
    if (h.feasible) best = std::min(best, h.objective);
  }
  for (const auto& h : r.history)
    if (!h.feasible && h.objective < best) some_infeasible_lower = true;
  EXPECT_EQ(r.objective, best);
  EXPECT_TRUE(some_infeasible_lower) << "the case should contain an infeasible point below the best feasible one";
}

// A failed evaluation (ok == false) never ends the run: the region shrinks away from it.
TEST(Sao, FailedEvaluationsAreSurvived) {
  opt::FunctionProblem p(
      "bowl_with_hole", {{"a", -1, 1, 1}, {"b", -1, 1, 1}},
      [](const std::vector<double>& x) {
        if (x[0] > 0.35 && x[0] < 0.45) return opt::Evaluation::failed("simulation did not finish");
        opt::Evaluation e;
        e.objective = (x[0] - 0.5) * (x[0] - 0.5) + (x[1] + 0.2) * (x[1] + 0.2);
        return e;
      });
  p.set_initial_point({-0.5, 0.5});
  opt::OptimizerOptions o;
  o.max_evaluations = 300;
  const opt::OptimizationResult r = opt::minimize_sao(p, o, opt::SaoOptions{});
  EXPECT_TRUE(r.success()) << r.full_report();
  EXPECT_NEAR(r.x[0], 0.5, 1e-3);
  EXPECT_NEAR(r.x[1], -0.2, 1e-3);
}

// A piecewise-constant, rippled bowl (a Monte Carlo estimate with common random numbers looks like
// this): the noise-aware ratio test (noise_tolerance, default 1) must not do worse than the
// classical one (0), which shrinks the region below the noise and stops early.
TEST(Sao, NoiseAwareRatioTestOnPiecewiseConstantResponse) {
  auto make = [] {
    auto p = std::make_unique<opt::FunctionProblem>(
        "quantised_bowl", std::vector<opt::Variable>{{"a", 0, 1, 1}, {"b", 0, 1, 1}, {"c", 0, 1, 1}},
        [](const std::vector<double>& x) {
          const double bowl = 4 * ((x[0] - 0.3) * (x[0] - 0.3) + (x[1] - 0.7) * (x[1] - 0.7) + (x[2] - 0.4) * (x[2] - 0.4));
          const double ripple = 0.2 * std::sin(53 * x[0] + 1) * std::sin(47 * x[1] + 2) * std::sin(59 * x[2] + 3);
          opt::Evaluation e;
          e.objective = std::floor((bowl + ripple) * 16) / 16;  // quantised: steps of 1/16
          return e;
        });
    p->set_initial_point({0.9, 0.1, 0.9});
    return p;
  };
  opt::OptimizerOptions o;
  o.max_evaluations = 60;
  opt::SaoOptions classical;
  classical.noise_tolerance = 0;
  auto p1 = make();
  auto p2 = make();
  const opt::OptimizationResult with_noise = opt::minimize_sao(*p1, o, opt::SaoOptions{});
  const opt::OptimizationResult without = opt::minimize_sao(*p2, o, classical);
  std::cout << "[measure] quantised bowl: noise_tolerance 1: " << with_noise.brief_report()
            << "; noise_tolerance 0: " << without.brief_report() << "\n";
  ASSERT_TRUE(with_noise.has_feasible_point());
  EXPECT_LE(with_noise.objective, without.objective);
}

// The points of an attached archive inform the surrogates and are not evaluated again.
TEST(Sao, ReusesArchivedPoints) {
  auto problem = opt::benchmarks::make_benchmark("two_bar_truss");
  const std::string path = std::string(ABUOPT_BINARY_DIR) + "/sao_test_archive.sqlite";
  std::remove(path.c_str());
  opt::OptimizerOptions o;
  o.max_evaluations = 200;
  long first = 0;
  {
    opt::EvaluationArchive archive(path, "truss");
    opt::ArchivedProblem archived(*problem, archive);
    opt::SaoOptions sao;
    sao.archive = &archive;
    const opt::OptimizationResult r = opt::minimize_sao(archived, o, sao);
    first = r.evaluations;
    EXPECT_EQ(archived.misses(), first);
  }
  opt::EvaluationArchive archive(path, "truss");
  opt::ArchivedProblem archived(*problem, archive);
  opt::SaoOptions sao;
  sao.archive = &archive;
  const opt::OptimizationResult r = opt::minimize_sao(archived, o, sao);
  EXPECT_TRUE(r.success()) << r.full_report();
  // the archived points cover the DOE of the rerun, which takes a slightly different path (its
  // first surrogates already see every archived point) and needs only a few new evaluations
  std::cout << "[measure] archive reuse: first run " << first << " evaluations, rerun " << archived.misses()
            << " new ones\n";
  EXPECT_LE(archived.misses(), first / 2);
  std::remove(path.c_str());
}

// minimize() knows SAO (any case), with its settings in OptimizerOptions::sao; minimize_sao() is
// the same run.
TEST(Sao, MinimizeRunsSaoByName) {
  auto problem = opt::benchmarks::make_benchmark("two_bar_truss");
  opt::OptimizerOptions o;
  o.algorithm = "Sao";
  o.max_evaluations = 200;
  EXPECT_EQ(opt::minimize(*problem, o).algorithm, "SAO(auto)");
  o.algorithm = "sao";
  o.sao.surrogate = opt::SurrogateKind::Linear;
  const opt::OptimizationResult via_minimize = opt::minimize(*problem, o);
  EXPECT_EQ(via_minimize.algorithm, "SAO(linear)");
  opt::SaoOptions linear;
  linear.surrogate = opt::SurrogateKind::Linear;
  const opt::OptimizationResult via_sao = opt::minimize_sao(*problem, opt::OptimizerOptions{}, linear);
  EXPECT_EQ(via_minimize.evaluations, via_sao.evaluations);
  EXPECT_EQ(via_minimize.x, via_sao.x);
}

// One record per iteration, consistent with the run: radii follow the ratio test, accepted steps
// have rho = actual / predicted > 0, the evaluation counts grow and end at the run's count.
TEST(Sao, IterationRecordsDescribeEveryIteration) {
  auto problem = opt::benchmarks::make_benchmark("hs071");
  opt::OptimizerOptions o;
  o.max_evaluations = 200;
  const opt::OptimizationResult r = opt::minimize_sao(*problem, o, {});
  ASSERT_EQ(static_cast<long>(r.iteration_records.size()), r.iterations);
  ASSERT_GT(r.iterations, 2);
  long accepted = 0, previous_evaluations = 0;
  for (std::size_t k = 0; k < r.iteration_records.size(); ++k) {
    const opt::IterationRecord& it = r.iteration_records[k];
    EXPECT_EQ(it.iteration, static_cast<long>(k) + 1);
    if (k > 0) {
      EXPECT_EQ(it.radius, r.iteration_records[k - 1].next_radius);
    }
    EXPECT_GE(it.evaluations, previous_evaluations);
    previous_evaluations = it.evaluations;
    if (it.step == opt::IterationStep::Accepted) {
      ++accepted;
      EXPECT_GT(it.actual_reduction, 0);
      EXPECT_DOUBLE_EQ(it.rho, it.actual_reduction / it.predicted_reduction);
    }
    if (it.step == opt::IterationStep::NoPredictedReduction) {
      EXPECT_TRUE(std::isnan(it.rho));
    }
    EXPECT_FALSE(it.surrogate.empty());
    EXPECT_EQ(it.runs, 0);  // hs071 has no Monte Carlo
  }
  EXPECT_GT(accepted, 0);
  EXPECT_EQ(r.iteration_records.front().radius, opt::SaoOptions{}.initial_radius);
  EXPECT_LE(r.iteration_records.back().evaluations, r.evaluations);
  EXPECT_EQ(opt::to_string(opt::IterationStep::NoPredictedReduction), "no_predicted_reduction");
}

// ---- options ----

std::string config_error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "<no ConfigError>";
}

TEST(SaoOptions, DefaultsAreValid) { EXPECT_NO_THROW(opt::SaoOptions{}.validate()); }

TEST(SaoOptions, BadValuesNameKeyValueAndRule) {
  auto message = [](const std::function<void(opt::SaoOptions&)>& change) {
    opt::SaoOptions s;
    change(s);
    return config_error_of([&] { s.validate(); });
  };
  EXPECT_EQ(message([](auto& s) { s.min_radius = 0; }), "sao.min_radius = 0: must be in (0, initial_radius = 0.1]");
  EXPECT_EQ(message([](auto& s) { s.max_radius = 0.05; }),
            "sao.max_radius = 0.05: must be in [initial_radius = 0.1, 1]");
  EXPECT_EQ(message([](auto& s) { s.shrink_factor = 1.5; }), "sao.shrink_factor = 1.5: must be in (0, 1)");
  EXPECT_EQ(message([](auto& s) { s.expand_factor = 0.5; }), "sao.expand_factor = 0.5: must be in [1, 100]");
  EXPECT_EQ(message([](auto& s) { s.initial_radius = -1; }), "sao.initial_radius = -1: must be in (0, 1]");
  EXPECT_EQ(message([](auto& s) { s.rho_expand_low = 0.2; }), "sao.rho_expand_low = 0.2: must be > rho_shrink = 0.25");
  EXPECT_EQ(message([](auto& s) { s.stall_iterations = 0; }), "sao.stall_iterations = 0: must be >= 1");
  EXPECT_EQ(config_error_of([] { opt::surrogate_kind_from_string("cubic"); }),
            "sao.surrogate = cubic: must be one of: auto, linear, interactions, pure_quadratic, quadratic, kriging");
  EXPECT_EQ(config_error_of([] { opt::doe_kind_from_string("sobol"); }),
            "sao.doe = sobol: must be one of: auto, koshal, axial, central_composite, lhs");
  EXPECT_EQ(config_error_of([] { opt::subproblem_solver_from_string("ipopt"); }),
            "sao.subproblem_solver = ipopt: must be one of: slsqp, cobyla");
  EXPECT_EQ(message([](auto& s) {
              s.surrogate = opt::SurrogateKind::Quadratic;
              s.doe = opt::DoeKind::Koshal;
            }),
            "sao.doe = koshal: koshal (n+1 points) cannot determine a quadratic surrogate; use auto, axial, "
            "central_composite or lhs");
  EXPECT_EQ(message([](auto& s) { s.reuse_distance = 0; }), "sao.reuse_distance = 0: must be in (0, 1]");
  EXPECT_EQ(message([](auto& s) { s.noise_tolerance = -1; }), "sao.noise_tolerance = -1: must be in [0, 100] (0: off)");
}

TEST(SaoOptions, ReadFromYaml) {
  YamlReader root = YamlReader::load_string(
      "sao:\n  surrogate: quadratic\n  doe: lhs\n  initial_radius: 0.2\n  max_radius: 0.8\n  correction: false\n");
  YamlReader section = root.child("sao");
  const opt::SaoOptions s = opt::read_sao_options(section);
  EXPECT_EQ(s.surrogate, opt::SurrogateKind::Quadratic);
  EXPECT_EQ(s.doe, opt::DoeKind::Lhs);
  EXPECT_DOUBLE_EQ(s.initial_radius, 0.2);
  EXPECT_DOUBLE_EQ(s.max_radius, 0.8);
  EXPECT_FALSE(s.correction);
  EXPECT_DOUBLE_EQ(s.min_radius, opt::SaoOptions{}.min_radius);  // absent keys keep defaults
  EXPECT_DOUBLE_EQ(s.noise_tolerance, 1.0);
  {
    YamlReader r2 = YamlReader::load_string("sao:\n  noise_tolerance: 0\n");
    YamlReader sec2 = r2.child("sao");
    EXPECT_DOUBLE_EQ(opt::read_sao_options(sec2).noise_tolerance, 0.0);
  }

  auto error_of = [](const std::string& text) {
    return config_error_of([&] {
      YamlReader r = YamlReader::load_string(text);
      YamlReader sec = r.child("sao");
      opt::read_sao_options(sec);
    });
  };
  EXPECT_EQ(error_of("sao:\n  initial_radius: 0.2\n  min_radius: 0.3\n"),
            "sao.min_radius = 0.3: must be in (0, initial_radius = 0.2]");
  EXPECT_NE(error_of("sao:\n  radius: 0.2\n").find("sao.radius"), std::string::npos);  // unknown key
  EXPECT_EQ(error_of("sao:\n  surrogate: cubic\n"),
            "sao.surrogate = cubic: must be one of: auto, linear, interactions, pure_quadratic, quadratic, kriging");
  EXPECT_EQ(error_of("sao:\n  subproblem_solver: ipopt\n"),
            "sao.subproblem_solver = ipopt: must be one of: slsqp, cobyla");
}

// Every enumerator's spelling reads back as itself (to_string and from_string are inverses).
TEST(SaoOptions, ChoicesRoundTripThroughText) {
  for (const std::string& name : opt::surrogate_kind_names())
    EXPECT_EQ(opt::to_string(opt::surrogate_kind_from_string(name)), name);
  for (const std::string& name : opt::doe_kind_names()) EXPECT_EQ(opt::to_string(opt::doe_kind_from_string(name)), name);
  for (const std::string& name : opt::intervening_kind_names())
    EXPECT_EQ(opt::to_string(opt::intervening_kind_from_string(name)), name);
  for (const std::string& name : opt::subproblem_solver_names())
    EXPECT_EQ(opt::to_string(opt::subproblem_solver_from_string(name)), name);
  EXPECT_EQ(opt::to_string(opt::SurrogateKind::PureQuadratic), "pure_quadratic");
  EXPECT_EQ(opt::to_string(opt::DoeKind::CentralComposite), "central_composite");
}

// Every surrogate and DOE choice runs and reaches the truss optimum.
TEST(Sao, EverySurrogateChoiceWorks) {
  for (const std::string surrogate : {"linear", "interactions", "pure_quadratic", "quadratic", "kriging"}) {
    auto problem = opt::benchmarks::make_benchmark("two_bar_truss");
    opt::OptimizerOptions o;
    o.max_evaluations = 300;
    opt::SaoOptions sao;
    sao.surrogate = opt::surrogate_kind_from_string(surrogate);
    const opt::OptimizationResult r = opt::minimize_sao(*problem, o, sao);
    std::cout << "[measure] two_bar_truss " << surrogate << ": " << r.brief_report() << "\n";
    ASSERT_TRUE(r.has_feasible_point()) << surrogate;
    EXPECT_NEAR(r.objective, 1.5086524, 1e-2) << surrogate << "\n" << r.full_report();
  }
}

