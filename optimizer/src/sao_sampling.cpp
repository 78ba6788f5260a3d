// SAO: the sample size that follows the need (docs/sao.md, "Adaptive sample size"; SaoSampling in
// sao_options.hpp). For a sampled problem (a Monte Carlo estimate per evaluation whose first n
// runs the optimiser may take: Problem::evaluate_sampled) the run starts at n0 runs and takes more
// as the trust region shrinks, n_k = n0 (r0 / r_k)^p rounded up to n0 2^j, and doubles the floor
// when a failed step's shortfall is within the noise of a merit difference. Every size is the
// first n runs of one fixed sequence (common random numbers), so values at different sizes of
// nearby designs differ by an almost constant shift: the fits use the smaller sizes' values
// shifted by the change seen at the centre when the size grew (Dakota's additive correction,
// between sample sizes instead of models), weighted by n_i / n (their variance is n / n_i times
// larger).
#include <cmath>

#include "abuopt/common/config_error.hpp"
#include "sao_run.hpp"

namespace abuopt::opt::detail {

namespace {

double response_value(const KnownPoint& p, std::size_t k, std::size_t m_ineq) {
  return k == 0 ? p.f : k <= m_ineq ? p.g[k - 1] : p.h[k - 1 - m_ineq];
}

}  // namespace

void check_sao_sampling(const Problem& problem, const SaoOptions& sao) {
  const SaoSampling& c = sao.samples;
  if (!c.enabled()) return;
  const std::size_t largest = problem.max_sample_size();
  if (largest == 0)
    throw ConfigError("sao.samples.initial", std::to_string(c.initial),
                      "needs a problem whose sample size can be chosen (a sampled problem with a nested sequence "
                      "of runs, e.g. the startup problem with montecarlo.design random, halton or sobol); problem '" +
                          problem.name() + "' has none");
  if (static_cast<std::size_t>(c.max) > largest)
    throw ConfigError("sao.samples.max", std::to_string(c.max),
                      "must be <= the problem's largest sample size " + std::to_string(largest));
  if (c.max == 0 && static_cast<std::size_t>(c.initial) > largest)
    throw ConfigError("sao.samples.initial", std::to_string(c.initial),
                      "must be <= the problem's largest sample size " + std::to_string(largest));
}

void SaoRun::start_sampling() {
  samples_ = driver_.sample_size();
  const SaoSampling& c = sao_.samples;
  if (!c.enabled()) return;
  const std::size_t largest = driver_.max_sample_size();  // checked by check_sao_sampling
  samples_max_ = c.max > 0 ? static_cast<std::size_t>(c.max) : largest;
  samples_min_ = std::min(static_cast<std::size_t>(c.initial), samples_max_);
  samples_floor_ = samples_min_;
  sampling_ = true;
  samples_ = scheduled_samples();
  driver_.set_sample_size(samples_);
}

std::size_t SaoRun::scheduled_samples() const {
  const double ratio = std::pow(sao_.initial_radius / radius_, sao_.samples.exponent);
  std::size_t n = samples_min_;
  if (ratio > 1) {
    // n0 2^j with j = ceil(log2 ratio) (a small tolerance keeps an exact power from rounding up)
    const double j = std::ceil(std::log2(ratio) - 1e-9);
    n = j >= 40 ? samples_max_ : static_cast<std::size_t>(std::ldexp(static_cast<double>(samples_min_), static_cast<int>(j)));
  }
  return std::min(std::max(n, samples_min_), samples_max_);
}

bool SaoRun::update_sample_size() {
  const std::size_t target = std::min(samples_max_, std::max({samples_, samples_floor_, scheduled_samples()}));
  if (target <= samples_) return true;
  const KnownPoint before = known_[centre_];  // a copy: evaluate() may grow known_
  const std::size_t old = samples_;
  samples_ = target;
  driver_.set_sample_size(target);
  const auto idx = evaluate(centre_z_);
  if (!idx) return false;
  const KnownPoint& after = known_[*idx];
  const std::size_t responses = 1 + m_ineq_ + m_eq_;
  std::vector<double> delta(responses, 0.0);
  if (before.ok && after.ok)
    for (std::size_t k = 0; k < responses; ++k)
      delta[k] = response_value(after, k, m_ineq_) - response_value(before, k, m_ineq_);
  for (auto& [size, shift] : shift_to_current_)
    for (std::size_t k = 0; k < responses; ++k) shift[k] += delta[k];
  // the old centre's size (a centre taken from an archive may have had another: then no shift)
  if (before.samples == old) shift_to_current_[old] = delta;
  centre_ = *idx;
  return true;
}

std::optional<double> SaoRun::fit_value(const KnownPoint& p, std::size_t k) const {
  const double v = response_value(p, k, m_ineq_);
  if (!sampling_ || p.samples == samples_) return v;
  const auto it = shift_to_current_.find(p.samples);
  if (it == shift_to_current_.end()) return std::nullopt;
  return v + it->second[k];
}

double SaoRun::sample_weight(const KnownPoint& p) const {
  if (!sampling_ || p.samples == 0 || samples_ == 0 || p.samples >= samples_) return 1.0;
  return static_cast<double>(p.samples) / static_cast<double>(samples_);
}

void SaoRun::double_samples_for_noise() { samples_floor_ = std::min(samples_max_, 2 * samples_); }

}  // namespace abuopt::opt::detail
