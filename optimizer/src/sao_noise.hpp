#pragma once
// Internal: SAO's noise estimate (docs/sao.md, "Noise"). The ratio test compares a predicted with
// an actual reduction of the merit; on a noisy response a reduction smaller than the noise cannot
// be checked by one evaluation. The noise level of each response is estimated from the residuals
// of its least-squares surrogate, and only taken as noise when it does not shrink with the region.
#include <cstddef>
#include <utility>
#include <vector>

#include <Eigen/Dense>

namespace abuopt::opt::detail {

// Residual RMS of a fitted least-squares model with p terms on m = y.size() points (weights w):
//   sigma = sqrt(sum w e^2 / sum w * m / (m - p))   (degrees-of-freedom correction; needs m > p)
//   fraction = min(1, sigma / sd), sd the weighted standard deviation of y (1: the model explains
//   nothing of the response's spread; ~0: smooth at this scale).
// An upper bound of the noise: it includes the lack of fit. Non-finite sigma gives {0, 0}.
struct ResidualNoise {
  double sigma = 0.0;
  double fraction = 0.0;
};
ResidualNoise residual_noise(const Eigen::VectorXd& y, const Eigen::VectorXd& fitted, const std::vector<double>& w,
                             int p);

// Lack of fit or noise? The residual RMS of a fit on a smooth response shrinks with the region
// (as r^2 for a linear model, faster for quadratic ones); on a noisy one it does not. A response's
// residual RMS is taken as its noise level only when an earlier fit on a region at least twice as
// wide had a residual RMS at most twice the current one, and the residuals are at least
// kNoiseFraction (0.1) of the response's spread on the fit zone; otherwise its noise is 0 (the
// classical ratio test applies).
class NoiseConfirmation {
 public:
  // `noise` (per response, from residual_noise; 0 where the fit interpolates) is set to 0 where
  // the noise is not confirmed; the fit is recorded in the history. Sizes of noise and fraction
  // agree.
  void confirm(std::vector<double>& noise, const std::vector<double>& fraction, double radius);

 private:
  // per response: (radius, residual RMS) of every fit that had degrees of freedom to spare
  std::vector<std::vector<std::pair<double, double>>> history_;
};

// The noise level of the merit at the centre: the objective's (outside the feasibility phase) plus
// mu times that of every constraint that is violated or within two noise levels of its bound (the
// others do not enter the L1 violation). `noise` holds objective, inequalities, equalities in that
// order; `centre_g` the centre's inequality values. 0 when noise has another size.
double merit_noise(const std::vector<double>& noise, const std::vector<double>& centre_g, std::size_t m_ineq,
                   std::size_t m_eq, double mu, bool phase1);

}  // namespace abuopt::opt::detail
