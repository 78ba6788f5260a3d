// Designs of experiments: sizes, geometry and reproducibility (doe.hpp).

#include "abuopt/surrogate/doe.hpp"

#include <cmath>
#include <set>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "expect_invalid_argument.hpp"

namespace abuopt::surrogate {
namespace {

// Number of rows of `design` equal to `point` (exactly).
int count_rows(const Eigen::MatrixXd& design, const Eigen::RowVectorXd& point) {
  int count = 0;
  for (Eigen::Index i = 0; i < design.rows(); ++i) count += design.row(i) == point ? 1 : 0;
  return count;
}

bool inside_box(const Eigen::MatrixXd& design, double half_width = 1.0) {
  return design.cwiseAbs().maxCoeff() <= half_width + 1e-15;
}

using test::invalid_argument_message;

TEST(FullFactorial, SizeLevelsAndOrder) {
  const Eigen::MatrixXd d = full_factorial(3, 3);
  ASSERT_EQ(d.rows(), 27);
  ASSERT_EQ(d.cols(), 3);
  EXPECT_TRUE(inside_box(d));
  // Last variable fastest: rows 0,1,2 = (-1,-1,-1), (-1,-1,0), (-1,-1,1).
  EXPECT_EQ(d.row(1), Eigen::RowVector3d(-1, -1, 0));
  EXPECT_EQ(d.row(2), Eigen::RowVector3d(-1, -1, 1));
  EXPECT_EQ(d.row(26), Eigen::RowVector3d(1, 1, 1));
  // Every combination exactly once.
  std::set<std::tuple<double, double, double>> seen;
  for (Eigen::Index i = 0; i < d.rows(); ++i) seen.insert({d(i, 0), d(i, 1), d(i, 2)});
  EXPECT_EQ(seen.size(), 27u);
}

TEST(FullFactorial, MixedLevelsPerVariable) {
  const Eigen::MatrixXd d = full_factorial(std::vector<int>{2, 5});
  ASSERT_EQ(d.rows(), 10);
  // Variable 1 has 5 levels: -1, -0.5, 0, 0.5, 1.
  for (int k = 0; k < 5; ++k) EXPECT_DOUBLE_EQ(d(k, 1), -1.0 + 0.5 * k);
  EXPECT_EQ(d(0, 0), -1.0);
  EXPECT_EQ(d(9, 0), 1.0);
}

TEST(FullFactorial, RejectsBadArguments) {
  EXPECT_EQ(invalid_argument_message([] { full_factorial(0, 3); }),
            "full_factorial: n = 0: must be >= 1");
  EXPECT_EQ(invalid_argument_message([] { full_factorial(2, 1); }),
            "full_factorial: levels = 1: must be >= 2");
  EXPECT_EQ(invalid_argument_message([] { full_factorial(std::vector<int>{3, 1}); }),
            "full_factorial: levels[1] = 1: must be >= 2");
}

TEST(CentralComposite, FaceCentredSizeAndStarPoints) {
  CentralCompositeOptions options;
  options.center_points = 3;
  const Eigen::MatrixXd d = central_composite(3, options);
  ASSERT_EQ(d.rows(), 8 + 2 * 3 + 3);
  EXPECT_TRUE(inside_box(d));
  for (int j = 0; j < 3; ++j) {
    Eigen::RowVector3d star = Eigen::RowVector3d::Zero();
    star[j] = 1.0;
    EXPECT_EQ(count_rows(d, star), 1) << "star +e" << j;
    EXPECT_EQ(count_rows(d, -star), 1) << "star -e" << j;
  }
  EXPECT_EQ(count_rows(d, Eigen::RowVector3d::Zero()), 3);
  // The 8 corners are at +-1 in every variable.
  EXPECT_TRUE((d.topRows(8).cwiseAbs().array() == 1.0).all());
}

TEST(CentralComposite, CircumscribedIsRotatable) {
  CentralCompositeOptions options;
  options.type = CentralCompositeType::kCircumscribed;
  options.center_points = 1;
  const Eigen::MatrixXd d = central_composite(3, options);
  const double alpha = std::pow(8.0, 0.25);  // (2^3)^(1/4) = 1.6818
  EXPECT_NEAR(rotatable_alpha(3), 1.6817928305074290, 1e-15);
  ASSERT_EQ(d.rows(), 15);
  for (int j = 0; j < 3; ++j) {
    EXPECT_NEAR(d(8 + 2 * j, j), -alpha, 1e-15);
    EXPECT_NEAR(d(8 + 2 * j + 1, j), alpha, 1e-15);
    // Rotatable: alpha^4 = number of factorial corners (2^3).
    EXPECT_NEAR(std::pow(d.row(8 + 2 * j).norm(), 4), 8.0, 1e-12);
  }
  EXPECT_FALSE(inside_box(d));
  EXPECT_TRUE(inside_box(d, alpha));
}

TEST(CentralComposite, InscribedStaysInsideTheBox) {
  CentralCompositeOptions options;
  options.type = CentralCompositeType::kInscribed;
  const Eigen::MatrixXd d = central_composite(2, options);
  ASSERT_EQ(d.rows(), 4 + 4 + 1);
  EXPECT_TRUE(inside_box(d));
  EXPECT_NEAR(d(0, 0), -1.0 / std::sqrt(2.0), 1e-15);  // alpha = 2^(2/4) = sqrt(2)
  EXPECT_EQ(d(4, 0), -1.0);
}

TEST(CentralComposite, TypeNamesRoundTrip) {
  for (const auto t : {CentralCompositeType::kFaceCentred, CentralCompositeType::kCircumscribed,
                       CentralCompositeType::kInscribed}) {
    EXPECT_EQ(central_composite_type_from_string(to_string(t)), t);
  }
  EXPECT_THROW(central_composite_type_from_string("rotatable"), std::invalid_argument);
  CentralCompositeOptions bad;
  bad.center_points = -1;
  EXPECT_EQ(invalid_argument_message([&] { central_composite(2, bad); }),
            "central_composite: center_points = -1: must be >= 0");
}

TEST(BoxBehnken, ThreeVariables) {
  const Eigen::MatrixXd d = box_behnken(3);  // one centre point by default
  ASSERT_EQ(d.rows(), 12 + 1);
  EXPECT_TRUE(inside_box(d));
  EXPECT_EQ(count_rows(d, Eigen::RowVector3d::Zero()), 1);
  for (Eigen::Index i = 0; i < 12; ++i) {
    // Edge midpoints: exactly one zero, the others +-1, and never a corner.
    EXPECT_EQ((d.row(i).array() == 0.0).count(), 1) << "row " << i;
    EXPECT_EQ((d.row(i).array().abs() == 1.0).count(), 2) << "row " << i;
  }
  // 12 distinct edge midpoints.
  std::set<std::tuple<double, double, double>> seen;
  for (Eigen::Index i = 0; i < 12; ++i) seen.insert({d(i, 0), d(i, 1), d(i, 2)});
  EXPECT_EQ(seen.size(), 12u);
}

TEST(BoxBehnken, FourVariablesWithCentres) {
  BoxBehnkenOptions options;
  options.center_points = 3;
  EXPECT_EQ(box_behnken(4, options).rows(), 24 + 3);
  EXPECT_EQ(invalid_argument_message([] { box_behnken(2); }),
            "box_behnken: n = 2: must be >= 3");
}

TEST(LatinHypercube, OnePointPerStratumInEveryVariable) {
  LatinHypercubeOptions options;
  options.points = 12;
  options.seed = 42;
  const Eigen::MatrixXd d = latin_hypercube(4, options);
  ASSERT_EQ(d.rows(), 12);
  ASSERT_EQ(d.cols(), 4);
  EXPECT_TRUE(inside_box(d));
  for (int j = 0; j < 4; ++j) {
    std::set<int> strata;
    for (Eigen::Index i = 0; i < d.rows(); ++i) {
      strata.insert(static_cast<int>(std::floor((d(i, j) + 1.0) / 2.0 * 12)));
    }
    EXPECT_EQ(strata.size(), 12u) << "variable " << j;
    EXPECT_EQ(*strata.begin(), 0);
    EXPECT_EQ(*strata.rbegin(), 11);
  }
}

TEST(LatinHypercube, CentredPointsAreStratumMidpoints) {
  LatinHypercubeOptions options;
  options.points = 5;
  options.centred = true;
  const Eigen::MatrixXd d = latin_hypercube(2, options);
  for (int j = 0; j < 2; ++j) {
    Eigen::VectorXd column = d.col(j);
    std::sort(column.begin(), column.end());
    for (int k = 0; k < 5; ++k) EXPECT_NEAR(column[k], -1.0 + (k + 0.5) * 0.4, 1e-15);
  }
}

TEST(LatinHypercube, SeedDeterminesTheDesign) {
  LatinHypercubeOptions options;
  options.points = 10;
  options.seed = 7;
  const Eigen::MatrixXd a = latin_hypercube(3, options);
  const Eigen::MatrixXd b = latin_hypercube(3, options);
  EXPECT_EQ(a, b);  // bit-identical
  options.seed = 8;
  const Eigen::MatrixXd c = latin_hypercube(3, options);
  EXPECT_GT((a - c).cwiseAbs().maxCoeff(), 1e-3);
}

TEST(LatinHypercube, MaximinImprovesOnASingleDraw) {
  // The best of 200 draws is at least as good as the first draw alone (same seed: the first
  // candidate is the same hypercube), and strictly better for this seed.
  LatinHypercubeOptions one;
  one.points = 10;
  one.seed = 3;
  one.candidates = 1;
  LatinHypercubeOptions many = one;
  many.candidates = 200;
  const double d1 = min_pairwise_distance(latin_hypercube(2, one));
  const double d200 = min_pairwise_distance(latin_hypercube(2, many));
  EXPECT_GE(d200, d1);
  EXPECT_GT(d200, 0.2);  // 10 points in [-1,1]^2: a good maximin LHS has spacing ~0.35..0.5
}

TEST(LatinHypercube, RejectsBadArguments) {
  LatinHypercubeOptions options;
  options.points = 0;
  EXPECT_EQ(invalid_argument_message([&] { latin_hypercube(2, options); }),
            "latin_hypercube: points = 0: must be >= 1");
  options.points = 4;
  options.candidates = 0;
  EXPECT_EQ(invalid_argument_message([&] { latin_hypercube(2, options); }),
            "latin_hypercube: candidates = 0: must be >= 1");
  EXPECT_EQ(invalid_argument_message([] { latin_hypercube(0); }),
            "latin_hypercube: n = 0: must be >= 1");
}

TEST(KoshalLinear, CentrePlusOnePointPerVariable) {
  const Eigen::MatrixXd d = koshal_linear(4);
  ASSERT_EQ(d.rows(), 5);
  EXPECT_EQ(d.row(0), Eigen::RowVectorXd::Zero(4));
  EXPECT_EQ(d.bottomRows(4), Eigen::MatrixXd::Identity(4, 4));
  EXPECT_THROW(koshal_linear(0), std::invalid_argument);
}

TEST(Scaling, MapsBoxToBoundsAndBack) {
  const Eigen::Vector2d lo(0.0, -10.0);
  const Eigen::Vector2d hi(4.0, 10.0);
  Eigen::MatrixXd scaled(3, 2);
  scaled << -1, -1, 0, 0, 1, 0.5;
  const Eigen::MatrixXd real = scale_to_bounds(scaled, lo, hi);
  EXPECT_EQ(real.row(0), Eigen::RowVector2d(0.0, -10.0));
  EXPECT_EQ(real.row(1), Eigen::RowVector2d(2.0, 0.0));
  EXPECT_EQ(real.row(2), Eigen::RowVector2d(4.0, 5.0));
  EXPECT_LT((scale_from_bounds(real, lo, hi) - scaled).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LT((point_to_bounds(Eigen::Vector2d(1, 0.5), lo, hi) - Eigen::Vector2d(4, 5)).norm(),
            1e-15);
  EXPECT_LT((point_from_bounds(Eigen::Vector2d(4, 5), lo, hi) - Eigen::Vector2d(1, 0.5)).norm(),
            1e-15);
  EXPECT_EQ(invalid_argument_message([&] { scale_to_bounds(scaled, hi, lo); }),
            "scale_to_bounds: lo[0] = 4.000000, hi[0] = 0.000000: must have lo < hi");
  EXPECT_THROW(scale_to_bounds(Eigen::MatrixXd::Zero(2, 3), lo, hi), std::invalid_argument);
}

}  // namespace
}  // namespace abuopt::surrogate
