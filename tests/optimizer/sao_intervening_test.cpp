// Intervening variables of SAO's surrogates (sao_intervening.hpp): a function linear in 1/x is
// recovered exactly by the reciprocal model, gradients follow the chain rule (against central
// finite differences), auto picks reciprocal for a reciprocal function and linear for a linear
// one, the exponential form finds the exponent of a power function, and a variable whose bounds
// include 0 is never transformed. Plus the options and a run of every form on the cantilever.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <iostream>
#include <random>
#include <string>

#include "abuopt/common/config_error.hpp"
#include "abuopt/optimizer/sao.hpp"
#include "abuopt/optimizer/sao_intervening.hpp"
#include "abuopt/optimizer/benchmarks/benchmark_factory.hpp"

namespace {

using namespace abuopt;
using opt::InterveningData;
using surrogate::Basis;

// Points in the region [-1,1]^n around centre c with step d (x = c + d s), all variables allowed
// unless `allowed` says otherwise.
InterveningData make_data(const Eigen::VectorXd& c, const Eigen::VectorXd& d, int points, unsigned seed,
                          std::vector<bool> allowed = {}) {
  const int n = static_cast<int>(c.size());
  InterveningData data;
  data.S.resize(points, n);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int r = 0; r < points; ++r)
    for (int i = 0; i < n; ++i) data.S(r, i) = u(rng);
  data.weights = Eigen::VectorXd::Ones(points);
  data.centre = c;
  data.step = d;
  data.allowed = allowed.empty() ? std::vector<bool>(n, true) : allowed;
  return data;
}

Eigen::VectorXd x_of(const InterveningData& data, const Eigen::VectorXd& s) {
  return data.centre + data.step.cwiseProduct(s);
}

Eigen::VectorXd values(const InterveningData& data, const std::function<double(const Eigen::VectorXd&)>& f) {
  Eigen::VectorXd y(data.S.rows());
  for (Eigen::Index r = 0; r < data.S.rows(); ++r) y[r] = f(x_of(data, data.S.row(r).transpose()));
  return y;
}

// f = 3 + 2/x0 - 5/x1 + 0.5/x2: linear in the reciprocal variables.
double reciprocal_linear(const Eigen::VectorXd& x) { return 3 + 2 / x[0] - 5 / x[1] + 0.5 / x[2]; }

TEST(InterveningVariables, ReciprocalModelRecoversReciprocalLinearFunctionExactly) {
  const InterveningData data = make_data(Eigen::Vector3d(2, 3, 1.5), Eigen::Vector3d(0.9, 1.2, 0.5), 8, 1);
  const Eigen::VectorXd y = values(data, reciprocal_linear);
  const opt::InterveningChoice c = opt::fit_intervening(opt::InterveningKind::Reciprocal, Basis::kLinear, data, y);
  ASSERT_TRUE(c.model);
  EXPECT_EQ(c.form, opt::InterveningKind::Reciprocal);
  EXPECT_EQ(c.exponents, Eigen::Vector3d(-1, -1, -1));
  EXPECT_LT(c.loo_error, 1e-20);
  // exact away from the fitted points too, across the whole region
  for (const Eigen::Vector3d& s : {Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(0.3, -0.7, 0.9)}) {
    const Eigen::VectorXd x = x_of(data, s);
    EXPECT_NEAR(c.model->value(s), reciprocal_linear(x), 1e-12);
    const Eigen::Vector3d df_dx(-2 / (x[0] * x[0]), 5 / (x[1] * x[1]), -0.5 / (x[2] * x[2]));
    EXPECT_TRUE(c.model->gradient(s).isApprox(df_dx.cwiseProduct(data.step), 1e-10)) << c.model->gradient(s);
  }
  // the linear model of the same data is not exact
  const opt::InterveningChoice lin = opt::fit_intervening(opt::InterveningKind::Linear, Basis::kLinear, data, y);
  EXPECT_GT(std::fabs(lin.model->value(Eigen::Vector3d(-1, -1, -1)) - reciprocal_linear(x_of(data, Eigen::Vector3d(-1, -1, -1)))), 1e-2);
}

