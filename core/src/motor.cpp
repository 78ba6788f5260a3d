#include "abuopt/core/motor.hpp"

#include <algorithm>
#include <cmath>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/config_fields.hpp"

namespace abuopt {

double MotorModel::realised_reference_hz(double target_hz) const {
  double f = target_hz;
  if (quantize_setpoint_1hz) f = std::round(f);
  if (setpoint_mismatch && f > 0) f = std::max(0.0, f - (f + 1.0) / 64.0);  // report eq 2.1
  return f;
}

std::vector<double> MotorModel::reference_step_times_s(const StartupProfile& profile) const {
  std::vector<double> out;
  if (!quantize_setpoint_1hz) return out;
  double f0 = profile.start_frequency_hz();
  for (std::size_t k = 0; k < profile.segments().size(); ++k) {
    const double f1 = profile.segments()[k].end_frequency_hz;
    // levels c = j + 1/2 strictly between f0 and f1 (none in a hold segment)
    const double lo = std::min(f0, f1), hi = std::max(f0, f1);
    std::vector<double> seg;
    for (double c = std::floor(lo - 0.5) + 0.5; c < hi; c += 1.0)
      if (c > lo) seg.push_back(profile.crossing_time_s(k, c));
    if (f1 < f0) std::reverse(seg.begin(), seg.end());  // a falling segment meets the levels downwards
    out.insert(out.end(), seg.begin(), seg.end());
    f0 = f1;
  }
  return out;
}

std::string to_string(MotorKind k) { return k == MotorKind::Ideal ? "ideal" : "pi"; }

StartupProfile feedforward_setpoint(const StartupProfile& wanted, const MotorModel& m, double end_time_s) {
  constexpr double kTwoPi = 2.0 * 3.14159265358979323846;
  const FeedForward& ff = m.feedforward;
  if (m.kind != MotorKind::PI || !ff.enabled)
    throw ConfigError("motor.feedforward.enabled", ff.enabled ? "true" : "false",
                      "the feed-forward setpoint needs motor.kind: pi and feedforward.enabled: true");
  if (wanted.start_frequency_hz() != 0.0)
    throw ConfigError("profile.start_frequency_hz", format_shortest(wanted.start_frequency_hz()),
                      "must be 0 with motor.feedforward (the inversion starts the drive at rest)");
  const double total = wanted.duration_s();
  if (!(ff.interval_s > 0 && ff.interval_s <= total))
    throw ConfigError("motor.feedforward.interval_s", format_shortest(ff.interval_s),
                      "must be in (0, " + format_shortest(total) + "] s (the profile's duration)");
  const long n = std::max(1L, std::lround(total / ff.interval_s));
  const double h = total / static_cast<double>(n);
  constexpr int kSubsteps = 100;
  constexpr double kTailToleranceHz = 1e-4;
  const double dt = h / kSubsteps;
  const double w = m.omega_m_rad_s, load = m.bearing_torque_Nm / m.inertia_kgm2;
  // delta' of the inversion at (t, delta)
  auto ddelta = [&](double t, double delta) {
    const ProfileSample s = wanted.sample(t);
    const double wd = kTwoPi * s.frequency_hz, wdp = kTwoPi * s.rate_hz_per_s;
    return (wdp + load * std::clamp(wd / 0.1, -1.0, 1.0) - w * w * delta) / (2.0 * m.xi * w);
  };
  std::vector<InclinedSineSegment> out;
  out.reserve(static_cast<std::size_t>(n));
  // the value the drive is given for the realised reference f (inverse of eq 2.1, whole Hz)
  double err = 0.0;
  auto given = [&](double f, bool feedback) {
    if (m.setpoint_mismatch) f = (64.0 * f + 1.0) / 63.0;  // inverse of eq 2.1
    if (m.quantize_setpoint_1hz) {
      const double q = std::round(f + (feedback ? err : 0.0));
      if (feedback) err += f - q;
      f = q;
    }
    return f;
  };
  const double f_end = wanted.final_frequency_hz();
  double delta = 0.0;
  // the profile's intervals, then (up to end_time_s) the settling tail with the wanted speed held at
  // f_end, until the exact setpoint is within kTailToleranceHz of f_end
  for (long k = 0;; ++k) {
    const double t0 = h * static_cast<double>(k), t1 = h * static_cast<double>(k + 1);
    const bool tail = k >= n;
    if (tail && t1 > end_time_s * (1 + 1e-12)) break;
    for (int j = 0; j < kSubsteps; ++j) {
      const double t = t0 + dt * j;
      const double k1 = ddelta(t, delta);
      const double k2 = ddelta(t + dt / 2, delta + dt / 2 * k1);
      const double k3 = ddelta(t + dt / 2, delta + dt / 2 * k2);
      const double k4 = ddelta(t + dt, delta + dt * k3);
      delta += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    double f = wanted.frequency_hz(t1) + ddelta(t1, delta) / kTwoPi;  // the realised reference wanted
    if (!(f >= 0 && f <= kMaxFrequencyHz))
      throw ConfigError("motor.feedforward", "setpoint " + format_shortest(f) + " Hz at t = " + format_shortest(t1) + " s",
                        "must be in [0, " + format_shortest(kMaxFrequencyHz) +
                            "] Hz: the profile asks the drive for more than its loop can be steered to (make it slower)");
    if (tail && std::abs(f - f_end) <= kTailToleranceHz) {
      out.push_back({given(f_end, false), h});  // settled: from here the drive holds f_end itself
      break;
    }
    out.push_back({given(f, true), h});
    if (k + 1 == n && !(end_time_s > total)) break;  // no tail asked for
  }
  return StartupProfile(std::move(out), 0.0);
}

}  // namespace abuopt
