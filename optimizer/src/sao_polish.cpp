// SAO: the direct-search polish of a Monte Carlo objective (docs/sao.md, "Polish on a sampled
// problem"; opt-in: `global_phase: {polish: true}`). With common random numbers a Monte Carlo
// estimate is a piecewise-constant function of the design (a run whose balls stick on the other
// side of a friction boundary jumps): at the scales where a step could gain, the response is a sum
// of jumps that no polynomial model predicts, and below about 1e-3 of a range it is flat. When a
// trust region has shrunk below kPolishRadius (or stalled), SAO polls the exact merit instead: a
// compass search (Kolda, Lewis and Torczon 2003, "Optimization by direct search") from the
// incumbent. The first polls put one variable at a time on either bound (a step of the whole
// range, clipped to the box), then +-step along every variable from kPolishStep down to
// kPolishRadius of each range, a step that leaves the box snapped to the bound (so faces and
// corners are tried); the first point of lower merit is taken (simple decrease), the step halves
// after a poll without one.
#include "sao_run.hpp"

namespace abuopt::opt::detail {

bool SaoRun::polish_wanted() const {
  return global_ && sao_.global_phase.polish && driver_.sample_size() > 0 && (!sampling_ || samples_ == samples_max_);
}

bool SaoRun::polish() {
  std::size_t best = incumbent();
  double step = 1.0;  // the first polls put one variable at a time on either bound
  while (step >= kPolishRadius) {
    bool improved = false;
    for (int i = 0; i < n_; ++i)
      for (const double dir : {1.0, -1.0}) {
        Eigen::VectorXd z = known_[best].z;
        z[i] = std::clamp(z[i] + dir * step, 0.0, 1.0);
        if (z[i] == known_[best].z[i]) continue;  // on the bound already
        const auto k = evaluate(z);
        if (!k) return false;
        if (known_[*k].ok && (!sampling_ || known_[*k].samples == samples_) &&
            merit(known_[*k]) < merit(known_[best])) {
          best = *k;
          improved = true;
        }
      }
    if (!improved) step = step >= 1.0 ? kPolishStep : 0.5 * step;
  }
  centre_ = best;
  centre_z_ = known_[best].z;
  return true;
}

}  // namespace abuopt::opt::detail
