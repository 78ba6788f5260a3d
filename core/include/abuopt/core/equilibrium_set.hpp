#pragma once
// Equilibrium sets of an ABU at constant speed (report section 4.2, fig 4.3; derivation and
// closed forms: docs/equilibrium_sets.md).
//
// At constant speed W = Omega/omega_n (W' = 0) with every ball stuck (beta_i' = beta_i'' = 0) at
// the angles beta, the table rests in the rotating frame at its steady state z = xbar + i ybar,
// from the static balance of the x and y rows (the 2x2 system of closed_form_tail):
//
//   [1 - W^2, -2 bbar W; 2 bbar W, 1 - W^2] [xbar; ybar] = W^2 [Re C; Im C]
//   <=>  z = G(W) C,  G(W) = W^2 / (1 - W^2 + 2 i bbar W),
//   C = mbar_I ebar + sum_i mbar_i e^{i beta_i}   (the combined imbalance U / (M L)).
//
// With x'' = y'' = 0 the ball rows and normal forces give, with w_i = z e^{-i beta_i},
//
//   fw_i = W^2 Im(w_i),   fn_i = W^2 (1 + Re(w_i))   (divided by m_i omega_n^2 L),
//
// and the configuration belongs to the equilibrium set when every ball's needed friction lies in
// its friction cone: |fw_i| <= mu fn_i (and fn_i > 0). The code evaluates the forces with
// AbuModel::evaluate (all modes Stick) on the steady state; the closed forms are for the tests.
//
// Coverage of the whole (beta_1, ..., beta_N) torus is 1 exactly when, for every ball i,
//
//   mu (1 + mbar_i Re G) - mbar_i |Im G| >= sqrt(1 + mu^2) |G| R_i,
//   R_i = mbar_I ebar + sum_{j != i} mbar_j,
//
// (the disc of all reachable w_i lies inside the cone); full_coverage_margin() is the smallest
// difference of the two sides, and exact_band_hz() finds where it is negative.
#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

#include "abuopt/core/abu_model.hpp"
#include "abuopt/core/parameters.hpp"

namespace abuopt {

// The largest constant speed an equilibrium set is computed for: the steady amplitude grows with
// (2 pi f)^4 terms, and 1e6 Hz keeps every product finite (`eqset --freq/--scan`, Python's
// equilibrium_set).
inline constexpr double kMaxEquilibriumFrequencyHz = 1e6;

// One configuration tested for membership.
struct EquilibriumPoint {
  double xbar = 0, ybar = 0;     // steady table position / L (rotating frame)
  double amplitude_mm = 0;       // sqrt(x^2 + y^2) in mm
  std::vector<double> fn, fw;    // normal force and needed friction per ball (/ m_i omega_n^2 L)
  std::vector<double> margins;   // mu fn_i - |fw_i| per ball (>= 0: inside the cone)
  double min_margin = 0;         // smallest of margins
  bool in_set = false;
  // abu.ball_contact: hard only (docs/equilibrium_sets.md section 5): two balls overlap (never in
  // the set), or some pair touches (its balls are judged as one stuck cluster).
  bool overlapping = false;
  bool touching = false;
};

// An n x n grid over (beta_1, beta_2) in [0, 2 pi)^2, beta_k = 2 pi k / n, row-major:
// index(i, j) has beta_1 = beta(i), beta_2 = beta(j). Further balls sit at `other_beta`.
struct EquilibriumGrid {
  double frequency_hz = 0;
  double mu = 0;
  std::size_t n = 0;
  std::size_t n_balls = 0;
  std::vector<double> other_beta;     // angles of balls 3..N (rad)
  std::vector<double> amplitude_mm;   // n*n
  std::vector<char> in_set;           // n*n (1 in the set)
  std::vector<double> margins;        // n*n*n_balls: margins[index * n_balls + ball]
  // abu.ball_contact: hard: 1 where two balls overlap (excluded: not a configuration). Empty
  // without contact.
  std::vector<char> excluded;
  double beta(std::size_t k) const;
  std::size_t index(std::size_t i, std::size_t j) const { return i * n + j; }
  double coverage() const;            // fraction of grid points in the set
  double min_amplitude_mm() const;
  double max_amplitude_mm() const;
};

// Coverage per frequency and the band where it is below 1.
struct EquilibriumScan {
  double mu = 0;
  std::size_t grid_n = 0;
  std::vector<double> frequency_hz;
  std::vector<double> coverage;
  // Lowest and highest scanned frequency with coverage < 1 (none if the set always covers).
  std::optional<std::pair<double, double>> band_hz;
  double natural_frequency_hz = 0;
};

class EquilibriumSet {
 public:
  // mu < 0: use p.friction_mu. `tolerance`: a ball counts as inside when
  // margin >= -tolerance * fn (rounding of a zero margin, e.g. mu = 0 at the balancing positions).
  explicit EquilibriumSet(const AbuParameters& p, double mu = -1, double tolerance = 1e-9);