TEST(InterveningVariables, GradientFollowsTheChainRule) {
  // every kind of exponent: power < 0, logarithm (0), root, linear (untouched), square
  InterveningData data = make_data(Eigen::VectorXd::Constant(5, 2.0), Eigen::VectorXd::Constant(5, 0.8), 30, 2);
  const Eigen::VectorXd p = (Eigen::VectorXd(5) << -3, 0, 0.5, 1, 2).finished();
  const Eigen::VectorXd y = values(data, [](const Eigen::VectorXd& x) {
    return std::sin(x[0]) + x[1] * x[2] + std::exp(0.3 * x[3]) / x[4] + x[0] * x[4];
  });
  opt::InterveningSurrogate model(opt::InterveningMap(data.centre, data.step, p, data.allowed),
                                  std::make_unique<surrogate::ResponseSurface>(Basis::kQuadratic), "exponential");
  model.fit(data.S, y, data.weights);
  const double h = 1e-6;
  for (const Eigen::VectorXd& s : {Eigen::VectorXd(Eigen::VectorXd::Zero(5)),
                                  Eigen::VectorXd((Eigen::VectorXd(5) << 0.4, -0.9, 0.7, -0.2, 0.95).finished())}) {
    const Eigen::VectorXd g = model.gradient(s);
    for (int i = 0; i < 5; ++i) {
      Eigen::VectorXd a = s, b = s;
      a[i] += h;
      b[i] -= h;
      const double fd = (model.value(a) - model.value(b)) / (2 * h);
      EXPECT_NEAR(g[i], fd, 1e-6 * std::max(1.0, std::fabs(fd))) << "variable " << i;
    }
  }
  // the map itself: u(0) = 0, du/ds(0) = 1, p = 1 is the identity, p = -1 is s c / x
  const opt::InterveningMap map(data.centre, data.step, p, data.allowed);
  EXPECT_TRUE(map.u(Eigen::VectorXd::Zero(5)).isZero(0));
  EXPECT_TRUE(map.du_ds(Eigen::VectorXd::Zero(5)).isOnes(1e-15));
  const opt::InterveningMap recip(Eigen::Vector2d(2, 4), Eigen::Vector2d(1, 2), Eigen::Vector2d(-1, 1), {true, true});
  const Eigen::VectorXd u = recip.u(Eigen::Vector2d(0.5, -0.5));
  EXPECT_NEAR(u[0], 0.5 * 2 / 2.5, 1e-15);
  EXPECT_EQ(u[1], -0.5);
}

TEST(InterveningVariables, AutoPicksReciprocalForReciprocalAndLinearForLinear) {
  const InterveningData data = make_data(Eigen::Vector3d(2, 3, 1.5), Eigen::Vector3d(0.9, 1.2, 0.5), 12, 3);
  for (Basis basis : {Basis::kLinear, Basis::kPureQuadratic}) {
    const opt::InterveningChoice r = opt::fit_intervening(opt::InterveningKind::Auto, basis, data, values(data, reciprocal_linear));
    EXPECT_EQ(r.form, opt::InterveningKind::Reciprocal) << surrogate::to_string(basis);
    const opt::InterveningChoice l = opt::fit_intervening(
        opt::InterveningKind::Auto, basis, data, values(data, [](const Eigen::VectorXd& x) { return 1 + 2 * x[0] - x[1] + 0.1 * x[2]; }));
    EXPECT_EQ(l.form, opt::InterveningKind::Linear) << surrogate::to_string(basis);
  }
  // a cantilever-like constraint sum a_i / x_i^3: exponential finds p = -3 and auto takes it
  const InterveningData five = make_data(Eigen::VectorXd::Constant(5, 5.0), Eigen::VectorXd::Constant(5, 2.0), 14, 4);
  auto deflection = [](const Eigen::VectorXd& x) {
    const double a[5] = {61, 37, 19, 7, 1};
    double v = -1;
    for (int i = 0; i < 5; ++i) v += a[i] / (x[i] * x[i] * x[i]);
    return v;
  };
  const opt::InterveningChoice e = opt::fit_intervening(opt::InterveningKind::Auto, Basis::kLinear, five, values(five, deflection));
  EXPECT_EQ(e.form, opt::InterveningKind::Exponential);
  EXPECT_TRUE(e.exponents.isApprox(Eigen::VectorXd::Constant(5, -3.0))) << e.exponents.transpose();
  EXPECT_LT(e.loo_error, 1e-20);
  // too few points to compare (as many as terms): the previous choice is kept, else linear
  const InterveningData few = make_data(Eigen::Vector3d(2, 3, 1.5), Eigen::Vector3d(0.9, 1.2, 0.5), 4, 5);
  EXPECT_EQ(opt::fit_intervening(opt::InterveningKind::Auto, Basis::kLinear, few, values(few, reciprocal_linear)).form, opt::InterveningKind::Linear);
  opt::InterveningChoice previous;
  previous.form = opt::InterveningKind::Reciprocal;
  previous.exponents = Eigen::Vector3d(-1, -1, -1);
  const opt::InterveningChoice kept =
      opt::fit_intervening(opt::InterveningKind::Auto, Basis::kLinear, few, values(few, reciprocal_linear), &previous);
  EXPECT_EQ(kept.form, opt::InterveningKind::Reciprocal);
  EXPECT_NEAR(kept.model->value(Eigen::Vector3d(-1, 1, -1)), reciprocal_linear(x_of(few, Eigen::Vector3d(-1, 1, -1))),
              1e-12);
}

