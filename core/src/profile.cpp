#include "abuopt/core/profile.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "abuopt/common/config_error.hpp"

namespace abuopt {

namespace {
constexpr double kTwoPi = 2.0 * M_PI;

// phi - sin(phi), accurate for small phi (the naive difference loses all digits as phi -> 0).
double phi_minus_sin(double phi, double sin_phi) {
  if (std::fabs(phi) < 0.5) {
    // phi^3/6 - phi^5/120 + phi^7/5040 - phi^9/362880 + phi^11/39916800 (error < 1e-16 rel)
    const double p2 = phi * phi;
    return phi * p2 * (1.0 / 6 - p2 * (1.0 / 120 - p2 * (1.0 / 5040 - p2 * (1.0 / 362880 - p2 / 39916800.0))));
  }
  return phi - sin_phi;
}
}  // namespace

StartupProfile::StartupProfile(std::vector<InclinedSineSegment> segments, double start_frequency_hz)
    : segments_(std::move(segments)), start_hz_(start_frequency_hz) {
  breaks_.assign(1, 0.0);
  double t = 0;
  for (const auto& s : segments_) {
    t += s.duration_s;
    breaks_.push_back(t);
  }
  duration_s_ = t;
  revs_.assign(1, 0.0);
  for (std::size_t k = 0; k < segments_.size(); ++k) {
    // a whole segment: tau = dt, the sine term vanishes
    const double f0 = k == 0 ? start_hz_ : segments_[k - 1].end_frequency_hz;
    revs_.push_back(revs_.back() + 0.5 * (f0 + segments_[k].end_frequency_hz) * segments_[k].duration_s);
  }
}

double StartupProfile::revolutions(double t) const {
  double r = 0;
  sample(t, &r);
  return r;
}

StartupProfile StartupProfile::report_final() {
  return StartupProfile({{25.0, 1.0}, {29.5, 10.0}, {100.0, 8.0}}, 0.0);
}

double StartupProfile::final_frequency_hz() const {
  return segments_.empty() ? start_hz_ : segments_.back().end_frequency_hz;
}

ProfileSample StartupProfile::sample(double t, double* revolutions) const {
  ProfileSample s;
  if (segments_.empty() || t <= 0) {
    s.frequency_hz = start_hz_;
    if (revolutions) *revolutions = start_hz_ * t;
    return s;
  }
  if (t >= duration_s_) {
    s.frequency_hz = final_frequency_hz();
    if (revolutions) *revolutions = revs_.back() + s.frequency_hz * (t - duration_s_);
    return s;
  }
  // Segment index: last breakpoint <= t.
  const auto it = std::upper_bound(breaks_.begin(), breaks_.end(), t);
  const std::size_t k = static_cast<std::size_t>(it - breaks_.begin()) - 1;
  const double t0 = breaks_[k];
  const double f0 = k == 0 ? start_hz_ : segments_[k - 1].end_frequency_hz;
  const double H = segments_[k].end_frequency_hz - f0;
  const double dt = segments_[k].duration_s;
  const double phi = kTwoPi * (t - t0) / dt;
  const double sh = std::sin(0.5 * phi), ch = std::cos(0.5 * phi);  // one sincos call
  s.frequency_hz = f0 + H / kTwoPi * phi_minus_sin(phi, 2.0 * sh * ch);
  s.rate_hz_per_s = 2.0 * H / dt * sh * sh;  // H/dt (1 - cos phi), without cancellation
  s.accel_hz_per_s2 = kTwoPi * H / (dt * dt) * 2.0 * sh * ch;
  if (revolutions) {
    const double tau = t - t0;  // sh = sin(pi tau / dt)
    *revolutions = revs_[k] + f0 * tau + H * (0.5 * tau * tau / dt - dt / (2.0 * M_PI * M_PI) * sh * sh);
  }
  return s;
}

double StartupProfile::crossing_time_s(std::size_t k, double level) const {
  if (k >= segments_.size()) throw std::invalid_argument("StartupProfile::crossing_time_s: no segment " + std::to_string(k));
  const double f0 = k == 0 ? start_hz_ : segments_[k - 1].end_frequency_hz;
  const double H = segments_[k].end_frequency_hz - f0;
  const double u = (level - f0) / H;  // in (0, 1) for a level strictly inside the segment
  if (!(u > 0 && u < 1))
    throw std::invalid_argument("StartupProfile::crossing_time_s: level " + std::to_string(level) +
                                " Hz is not strictly inside segment " + std::to_string(k));
  // (phi - sin phi)/(2 pi) rises strictly from 0 to 1 on [0, 2 pi]: bisection on phi.
  double lo = 0, hi = kTwoPi;
  for (int it = 0; it < 200 && hi - lo > 0; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    if (phi_minus_sin(mid, std::sin(mid)) / kTwoPi < u) lo = mid; else hi = mid;
  }
  return breaks_[k] + segments_[k].duration_s * (0.5 * (lo + hi)) / kTwoPi;
}

void validate(const StartupProfile& p, const char* path_c) {
  const std::string path(path_c);
  auto num = [](double v) {
    std::ostringstream os;
    os << v;
    return os.str();
  };
  if (!std::isfinite(p.start_frequency_hz()) || p.start_frequency_hz() < 0)
    throw ConfigError(path + ".start_frequency_hz", num(p.start_frequency_hz()), "must be >= 0");
  for (std::size_t i = 0; i < p.segments().size(); ++i) {
    const auto& s = p.segments()[i];
    const std::string sp = path + ".segments[" + std::to_string(i) + "]";
    if (!(std::isfinite(s.duration_s) && s.duration_s > 0))
      throw ConfigError(sp + ".duration_s", num(s.duration_s), "must be > 0");
    if (!(std::isfinite(s.end_frequency_hz) && s.end_frequency_hz >= 0))
      throw ConfigError(sp + ".end_frequency_hz", num(s.end_frequency_hz), "must be >= 0");
  }
}

}  // namespace abuopt
