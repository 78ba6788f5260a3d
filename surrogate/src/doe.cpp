#include "abuopt/surrogate/doe.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>

namespace abuopt::surrogate {
namespace {

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

void require_dimension(const char* who, int n, int minimum = 1) {
  require(n >= minimum, std::string(who) + ": n = " + std::to_string(n) + ": must be >= " +
                            std::to_string(minimum));
}

void require_center_points(const char* who, int center_points) {
  require(center_points >= 0, std::string(who) + ": center_points = " +
                                  std::to_string(center_points) + ": must be >= 0");
}

// 2^n must fit comfortably in memory; 2^20 rows of 20 doubles is already 160 MiB.
constexpr int kMaxFactorialDimension = 20;

void check_bounds(const char* who, Eigen::Index columns, const Eigen::VectorXd& lo,
                  const Eigen::VectorXd& hi) {
  require(lo.size() == columns && hi.size() == columns,
          std::string(who) + ": the design has " + std::to_string(columns) +
              " variables, lo has " + std::to_string(lo.size()) + " and hi has " +
              std::to_string(hi.size()));
  for (Eigen::Index j = 0; j < columns; ++j) {
    require(lo[j] < hi[j], std::string(who) + ": lo[" + std::to_string(j) + "] = " +
                               std::to_string(lo[j]) + ", hi[" + std::to_string(j) +
                               "] = " + std::to_string(hi[j]) + ": must have lo < hi");
  }
}

}  // namespace

Eigen::MatrixXd full_factorial(const std::vector<int>& levels) {
  const int n = static_cast<int>(levels.size());
  require_dimension("full_factorial", n);
  double count = 1.0;
  for (int j = 0; j < n; ++j) {
    require(levels[j] >= 2, "full_factorial: levels[" + std::to_string(j) + "] = " +
                                std::to_string(levels[j]) + ": must be >= 2");
    count *= levels[j];
  }
  require(count <= 1e7, "full_factorial: " + std::to_string(count) +
                            " points: must be <= 1e7 (reduce levels or variables)");
  const auto m = static_cast<Eigen::Index>(count);
  Eigen::MatrixXd design(m, n);
  // Row r is the mixed-radix number r written with digits (d_0, ..., d_{n-1}), last fastest.
  for (Eigen::Index r = 0; r < m; ++r) {
    Eigen::Index rest = r;
    for (int j = n - 1; j >= 0; --j) {
      const int digit = static_cast<int>(rest % levels[j]);
      rest /= levels[j];
      design(r, j) = -1.0 + 2.0 * digit / (levels[j] - 1);
    }
  }
  return design;
}

Eigen::MatrixXd full_factorial(int n, int levels) {
  require_dimension("full_factorial", n);
  require(levels >= 2,
          "full_factorial: levels = " + std::to_string(levels) + ": must be >= 2");
  return full_factorial(std::vector<int>(static_cast<std::size_t>(n), levels));
}

double rotatable_alpha(int n) {
  require_dimension("rotatable_alpha", n);
  return std::pow(2.0, n / 4.0);
}

Eigen::MatrixXd central_composite(int n, const CentralCompositeOptions& options) {
  require_dimension("central_composite", n);
  require(n <= kMaxFactorialDimension, "central_composite: n = " + std::to_string(n) +
                                           ": must be <= " +
                                           std::to_string(kMaxFactorialDimension));
  require_center_points("central_composite", options.center_points);
  const double rotatable = rotatable_alpha(n);
  double corner = 1.0;
  double alpha = 1.0;
  switch (options.type) {
    case CentralCompositeType::kFaceCentred: break;
    case CentralCompositeType::kCircumscribed: alpha = rotatable; break;
    case CentralCompositeType::kInscribed: corner = 1.0 / rotatable; break;
  }
  const Eigen::MatrixXd corners = full_factorial(n, 2);
  const Eigen::Index m = corners.rows() + 2 * n + options.center_points;
  Eigen::MatrixXd design = Eigen::MatrixXd::Zero(m, n);
  design.topRows(corners.rows()) = corner * corners;
  Eigen::Index row = corners.rows();
  for (int j = 0; j < n; ++j) {
    design(row++, j) = -alpha;
    design(row++, j) = +alpha;
  }
  return design;  // the remaining rows are the centre points (zeros)
}

Eigen::MatrixXd box_behnken(int n, const BoxBehnkenOptions& options) {
  require_dimension("box_behnken", n, 3);
  require_center_points("box_behnken", options.center_points);
  const Eigen::Index pairs = static_cast<Eigen::Index>(n) * (n - 1) / 2;
  Eigen::MatrixXd design = Eigen::MatrixXd::Zero(4 * pairs + options.center_points, n);
  Eigen::Index row = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      for (const double si : {-1.0, 1.0}) {
        for (const double sj : {-1.0, 1.0}) {
          design(row, i) = si;
          design(row, j) = sj;
          ++row;
        }
      }
    }
  }
  return design;
}

