// SAO: sequential approximate optimisation in a trust region (see sao.hpp for the algorithm).
#include "abuopt/optimizer/sao.hpp"

#include <nlopt.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <type_traits>

#include <Eigen/Dense>

#include "abuopt/common/config_error.hpp"
#include "abuopt/optimizer/evaluation_archive.hpp"
#include "abuopt/optimizer/sao_intervening.hpp"
#include "abuopt/surrogate/doe.hpp"
#include "abuopt/surrogate/kriging.hpp"
#include "abuopt/surrogate/response_surface.hpp"
#include "abuopt/surrogate/surrogate.hpp"
#include "adapters.hpp"
#include "evaluation_driver.hpp"

namespace abuopt::opt {

bool is_sao_algorithm(const std::string& name) {
  std::string u = name;
  std::transform(u.begin(), u.end(), u.begin(), [](unsigned char c) { return std::toupper(c); });
  return u == "SAO";
}

OptimizationResult minimize_any(Problem& problem, const OptimizerOptions& options, const SaoOptions& sao,
                                std::vector<double> x0, const EvaluationCallback& callback) {
  if (is_sao_algorithm(options.algorithm)) return minimize_sao(problem, options, sao, std::move(x0), callback);
  return minimize(problem, options, std::move(x0), callback);
}

// ---------------------------------------------------------------------------------------------
// The algorithm

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Residual RMS below this fraction of the responses' spread on the fit zone: not noise.
constexpr double kNoiseFraction = 0.1;

struct OptDeleter {
  void operator()(nlopt_opt o) const { nlopt_destroy(o); }
};
using OptPtr = std::unique_ptr<std::remove_pointer_t<nlopt_opt>, OptDeleter>;

// One known point (evaluated in this run, or taken from an archive).
struct KnownPoint {
  Eigen::VectorXd z;  // unit box
  double f = kInf;
  std::vector<double> g, h;
  bool ok = false;
  double l1_violation = kInf;  // sum max(0, g) + sum |h|
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

// NLopt callbacks on the surrogates.
struct SubContext {
  const Models* models;
  bool feasibility_phase;
};

double sub_objective(unsigned n, const double* s, double* grad, void* data) {
  const SubContext& c = *static_cast<SubContext*>(data);
  const Eigen::VectorXd xs = Eigen::Map<const Eigen::VectorXd>(s, n);
  const Models& m = *c.models;
  if (!c.feasibility_phase) {
    if (grad) {
      const Eigen::VectorXd gr = m.f_grad(xs);
      std::copy(gr.data(), gr.data() + n, grad);
    }
    return m.f(xs);
  }
  // sum max(0, g)^2 + sum h^2
  double p = 0;
  Eigen::VectorXd gr = Eigen::VectorXd::Zero(n);
  for (std::size_t i = 0; i < m.n_g(); ++i) {
    const double v = m.g(i, xs);
    if (v > 0) {
      p += v * v;
      if (grad) gr += 2 * v * m.g_grad(i, xs);
    }
  }
  for (std::size_t j = 0; j < m.n_h(); ++j) {
    const double v = m.h(j, xs);
    p += v * v;
    if (grad) gr += 2 * v * m.h_grad(j, xs);
  }
  if (grad) std::copy(gr.data(), gr.data() + n, grad);
  return p;
}

template <bool Equality>
void sub_constraints(unsigned m, double* result, unsigned n, const double* s, double* grad, void* data) {
  const SubContext& c = *static_cast<SubContext*>(data);
  const Eigen::VectorXd xs = Eigen::Map<const Eigen::VectorXd>(s, n);
  for (unsigned i = 0; i < m; ++i) {
    result[i] = Equality ? c.models->h(i, xs)
                         : c.models->g(i, xs) + (i < c.models->g_margin.size() ? c.models->g_margin[i] : 0.0);
    if (grad) {
      const Eigen::VectorXd gr = Equality ? c.models->h_grad(i, xs) : c.models->g_grad(i, xs);
      std::copy(gr.data(), gr.data() + n, grad + static_cast<std::size_t>(i) * n);
    }
  }
}

class SaoRun {
 public:
  SaoRun(Problem& problem, const OptimizerOptions& options, const SaoOptions& sao, detail::EvaluationDriver& driver)
      : problem_(problem), options_(options), sao_(sao), driver_(driver), variables_(problem.variables()) {
    n_ = static_cast<int>(variables_.size());
    m_ineq_ = driver.n_inequality();
    m_eq_ = driver.n_equality();
  }

  TerminationReason reason = TerminationReason::Failure;
  std::string message;
  long iterations = 0;

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

  // ---- points ----
  // Evaluates z on the true problem; the index into known_, or nullopt once the run is stopped.
  std::optional<std::size_t> evaluate(const Eigen::VectorXd& z);
  KnownPoint make_point(const Eigen::VectorXd& z, const Evaluation& e) const;
  double merit(const KnownPoint& p) const {
    if (!p.ok) return kInf;
    return feasibility_phase_ ? p.l1_violation : p.f + mu_ * p.l1_violation;
  }
  void load_archive();

