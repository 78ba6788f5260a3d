// Exact propagation of the table while every ball is stuck (stuck_propagator.hpp,
// docs/stuck_propagator.md).
#include "stuck_propagator.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <mutex>
#include <stdexcept>

#include "root_refine.hpp"
#include "run_forcing_table.hpp"

namespace abuopt::detail {

namespace {

constexpr int kNodes = 7;               // Gauss-Legendre nodes per interval
constexpr double kCheckFraction = 0.5;  // grid spacing / period of the fastest margin oscillation


}  // namespace

// Gauss-Legendre nodes and weights on [0, 1] (Newton on the Legendre polynomial).
void gauss_legendre(int m, std::vector<double>& x, std::vector<double>& w) {
  x.resize(static_cast<std::size_t>(m));
  w.resize(static_cast<std::size_t>(m));
  for (int i = 0; i < m; ++i) {
    double r = std::cos(M_PI * (i + 0.75) / (m + 0.5));
    double dp = 0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = r;
      for (int k = 2; k <= m; ++k) {
        const double p2 = ((2.0 * k - 1) * r * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = m * (r * p1 - p0) / (r * r - 1);
      const double dr = p1 / dp;
      r -= dr;
      if (std::fabs(dr) < 1e-16) break;
    }
    // recompute the derivative at the converged root for the weight
    double p0 = 1, p1 = r;
    for (int k = 2; k <= m; ++k) {
      const double p2 = ((2.0 * k - 1) * r * p1 - (k - 1.0) * p0) / k;
      p0 = p1;
      p1 = p2;
    }
    dp = m * (r * p1 - p0) / (r * r - 1);
    x[static_cast<std::size_t>(i)] = 0.5 * (1 - r);
    w[static_cast<std::size_t>(i)] = 1.0 / ((1 - r * r) * dp * dp);  // on [-1, 1]: 2/(...); halved
  }
}


bool StuckForcingTable::supports(const NondimParameters& nd) {
  return nd.bbar > 0 && std::fabs(nd.bbar - 1.0) > 1e-6 && std::isfinite(nd.bbar) && nd.omega_n > 0;
}

StuckForcingTable::StuckForcingTable(const StartupProfile& profile, const NondimParameters& nd, double t_end_bar)
    : profile_(profile), t_end_bar_(t_end_bar), omega_n_(nd.omega_n), bbar_(nd.bbar) {
  if (!supports(nd)) throw std::invalid_argument("StuckForcingTable: needs 0 < bbar != 1");
  const cplx root = std::sqrt(cplx(bbar_ * bbar_ - 1.0, 0.0));
  lam_[0] = -bbar_ + root;
  lam_[1] = -bbar_ - root;
  rho_[0] = 1.0 / (lam_[0] - lam_[1]);
  rho_[1] = -rho_[0];
  gauss_legendre(kNodes, gl_x_, gl_w_);
  const double wd = std::fabs(root.imag());

  // Pieces of the grid: each profile segment (W monotone), then constant speed to the end time.
  struct Piece {
    double a, b, Wmax;
    bool constant;
    bool tail = false;  // the constant speed after the profile: not stored
  };
  std::vector<Piece> pieces;
  const double to_W = 2.0 * M_PI / omega_n_;
  const auto& br = profile_.breakpoints_s();
  for (std::size_t k = 0; k < profile_.segments().size(); ++k) {
    const double a = br[k] * omega_n_, b = std::min(br[k + 1] * omega_n_, t_end_bar);
    if (a >= t_end_bar) break;
    const double f0 = k == 0 ? profile_.start_frequency_hz() : profile_.segments()[k - 1].end_frequency_hz;
    const double f1 = profile_.segments()[k].end_frequency_hz;
    pieces.push_back({a, b, to_W * std::max(f0, f1), f0 == f1});
  }
  const double tp = profile_.duration_s() * omega_n_;
  if (t_end_bar > tp) pieces.push_back({tp, t_end_bar, to_W * profile_.final_frequency_hz(), true, true});

  // every vector's final size first: no reallocation while filling (the table is ~100 B per
  // interval, ~17k intervals for the final profile)
  double stored = 1;
  for (const Piece& pc : pieces)
    if (!pc.tail) stored += std::max(1.0, std::ceil((pc.b - pc.a) / (kCheckFraction * 2.0 * M_PI / (pc.Wmax + wd))));
  if (!(stored <= static_cast<double>(kMaxStoredIntervals)))
    throw std::invalid_argument("StuckForcingTable: the profile needs more than kMaxStoredIntervals intervals");
  const auto total = static_cast<std::size_t>(stored);
  t_.reserve(total);
  W_.reserve(total);
  Wp_.reserve(total);
  rot_.reserve(total);
  E_.reserve(2 * total);
  P_.reserve(2 * total);
  t_.push_back(0.0);
  std::vector<cplx> wexp(2 * kNodes);
  auto push_point = [&](double W, double Wp, const cplx& e) {
    W_.push_back(W);
    Wp_.push_back(Wp);
    rot_.push_back(std::conj(e));
  };
  {
    double W, Wp;
    cplx e;
    sample(0.0, W, Wp, e);
    push_point(W, Wp, e);
  }
  for (const Piece& pc : pieces) {
    const double spacing = kCheckFraction * 2.0 * M_PI / (pc.Wmax + wd);
    const long n = std::max(1L, static_cast<long>(std::ceil((pc.b - pc.a) / spacing)));
    const double h = (pc.b - pc.a) / static_cast<double>(n);
    const cplx E[2] = {std::exp(lam_[0] * h), std::exp(lam_[1] * h)};
    // quadrature weights with the decay factor, the same for every interval of the piece
    for (int k = 0; k < 2; ++k)
      for (int i = 0; i < kNodes; ++i)
        wexp[static_cast<std::size_t>(k * kNodes + i)] =
            rho_[k] * gl_w_[static_cast<std::size_t>(i)] * h * std::exp(lam_[k] * (h - h * gl_x_[static_cast<std::size_t>(i)]));
    // constant speed: P_k = rho_k W^2 e^{i phi(t_j)} (e^{i W h} - e^{lambda_k h}) / (i W - lambda_k), and
    // e^{i phi} turns by W h per interval (from the piece's start, no drift)
    cplx Fc[2];
    for (int k = 0; k < 2; ++k)
      Fc[k] = rho_[k] * pc.Wmax * pc.Wmax * (std::exp(cplx(0, pc.Wmax * h)) - E[k]) / (cplx(0, pc.Wmax) - lam_[k]);
    double W0, Wp0;
    cplx e0;
    sample(pc.a, W0, Wp0, e0);
    if (pc.tail) {  // kept as its closed form (the same values the loop below would store)
      tail_n_ = static_cast<std::size_t>(n);
      tail_a_ = pc.a;
      tail_h_ = h;
      tail_W_ = pc.Wmax;
      tail_e0_ = e0;
      for (int k = 0; k < 2; ++k) {
        tail_E_[k] = E[k];
        tail_Fc_[k] = Fc[k];
      }
      const double t0 = pc.a + static_cast<double>(n - 1) * h;
      if (pc.b - t0 != h) {
        partial(t0, pc.b - t0, tail_last_P_);
        for (int k = 0; k < 2; ++k) tail_last_E_[k] = std::exp(lam_[k] * (pc.b - t0));
      } else {
        const cplx e = e0 * std::polar(1.0, pc.Wmax * (t0 - pc.a));
        for (int k = 0; k < 2; ++k) {
          tail_last_P_[k] = Fc[k] * e;
          tail_last_E_[k] = E[k];
        }
      }
      cplx e;
      sample(pc.b, tail_end_W_, tail_end_Wp_, e);
      tail_end_rot_ = std::conj(e);
      continue;
    }
    for (long j = 0; j < n; ++j) {
      const double t0 = pc.a + static_cast<double>(j) * h;
      const double t1 = j + 1 == n ? pc.b : pc.a + static_cast<double>(j + 1) * h;
      cplx P[2] = {0.0, 0.0};
      if (j + 1 == n && t1 - t0 != h) {  // the last interval ends exactly at the piece's end
        partial(t0, t1 - t0, P);
        E_.push_back(std::exp(lam_[0] * (t1 - t0)));
        E_.push_back(std::exp(lam_[1] * (t1 - t0)));
      } else {
        if (pc.constant) {
          const cplx e = e0 * std::polar(1.0, pc.Wmax * (t0 - pc.a));
          P[0] = Fc[0] * e;
          P[1] = Fc[1] * e;
        } else {
          for (int i = 0; i < kNodes; ++i) {
            double W, Wp;
            cplx e;
            sample(t0 + h * gl_x_[static_cast<std::size_t>(i)], W, Wp, e);
            const cplx g = cplx(W * W, -Wp) * e;
            P[0] += wexp[static_cast<std::size_t>(i)] * g;
            P[1] += wexp[static_cast<std::size_t>(kNodes + i)] * g;
          }
        }
        E_.push_back(E[0]);
        E_.push_back(E[1]);
      }
      P_.push_back(P[0]);
      P_.push_back(P[1]);
      t_.push_back(t1);
      if (pc.constant && j + 1 < n) {
        push_point(pc.Wmax, 0.0, e0 * std::polar(1.0, pc.Wmax * (t1 - pc.a)));
      } else {
        double W, Wp;
        cplx e;
        sample(t1, W, Wp, e);
        push_point(W, Wp, e);
      }
    }
  }
  if (intervals() < 1) throw std::invalid_argument("StuckForcingTable: empty time span");
}

double StuckForcingTable::t(std::size_t j) const {
  const std::size_t s = t_.size() - 1;
  if (j <= s) return t_[j];
  const std::size_t i = j - s;
  return i >= tail_n_ ? t_end_bar_ : tail_a_ + static_cast<double>(i) * tail_h_;
}

cplx StuckForcingTable::decay(int k, std::size_t j) const {
  const std::size_t s = t_.size() - 1;
  if (j < s) return E_[2 * j + static_cast<std::size_t>(k)];
  return j - s + 1 == tail_n_ ? tail_last_E_[k] : tail_E_[k];
}

cplx StuckForcingTable::forcing(int k, std::size_t j) const {
  const std::size_t s = t_.size() - 1;
  if (j < s) return P_[2 * j + static_cast<std::size_t>(k)];
  const std::size_t i = j - s;
  if (i + 1 == tail_n_) return tail_last_P_[k];
  const double t0 = tail_a_ + static_cast<double>(i) * tail_h_;
  return tail_Fc_[k] * (tail_e0_ * std::polar(1.0, tail_W_ * (t0 - tail_a_)));
}

cplx StuckForcingTable::unrotate(std::size_t j) const {
  const std::size_t s = t_.size() - 1;
  if (j <= s) return rot_[j];
  const std::size_t i = j - s;
  if (i >= tail_n_) return tail_end_rot_;
  const double t1 = tail_a_ + static_cast<double>(i) * tail_h_;
  return std::conj(tail_e0_ * std::polar(1.0, tail_W_ * (t1 - tail_a_)));
}

double StuckForcingTable::speed(std::size_t j) const {
  const std::size_t s = t_.size() - 1;
  if (j <= s) return W_[j];
  return j - s >= tail_n_ ? tail_end_W_ : tail_W_;
}

double StuckForcingTable::speed_rate(std::size_t j) const {
  const std::size_t s = t_.size() - 1;
  if (j <= s) return Wp_[j];
  return j - s >= tail_n_ ? tail_end_Wp_ : 0.0;
}

bool StuckForcingTable::same(const StartupProfile& profile, const NondimParameters& nd, double t_end_bar) const {
  if (!(t_end_bar == t_end_bar_ && nd.omega_n == omega_n_ && nd.bbar == bbar_ &&
        profile.start_frequency_hz() == profile_.start_frequency_hz() &&
        profile.segments().size() == profile_.segments().size()))
    return false;
  for (std::size_t k = 0; k < profile.segments().size(); ++k)
    if (profile.segments()[k].end_frequency_hz != profile_.segments()[k].end_frequency_hz ||
        profile.segments()[k].duration_s != profile_.segments()[k].duration_s)
      return false;
  return true;
}

std::shared_ptr<const StuckForcingTable> StuckForcingTable::shared(const StartupProfile& profile,
                                                                   const NondimParameters& nd, double t_end_bar) {
  static std::mutex mutex;
  static std::deque<std::shared_ptr<const StuckForcingTable>> cache;  // most recently used first
  auto lookup = [&]() -> std::shared_ptr<const StuckForcingTable> {
    for (auto it = cache.begin(); it != cache.end(); ++it)
      if ((*it)->same(profile, nd, t_end_bar)) {
        auto hit = *it;
        cache.erase(it);
        cache.push_front(hit);
        return hit;
      }
    return nullptr;
  };
  {
    const std::lock_guard<std::mutex> lock(mutex);
    if (auto hit = lookup()) return hit;
  }
  auto table = std::make_shared<const StuckForcingTable>(profile, nd, t_end_bar);
  const std::lock_guard<std::mutex> lock(mutex);
  if (auto hit = lookup()) return hit;  // another thread built it meanwhile
  cache.push_front(table);
  if (cache.size() > kSharedTables) cache.pop_back();
  return table;
}

std::size_t StuckForcingTable::interval(double tbar) const {
  const std::size_t s = t_.size() - 1;
  if (tail_n_ > 0 && tbar >= t_[s]) {
    const double q = (tbar - tail_a_) / tail_h_;
    std::size_t i = q <= 0 ? 0 : q >= static_cast<double>(tail_n_ - 1) ? tail_n_ - 1 : static_cast<std::size_t>(q);
    while (i + 1 < tail_n_ && t(s + i + 1) <= tbar) ++i;
    while (i > 0 && t(s + i) > tbar) --i;
    return s + i;
  }
  const auto it = std::upper_bound(t_.begin(), t_.end(), tbar);
  const std::size_t j = it == t_.begin() ? 0 : static_cast<std::size_t>(it - t_.begin()) - 1;
  return std::min(j, intervals() - 1);
}

void StuckForcingTable::sample(double tbar, double& W, double& Wp, cplx& eiphi) const {
  double rev = 0;
  const ProfileSample s = profile_.sample(tbar / omega_n_, &rev);
  W = 2.0 * M_PI * s.frequency_hz / omega_n_;
  Wp = 2.0 * M_PI * s.rate_hz_per_s / (omega_n_ * omega_n_);
  const double ph = 2.0 * M_PI * (rev - std::floor(rev));
  eiphi = cplx(std::cos(ph), std::sin(ph));
}

void StuckForcingTable::partial(double t0, double h, cplx P[2]) const {
  P[0] = P[1] = 0.0;
  if (!(h > 0)) return;
  for (int i = 0; i < kNodes; ++i) {
    const double s = h * gl_x_[static_cast<std::size_t>(i)];
    double W, Wp;
    cplx e;
    sample(t0 + s, W, Wp, e);
    const cplx g = cplx(W * W, -Wp) * e * (gl_w_[static_cast<std::size_t>(i)] * h);
    for (int k = 0; k < 2; ++k) P[k] += rho_[k] * std::exp(lam_[k] * (h - s)) * g;
  }
}

template <class Table>
StuckPropagatorT<Table>::StuckPropagatorT(const Table& tab, RunState& rs, RootFn g)
    : tab_(tab), rs_(rs), g_(g) {
  ywork_.resize(rs.lay().size());
  g0_.resize(rs.nroots());
  g1_.resize(rs.nroots());
  gtmp_.resize(rs.nroots());
  L_mm_ = rs.params.ball_track_radius_m * 1e3;
}

template <class Table>
void StuckPropagatorT<Table>::to_modal(double t, const double* y) {
  double W, Wp;
  cplx e;
  tab_.sample(t, W, Wp, e);
  const cplx z(y[StateLayout::x], y[StateLayout::y]), zd(y[StateLayout::x_dot], y[StateLayout::y_dot]);
  const cplx Z = z * e, Zd = (zd + cplx(0, W) * z) * e;
  const cplx& l1 = tab_.lambda(0);
  const cplx& l2 = tab_.lambda(1);
  const cplx r = tab_.rho(0);
  a_[0] = r * (Zd - l2 * Z);
  a_[1] = r * (l1 * Z - Zd);
}

template <class Table>
void StuckPropagatorT<Table>::from_modal(const cplx a[2], double W, const cplx& rot, double* y) const {
  const cplx Z = a[0] + a[1], Zd = tab_.lambda(0) * a[0] + tab_.lambda(1) * a[1];
  const cplx z = Z * rot, zd = Zd * rot - cplx(0, W) * z;
  y[StateLayout::x] = z.real();
  y[StateLayout::y] = z.imag();
  y[StateLayout::x_dot] = zd.real();
  y[StateLayout::y_dot] = zd.imag();
}

template <class Table>
void StuckPropagatorT<Table>::state_at(double t0, const cplx a0[2], double t, double* y) const {
  cplx P[2];
  tab_.partial(t0, t - t0, P);
  cplx a[2];
  for (int k = 0; k < 2; ++k) a[k] = std::exp(tab_.lambda(k) * (t - t0)) * a0[k] + C_ * P[k];
  double W, Wp;
  cplx e;
  tab_.sample(t, W, Wp, e);
  from_modal(a, W, std::conj(e), y);
}

// Illinois on the exact solution (the stepper's polished roots, docs/model.md 11.5).
template <class Table>
double StuckPropagatorT<Table>::locate(std::size_t k, double ta, double ga, double tb, double gb, const cplx a0[2], double t0) {
  std::vector<double> yc(ywork_);
  auto g = [&](double tc) {
    state_at(t0, a0, tc, yc.data());
    g_(tc, yc.data(), gtmp_.data(), &rs_);
    return gtmp_[k];
  };
  auto tol = [](double tbk) { return 4e-16 * std::max(1.0, std::fabs(tbk)); };
  return illinois_crossing(g, ta, ga, tb, gb, tol, 100);  // on the far side of the crossing
}

// roots_plain with every ball stuck, at a grid point (W, W' from the table, not the profile), from
// the model's equations with beta' = beta'' = 0 in complex form (docs/stuck_propagator.md 4):
//   z'' = C (W^2 - i W') - (2 bbar + 2 i W) z' - (1 - W^2 + i W' + 2 i bbar W) z,
//   with u = conj(e_i) z, v = conj(e_i) z', a = conj(e_i) z'' (e_i = e^{i beta_i}):
//   fn_i = -(Re a - 2 W Im v - W^2 Re u - W^2 - W' Im u),
//   fw_i = -(Im a + 2 W Re v - W^2 Im u + W' (Re u + 1 - 2 dbar_i Jbar)).
template <class Table>
void StuckPropagatorT<Table>::margins(double W, double Wp, const double* y, double* g) {
  const cplx z(y[StateLayout::x], y[StateLayout::y]), zd(y[StateLayout::x_dot], y[StateLayout::y_dot]);
  const double bb = rs_.nd.bbar, W2 = W * W;
  const cplx zdd = C_ * cplx(W2, -Wp) - cplx(2 * bb, 2 * W) * zd - cplx(1 - W2, Wp + 2 * bb * W) * z;
  for (std::size_t i = 0; i < rs_.n; ++i) {
    const cplx ce = std::conj(e_[i]);
    const cplx u = ce * z, v = ce * zd, a = ce * zdd;
    const double fn = -(a.real() - 2 * W * v.imag() - W2 * u.real() - W2 - Wp * u.imag());
    const double fw = -(a.imag() + 2 * W * v.real() - W2 * u.imag() +
                        Wp * (u.real() + 1 - 2 * rs_.nd.dbar[i] * NondimParameters::Jbar));
    const double lim = rs_.mu * fn;
    g[2 * i] = lim - fw + rs_.off_a[i];
    g[2 * i + 1] = lim + fw + rs_.off_b[i];
  }
}

template <class Table>
typename StuckPropagatorT<Table>::Result StuckPropagatorT<Table>::advance(double& t, std::vector<double>& y, double tstop,
                                                 std::vector<int>& roots, double& peak_amp_mm) {
  const std::size_t n = rs_.n;
  C_ = cplx(rs_.nd.mbar_I * rs_.nd.ebar, 0.0);
  e_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double b = y[rs_.lay().beta(i)];
    e_[i] = cplx(std::cos(b), std::sin(b));
    C_ += rs_.nd.mbar[i] * e_[i];
  }
  std::copy(y.begin(), y.begin() + static_cast<long>(ywork_.size()), ywork_.begin());
  to_modal(t, y.data());
  if (!(std::isfinite(std::abs(C_)) && std::isfinite(std::abs(a_[0])) && std::isfinite(std::abs(a_[1]))))
    return NotFinite;
  g_(t, y.data(), g0_.data(), &rs_);
  double tc = t;
  std::size_t j = tab_.interval(tc);
  while (tc < tstop) {
    if (!(tab_.t(j) <= tc && tc < tab_.t(j + 1))) j = tab_.interval(tc);
    double tn = std::min(tab_.t(j + 1), tstop);
    if (!(tn > tc)) tn = tstop;
    cplx an[2];
    if (tc == tab_.t(j) && tn == tab_.t(j + 1)) {
      for (int k = 0; k < 2; ++k) an[k] = tab_.decay(k, j) * a_[k] + C_ * tab_.forcing(k, j);
      from_modal(an, tab_.speed(j + 1), tab_.unrotate(j + 1), ywork_.data());
    } else {
      cplx P[2];
      tab_.partial(tc, tn - tc, P);
      for (int k = 0; k < 2; ++k) an[k] = std::exp(tab_.lambda(k) * (tn - tc)) * a_[k] + C_ * P[k];
      double W, Wp;
      cplx e;
      tab_.sample(tn, W, Wp, e);
      from_modal(an, W, std::conj(e), ywork_.data());
    }
    ++intervals_;
    const double x = ywork_[StateLayout::x], yy = ywork_[StateLayout::y];
    if (!std::isfinite(x * yy)) {
      t = tn;
      return NotFinite;
    }
    peak_amp_mm = std::max(peak_amp_mm, std::sqrt(x * x + yy * yy) * L_mm_);
    if (g_ == roots_plain && tn == tab_.t(j + 1))
      margins(tab_.speed(j + 1), tab_.speed_rate(j + 1), ywork_.data(), g1_.data());
    else
      g_(tn, ywork_.data(), g1_.data(), &rs_);
    double troot = tn + 1.0;
    int first = -1;
    for (std::size_t k = 0; k < g0_.size(); ++k) {
      const double a = g0_[k], b = g1_[k];
      if (a == 0.0 || !((a < 0) != (b < 0) || b == 0.0)) continue;
      const double tk = locate(k, tc, a, tn, b, a_, tc);
      if (tk < troot) {
        troot = tk;
        first = static_cast<int>(k);
      }
    }
    if (first >= 0) {
      state_at(tc, a_, troot, ywork_.data());
      g_(troot, ywork_.data(), g1_.data(), &rs_);
      roots.assign(g0_.size(), 0);
      roots[static_cast<std::size_t>(first)] = 1;
      for (std::size_t k = 0; k < g0_.size(); ++k) {
        const double a = g0_[k], b = g1_[k];
        if (a != 0.0 && ((a < 0) != (b < 0) || b == 0.0)) roots[k] = 1;
      }
      t = troot;
      std::copy(ywork_.begin(), ywork_.begin() + StateLayout::table_size, y.begin());
      return Root;
    }
    a_[0] = an[0];
    a_[1] = an[1];
    if (tn == tab_.t(j + 1) && j + 1 < tab_.intervals()) ++j;
    tc = tn;
    g0_.swap(g1_);
  }
  t = tc;
  std::copy(ywork_.begin(), ywork_.begin() + StateLayout::table_size, y.begin());
  return Stop;
}

template class StuckPropagatorT<StuckForcingTable>;
template class StuckPropagatorT<RunForcingTable>;

}  // namespace abuopt::detail