  const AbuParameters& parameters() const { return params_; }
  double mu() const { return mu_; }
  std::size_t n_balls() const { return model_.n_balls(); }
  double natural_frequency_hz() const { return params_.natural_frequency_hz(); }
  double speed_ratio(double frequency_hz) const;  // W = 2 pi f / omega_n

  // Steady table position (xbar, ybar) for all balls stuck at beta at frequency f (Hz > 0).
  // Infinite when the static balance is singular (bbar = 0 at W = 1).
  std::pair<double, double> steady_state(double frequency_hz, const std::vector<double>& beta) const;

  // Membership of one configuration (beta.size() == n_balls()).
  EquilibriumPoint point(double frequency_hz, const std::vector<double>& beta) const;

  // Grid over the first two balls (needs n_balls() >= 2; other_beta holds the rest, n_balls()-2).
  EquilibriumGrid grid(double frequency_hz, std::size_t n, const std::vector<double>& other_beta = {}) const;

  // Fraction of the n x n grid in the set (no per-point storage).
  double coverage(double frequency_hz, std::size_t n, const std::vector<double>& other_beta = {}) const;

  // Coverage at from, from + step, ..., <= to (+ rounding slack).
  EquilibriumScan scan(double from_hz, double to_hz, double step_hz, std::size_t n,
                       const std::vector<double>& other_beta = {}) const;

  // abu.ball_contact: hard, two balls: the contact lines beta_2 = beta_1 +- delta (delta the least
  // spacing), sampled at beta_1 = 2 pi k / n. in_set[side][k], side 0: ball 2 ahead of ball 1
  // (beta_2 = beta_1 + delta), side 1: behind. Throws std::invalid_argument without hard contact
  // or for other than two balls.
  struct ContactLine {
    double spacing_rad = 0;
    std::size_t n = 0;
    std::vector<char> in_set[2];
    double coverage(int side) const;  // fraction of the line's samples in the set
  };
  ContactLine contact_line(double frequency_hz, std::size_t n) const;

  // Closed form: min over balls of mu (1 + mbar_i Re G) - mbar_i |Im G| - sqrt(1 + mu^2) |G| R_i.
  // >= 0: every configuration is in the set (coverage 1 over the continuous torus).
  double full_coverage_margin(double frequency_hz) const;

  // Where full_coverage_margin < 0 within [from_hz, to_hz], edges bisected to ~1e-9 Hz
  // (sampled on `samples` points first; assumes one band, as near a single resonance).
  std::optional<std::pair<double, double>> exact_band_hz(double from_hz, double to_hz,
                                                         std::size_t samples = 2000) const;

 private:
  bool evaluate_point(double W, const double* beta, std::vector<double>& state, ModelForces& f,
                      double* margins_out, double& amp_mm, bool* overlapping = nullptr,
                      bool* touching = nullptr) const;
  AbuParameters params_;
  NondimParameters nd_;
  AbuModel model_;
  double mu_;
  double tol_;
};

}  // namespace abuopt