  // ---- one iteration ----
  std::string planned_basis() const;
  double geometry_spread() const { return sao_.geometry_spread; }
  int wanted_points(const std::string& basis) const;
  bool fill_region(const std::string& basis);  // false: stopped
  bool minimal_design() const;
  bool repair_geometry();  // false: stopped
  std::optional<Models> fit(const std::string& basis);
  Eigen::VectorXd solve_subproblem(Models& models, bool& feasibility_phase);
  Eigen::VectorXd run_nlopt(const Models& models, bool feasibility_phase, const Eigen::VectorXd& start,
                            const Eigen::VectorXd& lo, const Eigen::VectorXd& hi) const;
  void update_penalty(const Models& models, const Eigen::VectorXd& s);
  double merit_noise(const Models& models, bool phase1) const;
  std::unique_ptr<surrogate::Surrogate> make_model(const std::string& basis) const;

  Problem& problem_;
  const OptimizerOptions& options_;
  const SaoOptions& sao_;
  detail::EvaluationDriver& driver_;
  std::vector<Variable> variables_;
  int n_ = 0;
  std::size_t m_ineq_ = 0, m_eq_ = 0;

  std::vector<KnownPoint> known_;
  std::map<const detail::EvaluatedPoint*, std::size_t> by_driver_point_;
  Eigen::VectorXd centre_z_;
  std::size_t centre_ = 0;
  double radius_ = 0.1;
  double mu_ = 1.0;
  bool feasibility_phase_ = false;
  // the last intervening choice of every response (objective, inequalities, equalities; no
  // model): kept when too few points exist to compare the forms again
  std::vector<InterveningChoice> last_choice_;
  // per response: (radius, residual RMS) of every fit that had degrees of freedom to spare
  std::vector<std::vector<std::pair<double, double>>> noise_history_;
  void confirm_noise(Models& models);
};

KnownPoint SaoRun::make_point(const Eigen::VectorXd& z, const Evaluation& e) const {
  KnownPoint p;
  p.z = z;
  p.ok = e.ok && std::isfinite(e.objective) && e.inequality.size() == m_ineq_ && e.equality.size() == m_eq_;
  p.f = p.ok ? e.objective : kInf;
  p.g = e.inequality;
  p.h = e.equality;
  if (p.ok) {
    double v = 0;
    for (double gi : p.g) v += std::max(0.0, gi);
    for (double hj : p.h) v += std::fabs(hj);
    p.l1_violation = v;
    if (!std::isfinite(v)) p.ok = false;
  }
  return p;
}

std::optional<std::size_t> SaoRun::evaluate(const Eigen::VectorXd& z) {
  const std::vector<double> y = to_y(z);
  const detail::EvaluatedPoint* p = driver_.evaluate(y.data());
  if (!p) return std::nullopt;
  if (auto it = by_driver_point_.find(p); it != by_driver_point_.end()) return it->second;
  known_.push_back(make_point(to_z(p->x), p->e));
  by_driver_point_.emplace(p, known_.size() - 1);
  return known_.size() - 1;
}

void SaoRun::load_archive() {
  if (!sao_.archive) return;
  for (const EvaluationArchive::Entry& entry : sao_.archive->entries()) {
    if (entry.x.size() != static_cast<std::size_t>(n_)) continue;
    bool inside = true;
    for (int i = 0; i < n_; ++i)
      inside = inside && std::isfinite(entry.x[i]) && entry.x[i] >= variables_[i].lower &&
               entry.x[i] <= variables_[i].upper;
    if (!inside) continue;
    known_.push_back(make_point(to_z(entry.x), entry.evaluation));
  }
}

std::string SaoRun::planned_basis() const { return sao_.surrogate; }

int SaoRun::wanted_points(const std::string& basis) const {
  if (sao_.doe_points > 0) return sao_.doe_points;
  using surrogate::Basis;
  int count = 2 * n_ + 1;  // auto, pure_quadratic, kriging
  if (basis == "linear") count = n_ + 1;
  if (basis == "interactions") count = surrogate::terms_count(Basis::kInteractions, n_);
  if (basis == "quadratic") count = surrogate::terms_count(Basis::kQuadratic, n_);
  return static_cast<int>(std::ceil(sao_.doe_points_factor * count));
}

// The default (doe auto, no explicit point count, no factor, response surfaces): no fresh design
// per region; every evaluated point joins the fit and a point is added only where the geometry of
// the fit zone is poor (repair_geometry).
bool SaoRun::minimal_design() const {
  return sao_.doe == "auto" && sao_.doe_points == 0 && sao_.doe_points_factor == 1.0 && sao_.surrogate != "kriging";
}

// Adds points until the ok points of the fit zone (|s|_inf <= neighbourhood, weights as in fit())
// determine a linear model with spread: the weighted covariance of their local coordinates has
// smallest eigenvalue >= geometry^2 (in region units). Each added point lies on the region's
// boundary along the weakest direction (the eigenvector), on the side farther from known points.
bool SaoRun::repair_geometry() {
  Eigen::VectorXd lo(n_), hi(n_);
  for (int i = 0; i < n_; ++i) {
    lo[i] = (std::max(0.0, centre_z_[i] - radius_) - centre_z_[i]) / radius_;
    hi[i] = (std::min(1.0, centre_z_[i] + radius_) - centre_z_[i]) / radius_;
  }
  const double spread = geometry_spread();
  for (int added = 0; added <= 2 * n_ + 1; ++added) {
    std::vector<Eigen::VectorXd> occupied;
    Eigen::VectorXd mean = Eigen::VectorXd::Zero(n_);
    Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(n_, n_);
    double wsum = 0;
    int m = 0;
    std::vector<std::pair<Eigen::VectorXd, double>> zone;
    for (const KnownPoint& p : known_) {
      const Eigen::VectorXd sp = to_s(p.z);
      const double d = sp.cwiseAbs().maxCoeff();
      if (d <= sao_.neighbourhood * (1 + 1e-9)) occupied.push_back(sp);
      if (!p.ok || d > sao_.neighbourhood * (1 + 1e-9)) continue;
      const double w = d <= 1 + 1e-9 ? 1.0 : 1.0 / std::pow(d, 4);
      zone.emplace_back(sp, w);
      mean += w * sp;
      wsum += w;
      ++m;
    }
    Eigen::VectorXd weakest = Eigen::VectorXd::Unit(n_, 0);
    if (wsum > 0) {
      mean /= wsum;
      for (const auto& [sp, w] : zone) cov += w * (sp - mean) * (sp - mean).transpose();
      cov /= wsum;
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(cov);
      const double lambda = eig.eigenvalues()[0];
      if (m >= n_ + 1 && lambda >= spread * spread) return true;
      weakest = eig.eigenvectors().col(0);
    }
    weakest /= weakest.cwiseAbs().maxCoeff();
    auto distance_to_occupied = [&](const Eigen::VectorXd& s) {
      double d = kInf;
      for (const auto& o : occupied) d = std::min(d, (s - o).cwiseAbs().maxCoeff());
      return d;
    };
    const Eigen::VectorXd plus = weakest.cwiseMax(lo).cwiseMin(hi);
    const Eigen::VectorXd minus = (-weakest).cwiseMax(lo).cwiseMin(hi);
    const double dp = distance_to_occupied(plus), dm = distance_to_occupied(minus);
    const Eigen::VectorXd& s = dp >= dm ? plus : minus;
    if (std::max(dp, dm) < 1e-3) return true;  // nothing new to add inside the box
    if (!evaluate(from_s(s))) return false;
  }
  return true;
}

// Candidate DOE designs in [-1,1]^n for the region, in order of preference.
bool SaoRun::fill_region(const std::string& basis) {
  const int wanted = wanted_points(basis);
  Eigen::VectorXd lo(n_), hi(n_);  // the region in local coordinates
  for (int i = 0; i < n_; ++i) {
    lo[i] = (std::max(0.0, centre_z_[i] - radius_) - centre_z_[i]) / radius_;
    hi[i] = (std::min(1.0, centre_z_[i] + radius_) - centre_z_[i]) / radius_;
  }
  // known points in the region (failed ones cover space but do not count)
  std::vector<Eigen::VectorXd> occupied;
  int count = 0;
  for (const KnownPoint& p : known_)
    if (in_region(p.z)) {
      occupied.push_back(to_s(p.z));
      if (p.ok) ++count;
    }

  std::string doe = sao_.doe;
  if (doe == "auto") doe = basis == "linear" ? "koshal" : basis == "kriging" ? "lhs" : "axial";
  std::vector<Eigen::VectorXd> candidates;
  auto add_rows = [&](const Eigen::MatrixXd& d, bool box_mapped) {
    for (int r = 0; r < d.rows(); ++r) {
      Eigen::VectorXd s = d.row(r).transpose();
      if (box_mapped) s = 0.5 * (lo + hi) + 0.5 * (hi - lo).cwiseProduct(s);
      candidates.push_back(s.cwiseMax(lo).cwiseMin(hi));
    }
  };
  auto axial = [&] {
    Eigen::MatrixXd d = Eigen::MatrixXd::Zero(2 * n_ + 1, n_);
    for (int i = 0; i < n_; ++i) {
      d(1 + 2 * i, i) = 1;
      d(2 + 2 * i, i) = -1;
    }
    return d;
  };
  const std::uint64_t seed = options_.seed * 1000003ULL + static_cast<std::uint64_t>(iterations);
  surrogate::LatinHypercubeOptions lhs;
  lhs.points = std::max(wanted, 2);
  lhs.seed = seed;
  lhs.candidates = 20;
  if (doe == "koshal") {
    add_rows(surrogate::koshal_linear(n_), false);
    add_rows(axial(), false);
  } else if (doe == "axial") {
    add_rows(axial(), false);
    if (n_ <= 10) {
      surrogate::CentralCompositeOptions cc;
      cc.center_points = 0;
      add_rows(surrogate::central_composite(n_, cc).topRows(1 << n_), false);
    }
  } else if (doe == "central_composite") {
    surrogate::CentralCompositeOptions cc;
    cc.center_points = 1;
    add_rows(surrogate::central_composite(n_, cc), false);
  }
  add_rows(surrogate::latin_hypercube(n_, lhs), true);  // always as the filler

  auto distance_to_occupied = [&](const Eigen::VectorXd& s) {
    double d = kInf;
    for (const auto& o : occupied) d = std::min(d, (s - o).cwiseAbs().maxCoeff());
    return d;
  };
  std::vector<bool> used(candidates.size(), false);
  while (count < wanted) {
    // the first candidate (in preference order) that is not covered by a known point; among the
    // preferred design (before the LHS filler) the farthest one from the known points
    std::size_t best = candidates.size();
    double best_d = -1;
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      if (used[k]) continue;
      const double d = distance_to_occupied(candidates[k]);
      if (d < sao_.reuse_distance) {
        used[k] = true;
        continue;
      }
      if (d > best_d) {
        best_d = d;
        best = k;
      }
    }
    if (best == candidates.size()) break;
    used[best] = true;
    const auto idx = evaluate(from_s(candidates[best]));
    if (!idx) return false;
    occupied.push_back(to_s(known_[*idx].z));
    if (known_[*idx].ok) ++count;
  }
  // a linear model must be determined: add axial points until [1 s] has full column rank
  auto rank = [&] {
    std::vector<Eigen::VectorXd> rows;
    for (const KnownPoint& p : known_)
      if (p.ok && in_region(p.z)) rows.push_back(to_s(p.z));
    if (rows.empty()) return Eigen::Index{0};
    Eigen::MatrixXd a(rows.size(), n_ + 1);
    for (std::size_t r = 0; r < rows.size(); ++r) {
      a(r, 0) = 1;
      a.row(r).tail(n_) = rows[r].transpose();
    }
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
    qr.setThreshold(1e-6);
    return qr.rank();
  };
  const Eigen::MatrixXd ax = axial();
  for (int r = 1; r < ax.rows() && rank() < n_ + 1; ++r) {
    const Eigen::VectorXd s = Eigen::VectorXd(ax.row(r).transpose()).cwiseMax(lo).cwiseMin(hi);
    if (distance_to_occupied(s) < 1e-9) continue;
    const auto idx = evaluate(from_s(s));
    if (!idx) return false;
    occupied.push_back(to_s(known_[*idx].z));
  }
  return true;
}

std::unique_ptr<surrogate::Surrogate> SaoRun::make_model(const std::string& basis) const {
  if (basis == "kriging") {
    surrogate::KrigingOptions k;
    k.nugget = sao_.kriging_nugget;
    k.starts = 2;
    k.max_evaluations = 200;
    return surrogate::make_surrogate("kriging", &k);
  }
  return surrogate::make_surrogate(basis);
}

std::optional<Models> SaoRun::fit(const std::string& requested) {
  std::vector<Eigen::VectorXd> s;
  std::vector<double> w;
  std::vector<const KnownPoint*> pts;
  for (const KnownPoint& p : known_) {
    if (!p.ok) continue;
    const Eigen::VectorXd sp = to_s(p.z);
    const double d = sp.cwiseAbs().maxCoeff();
    if (d > sao_.neighbourhood * (1 + 1e-9)) continue;
    s.push_back(sp);
    w.push_back(d <= 1 + 1e-9 ? 1.0 : 1.0 / std::pow(d, 4));
    pts.push_back(&p);
  }
  const int m = static_cast<int>(s.size());
  if (m < 2) return std::nullopt;
  InterveningData data;
  data.S.resize(m, n_);
  data.weights.resize(m);
  for (int i = 0; i < m; ++i) {
    data.S.row(i) = s[i].transpose();
    data.weights[i] = w[i];
  }
  // the original variables of the centre and the trust region's half-width in them
  data.centre.resize(n_);
  data.step.resize(n_);
  data.allowed.resize(n_);
  for (int i = 0; i < n_; ++i) {
    const Variable& v = variables_[i];
    data.centre[i] = v.lower + centre_z_[i] * (v.upper - v.lower);
    data.step[i] = radius_ * (v.upper - v.lower);
    data.allowed[i] = intervening_allowed(v.lower, v.upper);
  }
  const std::size_t responses = 1 + m_ineq_ + m_eq_;
  last_choice_.resize(responses);
  auto form_of = [&](std::size_t k) {
    const std::string& specific = k == 0 ? sao_.intervening_objective : sao_.intervening_constraints;
    return specific.empty() ? sao_.intervening : specific;
  };

  std::vector<std::string> order;
  if (requested == "auto") order = {"quadratic", "pure_quadratic", "linear"};
  else if (requested == "kriging") order = {"kriging", "linear"};
  else order = {requested, "linear"};
  for (const std::string& basis : order) {
    if (basis != "kriging" && surrogate::terms_count(surrogate::basis_from_string(basis), n_) > m) continue;
    try {
      Models models;
      models.basis = basis;
      std::vector<InterveningChoice> choices(responses);
      std::vector<double> noise(responses, 0.0), noise_fraction(responses, 0.0);
      auto fit_one = [&](std::size_t k, const std::function<double(const KnownPoint&)>& value) {
        Eigen::VectorXd y(m);
        for (int i = 0; i < m; ++i) y[i] = value(*pts[i]);
        if (basis == "kriging") {
          // kriging interpolates: region points and neighbours alike; intervening variables only
          // when asked for explicitly (no leave-one-out error to choose them by)
          const bool reciprocal = form_of(k) == "reciprocal";
          Eigen::VectorXd p = Eigen::VectorXd::Constant(n_, reciprocal ? -1.0 : 1.0);
          auto model = std::make_unique<InterveningSurrogate>(
              reciprocal ? InterveningMap(data.centre, data.step, p, data.allowed) : InterveningMap::identity(n_),
              make_model(basis), reciprocal ? "reciprocal" : "linear");
          model->fit(data.S, y);
          choices[k].form = model->form();
          choices[k].exponents = model->map().exponents();
          return std::unique_ptr<surrogate::Surrogate>(std::move(model));
        }
        const InterveningChoice* previous = last_choice_[k].exponents.size() == n_ ? &last_choice_[k] : nullptr;
        InterveningChoice c = fit_intervening(form_of(k), surrogate::basis_from_string(basis), data, y, previous);
        // the noise probe: the residuals of this fit (none when it interpolates, m <= p)
        const int p = surrogate::terms_count(surrogate::basis_from_string(basis), n_);
        const surrogate::Surrogate* probe = c.model.get();
        if (m > p) {
          double wsum = 0, sse = 0, mean = 0;
          for (int i = 0; i < m; ++i) {
            const double e = y[i] - probe->value(data.S.row(i).transpose());
            sse += w[i] * e * e;
            wsum += w[i];
            mean += w[i] * y[i];
          }
          mean /= wsum;
          double var = 0;
          for (int i = 0; i < m; ++i) var += w[i] * (y[i] - mean) * (y[i] - mean);
          const double sigma = std::sqrt(sse / wsum * m / (m - p));
          const double sd = std::sqrt(var / wsum);
          noise[k] = std::isfinite(sigma) ? sigma : 0.0;
          noise_fraction[k] = sd > 0 && std::isfinite(sigma) ? std::min(1.0, sigma / sd) : 0.0;
        }
        choices[k].form = c.form;
        choices[k].exponents = c.exponents;
        choices[k].loo_error = c.loo_error;
        return std::unique_ptr<surrogate::Surrogate>(std::move(c.model));
      };
      models.fm = fit_one(0, [](const KnownPoint& p) { return p.f; });
      for (std::size_t i = 0; i < m_ineq_; ++i)
        models.gm.push_back(fit_one(1 + i, [i](const KnownPoint& p) { return p.g[i]; }));
      for (std::size_t j = 0; j < m_eq_; ++j)
        models.hm.push_back(fit_one(1 + m_ineq_ + j, [j](const KnownPoint& p) { return p.h[j]; }));
      models.g_offset.assign(m_ineq_, 0.0);
      models.h_offset.assign(m_eq_, 0.0);
      const KnownPoint& c = known_[centre_];
      if (sao_.correction && c.ok) {
        const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n_);
        models.f_offset = c.f - models.fm->value(zero);
        for (std::size_t i = 0; i < m_ineq_; ++i) models.g_offset[i] = c.g[i] - models.gm[i]->value(zero);
        for (std::size_t j = 0; j < m_eq_; ++j) models.h_offset[j] = c.h[j] - models.hm[j]->value(zero);
      }
      models.noise = std::move(noise);
      models.noise_fraction = std::move(noise_fraction);
      for (std::size_t k = 0; k < responses; ++k) {
        models.forms += (k == 0 ? "f:" : k <= m_ineq_ ? " g:" : " h:") + choices[k].form.substr(0, 1);
        last_choice_[k] = std::move(choices[k]);
      }
      return models;
    } catch (const std::exception&) {
      continue;  // rank-deficient or too few points: a simpler basis
    }
  }
  return std::nullopt;
}

