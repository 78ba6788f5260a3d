// The choice of clusters and modes at a hard-contact event (docs/model.md 11.5, 11.8): the
// pivoting choice against the enumeration of every joint option, over random event states.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <utility>

#include "abuopt/core/ball_contact.hpp"
#include "sim_contact.hpp"
#include "sim_run_state.hpp"

using namespace abuopt;
using abuopt::detail::ContactChoiceMethod;
using abuopt::detail::ContactChoiceResult;
using abuopt::detail::RunState;

namespace {

// One random event state: N balls in chains of touching balls (each chain at rest or at one
// speed), a random table state, speed W and acceleration Wp, friction mu; maybe one chain at rest
// whose stick margin has just crossed zero (forced).
struct EventState {
  AbuParameters p;
  std::vector<double> y;
  std::vector<char> forced;
  std::vector<char> touching;  // per ball: touches the next ball of the cyclic order (a link)
  double W = 0, Wp = 0;
};

EventState random_state(std::size_t n, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  EventState s;
  s.p.ball_contact = BallContact::Hard;
  s.p.friction_mu = 0.005 + 0.095 * u(rng);
  s.p.balls.clear();
  const bool identical = u(rng) < 0.5;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = identical ? 3e-3 : 2e-3 + 2e-3 * u(rng);
    s.p.balls.push_back(Ball{1.4e-4 * std::pow(d / 3e-3, 3), d});
  }
  const NondimParameters nd = NondimParameters::from(s.p);
  const StateLayout lay{n};
  s.y.assign(lay.size(), 0.0);
  // chains: ball i touches ball i + 1 with probability 0.6 (never all around)
  s.touching.assign(n, 0);
  for (std::size_t i = 0; i + 1 < n; ++i) s.touching[i] = u(rng) < 0.6;
  double slack = 2 * M_PI;
  for (std::size_t i = 0; i < n; ++i) slack -= contact_spacing(s.p, i, (i + 1) % n);
  std::vector<double> w(n, 0.0);
  double wsum = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (!s.touching[i]) wsum += (w[i] = 0.05 + u(rng));
  double beta = 2 * M_PI * u(rng);
  for (std::size_t i = 0; i < n; ++i) {
    s.y[lay.beta(i)] = detail::wrap_angle(beta);
    beta += contact_spacing(s.p, i, (i + 1) % n) + slack * w[i] / wsum;
  }
  // speeds: per chain at rest (60 %) or one random speed
  s.forced.assign(n, 0);
  const bool force = u(rng) < 0.3;
  bool forced_one = false;
  for (std::size_t i = 0; i < n;) {
    std::size_t j = i;
    while (j + 1 < n && s.touching[j]) ++j;
    const double v = u(rng) < 0.6 ? 0.0 : (u(rng) - 0.5);
    for (std::size_t k = i; k <= j; ++k) s.y[lay.beta_dot(k)] = v;
    if (v == 0.0 && force && !forced_one) {
      const char dirs = static_cast<char>(1 + static_cast<int>(3 * u(rng)) % 3);  // forward, backward or both
      for (std::size_t k = i; k <= j; ++k) s.forced[k] = dirs;
      forced_one = true;
    }
    i = j + 1;
  }
  const double f_hz = 5 + 115 * u(rng);
  s.W = 2 * M_PI * f_hz / nd.omega_n;
  s.Wp = 2 * M_PI * (u(rng) - 0.5) * 40 / (nd.omega_n * nd.omega_n);
  const double amp = 0.1 * u(rng);
  s.y[StateLayout::x] = amp * (2 * u(rng) - 1);
  s.y[StateLayout::y] = amp * (2 * u(rng) - 1);
  s.y[StateLayout::x_dot] = amp * s.W * (2 * u(rng) - 1);
  s.y[StateLayout::y_dot] = amp * s.W * (2 * u(rng) - 1);
  return s;
}

std::unique_ptr<RunState> make_run_state(const EventState& s) {
  auto rs = std::make_unique<RunState>(s.p);
  rs->omega_n = rs->nd.omega_n;
  rs->mu = s.p.friction_mu;
  rs->n = s.p.balls.size();
  rs->modes.assign(rs->n, BallMode::Stick);
  for (std::size_t i = 0; i < rs->n; ++i) {
    const double v = s.y[rs->lay().beta_dot(i)];
    if (v != 0.0) rs->modes[i] = v > 0 ? BallMode::SlipForward : BallMode::SlipBackward;
  }
  rs->forces.resize(rs->n);
  rs->off_a.assign(rs->n, 0);
  rs->off_b.assign(rs->n, 0);
  rs->contact = true;
  detail::contact_setup(*rs, s.y.data());
  return rs;
}

