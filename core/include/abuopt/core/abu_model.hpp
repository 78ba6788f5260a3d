#pragma once
// The reduced N-ball ABU equations (derivation: docs/model.md), non-dimensional.
//
// Variables: xbar = x/L, ybar = y/L (disc centre B in the rotating frame), beta_i (ball angle from
// the imbalance, disc frame), tbar = omega_n t, W = Omega/omega_n, W' = dW/dtbar; primes are
// d/dtbar, s_i = sin beta_i, c_i = cos beta_i, mbar_i = m_i/M, mbar_I = m_I/M, ebar = e/L,
// dbar_i = d_i/L, bbar = b/(2 M omega_n), Jbar = 1/10 (solid sphere), D_i = 1 + 4 Jbar.
//
//   x-row:   xbar'' - sum_i mbar_i s_i beta_i'' + h_x = 0
//   y-row:   ybar'' + sum_i mbar_i c_i beta_i'' + h_y = 0
//   ball i:  -s_i xbar'' + c_i ybar'' + D_i beta_i'' + h_b,i + cbar_i beta_i' + fw_i = 0
//   normal:  fn_i = -(c_i xbar'' + s_i ybar'' + h_l,i)
//
//   h_x   = -2 ybar' W - xbar W^2 - mbar_I ebar W^2 - W'(ybar + sum mbar_i s_i)
//           - sum mbar_i (beta_i' + W)^2 c_i + xbar + 2 bbar (xbar' - ybar W)
//   h_y   =  2 xbar' W - ybar W^2 + W'(xbar + mbar_I ebar + sum mbar_i c_i)
//           - sum mbar_i (beta_i' + W)^2 s_i + ybar + 2 bbar (ybar' + xbar W)
//   h_b,i =  2 xbar' W c_i + 2 ybar' W s_i + xbar W^2 s_i - ybar W^2 c_i
//           + W'(xbar c_i + ybar s_i + 1 - 2 dbar_i Jbar)
//   h_l,i =  2 xbar' W s_i - 2 ybar' W c_i - xbar W^2 c_i - ybar W^2 s_i - (beta_i' + W)^2
//           + 2 Jbar beta_i' (dbar_i W - 2 beta_i') + W'(xbar s_i - ybar c_i)
//
// fw_i, fn_i are divided by m_i omega_n^2 L; cbar_i = c_ball / (m_i omega_n L^2) is the optional
// viscous ball damping. Coulomb friction: fw_i in mu fn_i Sign(beta_i').
//   slip (sigma_i = sign beta_i' = +-1): fw_i = mu sigma_i fn_i
//   stick: beta_i'' = 0 and fw_i is what that needs; consistent while |fw_i| <= mu fn_i.
// Solving: each ball row gives beta_i'' = r_i + p_i xbar'' + q_i ybar'' (zero for a stuck ball);
// substituting into the x and y rows leaves one 2x2 solve: O(N) per evaluation.
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "abuopt/core/parameters.hpp"