Eigen::VectorXd SaoRun::run_nlopt(const Models& models, bool feasibility_phase, const Eigen::VectorXd& start,
                                  const Eigen::VectorXd& lo, const Eigen::VectorXd& hi) const {
  const unsigned n = static_cast<unsigned>(n_);
  const bool slsqp = sao_.subproblem_solver == "slsqp";
  OptPtr opt(nlopt_create(slsqp ? NLOPT_LD_SLSQP : NLOPT_LN_COBYLA, n));
  if (!opt) return start;
  SubContext ctx{&models, feasibility_phase};
  nlopt_set_lower_bounds(opt.get(), lo.data());
  nlopt_set_upper_bounds(opt.get(), hi.data());
  nlopt_set_min_objective(opt.get(), sub_objective, &ctx);
  if (!feasibility_phase) {
    const double tol = 0.1 * options_.constraint_tolerance;
    if (m_ineq_ > 0) {
      std::vector<double> t(m_ineq_, tol);
      nlopt_add_inequality_mconstraint(opt.get(), static_cast<unsigned>(m_ineq_), sub_constraints<false>, &ctx,
                                       t.data());
    }
    if (m_eq_ > 0) {
      std::vector<double> t(m_eq_, tol);
      nlopt_add_equality_mconstraint(opt.get(), static_cast<unsigned>(m_eq_), sub_constraints<true>, &ctx, t.data());
    }
  }
  nlopt_set_xtol_abs1(opt.get(), 1e-10);
  nlopt_set_ftol_rel(opt.get(), 1e-14);
  nlopt_set_maxeval(opt.get(), sao_.subproblem_max_evaluations);
  if (!slsqp) {
    std::vector<double> dx(n);
    for (unsigned i = 0; i < n; ++i) dx[i] = std::max(1e-3, 0.25 * (hi[i] - lo[i]));
    nlopt_set_initial_step(opt.get(), dx.data());
  }
  std::vector<double> x(start.data(), start.data() + n);
  for (unsigned i = 0; i < n; ++i) x[i] = std::clamp(x[i], lo[i], hi[i]);
  double f = 0;
  nlopt_optimize(opt.get(), x.data(), &f);  // whatever the code, x holds its last iterate
  Eigen::VectorXd out = Eigen::Map<Eigen::VectorXd>(x.data(), n);
  for (int i = 0; i < n_; ++i)
    if (!std::isfinite(out[i])) out[i] = start[i];
  return out.cwiseMax(lo).cwiseMin(hi);
}

