#pragma once
// Internal: the state and steps of one SAO run (sao.hpp describes the algorithm). The steps live
// in their own files: sao.cpp (the iteration loop, the ratio test, points), sao_design.cpp (the
// points of a region), sao_models.cpp (the surrogates), sao_subproblem.cpp (the sub-problem and the
// penalty), sao_noise.cpp (the noise estimate of the ratio test), sao_global.cpp (the optional
// global phase before the trust region), sao_noise_probe.cpp (noise detected from the data),
// sao_sampling.cpp (the adaptive sample size), sao_polish.cpp (the opt-in polish of a sampled
// problem).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "abuopt/optimizer/optimization_result.hpp"
#include "abuopt/optimizer/optimizer_options.hpp"
#include "abuopt/optimizer/sao_intervening.hpp"
#include "abuopt/surrogate/surrogate.hpp"
#include "evaluation_driver.hpp"
#include "sao_noise.hpp"

namespace abuopt::opt::detail {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Once noise is detected from the data, designs per region hold this many times the automatic
// point count (least squares over about twice the terms, as doe_points_factor 2 by hand).
constexpr double kNoisyPointsFactor = 2.0;
// The polish of a sampled problem (sao_polish.cpp): first step and smallest step, fractions of
// each range; a trust region below kPolishRadius hands over to it.
constexpr double kPolishStep = 0.1;
constexpr double kPolishRadius = 1e-3;

// One known point (evaluated in this run, or taken from an archive).
struct KnownPoint {
  Eigen::VectorXd z;  // unit box
  double f = kInf;
  std::vector<double> g, h;
  bool ok = false;
  double l1_violation = kInf;  // sum max(0, g) + sum |h|
  double runs = 0;             // the evaluation's metric "runs" (Monte Carlo runs), 0 without it
  std::size_t samples = 0;     // the sample size it was evaluated at (0: not a sampled problem)
  // a point of a noise probe that found no noise: it stays known (never evaluated again) but does
  // not enter the fits, so that a probe on a smooth problem changes nothing but the count
  bool probe_only = false;
  bool fits() const { return ok && !probe_only; }
};

// The surrogates of one iteration, in local coordinates s, each plus an additive offset (the
// zeroth-order correction that makes it match the true value at the centre).
struct Models {
  std::unique_ptr<surrogate::Surrogate> fm;
  std::vector<std::unique_ptr<surrogate::Surrogate>> gm, hm;
  double f_offset = 0;
  std::vector<double> g_offset, h_offset;
  std::string basis;
  std::string forms;  // intervening form per response, one letter each (l, r, e): "f:l g:r"
  // Noise level of every response (objective, inequalities, equalities) seen by this fit: the
  // weighted residual RMS of the least-squares fit with the degrees-of-freedom correction
  // sqrt(sum w e^2 / sum w * m / (m - p)); 0 when the fit interpolates (m <= p) or for kriging.
  // An upper bound of the noise (it includes the lack of fit, which vanishes as r shrinks on a
  // smooth response and does not on a noisy one).
  std::vector<double> noise;
  // The same residual RMS relative to the responses' weighted standard deviation on the fit zone
  // (1: the model explains nothing; ~0: smooth at this scale).
  std::vector<double> noise_fraction;
  // Back-off of every inequality in the sub-problem (g^ + margin <= 0): kappa times its confirmed
  // noise level, so that a candidate aims inside the noisy band of the bound instead of on it
  // (set by solve_subproblem; 0 without confirmed noise).
  std::vector<double> g_margin;

  std::size_t n_g() const { return gm.size(); }
  std::size_t n_h() const { return hm.size(); }
  double f(const Eigen::VectorXd& s) const { return fm->value(s) + f_offset; }
  double g(std::size_t i, const Eigen::VectorXd& s) const { return gm[i]->value(s) + g_offset[i]; }
  double h(std::size_t j, const Eigen::VectorXd& s) const { return hm[j]->value(s) + h_offset[j]; }
  Eigen::VectorXd f_grad(const Eigen::VectorXd& s) const { return fm->gradient(s); }
  Eigen::VectorXd g_grad(std::size_t i, const Eigen::VectorXd& s) const { return gm[i]->gradient(s); }
  Eigen::VectorXd h_grad(std::size_t j, const Eigen::VectorXd& s) const { return hm[j]->gradient(s); }

