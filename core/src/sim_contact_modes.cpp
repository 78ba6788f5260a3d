// The choice of clusters and modes at a hard-contact event (docs/model.md section 11.5, 11.8):
// an active-set pivoting from the modes before the event, and the enumeration of every joint
// option as the fallback (and the reference of the tests).
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "abuopt/core/sim_counters.hpp"
#include "sim_contact.hpp"

namespace abuopt::detail {

namespace {

// A chain of balls joined by links (clustered pairs or pairs touching at equal speed): the balls
// whose cuts and modes the choice decides together.
struct Touch {
  std::vector<std::size_t> balls;  // rear to front
  std::vector<std::size_t> links;  // pair index after balls[j] (j < size - 1)
  double v = 0;
  char forced = 0;  // kForcedForward / kForcedBackward of its balls
  std::size_t options = 0;
};

// The most violated consistency condition of a choice (the pivot's next flip).
struct Violation {
  enum Kind { None, MarginFwd, MarginBwd, WrongAccel, NegContact, Closing } kind = None;
  double size = 0;        // relative to the condition's tolerance
  std::size_t group = 0;  // index in cs.clusters.groups (margins, accelerations, contacts)
  std::size_t pos = 0;    // position in the group (margins, contacts)
  std::size_t pair = 0;   // the cut pair that closes (Closing)
};

// Two touching balls (rear speed va, front vb) move as one if their speeds agree: an approach
// slower than 1e-9 (1 + |va|) is a plastic touch (an impact below v_stop would join them too), but
// a pair that separates, however slowly, is not in contact: it is linked only if the speeds agree
// to 1e-9 of their size (rounding). With the absolute 1e-9 for separating pairs too, a ball that
// had just stopped behind a chain slipping away from it at |v| < 1e-9 was joined to the chain and
// given the chain's mean speed, stopped again, was joined again: a chain losing a fixed share of
// its speed per event, events accumulating at a finite time (Zeno), the chatter limit
// (docs/model.md 11.10).
bool touching_speeds(double va, double vb) {
  const double closing = va - vb;  // > 0: the rear ball gains on the front one
  if (closing >= 0) return closing <= 1e-9 * (1 + std::fabs(va));
  return -closing <= 1e-9 * std::max(std::fabs(va), std::fabs(vb));
}

class ModeChoice {
 public:
  ModeChoice(RunState& rs, const ChoiceSpeed& sp, std::vector<double>& y, const std::vector<char>& forced, double band)
      : rs_(rs), cs_(rs.cs), lay_(rs.lay()), sp_(sp), y_(y), forced_(forced), band_(band) {
    const std::size_t n = rs.n, K = cs_.geo.pairs();
    pos_of_.assign(n, 0);
    for (std::size_t k = 0; k < K; ++k) pos_of_[cs_.geo.order[k]] = k;
    const double* beta = y.data() + lay_.beta(0);
    // Links that may be closed: clustered pairs, and pairs touching at equal speed.
    link_.assign(K, 0);
    for (std::size_t k = 0; k < K; ++k) {
      const std::size_t a = cs_.geo.order[k], b = cs_.geo.order[(k + 1) % n];
      const double va = y[lay_.beta_dot(a)], vb = y[lay_.beta_dot(b)];
      link_[k] = cs_.closed[k] || (cs_.geo.gap(beta, k) <= kGapTol && touching_speeds(va, vb));
    }
    if (std::all_of(link_.begin(), link_.end(), [](char c) { return c != 0; })) link_[K - 1] = 0;
    std::size_t open = 0;
    for (std::size_t k = 0; k < K; ++k)
      if (!link_[k]) open = k;
    Touch cur;
    for (std::size_t step = 0; step < n; ++step) {
      const std::size_t pos = (open + 1 + step) % n;
      const std::size_t i = cs_.geo.order[pos];
      cur.balls.push_back(i);
      cur.forced = static_cast<char>(cur.forced | forced[i]);
      if (link_[pos]) {
        cur.links.push_back(pos);
      } else {
        touch_.push_back(cur);
        cur = Touch{};
      }
    }
    for (Touch& tc : touch_) {
      double sum = 0;
      for (std::size_t i : tc.balls) sum += y[lay_.beta_dot(i)];
      tc.v = sum / static_cast<double>(tc.balls.size());
      tc.options = 0;
      for (std::size_t mask = 0; mask < (std::size_t{1} << tc.links.size()); ++mask) tc.options += part_options(tc, mask);
    }
    // Equal speeds inside a touch cluster before choosing (balls at rest stay exactly at rest).
    for (const Touch& tc : touch_)
      for (std::size_t i : tc.balls) y[lay_.beta_dot(i)] = tc.v;
  }

