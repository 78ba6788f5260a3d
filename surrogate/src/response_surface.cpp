#include "abuopt/surrogate/response_surface.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "surrogate_checks.hpp"

namespace abuopt::surrogate {
namespace {

bool has_squares(Basis basis) {
  return basis == Basis::kPureQuadratic || basis == Basis::kQuadratic;
}
bool has_interactions(Basis basis) {
  return basis == Basis::kInteractions || basis == Basis::kQuadratic;
}

constexpr Basis kAllBases[] = {Basis::kLinear, Basis::kInteractions, Basis::kPureQuadratic,
                               Basis::kQuadratic};

// Relative pivot threshold of the QR: a design whose R has a pivot below 1e-10 times the largest
// is treated as rank-deficient (its coefficients would be noise).
constexpr double kRankThreshold = 1e-10;
// 1 - h_ii below this: the point is not predictable without itself.
constexpr double kLeverageOne = 1e-12;

}  // namespace

std::string to_string(Basis basis) {
  switch (basis) {
    case Basis::kLinear: return "linear";
    case Basis::kInteractions: return "interactions";
    case Basis::kPureQuadratic: return "pure_quadratic";
    case Basis::kQuadratic: return "quadratic";
  }
  return "unknown";
}

std::string describe(Basis basis) {
  switch (basis) {
    case Basis::kLinear: return "linear";
    case Basis::kInteractions: return "linear with interactions";
    case Basis::kPureQuadratic: return "pure quadratic";
    case Basis::kQuadratic: return "full quadratic";
  }
  return "unknown";
}

Basis basis_from_string(const std::string& name) {
  for (const Basis basis : kAllBases) {
    if (name == to_string(basis)) return basis;
  }
  throw std::invalid_argument("response surface basis \"" + name +
                              "\": must be one of linear, interactions, pure_quadratic, "
                              "quadratic");
}

int terms_count(Basis basis, int n) {
  if (n < 1) {
    throw std::invalid_argument("terms_count: n = " + std::to_string(n) + ": must be >= 1");
  }
  int p = 1 + n;
  if (has_squares(basis)) p += n;
  if (has_interactions(basis)) p += n * (n - 1) / 2;
  return p;
}

Eigen::VectorXd basis_terms(Basis basis, const Eigen::VectorXd& x) {
  const int n = static_cast<int>(x.size());
  Eigen::VectorXd phi(terms_count(basis, n));
  int k = 0;
  phi[k++] = 1.0;
  for (int i = 0; i < n; ++i) phi[k++] = x[i];
  if (has_squares(basis)) {
    for (int i = 0; i < n; ++i) phi[k++] = x[i] * x[i];
  }
  if (has_interactions(basis)) {
    for (int i = 0; i < n; ++i) {
      for (int j = i + 1; j < n; ++j) phi[k++] = x[i] * x[j];
    }
  }
  return phi;
}

std::vector<std::string> term_names(Basis basis, int n) {
  std::vector<std::string> names;
  names.reserve(static_cast<std::size_t>(terms_count(basis, n)));
  names.emplace_back("1");
  // Built by append(): `"x" + std::to_string(i)` trips GCC 12's false -Wrestrict (PR 105329).
  const auto var = [](int i) {
    std::string name("x");
    name.append(std::to_string(i));
    return name;
  };
  for (int i = 0; i < n; ++i) names.push_back(var(i));
  if (has_squares(basis)) {
    for (int i = 0; i < n; ++i) names.push_back(var(i) + "^2");
  }
  if (has_interactions(basis)) {
    for (int i = 0; i < n; ++i) {
      for (int j = i + 1; j < n; ++j) names.push_back(var(i) + "*" + var(j));
    }
  }
  return names;
}

ResponseSurface::ResponseSurface(Basis basis) : basis_(basis) {}

void ResponseSurface::fit(const Eigen::MatrixXd& X, const Eigen::VectorXd& y) {
  fit(X, y, Eigen::VectorXd::Ones(X.rows()));
}

void ResponseSurface::fit(const Eigen::MatrixXd& X, const Eigen::VectorXd& y,
                          const Eigen::VectorXd& weights) {
  const std::string who = "ResponseSurface(" + to_string(basis_) + ")::fit";
  detail::check_training_data(who, X, y);
  if (weights.size() != X.rows()) {
    throw std::invalid_argument(who + ": X has " + std::to_string(X.rows()) +
                                " rows (points), weights has " +
                                std::to_string(weights.size()) + " values: must be equal");
  }
  for (Eigen::Index i = 0; i < weights.size(); ++i) {
    if (!(std::isfinite(weights[i]) && weights[i] >= 0.0)) {
      throw std::invalid_argument(who + ": weights[" + std::to_string(i) +
                                  "] = " + std::to_string(weights[i]) +
                                  ": must be finite and >= 0");
    }
  }
  const int n = static_cast<int>(X.cols());
  const int p = terms_count(basis_, n);
  const Eigen::Index m_all = X.rows();
  const int m = static_cast<int>((weights.array() > 0.0).count());
  const std::string model = describe(basis_) + " in " + std::to_string(n) +
                            (n == 1 ? " variable" : " variables");
  if (m < p) {
    throw InsufficientData(model + " needs at least " + std::to_string(p) +
                                " points, got " + std::to_string(m) +
                                (m == m_all ? "" : " (with positive weight)"));
  }

  const Eigen::VectorXd sqrt_w = weights.cwiseSqrt();
  Eigen::MatrixXd A(m_all, p);
  for (Eigen::Index i = 0; i < m_all; ++i) {
    A.row(i) = basis_terms(basis_, X.row(i).transpose()).transpose();
  }
  const Eigen::MatrixXd Aw = sqrt_w.asDiagonal() * A;
  const Eigen::VectorXd yw = sqrt_w.cwiseProduct(y);

  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Aw);
  qr.setThreshold(kRankThreshold);
  if (qr.rank() < p) {
    throw InsufficientData(model + " needs at least " + std::to_string(p) +
                                " points in general position, got " + std::to_string(m) +
                                " whose design matrix has rank " + std::to_string(qr.rank()) +
                                " (rank-deficient design: e.g. two levels per variable cannot "
                                "determine squared terms)");
  }
  Eigen::VectorXd beta = qr.solve(yw);

