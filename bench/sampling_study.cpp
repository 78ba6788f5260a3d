// Sampling schemes over the joint space of a Monte Carlo (start angles + the envelope's uncertain
// parameters): the 95 % interval half-width of mean |I_r| against the run count (issue 32).
//
//   build/bench/sampling_study CONFIG [max_runs=4096] [threads=0] > sampling.csv
//
// CONFIG gives the setup (abu, profile, motor, simulation; its `envelope` section, else the
// issue-30 envelope). Schemes (d = balls + 4 dimensions, the start angles then friction, imbalance
// factor, stiffness factor, restitution; start angles mapped onto the contact-feasible set):
//   random   iid points, point i from hash(seed, i, dim); half-width 1.96 s / sqrt(n).
//   sobol    randomised QMC, the engine's envelope sampling (joint_sobol_coordinate): R = 16
//            independent Owen-scrambled Sobol' sequences, interleaved (run i: replicate i mod R,
//            point i / R); half-width t_{R-1} sd(replicate means) / sqrt(R).
//   lhs      R = 16 independent Latin hypercubes of n / R points; interval as sobol.
//   strat    stratified on the parameters: 2 halves of each of the 4 ranges, 16 cells, run i in cell
//            i mod 16 (proportional allocation), angles iid; half-width 1.96 sqrt(sum W^2 s_h^2/n_h).
//            The design of the engine's default envelope.sampling: stratified (other streams).
// Prints CSV: scheme,n,mean,half_width,half_width_rel (mean and half-width in 1e-7 kg m).
// The paired comparison: with `--paired OTHER_CONFIG`, also the random scheme's difference
// CONFIG - OTHER on common draws against unpaired ("paired" and "unpaired" rows, half-widths of
// the difference of the means). `--only SCHEME` runs one scheme.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "abuopt/core/ball_contact.hpp"
#include "abuopt/core/batch_runner.hpp"
#include "abuopt/core/envelope.hpp"
#include "abuopt/core/initial_conditions.hpp"
#include "abuopt/core/simulation_config.hpp"
#include "abuopt/core/simulator.hpp"

namespace {

using namespace abuopt;

constexpr std::size_t kReplicates = 16;
constexpr double kT15 = 2.131;  // t quantile 0.975 with 15 degrees of freedom
constexpr std::uint64_t kSeed = 3232;

double rnd(std::uint64_t a, std::uint64_t b, std::uint64_t c) { return unit_double(hash_seed(kSeed ^ a, b, c)); }

using Points = std::vector<std::vector<double>>;

Points random_points(std::size_t n, std::size_t d) {
  Points p(n, std::vector<double>(d));
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < d; ++j) p[i][j] = rnd(1, i, j);
  return p;
}

// The envelope's joint scrambled Sobol' points (envelope.hpp, the default of the engine): the
// parameters are coordinates 0..3 of the joint point, the angles 4...
Points sobol_points(std::size_t n, std::size_t d, std::size_t balls) {
  Points p(n, std::vector<double>(d));
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t b = 0; b < balls; ++b) p[i][b] = joint_sobol_coordinate(kSeed, i, Envelope::kParameters + b);
    for (std::size_t q = 0; q < Envelope::kParameters; ++q) p[i][balls + q] = joint_sobol_coordinate(kSeed, i, q);
  }
  return p;
}

// R Latin hypercubes of n / R points, interleaved like sobol.
Points lhs_points(std::size_t n, std::size_t d) {
  const std::size_t m = n / kReplicates;
  Points p(n, std::vector<double>(d));
  for (std::size_t r = 0; r < kReplicates; ++r)
    for (std::size_t j = 0; j < d; ++j) {
      std::vector<std::size_t> perm(m);
      for (std::size_t k = 0; k < m; ++k) perm[k] = k;
      for (std::size_t k = m; k > 1; --k) {  // Fisher-Yates from the hash
        const auto s = static_cast<std::size_t>(rnd(100 + r, n * 64 + j, k) * static_cast<double>(k));
        std::swap(perm[k - 1], perm[std::min(s, k - 1)]);
      }
      for (std::size_t k = 0; k < m; ++k)
        p[k * kReplicates + r][j] = (static_cast<double>(perm[k]) + rnd(200 + r, n * 64 + j, k)) / static_cast<double>(m);
    }
  return p;
}

Points strat_points(std::size_t n, std::size_t d, std::size_t balls) {
  Points p = random_points(n, d);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t cell = i % 16;
    for (std::size_t q = 0; q < 4; ++q) {
      const double half = static_cast<double>((cell >> q) & 1u);
      p[i][balls + q] = 0.5 * (half + rnd(4, i, q));
    }
  }
  return p;
}

struct Setup {
  SimulationSetup setup;
  Envelope envelope;
};

Setup load(const std::string& path) {
  YamlReader root = YamlReader::load_file(path);
  Setup s;
  s.setup = read_simulation_setup(root);
  s.envelope = root.has("envelope") ? read_envelope(root) : Envelope::report();
  return s;
}

