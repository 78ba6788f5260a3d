#pragma once
// Where the runs of a startup stop, measured against the equilibrium sets (docs/equilibrium_sets.md
// section 6; the command is `abuopt eqset CONFIG --runs RUNS_CSV`).
//
// U = m_I e + sum_i m_i L e^{i beta_i} [kg m] is the residual imbalance of a configuration, G(W) =
// W^2 / (1 - W^2 + 2 i bbar W) the steady gain at W = 2 pi f / omega_n, w_i = G U / (M L) e^{-i beta_i}.
// Every ball sticks at speed f while |Im w_i| <= mu (1 + Re w_i) (no contact forces).
//
//   gauge       g(f) = max_i |Im w_i| / (mu (1 + Re w_i))     (<= 1: in the set at f; +inf where
//               1 + Re w_i <= 0, or mu = 0 with Im w_i != 0)
//   r_in(f)     = M L mu / ((1 + mu) |G|): every |U| <= r_in(f) is in the set at f
//   r_lock      = min_f r_in(f) = 2 bbar sqrt(1 - bbar^2) M L mu / (1 + mu)
//   lock band   the speeds with r_in(f) <= 6 r_lock (the set is narrower than 6 r_lock only there;
//               27.19 .. 30.94 Hz for the report's ABU), sampled on kLockBandSamples points and at the peak
//   lock gauge  g_lock = max of g over the lock band: <= 1 means the configuration is in the set of
//               every constant speed (outside the band g <= |U| / r_in <= 1/3 for |U| <= 2 r_lock)
//   depth       |U| / r_lock; a stuck run has depth >= its gauge at any speed that holds it
//               (lemma of docs/equilibrium_sets.md section 6)
//
// A run is EARLY when it settled before the band and never moved again: split `speed` (default): its
// settling speed f_s (the profile's speed at its settling time) is below resonance with
// r_in(f_s) > 2 r_lock; split `passage`: it settled before the profile first reached the band edge
// (the speed below resonance where r_in = 2 r_lock, 28.36 Hz for the report's ABU at any mu).
//
// Clusters: balls whose neighbour on the ring is within kCloseTolRad of the contact distance
// 2 asin((d_i + d_j) / 4L) form a chain; with the chains kept as they are and turned freely, the least
// |U| is max(0, 2 max_j a_j - sum_j a_j), a_0 = m_I e, a_j = |sum over chain j of m_i L e^{i beta_i}|
// (a polygon closes iff its longest side is at most the sum of the others): the CLUSTER FLOOR. Two
// touching balls: |m_I e - 2 m L cos(s_c / 2)| (11.20e-7 kg m for the report's balls).
#include <complex>
#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "abuopt/core/parameters.hpp"
#include "abuopt/core/profile.hpp"

