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

std::string to_string(MotorKind k) { return k == MotorKind::Ideal ? "ideal" : "pi"; }

}  // namespace abuopt