  bool pivot(int& pivots);
  bool enumerate();
  // Stuck balls at exactly zero speed, and the forces of the choice in rs.forces.
  void finish() {
    for (std::size_t i = 0; i < rs_.n; ++i)
      if (rs_.modes[i] == BallMode::Stick) y_[lay_.beta_dot(i)] = 0.0;
    evaluate();
  }

 private:
  // The forces of the current trial; with the PI drive's friction feedback its W' comes from the
  // motor equation with the trial's modes (a fixed W' let the choice keep an inconsistent mode:
  // docs/model.md 11.12).
  void evaluate() {
    if (sp_.wp_from_modes) {
      evaluate_forces(rs_, sp_.tbar, y_.data());
      return;
    }
    rs_.model.evaluate_clusters(y_.data(), sp_.W, sp_.Wp, rs_.modes.data(), cs_.clusters, rs_.mu, rs_.forces);
  }
  // At rest: zero speed (event-driven), or within the switch model's band |v| <= switch_band
  // (docs/model.md 8.1); with band 0 the test is v == 0.
  bool at_rest(double v) const { return std::fabs(v) <= band_; }
  // at rest: each part sticks, slips forward or back; moving: the sign of the speed
  std::size_t part_options(const Touch& tc, std::size_t mask) const {
    const std::size_t parts = 1 + static_cast<std::size_t>(__builtin_popcountll(mask));
    std::size_t m = 1;
    if (at_rest(tc.v))
      for (std::size_t p = 0; p < parts; ++p) m *= 3;
    return m;
  }
  void decode(const Touch& tc, std::size_t code, std::size_t& mask, std::vector<BallMode>& part_modes) const;
  void apply_codes(const std::vector<std::size_t>& codes);
  bool forced_stuck() const;
  double violation(Violation* worst);
  void release_forced(std::size_t t);
  void flip(const Violation& v);
  std::string key() const {
    std::string s(cs_.closed.begin(), cs_.closed.end());
    for (BallMode m : rs_.modes) s.push_back(static_cast<char>(m));
    return s;
  }