  double l1(const Eigen::VectorXd& s) const {
    double v = 0;
    for (std::size_t i = 0; i < n_g(); ++i) v += std::max(0.0, g(i, s));
    for (std::size_t j = 0; j < n_h(); ++j) v += std::fabs(h(j, s));
    return v;
  }
  double max_violation(const Eigen::VectorXd& s) const {
    double v = 0;
    for (std::size_t i = 0; i < n_g(); ++i) v = std::max(v, g(i, s));
    for (std::size_t j = 0; j < n_h(); ++j) v = std::max(v, std::fabs(h(j, s)));
    return v;
  }
};

// The trust region in local coordinates s = (z - z_c) / r: [lo, hi] = ([max(0, z_c - r),
// min(1, z_c + r)] - z_c) / r, the box [-1, 1]^n clipped to the unit box of the bounds.
struct RegionBox {
  Eigen::VectorXd lo, hi;
};

class SaoRun {
 public:
  SaoRun(Problem& problem, const OptimizerOptions& options, const SaoOptions& sao, EvaluationDriver& driver)
      : options_(options), sao_(sao), driver_(driver), variables_(problem.variables()),
        global_(sao.global_phase.enabled(problem.stochastic())), stochastic_(problem.stochastic()) {
    n_ = static_cast<int>(variables_.size());
    m_ineq_ = driver.n_inequality();
    m_eq_ = driver.n_equality();
  }

  TerminationReason reason = TerminationReason::Failure;
  std::string message;
  long iterations = 0;
  std::vector<IterationRecord> records;  // one per iteration

  void run(const std::vector<double>& x0);

 private:
  // ---- coordinates ----
  Eigen::VectorXd to_z(const std::vector<double>& x) const {
    Eigen::VectorXd z(n_);
    for (int i = 0; i < n_; ++i) {
      const Variable& v = variables_[i];
      z[i] = std::clamp((x[i] - v.lower) / (v.upper - v.lower), 0.0, 1.0);
    }
    return z;
  }
  std::vector<double> to_y(const Eigen::VectorXd& z) const {  // driver coordinates x / scale
    std::vector<double> y(n_);
    for (int i = 0; i < n_; ++i) {
      const Variable& v = variables_[i];
      const double x = std::clamp(v.lower + z[i] * (v.upper - v.lower), v.lower, v.upper);
      y[i] = x / v.scale;
    }
    return y;
  }
  Eigen::VectorXd to_s(const Eigen::VectorXd& z) const { return (z - centre_z_) / radius_; }
  Eigen::VectorXd from_s(const Eigen::VectorXd& s) const {
    return (centre_z_ + radius_ * s).cwiseMax(0.0).cwiseMin(1.0);
  }
  bool in_region(const Eigen::VectorXd& z, double factor = 1.0) const {
    return ((z - centre_z_).cwiseAbs().maxCoeff()) <= factor * radius_ * (1 + 1e-9);
  }
  // The current trust region in local coordinates (the one place it is computed).
  RegionBox region_box() const;

  // ---- points (sao.cpp) ----
  // Evaluates z on the true problem; the index into known_, or nullopt once the run is stopped.
  std::optional<std::size_t> evaluate(const Eigen::VectorXd& z);
  KnownPoint make_point(const Eigen::VectorXd& z, const Evaluation& e, std::size_t samples) const;
  double merit(const KnownPoint& p) const {
    if (!p.ok) return kInf;
    return feasibility_phase_ ? p.l1_violation : p.f + mu_ * p.l1_violation;
  }
  void load_archive();

  // ---- sample size (sao_sampling.cpp; docs/sao.md "Adaptive sample size") ----
  // Checks the schedule against the problem and sets the first sample size (before any evaluation).
  void start_sampling();
  // The schedule's size for the current radius (n_k of SaoSampling without the floor and monotonicity).
  std::size_t scheduled_samples() const;
  // Raises the sample size to the schedule's and, if it grew, evaluates the centre again at the
  // new size and records the shift of every response (false: stopped).
  bool update_sample_size();
  // The value of response k (0 objective, then inequalities, equalities) of p as the fits see it:
  // its own value plus the shift from its sample size to the current one; nullopt when no shift is
  // known for its size (a point of another size from an archive).
  std::optional<double> fit_value(const KnownPoint& p, std::size_t k) const;
  // Weight factor of p in the fits: its sample size over the current one (1 without sampling).
  double sample_weight(const KnownPoint& p) const;
  // A failed step whose shortfall the noise of a merit difference explains: the floor doubles.
  void double_samples_for_noise();

  // ---- the points of a region (sao_design.cpp) ----
  int wanted_points(SurrogateKind basis) const;
  bool fill_region(SurrogateKind basis);  // false: stopped
  bool minimal_design() const;
  bool repair_geometry();  // false: stopped

  // ---- surrogates (sao_models.cpp) ----
  std::optional<Models> fit(SurrogateKind requested);
  std::unique_ptr<surrogate::Surrogate> make_model(SurrogateKind basis) const;

  // ---- sub-problem and penalty (sao_subproblem.cpp) ----
  Eigen::VectorXd solve_subproblem(Models& models, bool& feasibility_phase);
  Eigen::VectorXd run_nlopt(const Models& models, bool feasibility_phase, const Eigen::VectorXd& start,
                            const RegionBox& box) const;
  void update_penalty(const Models& models, const Eigen::VectorXd& s);

