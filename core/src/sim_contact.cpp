// Hard ball-ball contact in the event-driven simulator (docs/model.md section 11).
//
// Root functions with contact (two per ball as without contact, plus one per neighbour pair):
//   stuck cluster, ball i:     g_a = margin_fwd[i]  (the balls from i to the front slip forward)
//                              g_b = margin_bwd[i]  (the balls from the rear to i slip backward)
//   slipping cluster, ball i:  g_a = contact force to the next ball (a contact opens), or, for
//                              the front ball, sigma beta_i' (the cluster stops); g_b = 1
//   pair k:                    g = gap_k while the pair is apart (an approach), 1 when clustered
// A single ball is a cluster of one: its functions are the ones without contact (times mbar_i).
#include <algorithm>
#include <cmath>
#include <limits>

#include "abuopt/core/sim_counters.hpp"
#include "sim_contact.hpp"

namespace abuopt::detail {

namespace {

constexpr double kGapOffset = 1e-12;  // rad: a gap that starts below this is shifted up to it

}  // namespace

// Rebuilds the clusters from cs.closed, walking the cyclic order from just after an open pair.
void build_clusters(RunState& rs) {
  ContactState& cs = rs.cs;
  const std::size_t n = rs.n;
  cs.clusters.groups.clear();
  cs.group_of.assign(n, -1);
  std::size_t open = n;
  for (std::size_t k = 0; k < n; ++k)
    if (!cs.closed[k]) open = k;
  if (open == n) {  // all closed cannot happen (the balls fit with room to spare); keep one open
    open = n - 1;
    cs.closed[open] = 0;
  }
  std::vector<std::size_t> cur;
  for (std::size_t step = 0; step < n; ++step) {
    const std::size_t pos = (open + 1 + step) % n;
    cur.push_back(cs.geo.order[pos]);
    if (!cs.closed[pos]) {
      for (std::size_t i : cur) cs.group_of[i] = static_cast<int>(cs.clusters.groups.size());
      cs.clusters.groups.push_back(cur);
      cur.clear();
    }
  }
}

double group_scale(const RunState& rs, const std::vector<std::size_t>& g) {
  double s = 0;
  for (std::size_t i : g)
    s += rs.nd.mbar[i] * (rs.mu * std::fabs(rs.forces.fn[i]) + std::fabs(rs.forces.fw[i]) + std::fabs(rs.forces.hb[i]));
  return s;
}

void contact_setup(RunState& rs, const double* y) {
  ContactState& cs = rs.cs;
  const StateLayout& lay = rs.lay();
  std::vector<double> beta(rs.n);
  for (std::size_t i = 0; i < rs.n; ++i) beta[i] = y[lay.beta(i)];
  cs.geo = ContactGeometry::from(rs.params, beta);
  cs.closed.assign(rs.n, 0);
  for (std::size_t k = 0; k < cs.geo.pairs(); ++k) cs.closed[k] = cs.geo.gap(y + lay.beta(0), k) <= kGapTol ? 1 : 0;
  build_clusters(rs);
  cs.off_gap.assign(rs.n, 0.0);
  cs.off_lambda.assign(rs.n, 0.0);
  cs.restitution = rs.params.ball_restitution;
  // 1 mm/s relative speed along the rim, non-dimensional (L omega_n beta')
  cs.v_stop = 1e-3 / (rs.params.ball_track_radius_m * rs.omega_n);
}

void switch_contact_modes(RunState& rs, const ChoiceSpeed& sp, const double* y) {
  ContactState& cs = rs.cs;
  rs.switch_y.assign(y, y + rs.lay().size());
  rs.switch_forced.assign(rs.n, 0);
  rs.switch_closed = cs.closed;
  choose_contact_modes(rs, sp, rs.switch_y, rs.switch_forced, run_contact_choice(), rs.opt.switch_band);
  for (std::size_t k = 0; k < cs.geo.pairs(); ++k) {
    if (!rs.switch_closed[k] || cs.closed[k]) continue;
    const double gk = cs.geo.gap(y + rs.lay().beta(0), k);
    cs.off_gap[k] = gk < kGapOffset ? kGapOffset - gk : 0.0;
  }
}

void roots_contact(double tbar, const double* y, double* g, void* user) {
  auto& rs = *static_cast<RunState*>(user);
  const StateLayout& lay = rs.lay();
  const ContactState& cs = rs.cs;
  if (switch_model(rs)) {
    // the switch model's events: gaps closing only (stick, slip and separation are chosen at
    // every right-hand-side call)
    std::fill(g, g + 2 * rs.n, 1.0);
    for (std::size_t k = 0; k < cs.geo.pairs(); ++k)
      g[2 * rs.n + k] = cs.closed[k] ? 1.0 : cs.geo.gap(y + lay.beta(0), k) + cs.off_gap[k];
    return;
  }
  evaluate_forces(rs, tbar, y);
  for (const auto& grp : cs.clusters.groups) {
    const BallMode mode = rs.modes[grp.front()];
    for (std::size_t k = 0; k < grp.size(); ++k) {
      const std::size_t i = grp[k];
      if (mode == BallMode::Stick) {
        g[2 * i] = rs.forces.margin_fwd[i] + rs.off_a[i];
        g[2 * i + 1] = rs.forces.margin_bwd[i] + rs.off_b[i];
      } else {
        g[2 * i] = k + 1 < grp.size() ? rs.forces.contact[i] + cs.off_lambda[i]
                                      : static_cast<double>(static_cast<signed char>(mode)) * y[lay.beta_dot(i)];
        g[2 * i + 1] = 1.0;
      }
    }
  }
  for (std::size_t k = 0; k < cs.geo.pairs(); ++k)
    g[2 * rs.n + k] = cs.closed[k] ? 1.0 : cs.geo.gap(y + lay.beta(0), k) + cs.off_gap[k];
}

void root_rates_contact(double, const double* y, double* gd, void* user) {
  const auto& rs = *static_cast<const RunState*>(user);
  const StateLayout& lay = rs.lay();
  const ContactState& cs = rs.cs;
  std::fill(gd, gd + 2 * rs.n, 0.0);
  // the angles' rates: the speeds, but zero for a ball the switch model holds stuck
  const bool sw = switch_model(rs);
  auto rate = [&](std::size_t i) { return sw && rs.modes[i] == BallMode::Stick ? 0.0 : y[lay.beta_dot(i)]; };
  for (std::size_t k = 0; k < cs.geo.pairs(); ++k)
    gd[2 * rs.n + k] = cs.closed[k] ? 0.0 : rate(cs.geo.order[(k + 1) % rs.n]) - rate(cs.geo.order[k]);
}

// The slipping clusters' stop functions sigma beta_f' (f: the cluster's front ball) have the rate
// sigma beta_f'' = sigma dydt[beta_dot(f)], from the right-hand side the stepper has at a step's
// ends (docs/model.md 11.11): a cluster that reverses and back inside one step is then found by
// the dip check. Only for the dip check (ErkStepper::set_dip_rates), never for Newton polishing.
// Everything else 0 (margins, contact forces, gaps: their rates are root_rates_contact's or none).
void stop_rates_contact(double, const double* y, const double* dydt, double* gd, void* user) {
  (void)y;
  const auto& rs = *static_cast<const RunState*>(user);
  const StateLayout& lay = rs.lay();
  const ContactState& cs = rs.cs;
  std::fill(gd, gd + 2 * rs.n + cs.geo.pairs(), 0.0);
  if (switch_model(rs)) return;  // its functions 0 .. 2n-1 are constants
  for (const auto& grp : cs.clusters.groups) {
    const BallMode mode = rs.modes[grp.front()];
    if (mode == BallMode::Stick) continue;
    const std::size_t f = grp.back();
    gd[2 * f] = static_cast<double>(static_cast<signed char>(mode)) * dydt[lay.beta_dot(f)];
  }
}

// Functions that start at or below zero by rounding are shifted so their later crossing is seen.
void set_contact_root_offsets(RunState& rs, double tbar, const double* y) {
  const StateLayout& lay = rs.lay();
  ContactState& cs = rs.cs;
  evaluate_forces(rs, tbar, y);
  for (const auto& grp : cs.clusters.groups) {
    const double scale = 1e-10 * group_scale(rs, grp) + 1e-300;
    const bool stuck = rs.modes[grp.front()] == BallMode::Stick;
    for (std::size_t i : grp) {
      rs.off_a[i] = rs.off_b[i] = cs.off_lambda[i] = 0;
      if (stuck) {
        if (rs.forces.margin_fwd[i] < scale) rs.off_a[i] = scale - rs.forces.margin_fwd[i];
        if (rs.forces.margin_bwd[i] < scale) rs.off_b[i] = scale - rs.forces.margin_bwd[i];
      } else if (i != grp.back() && rs.forces.contact[i] < scale) {
        cs.off_lambda[i] = scale - rs.forces.contact[i];
      }
    }
  }
  for (std::size_t k = 0; k < cs.geo.pairs(); ++k) {
    cs.off_gap[k] = 0;
    if (cs.closed[k]) continue;
    const double gk = cs.geo.gap(y + lay.beta(0), k);
    if (gk < kGapOffset) cs.off_gap[k] = kGapOffset - gk;
  }
}

int handle_contact_event(RunState& rs, double tbar, std::vector<double>& y, const std::vector<int>& rinfo) {
  ContactState& cs = rs.cs;
  const StateLayout& lay = rs.lay();
  const std::size_t n = rs.n;
  const bool sw = switch_model(rs);
  if (sw) {
    // Switch model: the clusters and modes at the event's state; a stuck ball does not move
    // (its angle is frozen), so the impact sees it at zero speed, and a cluster at its mean speed.
    const Speed s = rs.pi_motor ? evaluate_forces(rs, tbar, y.data()) : ideal_speed(rs, tbar);
    switch_contact_modes(rs, {s.W, s.Wp}, y.data());
    for (const auto& g : cs.clusters.groups) {
      double v = 0;
      for (std::size_t i : g) v += y[lay.beta_dot(i)];
      v = rs.modes[g.front()] == BallMode::Stick ? 0.0 : v / static_cast<double>(g.size());
      for (std::size_t i : g) y[lay.beta_dot(i)] = v;
    }
  }
  const Speed sp0 = evaluate_forces(rs, tbar, y.data());
  const std::vector<std::vector<std::size_t>> old_groups = cs.clusters.groups;
  const std::vector<BallMode> old_modes = rs.modes;
  std::vector<char> forced(n, 0), struck(n, 0);
  int impacts = 0;
  for (std::size_t k = 0; k < cs.geo.pairs(); ++k) {
    if (!rinfo[2 * n + k] || cs.closed[k]) continue;
    const std::size_t rear = cs.geo.order[k], front = cs.geo.order[(k + 1) % n];
    const double vrel = y[lay.beta_dot(front)] - y[lay.beta_dot(rear)];
    if (!(vrel < 0)) continue;  // grazing: the mode choice may join them
    const double e = -vrel > cs.v_stop ? cs.restitution : 0.0;
    std::vector<double> qdot(2 + n);
    qdot[0] = y[StateLayout::x_dot];
    qdot[1] = y[StateLayout::y_dot];
    std::vector<char> held(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
      qdot[2 + i] = y[lay.beta_dot(i)];
      held[i] = rs.modes[i] == BallMode::Stick;
    }
    apply_impact(rs.nd, y.data() + lay.beta(0), qdot, cs.group_of, held, rear, front, e);
    for (std::size_t i = 0; i < n; ++i)
      if (cs.group_of[i] == cs.group_of[rear] || cs.group_of[i] == cs.group_of[front]) struck[i] = 1;
    y[StateLayout::x_dot] = qdot[0];
    y[StateLayout::y_dot] = qdot[1];
    for (std::size_t i = 0; i < n; ++i) y[lay.beta_dot(i)] = qdot[2 + i];
    if (e == 0.0) {
      // plastic: one cluster at the common speed (equal up to rounding; made exact)
      const int ga = cs.group_of[rear], gb = cs.group_of[front];
      double num = 0, den = 0;
      for (std::size_t i = 0; i < n; ++i)
        if (cs.group_of[i] == ga || cs.group_of[i] == gb) {
          num += rs.nd.mbar[i] * rs.nd.D[i] * y[lay.beta_dot(i)];
          den += rs.nd.mbar[i] * rs.nd.D[i];
        }
      for (std::size_t i = 0; i < n; ++i)
        if (cs.group_of[i] == ga || cs.group_of[i] == gb) y[lay.beta_dot(i)] = num / den;
      cs.closed[k] = 1;
      build_clusters(rs);
    }
    // a struck cluster that was stuck moves now: its mode follows its speed
    for (std::size_t i = 0; i < n; ++i)
      if (y[lay.beta_dot(i)] != 0.0)
        rs.modes[i] = y[lay.beta_dot(i)] > 0 ? BallMode::SlipForward : BallMode::SlipBackward;
    ++impacts;
  }
  cs.impacts += impacts;
  // then the stick/slip roots of the clusters (as they were before the impacts)
  for (const auto& grp : old_groups) {
    const BallMode mode = old_modes[grp.front()];
    bool hit = false;
    for (std::size_t i : grp) hit = hit || struck[i];
    if (mode == BallMode::Stick) {
      char fired = 0;  // the directions whose margins crossed
      for (std::size_t i : grp)
        fired |= static_cast<char>((rinfo[2 * i] != 0 ? kForcedForward : 0) | (rinfo[2 * i + 1] != 0 ? kForcedBackward : 0));
      for (std::size_t i : grp) forced[i] = hit ? 0 : fired;
    } else if (rinfo[2 * grp.back()] != 0 && !hit) {
      for (std::size_t i : grp) y[lay.beta_dot(i)] = 0.0;  // the cluster stopped
    }
  }
  // a gap that is still (rounding-small) negative is closed by moving the two sides apart
  for (std::size_t k = 0; k < cs.geo.pairs(); ++k) {
    const double gk = cs.geo.gap(y.data() + lay.beta(0), k);
    if (gk >= 0) continue;
    const std::size_t rear = cs.geo.order[k], front = cs.geo.order[(k + 1) % n];
    y[lay.beta(rear)] += 0.5 * gk;
    y[lay.beta(front)] -= 0.5 * gk;
    cs.max_correction = std::max(cs.max_correction, -gk);
    sim_counters().max_gap_correction = std::max(sim_counters().max_gap_correction, -gk);
  }
  const Speed sp = rs.pi_motor ? sp0 : ideal_speed(rs, tbar);
  // the switch model chooses with its band (balls chosen stuck get zero speed, as at its impacts)
  // (the switch model re-chooses at every right-hand-side call, with that call's W': its choice
  // takes W' as given; docs/model.md 11.12)
  choose_contact_modes(rs, sw ? ChoiceSpeed{sp.W, sp.Wp} : choice_speed(rs, tbar, sp), y, forced, run_contact_choice(),
                       sw ? rs.opt.switch_band : 0.0);
  return impacts;
}

}  // namespace abuopt::detail