// The conditions of docs/model.md 11.5, checked here from the forces of the choice (rs.forces,
// as choose_contact_modes leaves them) with the same relative tolerances. Returns "" if met.
std::string inconsistency(const RunState& rs, const EventState& s, const std::vector<double>& y) {
  const StateLayout& lay = rs.lay();
  const auto& f = rs.forces;
  const auto& cs = rs.cs;
  char buf[200];
  for (const auto& g : cs.clusters.groups) {
    double scale = 0;
    for (std::size_t i : g) scale += rs.nd.mbar[i] * (rs.mu * std::fabs(f.fn[i]) + std::fabs(f.fw[i]) + std::fabs(f.hb[i]));
    scale = 1e-9 * scale + 1e-300;
    const BallMode m = rs.modes[g.front()];
    char forced = 0;
    for (std::size_t k = 0; k < g.size(); ++k) {
      const std::size_t i = g[k];
      if (rs.modes[i] != m) return "a cluster with two modes";
      if (y[lay.beta_dot(i)] != y[lay.beta_dot(g.front())]) return "a cluster with two speeds";
      if (k + 1 < g.size() && !s.touching[i]) return "a cluster of balls apart";
      forced = static_cast<char>(forced | s.forced[i]);
    }
    if (m == BallMode::Stick) {
      if (y[lay.beta_dot(g.front())] != 0.0) return "a stuck cluster that moves";
      for (std::size_t i : g)
        if (f.margin_fwd[i] < -2 * scale || f.margin_bwd[i] < -2 * scale) {
          std::snprintf(buf, sizeof buf, "stuck margin %g / %g (scale %g)", f.margin_fwd[i], f.margin_bwd[i], scale);
          return buf;
        }
    } else {
      const double sg = m == BallMode::SlipForward ? 1.0 : -1.0;
      // from rest in its direction; a block whose margin in that direction crossed may not
      const bool crossed = (forced & (sg > 0 ? detail::kForcedForward : detail::kForcedBackward)) != 0;
      if (y[lay.beta_dot(g.front())] == 0.0 && !crossed && !(sg * f.betadd[g.front()] > 0)) return "slips against its acceleration";
      if (y[lay.beta_dot(g.front())] * sg < 0) return "slips against its speed";
      for (std::size_t k = 0; k + 1 < g.size(); ++k)
        if (f.contact[g[k]] < -2 * scale) return "a pulling contact";
    }
  }
  // touching neighbours in different clusters at one speed: the front does not fall behind
  for (std::size_t i = 0; i + 1 < rs.n; ++i) {
    if (!s.touching[i] || cs.group_of[i] == cs.group_of[i + 1]) continue;
    if (y[lay.beta_dot(i)] != y[lay.beta_dot(i + 1)]) continue;
    const double tol = 1e-9 * (std::fabs(f.betadd[i]) + std::fabs(f.betadd[i + 1])) + 1e-300;
    if (f.betadd[i + 1] - f.betadd[i] < -2 * tol) return "a cut that closes";
  }
  // a forced chain does not stay stuck whole
  bool any_forced = false, all_stuck = true;
  for (std::size_t i = 0; i < rs.n; ++i)
    if (s.forced[i]) {
      any_forced = true;
      all_stuck = all_stuck && rs.modes[i] == BallMode::Stick;
    }
  if (any_forced && all_stuck) return "a forced chain stays stuck";
  return "";
}

struct Choice {
  ContactChoiceResult res;
  std::vector<BallMode> modes;
  std::vector<char> closed;
  std::string why;
};

Choice choose(const EventState& s, ContactChoiceMethod method) {
  auto rs = make_run_state(s);
  std::vector<double> y = s.y;
  Choice c;
  c.res = detail::choose_contact_modes(*rs, {s.W, s.Wp}, y, s.forced, method);
  c.modes = rs->modes;
  c.closed = rs->cs.closed;
  c.why = inconsistency(*rs, s, y);
  return c;
}

}  // namespace

