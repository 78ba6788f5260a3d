#pragma once
// Motor models (spec section 3).
// - Ideal: Omega(t) = 2 pi f(t) exactly as the profile prescribes.
// - PI ("total ABU-model", report 3.2 / appendix C): the disc angle theta follows the reference
//   theta_ref = integral of 2 pi f_ref through
//     J [theta'' - 2 xi omega_m (theta_ref' - theta') - omega_m^2 (theta_ref - theta)]
//       = T_b + sum_i fw_i l_i          (friction feedback from the balls; optional)
//   with the setpoint mismatch of the drive f_real = f_target - (f_target + 1)/64 (eq 2.1) and
//   1 Hz setpoint quantisation as options.
// - Feed-forward (PI only, optional): the profile is the speed WANTED of the disc; the drive is
//   given the setpoint that makes its real speed follow it (feedforward_setpoint below,
//   docs/pi_feedforward.md).
#include <string>
#include <vector>

#include "abuopt/core/profile.hpp"

namespace abuopt {

enum class MotorKind { Ideal, PI };

// The feed-forward setpoint of the PI drive: with it the profile is the speed wanted of the disc,
// and the drive is steered with the setpoint computed from it, sampled every interval_s.
struct FeedForward {
  bool enabled = false;
  double interval_s = 0.01;  // the steering program's update interval (a setpoint every 10 ms)
};

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
  FeedForward feedforward;             // PI only: steer with the feed-forward setpoint of the profile
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

// The feed-forward setpoint that makes the PI drive's real speed follow `wanted` (the design made
// for the ideal motor). With e = Omega_ref - Omega and delta' = e the drive is
//   Omega' = 2 xi w e + w^2 delta - (T_b/J) sat(Omega/0.1)   (the balls' torque, ~1e-3: neglected),
// so for Omega = Omega_d = 2 pi f(t):
//   2 xi w delta' + w^2 delta = Omega_d' + (T_b/J) sat(Omega_d/0.1),  delta(0) = 0,
//   Omega_ref = Omega_d + delta'
// (a stable first-order ODE, pole -w/(2 xi); RK4 with interval_s/100 steps). The setpoint is sampled
// at the end of every interval (interval_s rounded so that a whole number fits the profile) and
// returned as inclined-sine segments between the samples, the value the drive is GIVEN:
// - with quantize_setpoint_1hz the samples are whole Hz chosen by first-order error feedback (their
//   running sum follows the exact setpoint's; the loop, 0.35 Hz, averages the +-1 Hz dither);
// - with setpoint_mismatch the samples are pre-distorted by the inverse of eq 2.1,
//   f_target = (64 f + 1)/63, so that the drive's realised reference is the setpoint.
// At the end of a ramp the exact setpoint is still away from the profile's end speed f_end (its
// error decays with the pole above), so with end_time_s > the profile's duration the inversion goes
// on past the profile with the wanted speed held at f_end (the settling tail, up to end_time_s) until
// the setpoint is within 1e-4 Hz of f_end; its last sample is f_end itself (pre-distorted, whole Hz),
// which the drive then holds. With end_time_s <= the duration: the profile's samples only, the drive
// holding the last one. Throws ConfigError ("motor.feedforward")
// when the profile does not start from rest, the motor is not PI or feed-forward is off, the
// interval is not in (0, duration], or a sample falls outside [0, kMaxFrequencyHz] (a design too
// fast for the loop).
StartupProfile feedforward_setpoint(const StartupProfile& wanted, const MotorModel& motor, double end_time_s = 0);

}  // namespace abuopt