// |I_r| [1e-7 kg m] of every point.
std::vector<double> evaluate(const Setup& s, const Points& pts, BatchRunner& runner) {
  const Simulator sim(s.setup);
  const std::size_t balls = s.setup.abu.balls.size();
  std::vector<double> out(pts.size());
  runner.run(pts.size(), [&](std::size_t i) {
    const std::vector<double>& u = pts[i];
    std::vector<double> beta(balls);
    for (std::size_t b = 0; b < balls; ++b) beta[b] = 2 * M_PI * u[b];
    if (s.setup.abu.ball_contact == BallContact::Hard && balls >= 2)
      beta = map_onto_contact_feasible_set(s.setup.abu, beta);
    const Envelope& e = s.envelope;
    const AbuParameters& a = s.setup.abu;
    RunOverrides o;
    if (e.friction_mu.given()) o.friction_mu = e.friction_mu.at(u[balls]);
    if (e.imbalance_mass_factor.given()) o.imbalance_mass_kg = a.imbalance_mass_kg * e.imbalance_mass_factor.at(u[balls + 1]);
    if (e.stiffness_factor.given()) o.stiffness_N_per_m = a.stiffness_N_per_m * e.stiffness_factor.at(u[balls + 2]);
    if (e.restitution.given()) o.ball_restitution = e.restitution.at(u[balls + 3]);
    const RunOutcome r = sim.run(beta, o);
    out[i] = r.ok() ? r.residual_imbalance_kgm * 1e7 : NAN;
  });
  return out;
}

double mean_of(const std::vector<double>& v, std::size_t n, std::size_t step = 1, std::size_t first = 0) {
  double s = 0;
  std::size_t c = 0;
  for (std::size_t i = first; i < n; i += step) s += v[i], ++c;
  return s / static_cast<double>(c);
}

double var_of(const std::vector<double>& v, std::size_t n, std::size_t step = 1, std::size_t first = 0) {
  const double m = mean_of(v, n, step, first);
  double s = 0;
  std::size_t c = 0;
  for (std::size_t i = first; i < n; i += step) s += (v[i] - m) * (v[i] - m), ++c;
  return s / static_cast<double>(c - 1);
}

void row(const char* scheme, std::size_t n, double mean, double hw) {
  std::printf("%s,%zu,%.6g,%.6g,%.6g\n", scheme, n, mean, hw, hw / std::fabs(mean));
}

// Interleaved replicates (run i in replicate i mod R): mean and t half-width of the replicate means.
void replicate_row(const char* scheme, const std::vector<double>& v, std::size_t n) {
  std::vector<double> means(kReplicates);
  for (std::size_t r = 0; r < kReplicates; ++r) means[r] = mean_of(v, n, kReplicates, r);
  row(scheme, n, mean_of(means, kReplicates), kT15 * std::sqrt(var_of(means, kReplicates) / kReplicates));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: sampling_study CONFIG [max_runs] [threads] [--paired OTHER]\n");
    return 2;
  }
  const Setup s = load(argv[1]);
  const std::size_t nmax = argc > 2 && argv[2][0] != '-' ? std::strtoul(argv[2], nullptr, 10) : 4096;
  const std::size_t threads = argc > 3 && argv[3][0] != '-' ? std::strtoul(argv[3], nullptr, 10) : 0;
  std::string paired, only;
  for (int k = 1; k + 1 < argc; ++k) {
    if (std::string(argv[k]) == "--paired") paired = argv[k + 1];
    if (std::string(argv[k]) == "--only") only = argv[k + 1];
  }
  auto want = [&](const char* scheme) { return only.empty() || only == scheme; };
  ThreadPoolRunner runner(threads);
  const std::size_t balls = s.setup.abu.balls.size(), d = balls + 4;
  std::vector<std::size_t> ns;
  for (std::size_t n = 64; n <= nmax; n *= 2) ns.push_back(n);
  std::printf("scheme,n,mean,half_width,half_width_rel\n");

  const Points rp = random_points(nmax, d);
  const std::vector<double> r = want("random") ? evaluate(s, rp, runner) : std::vector<double>{};
  if (want("random"))
    for (std::size_t n : ns) row("random", n, mean_of(r, n), 1.96 * std::sqrt(var_of(r, n) / static_cast<double>(n)));
  if (!paired.empty() && want("random")) {  // the same points for the other design: common draws
    const std::vector<double> o = evaluate(load(paired), rp, runner);
    std::vector<double> diff(nmax);
    for (std::size_t i = 0; i < nmax; ++i) diff[i] = r[i] - o[i];
    for (std::size_t n : ns) {
      const double dm = mean_of(diff, n);
      row("paired", n, dm, 1.96 * std::sqrt(var_of(diff, n) / static_cast<double>(n)));
      row("unpaired", n, dm, 1.96 * std::sqrt((var_of(r, n) + var_of(o, n)) / static_cast<double>(n)));
    }
  }
  if (want("sobol")) {
    const std::vector<double> q = evaluate(s, sobol_points(nmax, d, balls), runner);
    for (std::size_t n : ns) replicate_row("sobol", q, n);
  }
  const std::vector<double> st = want("strat") ? evaluate(s, strat_points(nmax, d, balls), runner) : std::vector<double>{};
  for (std::size_t n : ns) {
    if (!want("strat")) break;
    double v = 0, m = 0;
    for (std::size_t c = 0; c < 16; ++c) {
      const double nh = static_cast<double>(n / 16);
      m += mean_of(st, n, 16, c) / 16;
      v += var_of(st, n, 16, c) / nh / 256;
    }
    row("strat", n, m, 1.96 * std::sqrt(v));
  }
  for (std::size_t n : ns) {
    if (!want("lhs") || (n != 64 && n != 256 && n != 1024 && n != 4096)) continue;  // a new set per n
    replicate_row("lhs", evaluate(s, lhs_points(n, d), runner), n);
  }
  return 0;
}
