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

#include "sim_run_state.hpp"

namespace abuopt::detail {

namespace {

constexpr double kGapTol = 1e-9;      // rad: a pair this close counts as touching
constexpr double kGapOffset = 1e-12;  // rad: a gap that starts below this is shifted up to it

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

}  // namespace

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

void roots_contact(double tbar, const double* y, double* g, void* user) {
  auto& rs = *static_cast<RunState*>(user);
  const StateLayout& lay = rs.lay();
  const ContactState& cs = rs.cs;
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
  for (std::size_t k = 0; k < cs.geo.pairs(); ++k)
    gd[2 * rs.n + k] = cs.closed[k] ? 0.0
                                    : y[lay.beta_dot(cs.geo.order[(k + 1) % rs.n])] - y[lay.beta_dot(cs.geo.order[k])];
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

void choose_contact_modes(RunState& rs, double W, double Wp, std::vector<double>& y, const std::vector<char>& forced) {
  ContactState& cs = rs.cs;
  const StateLayout& lay = rs.lay();
  const std::size_t n = rs.n, K = cs.geo.pairs();
  const double* beta = y.data() + lay.beta(0);
  // Links that may be closed: clustered pairs, and pairs touching at equal speed.
  std::vector<char> link(K, 0);
  for (std::size_t k = 0; k < K; ++k) {
    const std::size_t a = cs.geo.order[k], b = cs.geo.order[(k + 1) % n];
    const double va = y[lay.beta_dot(a)], vb = y[lay.beta_dot(b)];
    link[k] = cs.closed[k] || (cs.geo.gap(beta, k) <= kGapTol && std::fabs(vb - va) <= 1e-9 * (1 + std::fabs(va)));
  }
  if (std::all_of(link.begin(), link.end(), [](char c) { return c != 0; })) link[K - 1] = 0;
  // Touch clusters: chains joined by links. Each is an independent choice of cuts and modes.
  struct Touch {
    std::vector<std::size_t> balls;  // rear to front
    std::vector<std::size_t> links;  // pair index after balls[j] (j < size - 1)
    double v = 0;
    bool forced = false;
    std::size_t options = 0;
  };
  std::vector<Touch> touch;
  {
    std::size_t open = 0;
    for (std::size_t k = 0; k < K; ++k)
      if (!link[k]) open = k;
    Touch cur;
    for (std::size_t step = 0; step < n; ++step) {
      const std::size_t pos = (open + 1 + step) % n;
      const std::size_t i = cs.geo.order[pos];
      cur.balls.push_back(i);
      cur.forced = cur.forced || forced[i];
      if (link[pos]) {
        cur.links.push_back(pos);
      } else {
        touch.push_back(cur);
        cur = Touch{};
      }
    }
  }
  std::size_t total = 1;
  for (Touch& tc : touch) {
    double sum = 0;
    for (std::size_t i : tc.balls) sum += y[lay.beta_dot(i)];
    tc.v = sum / static_cast<double>(tc.balls.size());
    const std::size_t cuts = std::size_t{1} << tc.links.size();
    // modes: zero speed -> each sub-cluster stick / slip+ / slip-; moving -> the sign of v
    std::size_t count = 0;
    for (std::size_t mask = 0; mask < cuts; ++mask) {
      const std::size_t parts = 1 + static_cast<std::size_t>(__builtin_popcountll(mask));
      std::size_t m = 1;
      if (tc.v == 0.0)
        for (std::size_t p = 0; p < parts; ++p) m *= 3;
      count += m;
    }
    tc.options = count;
    total = total > 100000 ? total : total * count;
  }
  // Decodes option `code` of touch cluster tc into (cut mask, per-part modes).
  auto decode = [&](const Touch& tc, std::size_t code, std::size_t& mask, std::vector<BallMode>& part_modes) {
    const std::size_t cuts = std::size_t{1} << tc.links.size();
    for (mask = 0; mask < cuts; ++mask) {
      const std::size_t parts = 1 + static_cast<std::size_t>(__builtin_popcountll(mask));
      std::size_t m = 1;
      if (tc.v == 0.0)
        for (std::size_t p = 0; p < parts; ++p) m *= 3;
      if (code < m) {
        part_modes.assign(parts, tc.v > 0 ? BallMode::SlipForward : BallMode::SlipBackward);
        if (tc.v == 0.0)
          for (std::size_t p = 0; p < parts; ++p, code /= 3)
            part_modes[p] = code % 3 == 0 ? BallMode::Stick : (code % 3 == 1 ? BallMode::SlipForward : BallMode::SlipBackward);
        return;
      }
      code -= m;
    }
  };
  // Applies a joint option: closed links, clusters and modes.
  std::vector<std::size_t> codes(touch.size(), 0);
  auto apply = [&](int& sticks, int& cuts) {
    sticks = cuts = 0;
    std::fill(cs.closed.begin(), cs.closed.end(), 0);
    for (std::size_t t = 0; t < touch.size(); ++t) {
      const Touch& tc = touch[t];
      std::size_t mask = 0;
      std::vector<BallMode> pm;
      decode(tc, codes[t], mask, pm);
      std::size_t part = 0;
      for (std::size_t j = 0; j < tc.balls.size(); ++j) {
        rs.modes[tc.balls[j]] = pm[part];
        sticks += pm[part] == BallMode::Stick;
        if (j + 1 < tc.balls.size()) {
          const bool cut = (mask >> j) & 1;
          cuts += cut;
          cs.closed[tc.links[j]] = cut ? 0 : 1;
          if (cut) ++part;
        }
      }
    }
    build_clusters(rs);
  };
  // Violation of the consistency conditions of the current clusters and modes (0: consistent).
  auto violation = [&]() {
    rs.model.evaluate_clusters(y.data(), W, Wp, rs.modes.data(), cs.clusters, rs.mu, rs.forces);
    double viol = 0;
    for (const auto& grp : cs.clusters.groups) {
      const BallMode mode = rs.modes[grp.front()];
      const double scale = 1e-9 * group_scale(rs, grp) + 1e-300;
      const double v = y[lay.beta_dot(grp.front())];
      if (mode == BallMode::Stick) {
        for (std::size_t i : grp) {
          viol += std::max(0.0, -rs.forces.margin_fwd[i] - scale) / scale;
          viol += std::max(0.0, -rs.forces.margin_bwd[i] - scale) / scale;
        }
      } else {
        // a cluster starting to slip must accelerate in its direction; one whose stick margin has
        // just crossed zero (forced) is not checked (as a ball without contact: the root is
        // located to the interpolant's accuracy, so the acceleration can have either sign there)
        const double sg = static_cast<double>(static_cast<signed char>(mode));
        const double acc = sg * rs.forces.betadd[grp.front()];
        const bool was_forced = std::any_of(grp.begin(), grp.end(), [&](std::size_t i) { return forced[i] != 0; });
        const double acc_scale = scale / rs.nd.mbar[grp.front()];
        if (v == 0.0 && !(acc > 0) && !was_forced) viol += 1.0 + std::fabs(acc) / acc_scale;
        for (std::size_t i : grp)
          if (i != grp.back()) viol += std::max(0.0, -rs.forces.contact[i] - scale) / scale;
      }
    }
    // a cut between touching parts at the same speed must not close: front accelerates no less
    for (const Touch& tc : touch)
      for (std::size_t j = 0; j + 1 < tc.balls.size(); ++j) {
        if (cs.closed[tc.links[j]]) continue;
        const std::size_t a = tc.balls[j], b = tc.balls[j + 1];
        if (y[lay.beta_dot(a)] != y[lay.beta_dot(b)]) continue;
        const double aa = rs.forces.betadd[a], ab = rs.forces.betadd[b];
        const double tol = 1e-9 * (std::fabs(aa) + std::fabs(ab)) + 1e-300;
        if (ab - aa < -tol) viol += 1e6;  // never let a ball run into its neighbour
      }
    return viol;
  };
  auto forced_stuck = [&]() {
    for (const Touch& tc : touch) {
      if (!tc.forced) continue;
      bool all = true;
      for (std::size_t i : tc.balls) all = all && rs.modes[i] == BallMode::Stick;
      if (all) return true;
    }
    return false;
  };
  // Equal speeds inside a touch cluster before choosing (balls at rest stay exactly at rest).
  for (const Touch& tc : touch)
    for (std::size_t i : tc.balls) y[lay.beta_dot(i)] = tc.v;

  // Options per touch cluster in the enumeration. Too many joint options (many balls: a chain
  // of six touching balls has 3 * 4^5 of its own): touching balls move together (no cuts: the
  // first 3, or 1 when moving, options of each), still every stick / slip choice per chain, so a
  // chain whose margin has crossed zero (forced) is not left stuck. (Before, this case kept
  // every ball stuck: a forced chain stayed stuck, its margin crossed zero again at once, and
  // 9-ball runs ended at the chatter limit; docs/performance.md.)
  std::vector<std::size_t> radix(touch.size());
  for (std::size_t t = 0; t < touch.size(); ++t) radix[t] = touch[t].options;
  if (total > 20000) {
    total = 1;
    for (std::size_t t = 0; t < touch.size(); ++t) {
      radix[t] = touch[t].v == 0.0 ? 3 : 1;
      total = total > 100000 ? total : total * radix[t];
    }
  }
  if (total <= 20000) {
    // Every joint option, the most stuck balls first, then the fewest cuts: the first
    // consistent one wins; if none is, the least violating one.
    std::vector<std::pair<std::pair<int, int>, std::size_t>> order;
    order.reserve(total);
    for (std::size_t code = 0; code < total; ++code) {
      std::size_t c = code;
      for (std::size_t t = 0; t < touch.size(); ++t) {
        codes[t] = c % radix[t];
        c /= radix[t];
      }
      int sticks = 0, cuts = 0;
      for (std::size_t t = 0; t < touch.size(); ++t) {
        std::size_t mask = 0;
        std::vector<BallMode> pm;
        decode(touch[t], codes[t], mask, pm);
        cuts += __builtin_popcountll(mask);
        std::size_t part = 0;
        for (std::size_t j = 0; j < touch[t].balls.size(); ++j) {
          sticks += pm[part] == BallMode::Stick;
          if (j + 1 < touch[t].balls.size() && ((mask >> j) & 1)) ++part;
        }
      }
      order.push_back({{-sticks, cuts}, code});
    }
    std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    double best = std::numeric_limits<double>::infinity();
    std::size_t best_code = order.front().second;
    for (const auto& o : order) {
      std::size_t c = o.second;
      for (std::size_t t = 0; t < touch.size(); ++t) {
        codes[t] = c % radix[t];
        c /= radix[t];
      }
      int sticks = 0, cuts = 0;
      apply(sticks, cuts);
      if (forced_stuck()) continue;
      const double v = violation();
      if (v == 0.0) {
        best_code = o.second;
        best = 0;
        break;
      }
      if (v < best) {
        best = v;
        best_code = o.second;
      }
    }
    std::size_t c = best_code;
    for (std::size_t t = 0; t < touch.size(); ++t) {
      codes[t] = c % radix[t];
      c /= radix[t];
    }
  } else {
    std::fill(codes.begin(), codes.end(), 0);  // too many combinations: all clustered, all stuck or moving
  }
  int sticks = 0, cuts = 0;
  apply(sticks, cuts);
  for (std::size_t i = 0; i < n; ++i)
    if (rs.modes[i] == BallMode::Stick) y[lay.beta_dot(i)] = 0.0;
  rs.model.evaluate_clusters(y.data(), W, Wp, rs.modes.data(), cs.clusters, rs.mu, rs.forces);
}

int handle_contact_event(RunState& rs, double tbar, std::vector<double>& y, const std::vector<int>& rinfo) {
  ContactState& cs = rs.cs;
  const StateLayout& lay = rs.lay();
  const std::size_t n = rs.n;
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
      bool fired = false;
      for (std::size_t i : grp) fired = fired || rinfo[2 * i] != 0 || rinfo[2 * i + 1] != 0;
      for (std::size_t i : grp) forced[i] = fired && !hit;
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
  }
  const Speed sp = rs.pi_motor ? sp0 : ideal_speed(rs, tbar);
  choose_contact_modes(rs, sp.W, sp.Wp, y, forced);
  return impacts;
}

}  // namespace abuopt::detail
