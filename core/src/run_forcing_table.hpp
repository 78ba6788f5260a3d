#pragma once
// The stuck-phase forcing for a run whose table constants (omega_n, bbar) are its own: an uncertain
// stiffness or imbalance mass (envelope.hpp) gives every run of a study another oscillator, so the
// Simulator's StuckForcingTable (one omega_n, one bbar) does not apply, and building a table per run
// would cost about two runs (the profile samples at the quadrature nodes are its price).
//
// The split: what depends on the profile only is sampled once, in physical time, and shared
// (ForcingSamples: the grid, Omega, Omega' and e^{i phi} at the grid points, and the forcing
// F = (Omega^2 - i Omega') e^{i phi} at the Gauss-Legendre nodes of every interval of a
// changing speed); what depends on the run's oscillator is formed per run from it (RunForcingTable:
// lambda, the decay factors per piece, and P_k of an interval as the same quadrature,
//   P_k = rho_k sum_i w_i hbar e^{lambda_k hbar (1 - x_i)} F_i / omega_n^2,
// 14 complex multiply-adds, only for the intervals the run visits; closed form at constant speed).
// The grid's spacing (half a period of Omega + omega_d) uses an omega_d from a ladder of 3 % steps
// at or above the run's, so a handful of ForcingSamples serve a whole envelope.
//
// Who owns them: the Simulator (SimulatorForcing below): its rungs live as long as it does, so
// several designs evaluated at once (batches, compare) no longer evict each other's rungs from a
// small process-wide cache, and the first run to need a rung builds it while the others wait.
#include <complex>
#include <cstdint>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

#include "abuopt/core/abu_model.hpp"
#include "abuopt/core/profile.hpp"

namespace abuopt::detail {

using cplx = std::complex<double>;

class ForcingSamples {
 public:
  static constexpr int kNodes = 7;  // Gauss-Legendre nodes per interval (as StuckForcingTable)
  // The grid of a profile up to t_end_s with spacing kCheckFraction 2 pi / (Omega_max + wd_ref).
  ForcingSamples(const StartupProfile& profile, double wd_ref_rad_s, double t_end_s);
  static double ladder(double wd_rad_s);  // 1.03^ceil(log_1.03 wd)

  struct Piece {
    std::size_t j0 = 0, n = 0;  // first interval, intervals
    std::size_t node0 = 0;      // changing speed: offset of interval j0's nodes in F_
    double h = 0;               // interval length [s]
    bool last_regular = true;   // false: the last interval is longer or shorter by rounding
    bool constant = false;      // constant speed: closed form
    double Wc = 0;              // constant: Omega [rad/s]
  };
  std::size_t intervals() const { return t_.size() - 1; }
  std::size_t interval(double t_s) const;

  StartupProfile profile_;
  double t_end_s_ = 0, wd_ref_ = 0;
  std::vector<double> gl_x_, gl_w_;
  std::vector<Piece> pieces_;
  std::vector<std::uint32_t> piece_of_;   // per interval
  std::vector<double> t_, Om_, Omp_;      // grid points: t [s], Omega [rad/s], Omega' [rad/s^2]
  std::vector<cplx> rot_;                 // e^{-i phi(t_j)}
  std::vector<cplx> F_;                   // changing-speed intervals: kNodes forcing values each
  // Interval j has its piece's length h (else: the last of a piece, by rounding).
  bool regular(std::size_t j) const {
    const Piece& p = pieces_[piece_of_[j]];
    return p.last_regular || j + 1 < p.j0 + p.n;
  }
};

// One run's view of ForcingSamples with the accessors of StuckForcingTable (non-dimensional time
// tbar = omega_n t of this run). Not shared: forcing() keeps the last interval it formed.
class RunForcingTable {
 public:
  RunForcingTable(std::shared_ptr<const ForcingSamples> samples, const NondimParameters& nd);
  // The damped frequency of the table rows [rad/s] (what ForcingSamples::shared takes).
  static double damped_frequency(const NondimParameters& nd);

  std::size_t intervals() const { return s_->intervals(); }
  double t(std::size_t j) const { return s_->t_[j] * w_; }
  std::size_t interval(double tbar) const;
  const cplx& lambda(int k) const { return lam_[k]; }
  const cplx& rho(int k) const { return rho_[k]; }
  cplx decay(int k, std::size_t j) const {
    if (s_->regular(j)) return pc_[s_->piece_of_[j]].E[k];
    return std::exp(lam_[k] * (t(j + 1) - t(j)));
  }
  cplx forcing(int k, std::size_t j) const {
    if (j != formed_) form(j);
    return P_[k];
  }
  const cplx& unrotate(std::size_t j) const { return s_->rot_[j]; }
  double speed(std::size_t j) const { return s_->Om_[j] * inv_w_; }
  double speed_rate(std::size_t j) const { return s_->Omp_[j] * inv_w2_; }
  void sample(double tbar, double& W, double& Wp, cplx& eiphi) const;
  void partial(double t0, double h, cplx P[2]) const;

 private:
  void form(std::size_t j) const;  // P of interval j into P_

  std::shared_ptr<const ForcingSamples> s_;
  double w_ = 1, inv_w_ = 1, inv_w2_ = 1;  // omega_n [rad/s], 1/omega_n, 1/omega_n^2
  cplx lam_[2], rho_[2];
  bool oscillating_ = true;  // bbar < 1: lambda_2 = conj(lambda_1)
  struct PieceConstants {
    double hbar = 0;
    cplx E[2];                                  // e^{lambda_k hbar}
    cplx Fc[2];                                 // constant speed: P_k / e^{i phi(t_j)}
    // changing speed: real quadrature weights. bbar < 1: u_i + i v_i = w_i hbar e^{lambda_1
    // tau_i} / omega_n^2 (tau_i = hbar (1 - x_i)), so the two modes' sums are A +- i B with
    // A = sum u_i F_i, B = sum v_i F_i; bbar > 1 (real lambda): u, v are the two modes' weights.
    double u[ForcingSamples::kNodes], v[ForcingSamples::kNodes];
  };
  std::vector<PieceConstants> pc_;
  mutable std::size_t formed_ = static_cast<std::size_t>(-1);
  mutable cplx P_[2];
};

class StuckForcingTable;

// A Simulator's stuck-phase forcing (thread-safe; one per Simulator, shared by its runs): the
// nominal StuckForcingTable, built at the first run with the Simulator's own omega_n and bbar (a
// study whose every run overrides stiffness or imbalance mass never builds it), and the
// ForcingSamples rungs of the runs with their own, one per ladder step. Each is built once, by
// the first run that needs it; runs needing it meanwhile wait for that build.
class SimulatorForcing {
 public:
  SimulatorForcing(const StartupProfile& profile, const NondimParameters& nominal, double t_end_s);
  // The nominal table when nd is the Simulator's (omega_n and bbar equal) and the table can be
  // stored; else null.
  const StuckForcingTable* nominal(const NondimParameters& nd);
  // The samples for a run with damped frequency wd [rad/s] (the ladder's step at or above wd).
  std::shared_ptr<const ForcingSamples> samples(double wd_rad_s);
  std::size_t rungs() const;  // built or being built

 private:
  StartupProfile profile_;
  NondimParameters nominal_;
  double t_end_s_ = 0;
  std::once_flag nominal_once_;
  std::shared_ptr<const StuckForcingTable> nominal_table_;
  mutable std::mutex mutex_;
  std::map<double, std::shared_future<std::shared_ptr<const ForcingSamples>>> rungs_;  // by wd_ref
};

}  // namespace abuopt::detail
