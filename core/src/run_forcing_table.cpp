// The stuck-phase forcing of a run with its own omega_n and bbar (run_forcing_table.hpp).
#include "run_forcing_table.hpp"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <stdexcept>

#include "stuck_propagator.hpp"

namespace abuopt::detail {

namespace {
constexpr double kCheckFraction = 0.5;  // as StuckForcingTable: grid spacing / fastest margin period
constexpr double kLadderStep = 1.03;
}  // namespace

double ForcingSamples::ladder(double wd) {
  if (!(wd > 1e-9)) return 0.0;
  return std::pow(kLadderStep, std::ceil(std::log(wd) / std::log(kLadderStep) - 1e-12));
}

ForcingSamples::ForcingSamples(const StartupProfile& profile, double wd_ref, double t_end_s)
    : profile_(profile), t_end_s_(t_end_s), wd_ref_(wd_ref) {
  gauss_legendre(kNodes, gl_x_, gl_w_);
  struct Span {
    double a, b, Wmax;
    bool constant;
  };
  std::vector<Span> spans;
  const double to_W = 2.0 * M_PI;
  const auto& br = profile_.breakpoints_s();
  for (std::size_t k = 0; k < profile_.segments().size(); ++k) {
    const double a = br[k], b = std::min(br[k + 1], t_end_s);
    if (a >= t_end_s) break;
    const double f0 = k == 0 ? profile_.start_frequency_hz() : profile_.segments()[k - 1].end_frequency_hz;
    const double f1 = profile_.segments()[k].end_frequency_hz;
    spans.push_back({a, b, to_W * std::max(f0, f1), f0 == f1});
  }
  const double tp = profile_.duration_s();
  if (t_end_s > tp) spans.push_back({tp, t_end_s, to_W * profile_.final_frequency_hz(), true});

  auto at = [&](double t, double& Om, double& Omp, cplx& e) {
    double rev = 0;
    const ProfileSample s = profile_.sample(t, &rev);
    Om = to_W * s.frequency_hz;
    Omp = to_W * s.rate_hz_per_s;
    const double ph = 2.0 * M_PI * (rev - std::floor(rev));
    e = cplx(std::cos(ph), std::sin(ph));
  };
  auto push_point = [&](double t, double Om, double Omp, const cplx& e) {
    t_.push_back(t);
    Om_.push_back(Om);
    Omp_.push_back(Omp);
    rot_.push_back(std::conj(e));
  };
  {
    double Om, Omp;
    cplx e;
    at(0.0, Om, Omp, e);
    push_point(0.0, Om, Omp, e);
  }
  for (const Span& sp : spans) {
    const double spacing = kCheckFraction * 2.0 * M_PI / (sp.Wmax + wd_ref_);
    const long n = std::max(1L, static_cast<long>(std::ceil((sp.b - sp.a) / spacing)));
    Piece pc;
    pc.j0 = t_.size() - 1;
    pc.n = static_cast<std::size_t>(n);
    pc.node0 = F_.size();
    pc.h = (sp.b - sp.a) / static_cast<double>(n);
    pc.constant = sp.constant;
    pc.Wc = sp.Wmax;
    pc.last_regular = sp.b - (sp.a + static_cast<double>(n - 1) * pc.h) == pc.h;
    pieces_.push_back(pc);
    double Om0, Omp0;
    cplx e0;
    at(sp.a, Om0, Omp0, e0);
    for (long j = 0; j < n; ++j) {
      const double t0 = sp.a + static_cast<double>(j) * pc.h;
      const double t1 = j + 1 == n ? sp.b : sp.a + static_cast<double>(j + 1) * pc.h;
      piece_of_.push_back(static_cast<std::uint32_t>(pieces_.size() - 1));
      if (!sp.constant) {
        for (int i = 0; i < kNodes; ++i) {
          double Om, Omp;
          cplx e;
          at(t0 + (t1 - t0) * gl_x_[static_cast<std::size_t>(i)], Om, Omp, e);
          F_.push_back(cplx(Om * Om, -Omp) * e);
        }
      }
      if (sp.constant && j + 1 < n) {
        push_point(t1, sp.Wmax, 0.0, e0 * std::polar(1.0, sp.Wmax * (t1 - sp.a)));
      } else {
        double Om, Omp;
        cplx e;
        at(t1, Om, Omp, e);
        push_point(t1, Om, Omp, e);
      }
    }
  }
  if (t_.size() < 2) throw std::invalid_argument("ForcingSamples: empty time span");
}

std::size_t ForcingSamples::interval(double t_s) const {
  const auto it = std::upper_bound(t_.begin(), t_.end(), t_s);
  const std::size_t j = it == t_.begin() ? 0 : static_cast<std::size_t>(it - t_.begin()) - 1;
  return std::min(j, intervals() - 1);
}

SimulatorForcing::SimulatorForcing(const StartupProfile& profile, const NondimParameters& nominal, double t_end_s)
    : profile_(profile), nominal_(nominal), t_end_s_(t_end_s) {}

const StuckForcingTable* SimulatorForcing::nominal(const NondimParameters& nd) {
  if (!(nd.omega_n == nominal_.omega_n && nd.bbar == nominal_.bbar) || !StuckForcingTable::supports(nominal_))
    return nullptr;
  std::call_once(nominal_once_, [this] {
    try {
      nominal_table_ = StuckForcingTable::shared(profile_, nominal_, t_end_s_ * nominal_.omega_n);
    } catch (const std::invalid_argument&) {
      // a profile too long for a stored table (kMaxStoredIntervals): the runs use the rungs
    }
  });
  return nominal_table_.get();
}

std::shared_ptr<const ForcingSamples> SimulatorForcing::samples(double wd) {
  const double ref = ForcingSamples::ladder(wd);
  std::promise<std::shared_ptr<const ForcingSamples>> build;
  std::shared_future<std::shared_ptr<const ForcingSamples>> rung;
  bool builder = false;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    const auto it = rungs_.find(ref);
    if (it != rungs_.end()) {
      rung = it->second;
    } else {
      rung = build.get_future().share();
      rungs_.emplace(ref, rung);
      builder = true;
    }
  }
  if (builder) {  // outside the lock: other rungs stay available; this rung's users wait in get()
    try {
      build.set_value(std::make_shared<const ForcingSamples>(profile_, ref, t_end_s_));
    } catch (...) {
      build.set_exception(std::current_exception());
    }
  }
  return rung.get();
}