namespace abuopt {

enum class BallMode : signed char { SlipBackward = -1, Stick = 0, SlipForward = 1 };

// Non-dimensional constants, computed in one place from SI parameters.
struct NondimParameters {
  double omega_n = 0;      // rad/s
  double length_m = 0;     // L
  double bbar = 0;
  double mbar_I = 0;
  double ebar = 0;
  double mu = 0;
  std::vector<double> mbar, dbar, cbar, D;  // per ball
  static constexpr double Jbar = 0.1;
  static NondimParameters from(const AbuParameters& p);
};

// Non-dimensional state layout: [x, y, x', y', beta_1..beta_N, beta_1'..beta_N'], followed by the
// PI motor's two states [delta = theta_ref - theta, W] when it is modelled.
struct StateLayout {
  static constexpr std::size_t x = 0, y = 1, x_dot = 2, y_dot = 3, table_size = 4;
  std::size_t n_balls;
  std::size_t size() const { return table_size + 2 * n_balls; }  // the ABU's states
  std::size_t beta(std::size_t i) const { return table_size + i; }
  std::size_t beta_dot(std::size_t i) const { return table_size + n_balls + i; }
  std::size_t motor_delta() const { return size(); }
  std::size_t motor_speed() const { return size() + 1; }
};

// Accelerations and contact forces for one state and set of modes.
struct ModelForces {
  double xdd = 0, ydd = 0;
  std::vector<double> betadd, fn, fw;
  // scratch of evaluate(): sin, cos, h_b, h_l and r per ball (kept to avoid allocations), and
  // the angle sin/cos were computed for: a stuck ball's angle does not change, so its sin/cos
  // are reused (sincos was ~40 % of a run's time before).
  std::vector<double> s, c, hb, hl, r, sc_beta;
  // A reference angle per ball with its sin/cos: within kAngleStep of it, sin/cos come from the
  // reference by angle addition with a Taylor series of the small difference (the stages of a
  // step move a slipping ball's angle by little), about 25 flops instead of a sincos (~150
  // instructions). Truncation for |d| <= 0.1: below 3e-19, i.e. rounding only.
  std::vector<double> ref_beta, ref_s, ref_c;
  static constexpr double kAngleStep = 0.1;
  // sets s[i], c[i] for the angle beta (and sc_beta[i] = beta)
  void sincos_at(std::size_t i, double beta) {
    if (beta == sc_beta[i]) return;
    sc_beta[i] = beta;
    const double d = beta - ref_beta[i];
    if (std::fabs(d) <= kAngleStep) {  // false for the NaN of a fresh ModelForces
      const double d2 = d * d;
      const double sd = d * (1.0 + d2 * (-1.0 / 6 + d2 * (1.0 / 120 + d2 * (-1.0 / 5040 + d2 * (1.0 / 362880)))));
      const double cd = 1.0 + d2 * (-0.5 + d2 * (1.0 / 24 + d2 * (-1.0 / 720 + d2 * (1.0 / 40320 + d2 * (-1.0 / 3628800)))));
      s[i] = ref_s[i] * cd + ref_c[i] * sd;
      c[i] = ref_c[i] * cd - ref_s[i] * sd;
      return;
    }
    s[i] = ref_s[i] = std::sin(beta);
    c[i] = ref_c[i] = std::cos(beta);
    ref_beta[i] = beta;
  }
  // evaluate_clusters() only (generalised forces, units of M omega_n^2 L^2): contact[i] is the
  // compressive force between ball i and the next ball of its slipping cluster (0 for the last);
  // for a stuck cluster margin_fwd[i] is the friction margin of the balls from i to the front
  // slipping forward together, margin_bwd[i] that of the balls from the rear to i slipping backward.
  std::vector<double> contact, margin_fwd, margin_bwd;
  explicit ModelForces(std::size_t n = 0) { resize(n); }
  void resize(std::size_t n) {
    for (auto* v : {&betadd, &fn, &fw, &s, &c, &hb, &hl, &r, &contact, &margin_fwd, &margin_bwd}) v->assign(n, 0.0);
    sc_beta.assign(n, std::numeric_limits<double>::quiet_NaN());
    ref_beta.assign(n, std::numeric_limits<double>::quiet_NaN());
    ref_s.assign(n, 0.0);
    ref_c.assign(n, 0.0);
  }
};

// Balls that move as rigid clusters (hard contact, docs/model.md section 11): groups[g] lists the
// balls of cluster g from the rear to the front (by angle); every ball is in exactly one group and
// the balls of a group share one mode. Singletons give the same equations as evaluate().
struct Clusters {
  std::vector<std::vector<std::size_t>> groups;
};

class AbuModel {
 public:
  explicit AbuModel(const NondimParameters& nd) : nd_(nd), layout_{nd.mbar.size()} {}

  const NondimParameters& nd() const { return nd_; }
  const StateLayout& layout() const { return layout_; }
  std::size_t n_balls() const { return layout_.n_balls; }

  // Solves for accelerations with the given modes (a stuck ball gets beta'' = 0 and the friction it
  // needs; a slipping ball gets mu sigma fn). `mu` may differ from nd().mu (uncertain friction).
  void evaluate(const double* y, double W, double Wp, const BallMode* modes, double mu, ModelForces& out) const;

  // evaluate() for clusters: a slipping cluster has one acceleration and the friction mu sigma fn_i
  // on each ball; a stuck one has beta'' = 0 and the friction each ball needs with no contact
  // force (fw), plus the margins of every block that could break away (margin_fwd/bwd).
  void evaluate_clusters(const double* y, double W, double Wp, const BallMode* modes, const Clusters& cl, double mu,
                         ModelForces& out) const;

  // Friction margin of a stuck ball: mu fn - |fw| (>= 0: stick is consistent).
  static double stick_margin(const ModelForces& f, std::size_t i, double mu) {
    const double a = f.fw[i] < 0 ? -f.fw[i] : f.fw[i];
    return mu * f.fn[i] - a;
  }

  // Chooses a consistent mode for every ball at an instant (all balls together: one ball's stick
  // force depends on the others' accelerations). Balls with |beta_i'| > vtol keep slipping in the
  // direction of beta_i'; for the others every combination of stick / slip+ / slip- is tried,
  // most sticks first, and the first consistent one wins (stick: |fw| <= mu fn (1 + rtol);
  // slip sigma: sigma beta'' > 0). Returns false when none is consistent (then the greedy choice
  // is left in `modes`). `forces` holds the forces of the chosen modes on return. Balls marked
  // in `fixed` (if given) keep the mode they have in `modes` (e.g. a ball whose friction margin
  // has just crossed zero must leave stick, whatever rounding says at the crossing itself).
  bool choose_modes(const double* y, double W, double Wp, double mu, double vtol, BallMode* modes,
                    ModelForces& forces, const std::vector<char>* fixed = nullptr) const;

  // Residual imbalance vector (kg m components, imbalance along +x): m_I e + sum m_i L (c_i, s_i).
  static void imbalance_vector(const AbuParameters& p, const double* beta, double& ix, double& iy);

 private:
  NondimParameters nd_;
  StateLayout layout_;
};

}  // namespace abuopt
