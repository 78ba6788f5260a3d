#pragma once
// Motor models (spec section 3).
// - Ideal: Omega(t) = 2 pi f(t) exactly as the profile prescribes.
// - PI ("total ABU-model", report 3.2 / appendix C): the disc angle theta follows the reference
//   theta_ref = integral of 2 pi f_ref through
//     J [theta'' - 2 xi omega_m (theta_ref' - theta') - omega_m^2 (theta_ref - theta)]
//       = T_b + sum_i fw_i l_i          (friction feedback from the balls; optional)
//   with the setpoint mismatch of the drive f_real = f_target - (f_target + 1)/64 (eq 2.1) and
//   1 Hz setpoint quantisation as options.
#include <string>
#include <vector>

#include "abuopt/core/profile.hpp"

namespace abuopt {

enum class MotorKind { Ideal, PI };

struct MotorModel {
  MotorKind kind = MotorKind::Ideal;
  // PI parameters (report table 3.3)
  double omega_m_rad_s = 0.7 * 3.14159265358979323846;
  double xi = 0.5;
  double bearing_torque_Nm = 5.0e-4;   // T_b
  double inertia_kgm2 = 30e-6;         // J
  bool friction_feedback = true;       // include sum_i fw_i l_i
  bool setpoint_mismatch = false;      // apply eq 2.1 to the reference
  bool quantize_setpoint_1hz = false;  // round the reference frequency to whole Hz
  // Reference frequency the drive actually follows for a target frequency (mismatch/quantisation).
  double realised_reference_hz(double target_hz) const;
  // With quantize_setpoint_1hz the realised reference is piecewise constant: it jumps where the
  // profile frequency crosses k + 1/2 Hz inside a segment (and possibly at segment breakpoints).
  // Returns those inside-segment crossing times [s], sorted (empty without quantisation). The
  // simulator integrates piecewise between them and the breakpoints (docs/model.md, "Quantised
  // reference").
  std::vector<double> reference_step_times_s(const StartupProfile& profile) const;
};

std::string to_string(MotorKind k);

}  // namespace abuopt