std::size_t SimulatorForcing::rungs() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return rungs_.size();
}

double RunForcingTable::damped_frequency(const NondimParameters& nd) {
  return nd.omega_n * std::fabs(std::sqrt(cplx(nd.bbar * nd.bbar - 1.0, 0.0)).imag());
}

RunForcingTable::RunForcingTable(std::shared_ptr<const ForcingSamples> samples, const NondimParameters& nd)
    : s_(std::move(samples)), w_(nd.omega_n), inv_w_(1.0 / nd.omega_n), inv_w2_(1.0 / (nd.omega_n * nd.omega_n)) {
  if (!StuckForcingTable::supports(nd)) throw std::invalid_argument("RunForcingTable: needs 0 < bbar != 1");
  const double bbar = nd.bbar;
  const cplx root = std::sqrt(cplx(bbar * bbar - 1.0, 0.0));
  lam_[0] = -bbar + root;
  lam_[1] = -bbar - root;
  rho_[0] = 1.0 / (lam_[0] - lam_[1]);
  rho_[1] = -rho_[0];
  oscillating_ = bbar < 1.0;
  const double inv_w2 = inv_w2_;
  pc_.resize(s_->pieces_.size());
  for (std::size_t p = 0; p < pc_.size(); ++p) {
    const ForcingSamples::Piece& piece = s_->pieces_[p];
    PieceConstants& c = pc_[p];
    c.hbar = piece.h * w_;
    for (int k = 0; k < 2; ++k) {
      c.E[k] = std::exp(lam_[k] * c.hbar);
      if (piece.constant) {
        const double W = piece.Wc / w_;
        c.Fc[k] = rho_[k] * W * W * (std::exp(cplx(0, W * c.hbar)) - c.E[k]) / (cplx(0, W) - lam_[k]);
      }
    }
    if (!piece.constant) {
      for (int i = 0; i < ForcingSamples::kNodes; ++i) {
        const auto ii = static_cast<std::size_t>(i);
        const double tau = c.hbar - c.hbar * s_->gl_x_[ii], wt = s_->gl_w_[ii] * c.hbar * inv_w2;
        if (oscillating_) {
          const cplx e = wt * std::exp(lam_[0] * tau);
          c.u[i] = e.real();
          c.v[i] = e.imag();
        } else {
          c.u[i] = wt * std::exp(lam_[0].real() * tau);
          c.v[i] = wt * std::exp(lam_[1].real() * tau);
        }
      }
    }
  }
}