namespace abuopt {

inline constexpr std::size_t kLockBandSamples = 281;
inline constexpr double kLockBandRatio = 6.0;    // the lock band: r_in(f) <= 6 r_lock
inline constexpr double kEarlyEdgeRatio = 2.0;   // the band edge of the early / late split: r_in = 2 r_lock
inline constexpr double kCloseTolRad = 0.04;     // a chain link: within 0.04 rad of touching

// The closed forms above; mu is p.friction_mu. beta.size() must be the ball count
// (std::invalid_argument otherwise).
std::complex<double> residual_complex_kgm(const AbuParameters& p, const std::vector<double>& beta);
std::complex<double> steady_gain(const AbuParameters& p, double frequency_hz);
double inscribed_radius_kgm(const AbuParameters& p, double frequency_hz);
double lock_radius_kgm(const AbuParameters& p);
double equilibrium_gauge(const AbuParameters& p, double frequency_hz, const std::vector<double>& beta);

// [from, to] of the lock band (bisected to 1e-12 relative) and its max of the gauge.
std::pair<double, double> lock_band_hz(const AbuParameters& p);
double lock_gauge(const AbuParameters& p, const std::vector<double>& beta);
// The speed below resonance where r_in = ratio r_lock (ratio > 1).
double band_edge_hz(const AbuParameters& p, double ratio = kEarlyEdgeRatio);

// Chains of balls (indices, in ring order); a lone ball is a chain of one.
std::vector<std::vector<std::size_t>> ball_clusters(const AbuParameters& p, const std::vector<double>& beta,
                                                    double tol_rad = kCloseTolRad);
double cluster_floor_kgm(const AbuParameters& p, const std::vector<double>& beta, double tol_rad = kCloseTolRad);

// One run of a Monte Carlo (a row of runs.csv with status ok), with the parameters it was run with.
struct FinalStateInput {
  long index = 0;
  std::vector<double> beta_final;      // rad, imbalance-relative
  bool settled = false;
  double settling_time_s = 0;
  std::optional<double> friction_mu, imbalance_mass_kg, stiffness_N_per_m;  // the run's overrides
};

enum class EarlySplit { speed, passage };

struct FinalStateRecord {
  long index = 0;
  bool early = false;
  double settling_time_s = 0, settle_hz = 0;
  double r_lock_kgm = 0;
  double depth = 0;           // |U| / r_lock
  double gauge_settle = 0;    // g(f_s)
  double lock_gauge = 0;
  double floor_depth = 0;     // cluster floor / r_lock (> 0: held up by a cluster)
  std::size_t largest_cluster = 1;
};

struct Interval {
  double lo = 0, hi = 0;
};

struct FinalStateGroup {
  std::size_t count = 0;
  double share = 0;
  Interval share_ci;          // Wilson 95 %
  double depth_mean = 0;
  Interval depth_mean_ci;     // mean +- 1.96 s / sqrt(n)
  double depth_median = 0;
  Interval depth_median_ci;   // order statistics n/2 -+ 1.96 sqrt(n)/2 (distribution-free, ~95 %)
  double lock_gauge_mean = 0, gauge_settle_mean = 0;
  double settle_hz_p10 = 0, settle_hz_median = 0, settle_hz_p90 = 0;  // type-7 quantiles
  double held_share = 0;      // share held up by a cluster (floor > 0)
  double locked_share = 0;    // share with lock gauge <= 1
};

struct FinalStateAnalysis {
  std::size_t settled = 0, not_settled = 0;
  EarlySplit split = EarlySplit::speed;
  double r_lock_kgm = 0;                 // of the nominal parameters
  double edge_hz = 0;                    // the split's band edge (nominal)
  std::optional<double> edge_time_s;     // passage: the first time the profile reaches edge_hz
  double depth_mean = 0;
  Interval depth_mean_ci;
  FinalStateGroup early, late;
  std::vector<FinalStateRecord> records;  // settled runs, in input order
};

// Every settled run measured with its own parameters (nominal with the run's overrides); edge_hz:
// the band edge of the split (default band_edge_hz of each run's parameters). Throws ConfigError
// (key "runs") when a run's angle count is not the ball count.
FinalStateAnalysis analyse_final_states(const AbuParameters& nominal, const StartupProfile& profile,
                                        const std::vector<FinalStateInput>& runs, EarlySplit split = EarlySplit::speed,
                                        std::optional<double> edge_hz = std::nullopt);

// Uniform starts in the lock set: the n x n grid beta_k = 2 pi (k + 1/2) / n over the first two balls (the
// others at other_beta; contact is not considered), the share of its points with g_lock <= 1, their mean
// depth and mean lock gauge. A ramp at the angular acceleration alpha [rad/s^2] reaches the locked
// configurations with g_lock > 1 - u, u = alpha / (mu omega_n^2) (its Euler term, docs/equilibrium_sets.md
// section 6): the share and mean depth of those with g_lock <= 1 - u ("unreached"; u = 0 without alpha).
struct LockSetStatistics {
  std::size_t grid = 0;
  double share = 0, depth_mean = 0, lock_gauge_mean = 0;
  double reach = 0, unreached_share = 0, unreached_depth_mean = 0;
};
LockSetStatistics lock_set_statistics(const AbuParameters& p, std::size_t n, const std::vector<double>& other_beta = {},
                                      double alpha_rad_s2 = 0);

// The first time [s] the profile reaches level_hz from below; nullopt if it never does.
std::optional<double> first_passage_s(const StartupProfile& profile, double level_hz);

}  // namespace abuopt