Eigen::VectorXd SaoRun::solve_subproblem(Models& models, bool& feasibility_phase) {
  Eigen::VectorXd lo(n_), hi(n_);
  for (int i = 0; i < n_; ++i) {
    lo[i] = (std::max(0.0, centre_z_[i] - radius_) - centre_z_[i]) / radius_;
    hi[i] = (std::min(1.0, centre_z_[i] + radius_) - centre_z_[i]) / radius_;
  }
  // starts: the centre and the best known point of the region (by the current merit)
  std::vector<Eigen::VectorXd> starts = {Eigen::VectorXd::Zero(n_)};
  {
    double best = merit(known_[centre_]);
    std::optional<Eigen::VectorXd> s_best;
    for (const KnownPoint& p : known_)
      if (p.ok && in_region(p.z) && merit(p) < best) {
        best = merit(p);
        s_best = to_s(p.z);
      }
    if (s_best) starts.push_back(*s_best);
  }
  const double tol = options_.constraint_tolerance;
  std::optional<Eigen::VectorXd> best_s;
  double best_f = kInf;
  // with confirmed constraint noise first with the constraints backed off by it, then (nothing
  // feasible so) without
  std::vector<double> margin(m_ineq_, 0.0);
  bool backed_off = false;
  for (std::size_t i = 0; i < m_ineq_ && i + 1 < models.noise.size(); ++i) {
    margin[i] = sao_.noise_tolerance * models.noise[1 + i];
    backed_off = backed_off || margin[i] > 0;
  }
  for (int attempt = backed_off ? 0 : 1; attempt < 2 && !best_s; ++attempt) {
    models.g_margin = attempt == 0 ? margin : std::vector<double>(m_ineq_, 0.0);
    for (const auto& st : starts) {
      const Eigen::VectorXd s = run_nlopt(models, false, st, lo, hi);
      double v = 0;
      for (std::size_t i = 0; i < m_ineq_; ++i) v = std::max(v, models.g(i, s) + models.g_margin[i]);
      for (std::size_t j = 0; j < m_eq_; ++j) v = std::max(v, std::fabs(models.h(j, s)));
      if (v > std::max(tol, 1e-12)) continue;
      const double f = models.f(s);
      if (f < best_f) {
        best_f = f;
        best_s = s;
      }
    }
  }
  models.g_margin.assign(m_ineq_, 0.0);
  if (best_s) {
    feasibility_phase = false;
    return *best_s;
  }
  // no surrogate-feasible point found in the region: minimise the predicted violation
  feasibility_phase = true;
  double best_v = kInf;
  Eigen::VectorXd out = Eigen::VectorXd::Zero(n_);
  for (const auto& st : starts) {
    const Eigen::VectorXd s = run_nlopt(models, true, st, lo, hi);
    const double v = models.l1(s);
    if (v < best_v) {
      best_v = v;
      out = s;
    }
  }
  return out;
}