std::size_t RunForcingTable::interval(double tbar) const {
  const auto& t = s_->t_;
  const double w = w_;
  const auto it = std::upper_bound(t.begin(), t.end(), tbar, [w](double v, double tj) { return v < tj * w; });
  const std::size_t j = it == t.begin() ? 0 : static_cast<std::size_t>(it - t.begin()) - 1;
  return std::min(j, intervals() - 1);
}


void RunForcingTable::form(std::size_t j) const {
  const PieceConstants& c = pc_[s_->piece_of_[j]];
  const ForcingSamples::Piece& piece = s_->pieces_[s_->piece_of_[j]];
  formed_ = j;
  if (!s_->regular(j)) {  // the last of a piece, of another length by rounding
    partial(t(j), t(j + 1) - t(j), P_);
    return;
  }
  if (piece.constant) {
    const cplx e = std::conj(s_->rot_[j]);
    P_[0] = c.Fc[0] * e;
    P_[1] = c.Fc[1] * e;
    return;
  }
  // real arithmetic on the interleaved (re, im) pairs: 28 multiply-adds
  const double* F = reinterpret_cast<const double*>(s_->F_.data() + piece.node0 +
                                                     (j - piece.j0) * ForcingSamples::kNodes);
  double ar = 0, ai = 0, br = 0, bi = 0;
  for (int i = 0; i < ForcingSamples::kNodes; ++i) {
    const double fr = F[2 * i], fi = F[2 * i + 1];
    ar += c.u[i] * fr;
    ai += c.u[i] * fi;
    br += c.v[i] * fr;
    bi += c.v[i] * fi;
  }
  if (oscillating_) {  // A +- i B
    P_[0] = rho_[0] * cplx(ar - bi, ai + br);
    P_[1] = rho_[1] * cplx(ar + bi, ai - br);
  } else {
    P_[0] = rho_[0] * cplx(ar, ai);
    P_[1] = rho_[1] * cplx(br, bi);
  }
}


void RunForcingTable::sample(double tbar, double& W, double& Wp, cplx& eiphi) const {
  double rev = 0;
  const ProfileSample s = s_->profile_.sample(tbar * inv_w_, &rev);
  W = 2.0 * M_PI * s.frequency_hz * inv_w_;
  Wp = 2.0 * M_PI * s.rate_hz_per_s * inv_w2_;
  const double ph = 2.0 * M_PI * (rev - std::floor(rev));
  eiphi = cplx(std::cos(ph), std::sin(ph));
}

void RunForcingTable::partial(double t0, double h, cplx P[2]) const {
  P[0] = P[1] = 0.0;
  if (!(h > 0)) return;
  for (int i = 0; i < ForcingSamples::kNodes; ++i) {
    const auto ii = static_cast<std::size_t>(i);
    const double s = h * s_->gl_x_[ii];
    double W, Wp;
    cplx e;
    sample(t0 + s, W, Wp, e);
    const cplx g = cplx(W * W, -Wp) * e * (s_->gl_w_[ii] * h);
    for (int k = 0; k < 2; ++k) P[k] += rho_[k] * std::exp(lam_[k] * (h - s)) * g;
  }
}

}  // namespace abuopt::detail