// Over random event states of 2 to 6 balls: wherever some joint option is consistent, the
// pivoting finds a consistent one; how often it is the enumeration's own choice is printed.
// Over random event states of 2 to 6 balls: wherever some joint option is consistent, the
// pivoting finds a consistent one, and Auto (the simulator's choice) is it. How often it is the
// enumeration's own choice is printed, apart for states with a forced chain: there the random
// state's margins are not at zero (as at a real event), so several blocks may leave stick
// consistently and the enumeration keeps the most balls stuck, the pivoting releases the block
// with the smallest margin; both are consistent (checked).
TEST(ContactModeChoice, PivotingIsConsistentWheneverTheEnumerationIsAndMostlyAgrees) {
  std::mt19937_64 rng(20261123);
  for (std::size_t n = 2; n <= 6; ++n) {
    int states = 0, consistent_e = 0, consistent_p = 0, fallback = 0, pivots = 0, max_pivots = 0;
    int plain = 0, plain_same = 0, forced = 0, forced_same = 0;
    for (int trial = 0; trial < 1000; ++trial) {
      const EventState s = random_state(n, rng);
      const Choice e = choose(s, ContactChoiceMethod::Enumerate);
      const Choice p = choose(s, ContactChoiceMethod::Pivot);
      const Choice a = choose(s, ContactChoiceMethod::Auto);
      ++states;
      // the enumeration's verdict and the independent check agree
      EXPECT_EQ(e.res.consistent, e.why.empty()) << "N " << n << " trial " << trial << ": " << e.why;
      if (p.res.consistent) {
        EXPECT_EQ(p.why, "") << "N " << n << " trial " << trial;
        EXPECT_FALSE(a.res.enumerated);  // Auto is the pivot's choice when that is consistent
        EXPECT_EQ(a.modes, p.modes);
        EXPECT_EQ(a.closed, p.closed);
      }
      if (e.res.consistent) {
        ++consistent_e;
        EXPECT_TRUE(p.res.consistent) << "N " << n << " trial " << trial;
        EXPECT_TRUE(a.res.consistent && a.why.empty()) << "N " << n << " trial " << trial;
        const bool same = p.res.consistent && p.modes == e.modes && p.closed == e.closed;
        const bool f = std::any_of(s.forced.begin(), s.forced.end(), [](char c) { return c != 0; });
        (f ? forced : plain) += 1;
        (f ? forced_same : plain_same) += same;
      }
      consistent_p += p.res.consistent;
      fallback += a.res.enumerated;
      pivots += p.res.pivots;
      max_pivots = std::max(max_pivots, p.res.pivots);
    }
    std::printf("N %zu: %d states, consistent: enumeration %d, pivoting %d; same choice: no forced chain %d of %d, "
                "a forced chain %d of %d; fallbacks %d; pivots mean %.2f max %d\n",
                n, states, consistent_e, consistent_p, plain_same, plain, forced_same, forced, fallback,
                static_cast<double>(pivots) / states, max_pivots);
    EXPECT_GE(consistent_e, states * 9 / 10);  // the random states are mostly solvable
    EXPECT_GE(plain_same, plain * 99 / 100);
    EXPECT_LE(max_pivots, static_cast<int>(4 * n) + 8);
  }
}

// Two touching balls at speeds far below the old absolute tolerance 1e-9 (docs/model.md 11.10):
// a pair that separates (the rear ball slips back, away from the front ball at rest) is not in
// contact: the choice leaves both speeds as they are and the pair open. A pair that approaches as
// slowly is a plastic touch: both at the mean speed (equal masses), momentum kept.
TEST(ContactModeChoice, ASlowlySeparatingPairIsNotJoinedAnApproachingOneIs) {
  EventState s;
  s.p.ball_contact = BallContact::Hard;
  s.p.friction_mu = 0.02;
  s.p.balls.assign(2, Ball{1.4e-4, 3e-3});
  const StateLayout lay{2};
  const NondimParameters nd = NondimParameters::from(s.p);
  s.y.assign(lay.size(), 0.0);
  s.y[lay.beta(0)] = 1.0;
  s.y[lay.beta(1)] = 1.0 + contact_spacing(s.p, 0, 1);  // touching: gap 0 (to rounding)
  s.W = 2 * M_PI * 28.9 / nd.omega_n;
  s.forced.assign(2, 0);
  s.touching = {1, 0};
  // The mode choice at an event where ball `slipping` slides back at -v and the other is at rest; the pair was
  // apart (or cut) before it: two clusters. Returns the run state (modes, links) and the speeds chosen.
  const auto choose = [&](int slipping, double v) {
    EventState a = s;
    a.y[lay.beta_dot(slipping)] = -v;
    auto rs = make_run_state(a);
    rs->cs.closed.assign(2, 0);
    detail::build_clusters(*rs);
    std::vector<double> y = a.y;
    detail::choose_contact_modes(*rs, {a.W, a.Wp}, y, a.forced);
    return std::make_pair(std::move(rs), y);
  };
  for (const double v : {1e-11, 1e-14}) {
    {  // separating: rear (ball 0) slips back at -v, front (ball 1) at rest
      const auto [rs, y] = choose(0, v);
      EXPECT_EQ(y[lay.beta_dot(0)], -v) << v;
      EXPECT_EQ(y[lay.beta_dot(1)], 0.0) << v;
      EXPECT_EQ(rs->cs.closed[0] + rs->cs.closed[1], 0) << v;
      EXPECT_EQ(rs->modes[0], BallMode::SlipBackward) << v;
    }
    {  // approaching: front (ball 1) slips back at -v onto the rear ball at rest
      const auto [rs, y] = choose(1, v);
      EXPECT_NEAR(y[lay.beta_dot(0)], -0.5 * v, 1e-16 * v) << v;
      EXPECT_EQ(y[lay.beta_dot(0)], y[lay.beta_dot(1)]) << v;
    }
  }
}

