#pragma once
// Shared argument checks of the surrogate models (private to the library).

#include <stdexcept>
#include <string>

#include <Eigen/Dense>

namespace abuopt::surrogate::detail {

// X (rows = points) and y agree in size, have >= 1 variable and finite entries.
inline void check_training_data(const std::string& who, const Eigen::MatrixXd& X,
                                const Eigen::VectorXd& y) {
  if (X.cols() < 1) {
    throw std::invalid_argument(who + ": X has 0 columns: needs at least 1 variable");
  }
  if (X.rows() != y.size()) {
    throw std::invalid_argument(who + ": X has " + std::to_string(X.rows()) +
                                " rows (points), y has " + std::to_string(y.size()) +
                                " values: must be equal");
  }
  if (!X.allFinite()) throw std::invalid_argument(who + ": X has a non-finite entry");
  if (!y.allFinite()) throw std::invalid_argument(who + ": y has a non-finite entry");
}

// The model is fitted and x has its number of variables.
inline void check_query_point(const std::string& who, int dimension, const Eigen::VectorXd& x) {
  if (dimension <= 0) throw std::logic_error(who + ": the surrogate has not been fitted");
  if (x.size() != dimension) {
    throw std::invalid_argument(who + ": the surrogate was fitted in " +
                                std::to_string(dimension) + " variables, x has " +
                                std::to_string(x.size()));
  }
}

}  // namespace abuopt::surrogate::detail
