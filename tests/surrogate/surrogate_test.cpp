// The common Surrogate interface and the factory by name (surrogate.hpp).

#include "abuopt/surrogate/surrogate.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "abuopt/surrogate/doe.hpp"
#include "abuopt/surrogate/kriging.hpp"
#include "abuopt/surrogate/response_surface.hpp"

namespace abuopt::surrogate {
namespace {

TEST(SurrogateFactory, MakesEveryNamedModel) {
  const std::vector<std::string> names = surrogate_names();
  ASSERT_EQ(names.size(), 5u);
  for (const std::string& name : names) {
    const auto model = make_surrogate(name);
    ASSERT_NE(model, nullptr);
    EXPECT_EQ(model->name(), name);
  }
  EXPECT_NE(dynamic_cast<ResponseSurface*>(make_surrogate("pure_quadratic").get()), nullptr);
  EXPECT_NE(dynamic_cast<Kriging*>(make_surrogate("kriging").get()), nullptr);
}

TEST(SurrogateFactory, UnknownNameListsTheValidOnes) {
  try {
    make_surrogate("cubic");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(),
                 "unknown surrogate \"cubic\": must be one of linear, interactions, "
                 "pure_quadratic, quadratic, kriging");
  }
}

TEST(SurrogateFactory, PassesKrigingOptions) {
  KrigingOptions options;
  options.nugget = 1e-3;
  options.optimize = false;
  options.initial_length_scales = Eigen::Vector2d(0.7, 0.4);
  const auto model = make_surrogate("kriging", &options);
  const auto& kriging = dynamic_cast<const Kriging&>(*model);
  EXPECT_EQ(kriging.options().nugget, 1e-3);
  EXPECT_FALSE(kriging.options().optimize);
}

// Every model, used only through the interface: fits a quadratic on a 3x3x3 grid, reproduces
// it at the training points (the quadratic ones exactly, kriging by interpolation), and its
// gradient matches central differences of its own value.
TEST(SurrogateInterface, FitValueGradientThroughTheBaseClass) {
  const Eigen::MatrixXd X = full_factorial(3, 3);
  Eigen::VectorXd y(X.rows());
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    const Eigen::RowVectorXd x = X.row(i);
    y[i] = 1.0 + x[0] - 2.0 * x[1] + 0.5 * x[0] * x[0] + x[1] * x[2] + 0.3 * x[2] * x[2];
  }
  const Eigen::Vector3d probe(0.25, -0.4, 0.6);
  const double h = 1e-4;  // central differences: error ~ h^2 f''' / 6
  for (const std::string& name : surrogate_names()) {
    SCOPED_TRACE(name);
    std::unique_ptr<Surrogate> model = make_surrogate(name);
    model->fit(X, y);
    const Eigen::VectorXd fitted = model->values(X);
    ASSERT_EQ(fitted.size(), X.rows());
    EXPECT_EQ(fitted[5], model->value(X.row(5).transpose()));
    if (name == "quadratic" || name == "kriging") {
      EXPECT_LT((fitted - y).cwiseAbs().maxCoeff(), 1e-6);
    }
    const Eigen::VectorXd g = model->gradient(probe);
    ASSERT_EQ(g.size(), 3);
    for (int j = 0; j < 3; ++j) {
      Eigen::VectorXd xp = probe, xm = probe;
      xp[j] += h;
      xm[j] -= h;
      EXPECT_NEAR(g[j], (model->value(xp) - model->value(xm)) / (2.0 * h), 1e-6)
          << "component " << j;
    }
  }
}

}  // namespace
}  // namespace abuopt::surrogate