// Under the PI drive with its friction feedback W' depends on the modes (docs/model.md 11.12).
// Over random event states with a strong coupling (the disc's inertia 1/100 of the report's: m L^2
// / J ~ 2e-2 per ball, against 2e-4), the choice whose trials take W' from the motor equation
// with their own modes is consistent with the forces the right-hand side evaluates for the chosen
// modes (evaluate_forces) wherever the enumeration finds a consistent choice; a choice with W'
// fixed at the modes before the event (version 5) is not, in some of those states.
TEST(ContactModeChoice, UnderThePiDriveTheChoiceIsConsistentWithTheWpOfItsOwnModes) {
  std::mt19937_64 rng(20261124);
  std::uniform_real_distribution<double> u(0, 1);
  const StartupProfile profile = StartupProfile::report_final();
  int solvable = 0, fresh_bad = 0, stale_bad = 0;
  for (std::size_t n = 2; n <= 6; ++n) {
    for (int trial = 0; trial < 300; ++trial) {
      EventState s = random_state(n, rng);
      const double tbar = (2 + 15 * u(rng)) * NondimParameters::from(s.p).omega_n;  // inside the profile
      const double delta = 1e-3 * (2 * u(rng) - 1);
      auto pi_state = [&] {
        auto rs = make_run_state(s);
        rs->pi_motor = true;
        rs->profile = &profile;
        rs->motor.kind = MotorKind::PI;
        rs->motor.friction_feedback = true;
        rs->motor.inertia_kgm2 = 0.3e-6;
        rs->motor.bearing_torque_Nm = 0;
        return rs;
      };
      std::vector<double> y0 = s.y;
      y0.push_back(delta);  // motor_delta
      y0.push_back(s.W);    // motor_speed
      // the choice with W' from its own modes, and its check with the right-hand side's forces
      auto fresh = [&](ContactChoiceMethod method, std::string& why) {
        auto rs = pi_state();
        std::vector<double> y = y0;
        const ContactChoiceResult r = detail::choose_contact_modes(*rs, detail::choice_speed(*rs, tbar, {s.W, 0}), y, s.forced, method);
        detail::evaluate_forces(*rs, tbar, y.data());
        why = inconsistency(*rs, s, y);
        return r.consistent;
      };
      std::string why_e, why_a;
      if (!fresh(ContactChoiceMethod::Enumerate, why_e)) continue;
      ++solvable;
      EXPECT_EQ(why_e, "") << "N " << n << " trial " << trial;
      EXPECT_TRUE(fresh(ContactChoiceMethod::Auto, why_a)) << "N " << n << " trial " << trial;
      fresh_bad += !why_a.empty();
      EXPECT_EQ(why_a, "") << "N " << n << " trial " << trial;
      // version 5: every trial with the W' of the modes before the event
      auto rs = pi_state();
      std::vector<double> y = y0;
      const double stale = detail::evaluate_forces(*rs, tbar, y.data()).Wp;
      detail::choose_contact_modes(*rs, {s.W, stale}, y, s.forced);
      detail::evaluate_forces(*rs, tbar, y.data());
      stale_bad += !inconsistency(*rs, s, y).empty();
    }
  }
  std::printf("PI drive, strong coupling: %d solvable states; inconsistent with the right-hand side's W': "
              "own-modes W' %d, W' of the old modes %d\n", solvable, fresh_bad, stale_bad);
  EXPECT_GE(solvable, 1200);
  EXPECT_EQ(fresh_bad, 0);
  EXPECT_GT(stale_bad, 0);  // the test can tell the two apart
}
