#pragma once
// Designs of experiments (DOE) in a box.
//
// Every design is produced in scaled variables: the box is [-1,1]^n, one row per point, one
// column per variable. Map a design to real bounds with scale_to_bounds() (x = c + h s, with
// c = (lo+hi)/2 and h = (hi-lo)/2) and back with scale_from_bounds(). Deterministic designs are
// returned in a fixed, documented row order; the random one (Latin hypercube) depends only on its
// explicit seed (std::mt19937_64), so the same seed always gives the same design.
//
// Bad arguments (n < 1, levels < 2, Box-Behnken with n < 3, ...) throw std::invalid_argument
// with a message naming the value and the rule, e.g. "box_behnken: n = 2: must be >= 3".

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace abuopt::surrogate {

// ---------------------------------------------------------------------------------------------
// Full factorial: every combination of `levels` equally spaced values in [-1,1] per variable,
// prod(levels) points. Row order: the first variable varies slowest, the last fastest.
Eigen::MatrixXd full_factorial(int n, int levels);
// Per-variable level counts (levels.size() = n variables, each >= 2).
Eigen::MatrixXd full_factorial(const std::vector<int>& levels);

// ---------------------------------------------------------------------------------------------
// Central composite design: 2^n factorial corners at +-1, 2n star (axial) points at +-alpha on
// each axis, and `center_points` copies of the centre. Row order: corners (as full_factorial
// with 2 levels), star points (-alpha e_1, +alpha e_1, -alpha e_2, ...), centres.
enum class CentralCompositeType {
  kFaceCentred,    // alpha = 1: star points on the faces of the box; every point inside the box.
  kCircumscribed,  // alpha = (2^n)^(1/4) (rotatable): star points OUTSIDE [-1,1]^n.
  kInscribed,      // the circumscribed design shrunk by 1/alpha: star points at +-1, corners at
                   // +-1/alpha; rotatable and inside the box.
};

struct CentralCompositeOptions {
  CentralCompositeType type = CentralCompositeType::kFaceCentred;  // default: face-centred
  int center_points = 1;  // copies of the centre point (>= 0)
};

// Rotatable alpha = (2^n)^(1/4) of a central composite design in n variables.
double rotatable_alpha(int n);
// Number of points: 2^n + 2n + center_points.
Eigen::MatrixXd central_composite(int n, const CentralCompositeOptions& options = {});

// ---------------------------------------------------------------------------------------------
// Box-Behnken design (n >= 3): for every pair of variables (i < j) the four points
// (x_i, x_j) = (+-1, +-1) with all other variables at 0, then `center_points` centres.
// Number of points: 4 n(n-1)/2 + center_points (n = 3: 12 + centres; n = 4: 24 + centres).
// No point lies on a corner of the box. (For n >= 6 the published designs use balanced
// incomplete blocks with fewer points; this pairwise construction is the general one.)
struct BoxBehnkenOptions {
  int center_points = 1;  // copies of the centre point (>= 0)
};
Eigen::MatrixXd box_behnken(int n, const BoxBehnkenOptions& options = {});

// ---------------------------------------------------------------------------------------------
// Latin hypercube with a maximin criterion. Each variable's range [-1,1] is cut into `points`
// equal strata of width 2/points; every stratum holds exactly one point in every variable.
// `candidates` random hypercubes are drawn and the one whose smallest pairwise Euclidean
// distance is largest is returned (ties: the first drawn).
struct LatinHypercubeOptions {
  int points = 10;            // number of points m (>= 1), also the number of strata
  int candidates = 50;        // K random hypercubes compared by minimal pairwise distance (>= 1)
  std::uint64_t seed = 0;     // seed of std::mt19937_64; same seed -> same design
  bool centred = false;       // true: each point at its stratum's midpoint; false: uniform in it
};
Eigen::MatrixXd latin_hypercube(int n, const LatinHypercubeOptions& options = {});

// Smallest pairwise Euclidean distance between the rows of `design` (+infinity for < 2 rows);
// the maximin criterion used by latin_hypercube().
double min_pairwise_distance(const Eigen::MatrixXd& design);

// ---------------------------------------------------------------------------------------------
// Minimal linear design (Koshal first-order / one-at-a-time): the centre, then one point per
// variable at +1 on that axis (row i+1 = e_i). n+1 points: exactly enough for a linear model,
// which it determines uniquely (no degrees of freedom left for error estimates).
Eigen::MatrixXd koshal_linear(int n);

// ---------------------------------------------------------------------------------------------
// Scaling between [-1,1]^n and real bounds [lo, hi] (lo < hi componentwise, sizes = columns).
// Rows are points. Throws std::invalid_argument on size mismatch or lo >= hi.
Eigen::MatrixXd scale_to_bounds(const Eigen::MatrixXd& scaled, const Eigen::VectorXd& lo,
                                const Eigen::VectorXd& hi);
Eigen::MatrixXd scale_from_bounds(const Eigen::MatrixXd& real, const Eigen::VectorXd& lo,
                                  const Eigen::VectorXd& hi);
// Single-point versions (x is one point).
Eigen::VectorXd point_to_bounds(const Eigen::VectorXd& scaled, const Eigen::VectorXd& lo,
                                const Eigen::VectorXd& hi);
Eigen::VectorXd point_from_bounds(const Eigen::VectorXd& real, const Eigen::VectorXd& lo,
                                  const Eigen::VectorXd& hi);

std::string to_string(CentralCompositeType type);
// "face_centred", "circumscribed", "inscribed"; throws std::invalid_argument otherwise.
CentralCompositeType central_composite_type_from_string(const std::string& name);

}  // namespace abuopt::surrogate
