#include "abuopt/core/motor.hpp"

#include <algorithm>
#include <cmath>

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

}  // namespace abuopt
