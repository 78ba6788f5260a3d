#pragma once
// The common surrogate interface (train / predict / gradient, as OpenMDAO's SurrogateModel) and
// a factory by name.
//
//   auto model = abuopt::surrogate::make_surrogate("quadratic");
//   model->fit(X, y);                 // X: one row per point, y: one value per row
//   double f = model->value(x);       // x: one point, x.size() == X.cols()
//   Eigen::VectorXd g = model->gradient(x);
//
// Errors: fit() with inconsistent or insufficient data throws std::invalid_argument (data that
// cannot determine the model, too few points or a rank-deficient design, as InsufficientData);
// value()/gradient() before fit() throw std::logic_error; a point of the wrong size throws
// std::invalid_argument ("the surrogate was fitted in 3 variables, x has 2").

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace abuopt::surrogate {

struct KrigingOptions;  // kriging.hpp

// fit() on data that cannot determine the model: fewer points than terms, a rank-deficient design,
// a correlation matrix that no nugget makes positive definite. Valid data, just not enough of it:
// a caller that tries a simpler model next catches this one (and nothing else).
class InsufficientData : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

class Surrogate {
 public:
  virtual ~Surrogate() = default;

  // Trains on the points X (rows) with responses y (y.size() == X.rows()).
  virtual void fit(const Eigen::MatrixXd& X, const Eigen::VectorXd& y) = 0;
  // Prediction at one point.
  virtual double value(const Eigen::VectorXd& x) const = 0;
  // Analytic gradient of the prediction at one point (size = number of variables).
  virtual Eigen::VectorXd gradient(const Eigen::VectorXd& x) const = 0;
  // The factory name of the model ("quadratic", "kriging", ...).
  virtual std::string name() const = 0;

  // Predictions at every row of X.
  Eigen::VectorXd values(const Eigen::MatrixXd& X) const;
};

// The names make_surrogate() accepts: linear, interactions, pure_quadratic, quadratic, kriging.
std::vector<std::string> surrogate_names();

// A fresh, unfitted surrogate by name; `kriging` options apply only to "kriging" (nullptr:
// defaults). Unknown names throw std::invalid_argument listing the valid names.
std::unique_ptr<Surrogate> make_surrogate(const std::string& name,
                                          const KrigingOptions* kriging = nullptr);

}  // namespace abuopt::surrogate
