// SAO's noise estimate (see sao_noise.hpp).
#include "sao_noise.hpp"

#include <algorithm>
#include <cmath>

namespace abuopt::opt::detail {

namespace {

// Residual RMS below this fraction of the responses' spread on the fit zone: not noise.
constexpr double kNoiseFraction = 0.1;

}  // namespace

ResidualNoise residual_noise(const Eigen::VectorXd& y, const Eigen::VectorXd& fitted, const std::vector<double>& w,
                             int p) {
  const int m = static_cast<int>(y.size());
  ResidualNoise out;
  if (m <= p) return out;
  double wsum = 0, sse = 0, mean = 0;
  for (int i = 0; i < m; ++i) {
    const double e = y[i] - fitted[i];
    sse += w[i] * e * e;
    wsum += w[i];
    mean += w[i] * y[i];
  }
  mean /= wsum;
  double var = 0;
  for (int i = 0; i < m; ++i) var += w[i] * (y[i] - mean) * (y[i] - mean);
  const double sigma = std::sqrt(sse / wsum * m / (m - p));
  const double sd = std::sqrt(var / wsum);
  out.sigma = std::isfinite(sigma) ? sigma : 0.0;
  out.fraction = sd > 0 && std::isfinite(sigma) ? std::min(1.0, sigma / sd) : 0.0;
  return out;
}

void NoiseConfirmation::confirm(std::vector<double>& noise, const std::vector<double>& fraction, double radius) {
  const std::size_t responses = noise.size();
  history_.resize(responses);
  for (std::size_t k = 0; k < responses; ++k) {
    const double now = noise[k];
    bool confirmed = false;
    for (const auto& [r, sigma] : history_[k])
      if (r >= 2 * radius * (1 - 1e-9) && sigma <= 2 * now) confirmed = now > 0;
    if (now > 0) history_[k].emplace_back(radius, now);
    // a model that explains all but a small part of the response's spread on the zone: smooth
    if (fraction[k] < kNoiseFraction) confirmed = false;
    if (!confirmed) noise[k] = 0;
  }
}

double merit_noise(const std::vector<double>& noise, const std::vector<double>& centre_g, std::size_t m_ineq,
                   std::size_t m_eq, double mu, bool phase1) {
  if (noise.size() != 1 + m_ineq + m_eq) return 0.0;
  double v = 0;
  for (std::size_t i = 0; i < m_ineq; ++i)
    if (centre_g[i] > -2 * noise[1 + i]) v += noise[1 + i];
  for (std::size_t j = 0; j < m_eq; ++j) v += noise[1 + m_ineq + j];
  return phase1 ? v : noise[0] + mu * v;
}

}  // namespace abuopt::opt::detail