double min_pairwise_distance(const Eigen::MatrixXd& design) {
  double best = std::numeric_limits<double>::infinity();
  for (Eigen::Index a = 0; a < design.rows(); ++a) {
    for (Eigen::Index b = a + 1; b < design.rows(); ++b) {
      best = std::min(best, (design.row(a) - design.row(b)).squaredNorm());
    }
  }
  return std::sqrt(best);
}

Eigen::MatrixXd latin_hypercube(int n, const LatinHypercubeOptions& options) {
  require_dimension("latin_hypercube", n);
  require(options.points >= 1, "latin_hypercube: points = " + std::to_string(options.points) +
                                   ": must be >= 1");
  require(options.candidates >= 1, "latin_hypercube: candidates = " +
                                       std::to_string(options.candidates) + ": must be >= 1");
  const int m = options.points;
  std::mt19937_64 rng(options.seed);
  // Uniform in [0,1) from the top 53 bits; portable, unlike std::uniform_real_distribution.
  const auto unit = [&rng] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  std::vector<int> strata(static_cast<std::size_t>(m));
  const double width = 2.0 / m;

  Eigen::MatrixXd best;
  double best_distance = -1.0;
  Eigen::MatrixXd candidate(m, n);
  for (int k = 0; k < options.candidates; ++k) {
    for (int j = 0; j < n; ++j) {
      std::iota(strata.begin(), strata.end(), 0);
      // Fisher-Yates with our own index draws: std::shuffle's use of the engine is
      // implementation-defined, which would make designs differ between standard libraries
      // (the modulo bias is below 2^-40 for any practical m).
      for (int i = m - 1; i > 0; --i) {
        const auto pick = static_cast<int>(rng() % static_cast<std::uint64_t>(i + 1));
        std::swap(strata[static_cast<std::size_t>(i)], strata[static_cast<std::size_t>(pick)]);
      }
      for (int i = 0; i < m; ++i) {
        const double offset = options.centred ? 0.5 : unit();
        candidate(i, j) = -1.0 + (strata[static_cast<std::size_t>(i)] + offset) * width;
      }
    }
    const double distance = min_pairwise_distance(candidate);
    if (distance > best_distance) {
      best_distance = distance;
      best = candidate;
    }
  }
  return best;
}

Eigen::MatrixXd koshal_linear(int n) {
  require_dimension("koshal_linear", n);
  Eigen::MatrixXd design = Eigen::MatrixXd::Zero(n + 1, n);
  design.bottomRows(n) = Eigen::MatrixXd::Identity(n, n);
  return design;
}

Eigen::MatrixXd scale_to_bounds(const Eigen::MatrixXd& scaled, const Eigen::VectorXd& lo,
                                const Eigen::VectorXd& hi) {
  check_bounds("scale_to_bounds", scaled.cols(), lo, hi);
  const Eigen::RowVectorXd centre = 0.5 * (lo + hi).transpose();
  const Eigen::RowVectorXd half = 0.5 * (hi - lo).transpose();
  return (scaled.array().rowwise() * half.array()).rowwise() + centre.array();
}

Eigen::MatrixXd scale_from_bounds(const Eigen::MatrixXd& real, const Eigen::VectorXd& lo,
                                  const Eigen::VectorXd& hi) {
  check_bounds("scale_from_bounds", real.cols(), lo, hi);
  const Eigen::RowVectorXd centre = 0.5 * (lo + hi).transpose();
  const Eigen::RowVectorXd half = 0.5 * (hi - lo).transpose();
  return (real.array().rowwise() - centre.array()).rowwise() / half.array();
}

Eigen::VectorXd point_to_bounds(const Eigen::VectorXd& scaled, const Eigen::VectorXd& lo,
                                const Eigen::VectorXd& hi) {
  return scale_to_bounds(scaled.transpose(), lo, hi).transpose();
}

Eigen::VectorXd point_from_bounds(const Eigen::VectorXd& real, const Eigen::VectorXd& lo,
                                  const Eigen::VectorXd& hi) {
  return scale_from_bounds(real.transpose(), lo, hi).transpose();
}

std::string to_string(CentralCompositeType type) {
  switch (type) {
    case CentralCompositeType::kFaceCentred: return "face_centred";
    case CentralCompositeType::kCircumscribed: return "circumscribed";
    case CentralCompositeType::kInscribed: return "inscribed";
  }
  return "unknown";
}

CentralCompositeType central_composite_type_from_string(const std::string& name) {
  for (const auto type : {CentralCompositeType::kFaceCentred,
                          CentralCompositeType::kCircumscribed,
                          CentralCompositeType::kInscribed}) {
    if (name == to_string(type)) return type;
  }
  throw std::invalid_argument("central composite type \"" + name +
                              "\": must be one of face_centred, circumscribed, inscribed");
}

}  // namespace abuopt::surrogate