  // ---- global phase and restarts (sao_global.cpp) ----
  // Space-filling design and constrained-expected-improvement infill over the whole box, then the
  // centre moves to the incumbent (incumbent()). false: stopped.
  bool global_phase();
  // `count` infill points by constrained expected improvement of kriging models of every response
  // on the known points (their values at the current sample size). false: stopped.
  bool global_infill(int count);
  // The lowest objective among the known points at the current sample size that satisfy every
  // inequality within the constraint tolerance and every equality within its band; without one,
  // the point of lowest merit (the centre if none is lower).
  std::size_t incumbent() const;
  // After the trust region converged with budget left: n + 1 infill points, then a new trust region
  // of initial_radius at the incumbent. nullopt: stopped; false: no new point could be evaluated
  // (the run ends as converged); true: restarted.
  std::optional<bool> restart();
  // Whether a converged trust region restarts: the global phase is on with `restart` and the
  // budget (max_evaluations > 0) has at least n + 2 evaluations left.
  bool restart_wanted() const;

  // ---- polish of a sampled problem (sao_polish.cpp) ----
  // Whether a trust region that shrank below kPolishRadius hands over to the polish: the global
  // phase is on, the problem is sampled (a Monte Carlo: piecewise constant under common random
  // numbers) and the sample size is final.
  bool polish_wanted() const;
  // Compass search on the exact merit from the incumbent (steps kPolishStep down to kPolishRadius,
  // snapped to the bounds); the centre moves to its best point. false: stopped.
  bool polish();

  // ---- noise (sao_noise.cpp does the arithmetic) ----
  double merit_noise(const Models& models, bool phase1) const;
  // The noise probe after two failed steps in a row (sao_noise_probe.cpp, docs/sao.md "Noise
  // detected from the data"): four evaluations on a short segment from the centre; true when the
  // second differences of the responses say the merit's noise is comparable to the predicted reduction; nullopt once
  // the run is stopped.
  std::optional<bool> probe_noise(double predicted, bool phase1);
  // The stop on noise (sao_noise_probe.cpp, docs/sao.md "Stop when the rest is noise"): records
  // the best feasible objective at the current evaluation count. Restart: it has improved by less
  // than noise_stop * noise_f_ for noise_stop_window evaluations and no restart has been tried
  // since (the trust region is treated as converged); Stop: the same, and a restart tried since
  // has had the window too. None while the objective's noise is unknown.
  enum class NoiseStall { None, Restart, Stop };
  NoiseStall noise_stall();
  long noise_window() const { return sao_.noise_stop_window > 0 ? sao_.noise_stop_window : 10L * (n_ + 1); }

  const OptimizerOptions& options_;
  const SaoOptions& sao_;
  EvaluationDriver& driver_;
  std::vector<Variable> variables_;
  bool global_ = false;  // the global phase runs (SaoGlobalPhase::enabled for this problem)
  bool stochastic_ = false;  // Problem::stochastic(): the stop on noise may act without a probe
  int infill_calls_ = 0;
  int restarts_ = 0;      // trust regions restarted after convergence  // global_infill calls so far (each its own random stream)
  int n_ = 0;
  std::size_t m_ineq_ = 0, m_eq_ = 0;

  std::vector<KnownPoint> known_;
  std::map<const EvaluatedPoint*, std::size_t> by_driver_point_;
  Eigen::VectorXd centre_z_;
  std::size_t centre_ = 0;
  double radius_ = 0.1;
  double mu_ = 1.0;
  bool feasibility_phase_ = false;
  // the last intervening choice of every response (objective, inequalities, equalities; no
  // model): kept when too few points exist to compare the forms again
  std::vector<InterveningChoice> last_choice_;
  // which residual noise levels are noise, not lack of fit
  NoiseConfirmation noise_confirmation_;
  // noise detected from the data (probe_noise): designs per region with twice the points
  bool noisy_ = false;
  double last_probe_radius_ = kInf;
  std::vector<double> probed_noise_;  // per response, set when the probe finds noise
  std::size_t probed_samples_ = 0;    // the sample size the probe's noise was measured at
  // the objective's noise level of the latest fit that knew it (confirmed or probed; 0: unknown)
  double noise_f_ = 0;
  // (evaluations, best feasible objective) at the start of every trust-region iteration
  std::vector<std::pair<long, double>> best_trace_;
  long last_restart_evaluations_ = -1;  // the evaluation count when the latest restart began

  // adaptive sample size (off: samples_ stays the problem's own size and nothing is shifted)
  bool sampling_ = false;
  std::size_t samples_ = 0, samples_min_ = 0, samples_max_ = 0, samples_floor_ = 0;
  // per smaller sample size: what to add to each response's value to express it at samples_
  std::map<std::size_t, std::vector<double>> shift_to_current_;
};

}  // namespace abuopt::opt::detail
