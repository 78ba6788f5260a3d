// The closed-form tail under the PI drive (docs/model.md 6.1): a run that finishes in closed form
// after the profile ends the same as the integrated run (the balls' final angles to the bit, the
// settling time, the amplitude peak to 1e-9 relative), with far fewer right-hand-side calls; and
// the tail is refused while a ball can still slip (a fast ramp that the drive overshoots).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "abuopt/core/simulator.hpp"

namespace {

using namespace abuopt;

struct Totals {
  long rhs_on = 0, rhs_off = 0;
  int runs = 0;
};

// n starts of `s` with the tail and without it; every outcome must agree.
Totals compare(SimulationSetup s, int n, std::uint64_t seed, const std::string& what) {
  SimulationSetup off = s;
  off.options.closed_form_tail = false;
  s.options.closed_form_tail = true;
  Simulator on_sim(s), off_sim(off);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 2 * M_PI), jitter(-0.3, 0.3);
  const std::size_t nb = s.abu.balls.size();
  Totals t;
  for (int k = 0; k < n; ++k) {
    std::vector<double> b(nb);
    for (std::size_t i = 0; i < nb; ++i)  // with contact: spread, so no start overlaps
      b[i] = s.abu.ball_contact == BallContact::Hard ? 2 * M_PI * static_cast<double>(i) / static_cast<double>(nb) + jitter(rng)
                                                     : u(rng);
    const RunOutcome a = on_sim.run(b), c = off_sim.run(b);
    SCOPED_TRACE(what + ", start " + std::to_string(k));
    EXPECT_EQ(a.status, c.status);
    for (std::size_t i = 0; i < nb; ++i) EXPECT_EQ(a.beta_final[i], c.beta_final[i]);  // bitwise
    EXPECT_EQ(a.residual_imbalance_kgm, c.residual_imbalance_kgm);
    EXPECT_EQ(a.settled, c.settled);
    EXPECT_EQ(a.settling_time_s, c.settling_time_s);
    EXPECT_EQ(a.events, c.events);
    EXPECT_NEAR(a.max_amplitude_mm, c.max_amplitude_mm, 1e-9 * c.max_amplitude_mm);
    t.rhs_on += a.rhs_evaluations;
    t.rhs_off += c.rhs_evaluations;
    ++t.runs;
  }
  return t;
}

SimulationSetup pi_setup() {
  SimulationSetup s;
  s.motor.kind = MotorKind::PI;
  return s;
}

}  // namespace

// The 2003 profile under the report's PI drive (friction feedback on): the tail saves at least
// 40 % of the right-hand sides (measured 59 % on 128 starts).
TEST(ClosedFormTailPi, MatchesIntegrationUnderThePiDrive) {
  const Totals t = compare(pi_setup(), 16, 11, "PI");
  EXPECT_LT(static_cast<double>(t.rhs_on), 0.6 * static_cast<double>(t.rhs_off));
}

TEST(ClosedFormTailPi, MatchesIntegrationWithQuantisedSetpointsAndTheMismatch) {
  SimulationSetup s = pi_setup();
  s.motor.quantize_setpoint_1hz = true;
  s.motor.setpoint_mismatch = true;
  const Totals t = compare(s, 12, 12, "PI + 1 Hz + mismatch");
  EXPECT_LT(static_cast<double>(t.rhs_on), 0.6 * static_cast<double>(t.rhs_off));
}

TEST(ClosedFormTailPi, MatchesIntegrationWithSixBallsInContact) {
  SimulationSetup s = pi_setup();
  s.abu.ball_contact = BallContact::Hard;
  s.abu.balls.assign(6, Ball{1.4e-4 / 3, 3.0e-3});
  const Totals t = compare(s, 8, 13, "six balls, hard contact");
  EXPECT_LT(static_cast<double>(t.rhs_on), 0.6 * static_cast<double>(t.rhs_off));
}

TEST(ClosedFormTailPi, MatchesIntegrationWithoutFrictionFeedbackAndAtHigherFriction) {
  SimulationSetup s = pi_setup();
  s.motor.friction_feedback = false;
  s.abu.friction_mu = 0.04;
  compare(s, 8, 14, "no feedback, mu 0.04");
}

// A ramp to 40 Hz in 0.3 s that the drive cannot follow: it lags and then overshoots after the
// profile has ended, and balls stuck at the end slip again during the overshoot. The tail must wait
// for that (the speed gate and the margin reserve); the outcomes agree with integration.
TEST(ClosedFormTailPi, WaitsForTheDrivesOvershootAfterAFastRamp) {
  SimulationSetup s = pi_setup();
  s.profile = StartupProfile({{40.0, 0.3}});
  s.options.end_time_s = 8.0;
  const Totals fast = compare(s, 16, 15, "fast ramp");
  EXPECT_LT(fast.rhs_on, fast.rhs_off);  // the tail is taken in the end (after the overshoot)
  s.profile = StartupProfile({{25.0, 1.0}, {30.0, 0.2}});  // ends just above resonance
  const Totals near = compare(s, 16, 16, "ends near resonance");
  EXPECT_LT(near.rhs_on, near.rhs_off);
}