  // Leverages: the thin Q spans the column space of W^(1/2) A (full rank), so
  // H = Q Q^T and h_ii = |row i of Q|^2.
  const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(m_all, p);
  FitDiagnostics d;
  d.points = m;
  d.terms = p;
  d.residuals = y - A * beta;
  d.leverages = Q.rowwise().squaredNorm();

  const double sum_w = weights.sum();
  const double y_mean = weights.dot(y) / sum_w;
  const double ss_res = weights.dot(d.residuals.cwiseAbs2());
  const double ss_tot = weights.dot((y.array() - y_mean).matrix().cwiseAbs2());
  // A constant response is reproduced exactly by every basis (all contain the constant term).
  d.r_squared = ss_tot > 0.0 ? 1.0 - ss_res / ss_tot : 1.0;
  d.adjusted_r_squared = m > p ? 1.0 - (1.0 - d.r_squared) * (m - 1) / static_cast<double>(m - p)
                               : std::numeric_limits<double>::quiet_NaN();
  double sum_e2 = 0.0;
  double press = 0.0;
  double max_leverage = 0.0;
  for (Eigen::Index i = 0; i < m_all; ++i) {
    if (weights[i] <= 0.0) continue;
    const double e = d.residuals[i];
    const double h = d.leverages[i];
    sum_e2 += e * e;
    max_leverage = std::max(max_leverage, h);
    press += (1.0 - h) > kLeverageOne ? (e / (1.0 - h)) * (e / (1.0 - h))
                                      : std::numeric_limits<double>::infinity();
  }
  d.residual_rms = std::sqrt(sum_e2 / m);
  d.press = press;
  d.loo_rms = std::sqrt(press / m);
  d.max_leverage = max_leverage;

  coefficients_ = std::move(beta);
  diagnostics_ = std::move(d);
  dimension_ = n;
}

void ResponseSurface::check_point(const Eigen::VectorXd& x) const {
  detail::check_query_point("ResponseSurface(" + to_string(basis_) + ")", dimension_, x);
}

double ResponseSurface::value(const Eigen::VectorXd& x) const {
  check_point(x);
  return basis_terms(basis_, x).dot(coefficients_);
}

Eigen::VectorXd ResponseSurface::gradient(const Eigen::VectorXd& x) const {
  check_point(x);
  const int n = dimension_;
  Eigen::VectorXd g = coefficients_.segment(1, n);
  int k = 1 + n;
  if (has_squares(basis_)) {
    for (int i = 0; i < n; ++i) g[i] += 2.0 * coefficients_[k++] * x[i];
  }
  if (has_interactions(basis_)) {
    for (int i = 0; i < n; ++i) {
      for (int j = i + 1; j < n; ++j) {
        g[i] += coefficients_[k] * x[j];
        g[j] += coefficients_[k] * x[i];
        ++k;
      }
    }
  }
  return g;
}

Eigen::MatrixXd ResponseSurface::hessian(const Eigen::VectorXd& x) const {
  check_point(x);
  const int n = dimension_;
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, n);
  int k = 1 + n;
  if (has_squares(basis_)) {
    for (int i = 0; i < n; ++i) H(i, i) = 2.0 * coefficients_[k++];
  }
  if (has_interactions(basis_)) {
    for (int i = 0; i < n; ++i) {
      for (int j = i + 1; j < n; ++j) {
        H(i, j) = H(j, i) = coefficients_[k++];
      }
    }
  }
  return H;
}

}  // namespace abuopt::surrogate