  RunState& rs_;
  ContactState& cs_;
  const StateLayout& lay_;
  ChoiceSpeed sp_;
  std::vector<double>& y_;
  const std::vector<char>& forced_;
  double band_;
  std::vector<std::size_t> pos_of_;  // ball -> its place in the cyclic order (the pair after it)
  std::vector<char> link_;
  std::vector<Touch> touch_;
};

// Decodes option `code` of touch cluster tc into (cut mask, per-part modes).
void ModeChoice::decode(const Touch& tc, std::size_t code, std::size_t& mask, std::vector<BallMode>& part_modes) const {
  const std::size_t cuts = std::size_t{1} << tc.links.size();
  for (mask = 0; mask < cuts; ++mask) {
    const std::size_t parts = 1 + static_cast<std::size_t>(__builtin_popcountll(mask));
    const std::size_t m = part_options(tc, mask);
    if (code < m) {
      part_modes.assign(parts, tc.v > 0 ? BallMode::SlipForward : BallMode::SlipBackward);
      if (at_rest(tc.v))
        for (std::size_t p = 0; p < parts; ++p, code /= 3)
          part_modes[p] = code % 3 == 0 ? BallMode::Stick : (code % 3 == 1 ? BallMode::SlipForward : BallMode::SlipBackward);
      return;
    }
    code -= m;
  }
}

// Applies a joint option (one code per touch cluster): closed links, clusters and modes.
void ModeChoice::apply_codes(const std::vector<std::size_t>& codes) {
  std::fill(cs_.closed.begin(), cs_.closed.end(), 0);
  for (std::size_t t = 0; t < touch_.size(); ++t) {
    const Touch& tc = touch_[t];
    std::size_t mask = 0;
    std::vector<BallMode> pm;
    decode(tc, codes[t], mask, pm);
    std::size_t part = 0;
    for (std::size_t j = 0; j < tc.balls.size(); ++j) {
      rs_.modes[tc.balls[j]] = pm[part];
      if (j + 1 < tc.balls.size()) {
        const bool cut = (mask >> j) & 1;
        cs_.closed[tc.links[j]] = cut ? 0 : 1;
        if (cut) ++part;
      }
    }
  }
  build_clusters(rs_);
}

// A touch cluster with a forced ball (its stuck margin crossed zero) may not stay stuck whole.
bool ModeChoice::forced_stuck() const {
  for (const Touch& tc : touch_) {
    if (!tc.forced) continue;
    bool all = true;
    for (std::size_t i : tc.balls) all = all && rs_.modes[i] == BallMode::Stick;
    if (all) return true;
  }
  return false;
}

// Violation of the consistency conditions of the current clusters and modes (0: consistent),
// evaluated with their forces; `worst` (if given) gets the most violated condition.
double ModeChoice::violation(Violation* worst) {
  evaluate();
  const RunState& rs = rs_;
  double viol = 0;
  auto note = [&](Violation::Kind kind, double size, std::size_t g, std::size_t pos, std::size_t pair) {
    if (worst && size > worst->size) *worst = Violation{kind, size, g, pos, pair};
  };
  for (std::size_t g = 0; g < cs_.clusters.groups.size(); ++g) {
    const auto& grp = cs_.clusters.groups[g];
    const BallMode mode = rs.modes[grp.front()];
    const double scale = 1e-9 * group_scale(rs, grp) + 1e-300;
    const double v = y_[lay_.beta_dot(grp.front())];
    if (mode == BallMode::Stick) {
      for (std::size_t j = 0; j < grp.size(); ++j) {
        const std::size_t i = grp[j];
        const double f = std::max(0.0, -rs.forces.margin_fwd[i] - scale) / scale;
        const double b = std::max(0.0, -rs.forces.margin_bwd[i] - scale) / scale;
        viol += f + b;
        if (f > 0) note(Violation::MarginFwd, f, g, j, 0);
        if (b > 0) note(Violation::MarginBwd, b, g, j, 0);
      }
    } else {
      // a cluster starting to slip must accelerate in its direction; one whose stick margin in
      // that direction has just crossed zero (forced) is not checked (as a ball without
      // contact: the root is located to the interpolant's accuracy, so the acceleration can have
      // either sign there). Not the other direction: a forced block slipping against its
      // acceleration from rest would reverse at once, unseen (its stop function starts at zero).
      const double sg = static_cast<double>(static_cast<signed char>(mode));
      const double acc = sg * rs.forces.betadd[grp.front()];
      char dirs = 0;
      for (std::size_t i : grp) dirs = static_cast<char>(dirs | forced_[i]);
      const bool was_forced = (dirs & (mode == BallMode::SlipForward ? kForcedForward : kForcedBackward)) != 0;
      const double acc_scale = scale / rs.nd.mbar[grp.front()];
      if (at_rest(v) && !(acc > 0) && !was_forced) {
        viol += 1.0 + std::fabs(acc) / acc_scale;
        note(Violation::WrongAccel, 1.0 + std::fabs(acc) / acc_scale, g, 0, 0);
      }
      for (std::size_t j = 0; j + 1 < grp.size(); ++j) {
        const double c = std::max(0.0, -rs.forces.contact[grp[j]] - scale) / scale;
        viol += c;
        if (c > 0) note(Violation::NegContact, c, g, j, 0);
      }
    }
  }
  // a cut between touching parts at the same speed must not close: front accelerates no less
  for (const Touch& tc : touch_)
    for (std::size_t j = 0; j + 1 < tc.balls.size(); ++j) {
      if (cs_.closed[tc.links[j]]) continue;
      const std::size_t a = tc.balls[j], b = tc.balls[j + 1];
      if (y_[lay_.beta_dot(a)] != y_[lay_.beta_dot(b)]) continue;
      const double aa = rs.forces.betadd[a], ab = rs.forces.betadd[b];
      const double tol = 1e-9 * (std::fabs(aa) + std::fabs(ab)) + 1e-300;
      if (ab - aa < -tol) {
        viol += 1e6;  // never let a ball run into its neighbour
        note(Violation::Closing, 1e6 + (aa - ab) / tol, 0, 0, tc.links[j]);
      }
    }
  return viol;
}

// Enumeration: every joint option, the most stuck balls first, then the fewest cuts; the first
// consistent one wins; if none is, the least violating one. Returns whether one was consistent.
bool ModeChoice::enumerate() {
  std::size_t total = 1;
  for (const Touch& tc : touch_) total = total > 100000 ? total : total * tc.options;
  // Too many joint options (many balls: a chain of six touching balls has 3 * 4^5 of its own):
  // touching balls move together (no cuts: the first 3, or 1 when moving, options of each),
  // still every stick / slip choice per chain, so a chain whose margin has crossed zero (forced)
  // is not left stuck.
  std::vector<std::size_t> radix(touch_.size());
  for (std::size_t t = 0; t < touch_.size(); ++t) radix[t] = touch_[t].options;
  if (total > 20000) {
    total = 1;
    for (std::size_t t = 0; t < touch_.size(); ++t) {
      radix[t] = at_rest(touch_[t].v) ? 3 : 1;
      total = total > 100000 ? total : total * radix[t];
    }
  }
  std::vector<std::size_t> codes(touch_.size(), 0);
  auto set_codes = [&](std::size_t c) {
    for (std::size_t t = 0; t < touch_.size(); ++t) {
      codes[t] = c % radix[t];
      c /= radix[t];
    }
  };
  if (total > 20000) {  // too many combinations: all clustered, all stuck or moving
    apply_codes(codes);
    return false;
  }
  std::vector<std::pair<std::pair<int, int>, std::size_t>> order;
  order.reserve(total);
  for (std::size_t code = 0; code < total; ++code) {
    set_codes(code);
    int sticks = 0, cuts = 0;
    for (std::size_t t = 0; t < touch_.size(); ++t) {
      std::size_t mask = 0;
      std::vector<BallMode> pm;
      decode(touch_[t], codes[t], mask, pm);
      cuts += __builtin_popcountll(mask);
      std::size_t part = 0;
      for (std::size_t j = 0; j < touch_[t].balls.size(); ++j) {
        sticks += pm[part] == BallMode::Stick;
        if (j + 1 < touch_[t].balls.size() && ((mask >> j) & 1)) ++part;
      }
    }
    order.push_back({{-sticks, cuts}, code});
  }
  std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  double best = std::numeric_limits<double>::infinity();
  std::size_t best_code = order.front().second;
  for (const auto& o : order) {
    set_codes(o.second);
    apply_codes(codes);
    if (forced_stuck()) continue;
    const double v = violation(nullptr);
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
  set_codes(best_code);
  apply_codes(codes);
  return best == 0.0;
}

// A forced touch cluster that is stuck whole: the block with the smallest margin leaves stick
// in the margin's direction (the margin that crossed zero at the event).
void ModeChoice::release_forced(std::size_t t) {
  evaluate();
  Violation v;
  v.size = std::numeric_limits<double>::infinity();
  for (std::size_t g = 0; g < cs_.clusters.groups.size(); ++g) {
    const auto& grp = cs_.clusters.groups[g];
    if (std::find(touch_[t].balls.begin(), touch_[t].balls.end(), grp.front()) == touch_[t].balls.end()) continue;
    const double scale = group_scale(rs_, grp) + 1e-300;
    for (std::size_t j = 0; j < grp.size(); ++j) {
      const double f = rs_.forces.margin_fwd[grp[j]] / scale, b = rs_.forces.margin_bwd[grp[j]] / scale;
      if ((touch_[t].forced & kForcedForward) && f < v.size) v = Violation{Violation::MarginFwd, f, g, j, 0};
      if ((touch_[t].forced & kForcedBackward) && b < v.size) v = Violation{Violation::MarginBwd, b, g, j, 0};
    }
  }
  flip(v);
}

// The pivot for the violated condition v (docs/model.md 11.8).
void ModeChoice::flip(const Violation& v) {
  auto& closed = cs_.closed;
  auto& modes = rs_.modes;
  if (v.kind == Violation::Closing) {
    // the cut closes; the joined parts share a mode: if they differ, stick (most stuck first),
    // but a forced chain's slipping mode (it may not stay stuck whole)
    const std::size_t a = cs_.geo.order[v.pair], b = cs_.geo.order[(v.pair + 1) % rs_.n];
    const BallMode ma = modes[a], mb = modes[b];
    const auto ga = cs_.clusters.groups[static_cast<std::size_t>(cs_.group_of[a])];
    const auto gb = cs_.clusters.groups[static_cast<std::size_t>(cs_.group_of[b])];
    char dirs = 0;
    for (std::size_t i : ga) dirs = static_cast<char>(dirs | forced_[i]);
    for (std::size_t i : gb) dirs = static_cast<char>(dirs | forced_[i]);
    BallMode m = ma == mb ? ma : BallMode::Stick;
    if (ma != mb && (ma == BallMode::Stick || mb == BallMode::Stick)) {
      const BallMode slip = ma == BallMode::Stick ? mb : ma;
      if (dirs & (slip == BallMode::SlipForward ? kForcedForward : kForcedBackward)) m = slip;
    }
    for (std::size_t i : ga) modes[i] = m;
    for (std::size_t i : gb) modes[i] = m;
    closed[v.pair] = 1;
  } else {
    const auto grp = cs_.clusters.groups[v.group];
    switch (v.kind) {
      case Violation::MarginFwd:  // the balls from pos to the front slip forward
        for (std::size_t j = v.pos; j < grp.size(); ++j) modes[grp[j]] = BallMode::SlipForward;
        if (v.pos > 0) closed[pos_of_[grp[v.pos - 1]]] = 0;
        break;
      case Violation::MarginBwd:  // the balls from the rear to pos slip back
        for (std::size_t j = 0; j <= v.pos; ++j) modes[grp[j]] = BallMode::SlipBackward;
        if (v.pos + 1 < grp.size()) closed[pos_of_[grp[v.pos]]] = 0;
        break;
      case Violation::WrongAccel:  // a part at rest that would not move off in its direction
        for (std::size_t i : grp) modes[i] = BallMode::Stick;
        break;
      case Violation::NegContact:  // the contact after pos opens
        closed[pos_of_[grp[v.pos]]] = 0;
        break;
      default: break;
    }
  }
  build_clusters(rs_);
}

// Active set: start from every link closed, parts at rest stuck, moving parts slipping with
// their speed; release a forced chain; then flip the most violated condition until none is.
// Fails on a repeated choice (a cycle) or after the pivot budget.
bool ModeChoice::pivot(int& pivots) {
  for (std::size_t k = 0; k < link_.size(); ++k) cs_.closed[k] = link_[k];
  for (const Touch& tc : touch_)
    for (std::size_t i : tc.balls)
      rs_.modes[i] = at_rest(tc.v) ? BallMode::Stick : (tc.v > 0 ? BallMode::SlipForward : BallMode::SlipBackward);
  build_clusters(rs_);
  pivots = 0;
  for (std::size_t t = 0; t < touch_.size(); ++t)
    if (touch_[t].forced && at_rest(touch_[t].v)) {
      release_forced(t);
      ++pivots;
    }
  std::vector<std::string> seen;
  const int budget = static_cast<int>(4 * rs_.n) + 8;
  for (; pivots <= budget; ++pivots) {
    std::string k = key();
    if (std::find(seen.begin(), seen.end(), k) != seen.end()) return false;
    seen.push_back(std::move(k));
    std::size_t stuck_forced = touch_.size();
    for (std::size_t t = 0; t < touch_.size() && stuck_forced == touch_.size(); ++t) {
      bool all = touch_[t].forced;
      for (std::size_t i : touch_[t].balls) all = all && rs_.modes[i] == BallMode::Stick;
      if (all) stuck_forced = t;
    }
    if (stuck_forced < touch_.size()) {
      release_forced(stuck_forced);
      continue;
    }
    Violation worst;
    if (violation(&worst) == 0.0) return true;
    flip(worst);
  }
  return false;
}

}  // namespace

ContactChoiceMethod& run_contact_choice() {
  thread_local ContactChoiceMethod method = ContactChoiceMethod::Auto;
  return method;
}

ContactChoiceResult choose_contact_modes(RunState& rs, const ChoiceSpeed& sp, std::vector<double>& y,
                                         const std::vector<char>& forced, ContactChoiceMethod method, double band) {
  SimCounters& cnt = sim_counters();
  if (method == ContactChoiceMethod::Compare) {
    // the enumeration on a copy, then Auto on this state
    RunState ref = rs;
    std::vector<double> yref = y;
    const long choices = cnt.mode_choices;
    const ContactChoiceResult e = choose_contact_modes(ref, sp, yref, forced, ContactChoiceMethod::Enumerate, band);
    cnt.mode_choices = choices;
    const ContactChoiceResult res = choose_contact_modes(rs, sp, y, forced, ContactChoiceMethod::Auto, band);
    cnt.mode_differs += ref.modes != rs.modes || ref.cs.closed != rs.cs.closed;
    cnt.mode_enum_consistent += e.consistent;
    return res;
  }
  // W' from the motor equation reads the motor's states (the switch model's scratch copy holds the
  // ABU's states only: it takes W' as given)
  if (sp.wp_from_modes && y.size() < rs.nstate) throw std::logic_error("choose_contact_modes: W' from the modes needs the motor states");
  ModeChoice mc(rs, sp, y, forced, band);
  ContactChoiceResult res;
  ++cnt.mode_choices;
  if (method != ContactChoiceMethod::Enumerate) {
    res.consistent = mc.pivot(res.pivots);
    cnt.mode_pivots += res.pivots;
  }
  if (!res.consistent && method != ContactChoiceMethod::Pivot) {
    res.enumerated = method == ContactChoiceMethod::Auto;
    cnt.mode_fallbacks += res.enumerated;
    res.consistent = mc.enumerate();
  }
  mc.finish();
  return res;
}

}  // namespace abuopt::detail