// mu >= factor * max |lambda|, the multipliers estimated by least squares from the surrogate
// gradients at s (free variables, active inequality constraints and the equalities).
void SaoRun::update_penalty(const Models& models, const Eigen::VectorXd& s) {
  if (m_ineq_ + m_eq_ == 0) return;
  Eigen::VectorXd lo(n_), hi(n_);
  for (int i = 0; i < n_; ++i) {
    lo[i] = (std::max(0.0, centre_z_[i] - radius_) - centre_z_[i]) / radius_;
    hi[i] = (std::min(1.0, centre_z_[i] + radius_) - centre_z_[i]) / radius_;
  }
  std::vector<int> free;
  for (int i = 0; i < n_; ++i)
    if (s[i] > lo[i] + 1e-7 && s[i] < hi[i] - 1e-7) free.push_back(i);
  std::vector<Eigen::VectorXd> grads;
  for (std::size_t i = 0; i < models.n_g(); ++i)
    if (models.g(i, s) >= -1e-6 * std::max(1.0, std::fabs(models.g(i, Eigen::VectorXd::Zero(n_)))))
      grads.push_back(models.g_grad(i, s));
  for (std::size_t j = 0; j < models.n_h(); ++j) grads.push_back(models.h_grad(j, s));
  if (free.empty() || grads.empty()) return;
  const Eigen::VectorXd gf = models.f_grad(s);
  Eigen::MatrixXd A(free.size(), grads.size());
  Eigen::VectorXd b(free.size());
  for (std::size_t r = 0; r < free.size(); ++r) {
    b[r] = -gf[free[r]];
    for (std::size_t c = 0; c < grads.size(); ++c) A(r, c) = grads[c][free[r]];
  }
  const Eigen::VectorXd lambda = A.completeOrthogonalDecomposition().solve(b);
  if (!lambda.allFinite()) return;
  const double need = sao_.penalty_multiplier_factor * lambda.cwiseAbs().maxCoeff();
  if (need > mu_ && need < 1e12) mu_ = need;
}

