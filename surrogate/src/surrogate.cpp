#include "abuopt/surrogate/surrogate.hpp"

#include <stdexcept>

#include "abuopt/surrogate/kriging.hpp"
#include "abuopt/surrogate/response_surface.hpp"

namespace abuopt::surrogate {

Eigen::VectorXd Surrogate::values(const Eigen::MatrixXd& X) const {
  Eigen::VectorXd out(X.rows());
  for (Eigen::Index i = 0; i < X.rows(); ++i) out[i] = value(X.row(i).transpose());
  return out;
}

std::vector<std::string> surrogate_names() {
  return {"linear", "interactions", "pure_quadratic", "quadratic", "kriging"};
}

std::unique_ptr<Surrogate> make_surrogate(const std::string& name,
                                          const KrigingOptions* kriging) {
  if (name == "kriging") {
    return std::make_unique<Kriging>(kriging != nullptr ? *kriging : KrigingOptions{});
  }
  for (const Basis basis : {Basis::kLinear, Basis::kInteractions, Basis::kPureQuadratic,
                            Basis::kQuadratic}) {
    if (name == to_string(basis)) return std::make_unique<ResponseSurface>(basis);
  }
  std::string valid;
  for (const auto& known : surrogate_names()) valid += (valid.empty() ? "" : ", ") + known;
  throw std::invalid_argument("unknown surrogate \"" + name + "\": must be one of " + valid);
}

}  // namespace abuopt::surrogate
