#pragma once
// What residual imbalance the equilibrium set of a speed allows (issue 10, section 1; derivation
// and figures: docs/equilibrium_sets.md section 4).
//
// The residual imbalance of a configuration, U = m_I e + sum_i m_i L e^{i beta_i} [kg m], does not
// depend on the speed: |I_r| = |U| and the report's I_r,x = |Re U|. The speed decides only which
// configurations are in the set. Per frequency this computes, over the grid points in the set
// (a uniform grid: statistics over the set's area), over the connected part of the set that holds
// the frictionless balancing points (C = 0), and over that part's boundary, the smallest, median,
// mean and largest |I_r| and I_r,x.
//
// Closed form (the inscribed disc): ball i is outside its friction cone only if
// |Im w_i| > mu (1 + Re w_i), which needs |w_i| > mu / (1 + mu); |w_i| = |G(W)| |U| / (M L), so
//
//   every configuration with |U| <= r_in(f) = M L mu / ((1 + mu) |G(W)|) is in the set at f,
//
// and r_lock = M L mu / ((1 + mu) max_W |G(W)|), max |G| = 1 / (2 bbar sqrt(1 - bbar^2)), is in the
// set at EVERY speed: no constant speed can set balls stuck there sliding again.
#include <cstddef>
#include <vector>

#include "abuopt/core/equilibrium_set.hpp"

namespace abuopt {

// Statistics of a residual imbalance over a set of grid points [kg m]; NaN when count == 0.
struct ResidualStatistics {
  std::size_t count = 0;
  double min = 0, median = 0, mean = 0, max = 0;
};

// |I_r| and I_r,x over one set of grid points.
struct ResidualPair {
  ResidualStatistics magnitude;  // |I_r| = |U|
  ResidualStatistics x;          // I_r,x = |Re U| (report eq 4.2)
};

struct EquilibriumResidual {
  double frequency_hz = 0;
  double speed_ratio = 0;
  std::size_t grid_n = 0;
  double coverage = 0;                  // fraction of grid points in the set
  double inscribed_kgm = 0;             // r_in(f), closed form
  ResidualPair in_set;                  // over every grid point in the set
  ResidualPair around_balance;          // the connected part(s) of the set holding a balancing point
  double around_balance_fraction = 0;   // its share of the grid
  ResidualPair boundary;                // points of that part with a 4-neighbour outside it (empty:
                                        // the part is the whole torus)
};

// Residual imbalance U of a configuration [kg m] as (Re U, Im U).
std::pair<double, double> residual_vector_kgm(const AbuParameters& p, const std::vector<double>& beta);

// r_in(f) and r_lock of the header comment [kg m] (mu and parameters of `set`).
double inscribed_residual_kgm(const EquilibriumSet& set, double frequency_hz);
double locked_residual_kgm(const EquilibriumSet& set);

// Two balls of masses m_1, m_2 a (wrapped) angle s apart: U = m_I e + L (m_1 e^{i b_1} + m_2 e^{i b_2}),
// and the ball pair's vector has length L |m_1 + m_2 e^{i s}| whatever its orientation, so
//   |I_r| >= | m_I e - L |m_1 + m_2 e^{i s}| |   (= |m_I e - 2 m L cos(s/2)| for equal balls),
// with equality when the pair points away from the imbalance. No orientation does better: a run whose
// balls end s apart cannot end below this, which bounds what balls that travel together can reach.
// Needs exactly two balls (std::invalid_argument otherwise).
double pair_separation_floor_kgm(const AbuParameters& p, double separation_rad);

// The balancing configurations in the (beta_1, beta_2) plane with balls 3..N at other_beta: the
// (0, 1 or 2) solutions of U = 0, each {beta_1, beta_2} in [0, 2 pi).
std::vector<std::pair<double, double>> balancing_angles(const AbuParameters& p,
                                                        const std::vector<double>& other_beta = {});

// The statistics of one frequency on an n x n grid (as EquilibriumSet::grid).
EquilibriumResidual equilibrium_residual(const EquilibriumSet& set, double frequency_hz, std::size_t n,
                                         const std::vector<double>& other_beta = {});

// The same at from, from + step, ..., <= to.
std::vector<EquilibriumResidual> equilibrium_residual_scan(const EquilibriumSet& set, double from_hz, double to_hz,
                                                           double step_hz, std::size_t n,
                                                           const std::vector<double>& other_beta = {});

}  // namespace abuopt