// The noise level of the merit at the centre as the models see it: the objective's (outside the
// feasibility phase) plus mu times that of every constraint that is violated or within two noise
// levels of its bound (the others do not enter the L1 violation).
// Lack of fit or noise? The residual RMS of a fit on a smooth response shrinks with the region
// (as r^2 for a linear model, faster for quadratic ones); on a noisy one it does not. A response's
// residual RMS is taken as its noise level only when an earlier fit on a region at least twice as
// wide had a residual RMS at most twice the current one, and the residuals are at least
// kNoiseFraction of the responses' spread on the fit zone; otherwise its noise is 0 (the classical
// ratio test applies). Records the current fit in the history.
void SaoRun::confirm_noise(Models& models) {
  const std::size_t responses = models.noise.size();
  noise_history_.resize(responses);
  for (std::size_t k = 0; k < responses; ++k) {
    const double now = models.noise[k];
    bool confirmed = false;
    for (const auto& [r, sigma] : noise_history_[k])
      if (r >= 2 * radius_ * (1 - 1e-9) && sigma <= 2 * now) confirmed = now > 0;
    if (now > 0) noise_history_[k].emplace_back(radius_, now);
    // a model that explains all but a small part of the response's spread on the zone: smooth
    if (models.noise_fraction[k] < kNoiseFraction) confirmed = false;
    if (!confirmed) models.noise[k] = 0;
  }
}