TEST(InterveningVariables, ReciprocalRefusedWhenBoundsIncludeZero) {
  EXPECT_FALSE(opt::intervening_allowed(0.0, 1.0));
  EXPECT_FALSE(opt::intervening_allowed(-1.0, 1.0));
  EXPECT_FALSE(opt::intervening_allowed(-2.0, -1.0));
  EXPECT_TRUE(opt::intervening_allowed(0.2, 4.0));
  // variable 0 has bounds [0, 2] (centre 1, step 1: s = -1 is x = 0): it stays linear, and u stays
  // finite there; variable 1 is transformed
  InterveningData data = make_data(Eigen::Vector2d(1, 3), Eigen::Vector2d(1, 1), 10, 6, {false, true});
  data.S.row(0) << -1, -1;
  const Eigen::VectorXd y = values(data, [](const Eigen::VectorXd& x) { return 2 * x[0] + 1 / x[1]; });
  for (const opt::InterveningKind form :
       {opt::InterveningKind::Reciprocal, opt::InterveningKind::Exponential, opt::InterveningKind::Auto}) {
    const opt::InterveningChoice c = opt::fit_intervening(form, Basis::kLinear, data, y);
    EXPECT_EQ(c.exponents[0], 1.0) << opt::to_string(form);
    EXPECT_TRUE(std::isfinite(c.model->value(Eigen::Vector2d(-1, -1)))) << opt::to_string(form);
    EXPECT_TRUE(c.model->gradient(Eigen::Vector2d(-1, -1)).allFinite()) << opt::to_string(form);
  }
  EXPECT_EQ(opt::fit_intervening(opt::InterveningKind::Reciprocal, Basis::kLinear, data, y).exponents[1], -1.0);
  EXPECT_NEAR(opt::fit_intervening(opt::InterveningKind::Auto, Basis::kLinear, data, y).model->value(Eigen::Vector2d(0.5, -0.5)),
              2 * 1.5 + 1 / 2.5, 1e-12);
  // no variable may be transformed: every form is the linear one
  const InterveningData none = make_data(Eigen::Vector2d(1, 3), Eigen::Vector2d(1, 1), 10, 7, {false, false});
  EXPECT_EQ(opt::fit_intervening(opt::InterveningKind::Reciprocal, Basis::kLinear, none, y).form, opt::InterveningKind::Linear);
  // the map refuses by itself too
  const opt::InterveningMap map(Eigen::Vector2d(1, 3), Eigen::Vector2d(1, 1), Eigen::Vector2d(-1, -1), {false, true});
  EXPECT_EQ(map.exponents(), Eigen::Vector2d(1, -1));
  EXPECT_EQ(map.u(Eigen::Vector2d(-1, 0))[0], -1.0);
}

// ---- options ----

TEST(InterveningVariables, OptionsAreValidatedAndRead) {
  opt::SaoOptions s;
  EXPECT_EQ(s.intervening, opt::InterveningKind::Auto);
  try {
    opt::intervening_kind_from_string("cubic");
    ADD_FAILURE() << "no ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(), "sao.intervening = cubic: must be one of: auto, linear, reciprocal, exponential");
  }
  YamlReader root = YamlReader::load_string(
      "sao:\n  intervening: reciprocal\n  intervening_objective: linear\n");
  YamlReader section = root.child("sao");
  const opt::SaoOptions r = opt::read_sao_options(section);
  EXPECT_EQ(r.intervening, opt::InterveningKind::Reciprocal);
  EXPECT_EQ(r.intervening_objective, opt::InterveningKind::Linear);
  EXPECT_FALSE(r.intervening_constraints.has_value());  // as `intervening`
}

// Every form reaches the cantilever's optimum (its objective is linear in x, its constraint a sum
// of 1 / x^3); the [measure] lines give the evaluations to 1 % of best_known.
TEST(InterveningVariables, EveryFormSolvesTheCantilever) {
  for (const std::string form : {"linear", "reciprocal", "exponential", "auto"}) {
    auto problem = opt::benchmarks::make_benchmark("cantilever");
    const double f_star = problem->best_known()->objective;
    opt::OptimizerOptions o;
    o.max_evaluations = 300;
    opt::SaoOptions sao;
    sao.intervening = opt::intervening_kind_from_string(form);
    const opt::OptimizationResult r = opt::minimize_sao(*problem, o, sao);
    long to_one_percent = -1;
    for (const auto& h : r.history)
      if (h.feasible && h.objective - f_star <= 0.01 * std::max(1.0, std::fabs(f_star))) {
        to_one_percent = h.index + 1;
        break;
      }
    std::cout << "[measure] cantilever intervening " << form << ": " << r.brief_report()
              << "; evaluations to 1%: " << to_one_percent << "\n";
    ASSERT_TRUE(r.has_feasible_point()) << form;
    EXPECT_NEAR(r.objective, f_star, 1e-3 * f_star) << form << "\n" << r.full_report();
  }
}

}  // namespace
