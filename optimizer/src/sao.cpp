// SAO: sequential approximate optimisation in a trust region (sao.hpp describes the algorithm).
// This file: the points known to a run, the iteration loop with its ratio test and the entry
// points; the steps are in sao_design.cpp, sao_models.cpp, sao_subproblem.cpp and sao_noise.cpp.
#include "abuopt/optimizer/sao.hpp"

#include <algorithm>
#include <cmath>

#include "abuopt/optimizer/evaluation_archive.hpp"
#include "adapters.hpp"
#include "sao_run.hpp"

namespace abuopt::opt {

namespace detail {

KnownPoint SaoRun::make_point(const Eigen::VectorXd& z, const Evaluation& e, std::size_t samples) const {
  KnownPoint p;
  p.z = z;
  p.samples = samples;
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
  if (const auto it = e.metrics.find("runs"); it != e.metrics.end()) p.runs = it->second;
  return p;
}

std::optional<std::size_t> SaoRun::evaluate(const Eigen::VectorXd& z) {
  const std::vector<double> y = to_y(z);
  const EvaluatedPoint* p = driver_.evaluate(y.data());
  if (!p) return std::nullopt;
  if (auto it = by_driver_point_.find(p); it != by_driver_point_.end()) return it->second;
  known_.push_back(make_point(to_z(p->x), p->e, p->samples));
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
    const std::size_t samples = entry.runs == 0 ? driver_.default_sample_size() : static_cast<std::size_t>(entry.runs);
    known_.push_back(make_point(to_z(entry.x), entry.evaluation, samples));
  }
}

// The noise level of the merit at the centre as the models see it (sao_noise.hpp).
double SaoRun::merit_noise(const Models& models, bool phase1) const {
  const KnownPoint& c = known_[centre_];
  if (!c.ok) return 0.0;
  return detail::merit_noise(models.noise, c.g, m_ineq_, m_eq_, mu_, phase1);
}

void SaoRun::run(const std::vector<double>& x0) {
  load_archive();
  radius_ = sao_.initial_radius;
  start_sampling();
  centre_z_ = to_z(x0);
  const auto c0 = evaluate(centre_z_);
  if (!c0) return;
  centre_ = *c0;
  centre_z_ = known_[centre_].z;
  // automatic: 10 max(1, |f(x0)|) on a stochastic problem (as measured on the startup problem);
  // on a deterministic one 1e-3 max(1, |f(x0)|), and the multiplier estimates raise it
  // (update_penalty): a large mu rejected the steps along hs071's curved equality (the Maratos
  // effect) and the trust region crept at radii ~1e-3 (docs/sao.md, "Options", penalty_initial)
  const double f0_scale = std::max(1.0, known_[centre_].ok ? std::fabs(known_[centre_].f) : 1.0);
  mu_ = sao_.penalty_initial > 0 ? sao_.penalty_initial : (stochastic_ ? 10.0 : 1e-3) * f0_scale;
  if (global_ && !global_phase()) return;

  int stalled = 0;
  int failures_in_a_row = 0;  // steps rejected or with rho <= rho_shrink
  double streak_radius = radius_;  // the radius before the first of them
  bool polished = false;  // the current trust region has handed over to the polish
  // Converged with budget left: infill points and a new trust region (docs/sao.md, "Global phase",
  // restarts). False when there is no restart (the run ends).
  auto restart_run = [&]() -> bool {
    if (!restart_wanted()) return false;
    const long before = driver_.evaluations();
    const std::optional<bool> restarted = restart();
    if (!restarted || !*restarted) return false;
    ++restarts_;
    last_restart_evaluations_ = before;
    polished = false;
    message += "; restart " + std::to_string(restarts_);
    stalled = 0;
    failures_in_a_row = 0;
    streak_radius = radius_;
    return true;
  };
  while (true) {
    // the best objective's gains of the last window are within the noise: the trust region has
    // converged as far as the noise lets one tell, and after a restart the run (docs/sao.md,
    // "Stop when the rest is noise")
    const NoiseStall stall = noise_stall();
    if (stall != NoiseStall::None) {
      reason = TerminationReason::ConvergedFtol;
      message = "the best objective improved by less than " + format_number(sao_.noise_stop) +
                " noise levels (" + format_number(noise_f_) + ") in " + std::to_string(noise_window()) +
                " evaluations" + (stall == NoiseStall::Stop ? " after a restart" : "");
      if (stall == NoiseStall::Stop || !restart_run()) return;
      continue;
    }
    if (!polished && (radius_ < kPolishRadius || stalled >= sao_.stall_iterations) && polish_wanted()) {
      if (!polish()) return;
      polished = true;
      radius_ = 0;  // converged: the restart (if any) follows
      stalled = 0;
    }
    if (radius_ < sao_.min_radius || stalled >= sao_.stall_iterations) {
      if (polished) {
        reason = TerminationReason::ConvergedXtol;
        message = "the polish's step below " + format_number(kPolishRadius) + " of the ranges";
      } else if (radius_ < sao_.min_radius) {
        reason = TerminationReason::ConvergedXtol;
        message = "trust region radius " + format_number(radius_) + " below min_radius " +
                  format_number(sao_.min_radius);
      } else {
        reason = TerminationReason::ConvergedFtol;
        message = "no improvement of the merit by more than stall_tolerance in " +
                  std::to_string(sao_.stall_iterations) + " iterations";
      }
      // converged with budget left: infill points and a new trust region (docs/sao.md, "Global
      // phase", restarts); the result is the best point of the whole run (the driver's)
      if (!restart_run()) return;
      continue;
    }
    if (options_.max_iterations > 0 && iterations >= options_.max_iterations) {
      reason = TerminationReason::MaxIterations;
      message = "iteration limit of " + std::to_string(options_.max_iterations) + " reached";
      return;
    }
    if (sampling_ && !update_sample_size()) return;
    ++iterations;

    IterationRecord record;
    record.iteration = iterations;
    record.radius = radius_;
    // every path below ends the iteration through this (the records of a run are complete)
    auto close = [&](IterationStep step) {
      record.step = step;
      record.next_radius = radius_;
      record.evaluations = driver_.evaluations();
      record.penalty = mu_;
      record.feasibility_phase = feasibility_phase_;
      record.centre_merit = merit(known_[centre_]);
      record.runs = static_cast<long>(known_[centre_].runs);
      records.push_back(record);
    };

    const SurrogateKind basis = sao_.surrogate;
    if (!(minimal_design() ? repair_geometry() : fill_region(basis))) return;
    std::optional<Models> models = fit(basis);
    if (!models) {  // nothing to fit (e.g. every point failed): try a smaller region
      radius_ *= sao_.shrink_factor;
      ++stalled;
      close(IterationStep::NoModel);
      continue;
    }
    record.surrogate = models->basis;
    noise_confirmation_.confirm(models->noise, models->noise_fraction, radius_);
    // noise measured by the probe holds whatever the fit says (the residuals of a fit that
    // interpolates, or of too few points, say nothing)
    // (measured at probed_samples_ runs: its standard error scales as 1 / sqrt(n))
    const double probe_scale =
        sampling_ && probed_samples_ > 0 ? std::sqrt(double(probed_samples_) / double(samples_)) : 1.0;
    for (std::size_t k = 0; k < probed_noise_.size() && k < models->noise.size(); ++k)
      models->noise[k] = std::max(models->noise[k], probe_scale * probed_noise_[k]);
    if (!models->noise.empty() && models->noise[0] > 0) noise_f_ = models->noise[0];
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
    record.predicted_reduction = predicted;
    record.forms = models->forms;
    if (!(predicted > 1e-14 * std::max(1.0, std::fabs(predicted_merit(zero)))) || step < 1e-9) {
      // the surrogate sees no better point in the region: refine the model in a smaller region
      radius_ *= sao_.shrink_factor;
      ++stalled;
      close(IterationStep::NoPredictedReduction);
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
    // Noise: a prediction within the merit's noise level cannot be checked by one evaluation, and
    // a smaller region only makes the predicted reductions smaller still. Such a failed step
    // keeps the radius (the candidate joins the fit: more points average the noise), and an
    // accepted step whose shortfall is within the noise counts as a success.
    const double sigma = sao_.noise_tolerance * merit_noise(*models, phase1);
    // a new design whose merit is exactly the centre's: the response is flat (quantised,
    // piecewise constant) at this scale, and a smaller region would only see more of the same
    const bool flat = actual == 0 && !repeated;
    bool within_noise = (predicted <= sigma || flat) && !repeated;
    // Noise detected from the data (docs/sao.md): the second failed step in a row, at a radius at
    // least 16 times smaller than the last probe's (the first: any), is checked by the probe
    // (sao_noise_probe.cpp); if noise explains it, the run switches to regression designs (as
    // doe_points_factor 2) and the radius returns to its value before the streak of failures.
    const bool failed = !(actual > 0) || rho <= sao_.rho_shrink;
    if (failed && failures_in_a_row == 0) streak_radius = radius_;
    failures_in_a_row = failed ? failures_in_a_row + 1 : 0;
    if (!noisy_ && sao_.noise_detection && !repeated && failures_in_a_row >= 2 &&
        radius_ <= last_probe_radius_ / 16) {
      const std::optional<bool> noise = probe_noise(predicted, phase1);
      if (!noise) return;
      if (*noise) {  // the failures of the streak were noise: their shrinks are undone
        noisy_ = true;
        within_noise = true;
        radius_ = std::max(radius_, streak_radius);
      }
    }
    // Adaptive sample size: a failed step whose shortfall is within the noise of a difference of
    // two merits (sqrt 2 sigma), or exactly flat, could be noise: more runs tell the next time.
    if (sampling_ && failed && !repeated && (predicted - actual <= std::sqrt(2.0) * sigma || flat))
      double_samples_for_noise();
    if (!(actual > 0)) {
      if (!within_noise) radius_ *= sao_.shrink_factor;  // rejected: keep the centre
    } else {
      if (rho <= sao_.rho_shrink) {
        if (predicted - actual > sigma && !within_noise) radius_ *= sao_.shrink_factor;
      }
      else if (rho >= sao_.rho_expand_low && rho <= sao_.rho_expand_high && on_boundary)
        radius_ = std::min(sao_.max_radius, radius_ * sao_.expand_factor);
      else if (step < sao_.short_step) radius_ *= sao_.shrink_factor;
      centre_ = *cand;
      centre_z_ = known_[centre_].z;
    }
    record.actual_reduction = actual;
    record.rho = rho;
    record.noise = sigma;
    record.step_length = step;
    close(actual > 0 ? IterationStep::Accepted : IterationStep::Rejected);
    const bool progress = actual > sao_.stall_tolerance * std::max(1.0, std::fabs(phi_c));
    stalled = progress ? 0 : stalled + 1;
  }
}

}  // namespace detail

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
  out.algorithm_label = "SAO(" + to_string(options.sao.surrogate) + ")";
  try {
    run.run(x0);
    out.reason = run.reason;
    out.message = run.message;
  } catch (const std::exception& ex) {
    out.reason = TerminationReason::Failure;
    out.message = std::string("SAO threw: ") + ex.what();
  }
  out.iterations = run.iterations;
  out.records = std::move(run.records);
  return out;
}

}  // namespace detail

}  // namespace abuopt::opt
