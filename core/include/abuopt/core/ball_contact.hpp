#pragma once
// Hard ball-ball contact along the rim (derivation: docs/model.md section 11).
//
// Geometry: balls i and j touch when their centres, both at radius L, are 2 asin((d_i + d_j)/4L)
// apart in angle. Balls keep their cyclic order on the track (they cannot pass each other), so
// the constraint is one gap per neighbour pair of that order, g_k = beta_next - beta_k - spacing_k
// (+ 2 pi for the pair that wraps around) >= 0, linear in the angles.
//
// Impacts: with the model's mass matrix M (symmetric form of the reduced equations: the ball rows
// times mbar_i), an impulse P along the gap's gradient G changes the velocities by
// M^-1 G^T P; Newton's law g'+ = -e g'- gives P = -(1 + e) g'- / (G M^-1 G^T). The table and every
// ball not held by stick take part (the effective mass of the constrained system, not m_i).
#include <cstddef>
#include <vector>

#include "abuopt/core/abu_model.hpp"
#include "abuopt/core/parameters.hpp"

namespace abuopt {

// Least centre angle between touching balls i and j: 2 asin((d_i + d_j) / 4L).
double contact_spacing(const AbuParameters& p, std::size_t i, std::size_t j);

// The cyclic order of the balls by angle and the least spacing of each neighbour pair.
struct ContactGeometry {
  std::vector<std::size_t> order;  // ball indices by increasing angle in [0, 2 pi)
  std::vector<double> spacing;     // spacing[k]: between order[k] and order[(k + 1) % N]
  // Orders the balls by their angles (ties by index).
  static ContactGeometry from(const AbuParameters& p, const std::vector<double>& beta);
  std::size_t pairs() const { return order.size() < 2 ? 0 : order.size(); }
  // Gap of pair k for continuous (unwrapped) angles whose order is `order`.
  double gap(const double* beta, std::size_t k) const;
};

// Smallest gap - spacing over neighbour pairs of angles given in any range (wrapped here);
// negative: two balls overlap. +inf for fewer than two balls.
double min_contact_clearance(const AbuParameters& p, const std::vector<double>& beta);

// Maps any angles onto the feasible set (docs/model.md 11.6): keeps ball 0, walks around the
// circle from it in increasing angle and scales every free spacing by (2 pi - S) / 2 pi, S the
// sum of the least spacings: gap_k = spacing_k + raw_gap_k (2 pi - S) / 2 pi. Deterministic (so a
// design point stays replayable from (seed, index)), continuous, and it maps the uniform
// distribution on the torus onto the uniform distribution on the feasible set. Result in [0, 2 pi).
std::vector<double> map_onto_contact_feasible_set(const AbuParameters& p, const std::vector<double>& beta);

// Non-dimensional mass matrix of the reduced equations (x, y, beta_1..beta_N) at angles beta:
// [1, 0, -mbar_i s_i; 0, 1, mbar_i c_i; sym, diag(mbar_i D_i)], in units of M L^2.
std::vector<double> mass_matrix(const NondimParameters& nd, const double* beta);  // row-major

// Velocity jump of an impact between ball `rear` and ball `front` (front = the one ahead in
// angle). qdot = (x', y', beta_1'..beta_N'). group_of[i]: balls with the same id move rigidly
// together (clusters); held[i] != 0: the ball's velocity is held (stuck by friction, not part of
// the impact). Restitution e in [0, 1]. Returns the impulse P (>= 0 for an approach).
double apply_impact(const NondimParameters& nd, const double* beta, std::vector<double>& qdot,
                    const std::vector<int>& group_of, const std::vector<char>& held, std::size_t rear,
                    std::size_t front, double e);

// Kinetic energy 1/2 qdot^T M qdot (units of M L^2 omega_n^2).
double kinetic_energy(const NondimParameters& nd, const double* beta, const std::vector<double>& qdot);

}  // namespace abuopt
