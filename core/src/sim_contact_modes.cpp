// The choice of clusters and modes at a hard-contact event (docs/model.md section 11.5).
#include <algorithm>
#include <cmath>
#include <limits>

#include "sim_contact.hpp"

namespace abuopt::detail {

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

}  // namespace abuopt::detail
