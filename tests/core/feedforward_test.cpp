// The PI drive's feed-forward setpoint (motor.feedforward, docs/pi_feedforward.md): the samples
// against the reference numbers of the script it replaces (scripts/pi_feedforward.py, removed,
// run on the deep six-ball design), the derivation's closed forms (steady state, the lead on a
// run-up), the whole-Hz error feedback, the inverse of the setpoint mismatch, and the point of it:
// under `kind: pi` the drive's real speed follows the profile; the config keys and their errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "abuopt/common/config_error.hpp"
#include "abuopt/core/simulation_config.hpp"
#include "abuopt/core/simulator.hpp"

using namespace abuopt;

namespace {

// The deep six-ball design's profile (contact_best_19s_deep_6balls.yaml, as written; git show
// e47fec4:configs/studies/best/contact_best_19s_deep_6balls.yaml).
StartupProfile deep_6balls() {
  return StartupProfile({{26.30880504, 1.891213032},
                         {28.9422839, 4.88322},
                         {28.9422839, 0.062253},
                         {24.10073103, 0.195618},
                         {29.02495726, 0.198959},
                         {29.02495726, 2.360223},
                         {31.28616402, 0.113857},
                         {28.89844118, 0.096474},
                         {28.89844118, 1.645636},
                         {100, 7.410223}},
                        0.0);
}

MotorModel ff_pi(bool whole_hz = false, bool mismatch = false, double interval = 0.01) {
  MotorModel m;
  m.kind = MotorKind::PI;
  m.feedforward.enabled = true;
  m.feedforward.interval_s = interval;
  m.quantize_setpoint_1hz = whole_hz;
  m.setpoint_mismatch = mismatch;
  return m;
}

// A run-up, a dwell, a 5 Hz dip and back at 50 Hz/s peak (0.2 s each way), a dwell: a fast
// excursion that the drive alone does not follow.
StartupProfile dip() { return StartupProfile({{25, 2.0}, {25, 1.0}, {20, 0.2}, {25, 0.2}, {25, 1.0}}, 0.0); }

// The largest |real speed - profile| from t0 to the profile's end, PI drive, two report balls.
double speed_error(const MotorModel& m, double t0) {
  SimulationSetup s;
  s.profile = dip();
  s.motor = m;
  s.abu.friction_mu = 0.02;
  s.options.trajectory_interval_s = 0.005;
  s.options.end_time_s = dip().duration_s();
  const Simulator sim(s);
  std::vector<TrajectoryPoint> traj;
  const RunOutcome out = sim.run({0.5, 2.0}, {}, &traj);
  EXPECT_EQ(out.status, RunStatus::Ok) << out.message;
  double worst = 0;
  for (const TrajectoryPoint& p : traj)
    if (p.t_s >= t0 && p.t_s <= dip().duration_s())
      worst = std::max(worst, std::fabs(p.frequency_hz - dip().frequency_hz(p.t_s)));
  return worst;
}

std::string error_of(const std::string& yaml) {
  try {
    YamlReader root = YamlReader::load_string(yaml);
    const SimulationSetup s = read_simulation_setup(root);
    root.finish();
    Simulator sim(s);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "<no error>";
}

}  // namespace

// scripts/pi_feedforward.py on deep_6balls() above (its setpoint() with the defaults: 0.01 s,
// 100 RK4 substeps, the report's drive), printed with repr.
TEST(FeedForward, MatchesTheScriptItReplaces) {
  const StartupProfile sp = feedforward_setpoint(deep_6balls(), ff_pi());
  ASSERT_EQ(sp.segments().size(), 1886u);
  EXPECT_NEAR(sp.segments()[0].duration_s, 0.00999876777942736, 1e-15);
  EXPECT_EQ(sp.start_frequency_hz(), 0.0);
  const std::vector<std::pair<std::size_t, double>> ref = {
      {0, 0.00541811563471706},  {9, 1.4625088184190038},  {99, 19.10746905362482},  {188, 21.9870297392255},
      {500, 28.265004254856667}, {700, 25.2088270755173},  {701, 27.103646385835177}, {702, 27.950426517415472},
      {710, 47.18922710650736},  {720, 30.132291898492007}, {730, 27.791721113741925}, {740, 28.035147642853943},
      {750, 28.230524595041604}, {1000, 29.233692520217154}, {1885, 99.43531166366408}};
  for (const auto& [k, f] : ref) EXPECT_NEAR(sp.segments()[k].end_frequency_hz, f, 1e-9) << "sample " << k;
  // the script's --whole-hz: the same error feedback gives the same integers
  const StartupProfile q = feedforward_setpoint(deep_6balls(), ff_pi(true));
  const std::vector<std::pair<std::size_t, double>> qref = {{0, 0},    {9, 1},    {99, 19},  {188, 22}, {500, 29},
                                                            {700, 25}, {710, 47}, {720, 30}, {730, 27}, {1885, 99}};
  for (const auto& [k, f] : qref) EXPECT_EQ(q.segments()[k].end_frequency_hz, f) << "sample " << k;
  double sum = 0;
  for (std::size_t k = 0; k < 1000; ++k) sum += q.segments()[k].end_frequency_hz;
  EXPECT_EQ(sum, 25316.0);  // the script's; the exact samples sum to 25315.86
}

// docs/pi_feedforward.md, "The inverse": in steady state (Omega_d' = 0) delta -> T_b/(J w^2) and
// e = delta' -> 0 with the pole -w/(2 xi): the setpoint becomes the speed. While the speed rises,
// delta' > 0: the setpoint leads. In a dwell the forcing is constant and the lead decays as e^{-p t}.
TEST(FeedForward, FollowsTheDerivation) {
  const MotorModel m = ff_pi();
  const StartupProfile up({{25.0, 2.0}, {25.0, 10.0}}, 0.0);
  const StartupProfile sp = feedforward_setpoint(up, m);
  ASSERT_EQ(sp.segments().size(), 1200u);
  // 10 s of dwell = 22 time constants (2 xi / w = 0.45 s): e decays as e^{-22}
  EXPECT_NEAR(sp.segments().back().end_frequency_hz, 25.0, 1e-6);
  // at 1 s (half way up, 12.5 Hz, Omega_d' = 2 pi 25 rad/s^2) the setpoint leads by more than 1 Hz
  EXPECT_GT(sp.segments()[99].end_frequency_hz, up.frequency_hz(1.0) + 1.0);
  // in the dwell the forcing is constant: e = delta' decays exactly as e^{-p t}, p = w/(2 xi)
  const double p = m.omega_m_rad_s / (2 * m.xi);
  const double e1 = sp.segments()[299].end_frequency_hz - 25.0, e2 = sp.segments()[399].end_frequency_hz - 25.0;
  EXPECT_GT(std::fabs(e1), 0.01);
  EXPECT_NEAR(e2 / e1, std::exp(-p * 1.0), 1e-6);
  // the fast content: e ~ Omega_d'/(2 xi w) below and above the speed in the deep excursion
  // (-311 rad/s^2: ~22.5 Hz below; the exact samples bottom at 6.3 Hz and peak at 49.8 Hz)
  const StartupProfile deep = feedforward_setpoint(deep_6balls(), m);
  double lo = 1e9, hi = 0;
  for (std::size_t k = 690; k < 730; ++k) {
    lo = std::min(lo, deep.segments()[k].end_frequency_hz);
    hi = std::max(hi, deep.segments()[k].end_frequency_hz);
  }
  EXPECT_NEAR(lo, 6.3, 0.5);
  EXPECT_NEAR(hi, 49.8, 0.5);
}

// Whole Hz by first-order error feedback: integers whose running sum follows the exact samples'
// within half a hertz-sample; with the mismatch the samples are pre-distorted by (64 f + 1)/63.
TEST(FeedForward, WholeHzAndMismatch) {
  const StartupProfile exact = feedforward_setpoint(dip(), ff_pi());
  const StartupProfile q = feedforward_setpoint(dip(), ff_pi(true));
  ASSERT_EQ(q.segments().size(), exact.segments().size());
  double run = 0, worst = 0;
  for (std::size_t k = 0; k < q.segments().size(); ++k) {
    const double f = q.segments()[k].end_frequency_hz;
    EXPECT_EQ(f, std::round(f));
    run += exact.segments()[k].end_frequency_hz - f;
    worst = std::max(worst, std::fabs(run));
  }
  EXPECT_LE(worst, 0.5 + 1e-9);
  MotorModel mm = ff_pi(false, true);
  const StartupProfile pre = feedforward_setpoint(dip(), mm);
  for (std::size_t k : {0u, 150u, 300u, 439u}) {
    const double target = pre.segments()[k].end_frequency_hz;
    EXPECT_NEAR(mm.realised_reference_hz(target), exact.segments()[k].end_frequency_hz, 1e-12) << k;
  }
}

// The point of it: under the PI drive the feed-forward setpoint keeps the real speed on the
// profile over the 5 Hz dip, where the profile itself as the setpoint is off by more than 1 Hz;
// also with the 1 Hz setpoints (the dither is averaged by the loop) and with the mismatch.
TEST(FeedForward, TheDriveFollowsTheProfile) {
  MotorModel plain;
  plain.kind = MotorKind::PI;
  EXPECT_GT(speed_error(plain, 3.0), 1.0);
  EXPECT_LT(speed_error(ff_pi(), 0.0), 0.05);
  EXPECT_LT(speed_error(ff_pi(true), 0.0), 0.1);
  EXPECT_LT(speed_error(ff_pi(false, true), 0.0), 0.05);
  EXPECT_LT(speed_error(ff_pi(true, true), 0.0), 0.1);
}

TEST(FeedForward, ConfigKeysAndErrors) {
  const std::string head = "profile: {segments: [{end_frequency_hz: 25, duration_s: 2}, {end_frequency_hz: 25, "
                           "duration_s: 1}]}\n";
  YamlReader root = YamlReader::load_string(head + "motor: {kind: pi, feedforward: {enabled: true, interval_s: 0.02}}\n");
  const SimulationSetup s = read_simulation_setup(root);
  root.finish();
  EXPECT_TRUE(s.motor.feedforward.enabled);
  EXPECT_EQ(s.motor.feedforward.interval_s, 0.02);
  EXPECT_EQ(feedforward_setpoint(s.profile, s.motor).segments().size(), 150u);
  EXPECT_NE(to_yaml(s).find("feedforward:"), std::string::npos);
  // strict keys, the ideal motor, the interval, a start above rest, a design too fast for the loop
  EXPECT_NE(error_of(head + "motor: {kind: pi, feedforward: {enabled: true, interval: 0.02}}\n").find("interval"),
            std::string::npos);
  EXPECT_NE(error_of(head + "motor: {kind: ideal, feedforward: {enabled: true}}\n")
                .find("motor.feedforward.enabled = true: needs kind: pi"),
            std::string::npos);
  EXPECT_NE(error_of(head + "motor: {kind: pi, feedforward: {enabled: true, interval_s: 5}}\n")
                .find("motor.feedforward.interval_s = 5: must be in (0, 3]"),
            std::string::npos);
  EXPECT_NE(error_of("profile: {start_frequency_hz: 5, segments: [{end_frequency_hz: 25, duration_s: 2}]}\n"
                     "motor: {kind: pi, feedforward: {enabled: true}}\n")
                .find("profile.start_frequency_hz = 5: must be 0"),
            std::string::npos);
  EXPECT_NE(error_of("profile: {segments: [{end_frequency_hz: 25, duration_s: 2}, {end_frequency_hz: 0, "
                     "duration_s: 0.05}]}\nmotor: {kind: pi, feedforward: {enabled: true}}\n")
                .find("motor.feedforward = setpoint -"),
            std::string::npos);
  EXPECT_EQ(error_of(head + "motor: {kind: pi, feedforward: {enabled: false, interval_s: 0.02}}\n"), "<no error>");
}

// The settling tail (review finding 3): at the end of a ramp the exact setpoint is still away from
// the end speed (the error decays as e^(-2.2 t)); holding the profile's last sample set the final
// speed wrong for the whole tail, where the residual imbalance is measured. With the end time the
// setpoint goes on to f_end itself, and the drive ends at f_end.
TEST(FeedForward, TheSettlingTailEndsAtTheProfilesEndSpeed) {
  const StartupProfile ramp({{25, 2.0}}, 0.0);  // ends on a ramp
  for (bool whole_hz : {false, true}) {
    SCOPED_TRACE(whole_hz ? "1 Hz setpoints" : "exact setpoints");
    const MotorModel m = ff_pi(whole_hz);
    const StartupProfile cut = feedforward_setpoint(ramp, m);  // no end time: the profile's samples only
    const StartupProfile tail = feedforward_setpoint(ramp, m, 12.0);
    ASSERT_EQ(cut.segments().size(), 200u);
    // the old hold: off by more than 3 Hz (the exact setpoint is 21.25 Hz at 2 s)
    if (!whole_hz) {
      EXPECT_GT(std::fabs(cut.final_frequency_hz() - 25.0), 3.0);
    }
    // the profile's samples unchanged, then a tail (4.8 s) that ends at 25 Hz exactly
    for (std::size_t k = 0; k < 200; ++k)
      ASSERT_EQ(tail.segments()[k].end_frequency_hz, cut.segments()[k].end_frequency_hz) << k;
    EXPECT_GT(tail.duration_s(), 3.0);
    EXPECT_LT(tail.duration_s(), 12.0 - 1e-9);
    EXPECT_EQ(tail.final_frequency_hz(), 25.0);
    // an end time before the tail has settled: the tail stops there
    EXPECT_NEAR(feedforward_setpoint(ramp, m, 2.5).duration_s(), 2.5, 1e-9);

    // the drive's real speed at the end of a run: within 0.01 Hz of 25 Hz (the held last sample: 3.75 Hz off)
    SimulationSetup s;
    s.profile = ramp;
    s.motor = m;
    s.abu.friction_mu = 0.02;
    s.options.trajectory_interval_s = 0.01;
    s.options.end_time_s = 12.0;
    std::vector<TrajectoryPoint> traj;
    const RunOutcome out = Simulator(s).run({0.5, 2.0}, {}, &traj);
    ASSERT_EQ(out.status, RunStatus::Ok) << out.message;
    ASSERT_FALSE(traj.empty());
    EXPECT_NEAR(traj.back().t_s, 12.0, 0.011);
    EXPECT_NEAR(traj.back().frequency_hz, 25.0, 0.01);
  }
}
