// SAO: the points of a trust region (see sao.hpp, steps 1-2): a geometry repair that adds a point
// only where the fit zone lacks spread (the default), or a design of experiments per region.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "abuopt/surrogate/doe.hpp"
#include "abuopt/surrogate/response_surface.hpp"
#include "sao_run.hpp"

namespace abuopt::opt::detail {

RegionBox SaoRun::region_box() const {
  RegionBox box{Eigen::VectorXd(n_), Eigen::VectorXd(n_)};
  for (int i = 0; i < n_; ++i) {
    box.lo[i] = (std::max(0.0, centre_z_[i] - radius_) - centre_z_[i]) / radius_;
    box.hi[i] = (std::min(1.0, centre_z_[i] + radius_) - centre_z_[i]) / radius_;
  }
  return box;
}

int SaoRun::wanted_points(SurrogateKind basis) const {
  if (sao_.doe_points > 0) return sao_.doe_points;
  using surrogate::Basis;
  int count = 2 * n_ + 1;  // auto, pure_quadratic, kriging
  if (basis == SurrogateKind::Linear) count = n_ + 1;
  if (basis == SurrogateKind::Interactions) count = surrogate::terms_count(Basis::kInteractions, n_);
  if (basis == SurrogateKind::Quadratic) count = surrogate::terms_count(Basis::kQuadratic, n_);
  const double factor = noisy_ ? std::max(sao_.doe_points_factor, kNoisyPointsFactor) : sao_.doe_points_factor;
  return static_cast<int>(std::ceil(factor * count));
}

// The default (doe auto, no explicit point count, no factor, response surfaces, no noise detected): no fresh design
// per region; every evaluated point joins the fit and a point is added only where the geometry of
// the fit zone is poor (repair_geometry).
bool SaoRun::minimal_design() const {
  return sao_.doe == DoeKind::Auto && sao_.doe_points == 0 && sao_.doe_points_factor == 1.0 &&
         sao_.surrogate != SurrogateKind::Kriging && !noisy_;
}

// Adds points until the ok points of the fit zone (|s|_inf <= neighbourhood, weights as in fit())
// determine a linear model with spread: the weighted covariance of their local coordinates has
// smallest eigenvalue >= geometry^2 (in region units). Each added point lies on the region's
// boundary along the weakest direction (the eigenvector), on the side farther from known points.
bool SaoRun::repair_geometry() {
  const RegionBox box = region_box();
  const Eigen::VectorXd& lo = box.lo;
  const Eigen::VectorXd& hi = box.hi;
  const double spread = sao_.geometry_spread;
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
      if (!p.fits() || d > sao_.neighbourhood * (1 + 1e-9)) continue;
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

// Fills the region with a design (candidates in [-1,1]^n, in order of preference), reusing known
// points, until it holds `wanted_points` ok points and determines a linear model.
bool SaoRun::fill_region(SurrogateKind basis) {
  const int wanted = wanted_points(basis);
  const RegionBox box = region_box();  // the region in local coordinates
  const Eigen::VectorXd& lo = box.lo;
  const Eigen::VectorXd& hi = box.hi;
  // known points in the region (failed ones cover space but do not count)
  std::vector<Eigen::VectorXd> occupied;
  int count = 0;
  for (const KnownPoint& p : known_)
    if (in_region(p.z)) {
      occupied.push_back(to_s(p.z));
      if (p.fits()) ++count;
    }

  DoeKind doe = sao_.doe;
  if (doe == DoeKind::Auto)
    doe = basis == SurrogateKind::Linear    ? DoeKind::Koshal
          : basis == SurrogateKind::Kriging ? DoeKind::Lhs
                                            : DoeKind::Axial;
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
  if (doe == DoeKind::Koshal) {
    add_rows(surrogate::koshal_linear(n_), false);
    add_rows(axial(), false);
  } else if (doe == DoeKind::Axial) {
    add_rows(axial(), false);
    if (n_ <= 10) {
      surrogate::CentralCompositeOptions cc;
      cc.center_points = 0;
      add_rows(surrogate::central_composite(n_, cc).topRows(1 << n_), false);
    }
  } else if (doe == DoeKind::CentralComposite) {
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
  // The design's points are independent: they are chosen as the one-at-a-time loop would choose
  // them if every one turned out ok (the choice never looks at the values), evaluated as one
  // batch (EvaluationDriver::evaluate_batch), and the choice goes on only if some failed.
  while (count < wanted) {
    std::vector<std::vector<double>> batch;
    for (int assumed = count; assumed < wanted; ++assumed) {
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
      batch.push_back(to_y(from_s(candidates[best])));
      occupied.push_back(to_s(to_z(driver_.evaluated_x(batch.back()))));  // exactly where it will be
    }
    if (batch.empty()) break;
    const std::vector<const EvaluatedPoint*> done = driver_.evaluate_batch(batch);
    for (const EvaluatedPoint* p : done) {
      if (!p) return false;
      std::size_t idx = 0;
      if (auto it = by_driver_point_.find(p); it != by_driver_point_.end()) {
        idx = it->second;
      } else {
        known_.push_back(make_point(to_z(p->x), p->e, p->samples));
        idx = known_.size() - 1;
        by_driver_point_.emplace(p, idx);
      }
      if (known_[idx].ok) ++count;
    }
  }
  // a linear model must be determined: add axial points until [1 s] has full column rank
  auto rank = [&] {
    std::vector<Eigen::VectorXd> rows;
    for (const KnownPoint& p : known_)
      if (p.fits() && in_region(p.z)) rows.push_back(to_s(p.z));
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

}  // namespace abuopt::opt::detail