double SaoRun::merit_noise(const Models& models, bool phase1) const {
  if (models.noise.size() != 1 + m_ineq_ + m_eq_) return 0.0;
  const KnownPoint& c = known_[centre_];
  if (!c.ok) return 0.0;
  double v = 0;
  for (std::size_t i = 0; i < m_ineq_; ++i)
    if (c.g[i] > -2 * models.noise[1 + i]) v += models.noise[1 + i];
  for (std::size_t j = 0; j < m_eq_; ++j) v += models.noise[1 + m_ineq_ + j];
  return phase1 ? v : models.noise[0] + mu_ * v;
}

void SaoRun::run(const std::vector<double>& x0) {
  load_archive();
  radius_ = sao_.initial_radius;
  centre_z_ = to_z(x0);
  const auto c0 = evaluate(centre_z_);
  if (!c0) return;
  centre_ = *c0;
  centre_z_ = known_[centre_].z;
  mu_ = sao_.penalty_initial > 0 ? sao_.penalty_initial
                                 : 10.0 * std::max(1.0, known_[centre_].ok ? std::fabs(known_[centre_].f) : 1.0);

  int stalled = 0;
  while (true) {
    if (radius_ < sao_.min_radius) {
      reason = TerminationReason::ConvergedXtol;
      message = "trust region radius " + format_number(radius_) + " below min_radius " +
                format_number(sao_.min_radius);
      return;
    }
    if (stalled >= sao_.stall_iterations) {
      reason = TerminationReason::ConvergedFtol;
      message = "no improvement of the merit by more than stall_tolerance in " +
                std::to_string(sao_.stall_iterations) + " iterations";
      return;
    }
    if (options_.max_iterations > 0 && iterations >= options_.max_iterations) {
      reason = TerminationReason::MaxIterations;
      message = "iteration limit of " + std::to_string(options_.max_iterations) + " reached";
      return;
    }
    ++iterations;

    const std::string basis = planned_basis();
    if (!(minimal_design() ? repair_geometry() : fill_region(basis))) return;
    std::optional<Models> models = fit(basis);
    if (!models) {  // nothing to fit (e.g. every point failed): try a smaller region
      radius_ *= sao_.shrink_factor;
      ++stalled;
      continue;
    }
    confirm_noise(*models);
    bool phase1 = false;
    const Eigen::VectorXd s = solve_subproblem(*models, phase1);
    feasibility_phase_ = phase1;
    if (!phase1) update_penalty(*models, s);

    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n_);
    auto predicted_merit = [&](const Eigen::VectorXd& x) {
      return phase1 ? models->l1(x) : models->f(x) + mu_ * models->l1(x);
    };
    if (!phase1 && models->l1(zero) > 0) {
      // the step must reduce the predicted merit: mu >= 2 (f^(s) - f^(0)) / V^(0)
      const double df = models->f(s) - models->f(zero);
      if (df > 0) mu_ = std::max(mu_, 2 * df / models->l1(zero));
    }
    const double predicted = predicted_merit(zero) - predicted_merit(s);
    const double step = s.cwiseAbs().maxCoeff();
    if (!(predicted > 1e-14 * std::max(1.0, std::fabs(predicted_merit(zero)))) || step < 1e-9) {
      // the surrogate sees no better point in the region: refine the model in a smaller region
      radius_ *= sao_.shrink_factor;
      ++stalled;
      continue;
    }
    const std::size_t known_before = known_.size();
    const auto cand = evaluate(from_s(s));
    if (!cand) return;
    const bool repeated = known_.size() == known_before;  // a known point: the models learn nothing
    const double phi_c = merit(known_[centre_]);
    const double phi_x = merit(known_[*cand]);
    const double actual = phi_c - phi_x;
    const double rho = actual / predicted;
    const bool on_boundary = step >= 1 - 1e-3;
    const double old_radius = radius_;
    // Noise: a prediction within the merit's noise level cannot be checked by one evaluation, and
    // a smaller region only makes the predicted reductions smaller still. Such a failed step
    // keeps the radius (the candidate joins the fit: more points average the noise), and an
    // accepted step whose shortfall is within the noise counts as a success.
    const double sigma = sao_.noise_tolerance * merit_noise(*models, phase1);
    // a new design whose merit is exactly the centre's: the response is flat (quantised,
    // piecewise constant) at this scale, and a smaller region would only see more of the same
    const bool flat = actual == 0 && !repeated;
    const bool within_noise = (predicted <= sigma || flat) && !repeated;
    if (!(actual > 0)) {
      if (!within_noise) radius_ *= sao_.shrink_factor;  // rejected: keep the centre
    } else {
      if (rho <= sao_.rho_shrink) {
        if (predicted - actual > sigma) radius_ *= sao_.shrink_factor;
      }
      else if (rho >= sao_.rho_expand_low && rho <= sao_.rho_expand_high && on_boundary)
        radius_ = std::min(sao_.max_radius, radius_ * sao_.expand_factor);
      else if (step < sao_.short_step) radius_ *= sao_.shrink_factor;
      centre_ = *cand;
      centre_z_ = known_[centre_].z;
    }
    if (std::getenv("ABUOPT_SAO_TRACE"))
      std::fprintf(stderr, "it %ld evals %ld basis %s [%s] phase1 %d r %.3g->%.3g rho %.3g pred %.3g act %.3g sigma %.3g "
                   "(f %.2g) mu %.3g step %.3f fc %.8g\n",
                   iterations, driver_.evaluations(), models->basis.c_str(), models->forms.c_str(), phase1 ? 1 : 0, old_radius,
                   radius_, rho, predicted, actual, sigma, models->noise.empty() ? 0.0 : models->noise_fraction[0], mu_, step,
                   known_[centre_].f);
    const bool progress = actual > sao_.stall_tolerance * std::max(1.0, std::fabs(phi_c));
    stalled = progress ? 0 : stalled + 1;
  }
}

}  // namespace

OptimizationResult minimize_sao(Problem& problem, const OptimizerOptions& options, const SaoOptions& sao,
                                std::vector<double> x0, const EvaluationCallback& callback) {
  OptimizerOptions o = options;
  o.algorithm = "SAO";
  o.local_algorithm.clear();  // SAO has no local algorithm
  o.sao = sao;
  return minimize(problem, o, std::move(x0), callback);
}

namespace detail {

AdapterOutcome run_sao(EvaluationDriver& driver, Problem& problem, const OptimizerOptions& options,
                       const std::vector<double>& x0) {
  SaoRun run(problem, options, options.sao, driver);
  AdapterOutcome out;
  out.algorithm_label = "SAO(" + options.sao.surrogate + ")";
  try {
    run.run(x0);
    out.reason = run.reason;
    out.message = run.message;
  } catch (const std::exception& ex) {
    out.reason = TerminationReason::Failure;
    out.message = std::string("SAO threw: ") + ex.what();
  }
  out.iterations = run.iterations;
  return out;
}

}  // namespace detail

}  // namespace abuopt::opt
