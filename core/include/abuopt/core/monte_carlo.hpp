#pragma once
// Monte Carlo over initial ball angles (and optionally uncertain parameters) for one setup.
//
// Run i of a study is a pure function of (study, i):
//   beta0     = point i of the initial-condition design (initial_conditions.hpp),
//   overrides = sample_overrides(study.uncertain, setup.abu, study.seed, i) (hash of (seed, i)),
//   (with the envelope's joint sampling, beta0 and the overrides are one scrambled Sobol' point),
//   outcome   = the per-sample function (by default Simulator::run) of (beta0, overrides).
// The engine writes outcome i into slot i of a pre-sized vector, whatever worker ran it, so the
// results are bit-identical for any thread count or batch backend, and run_one(study, i) replays
// run i alone (the way to debug one odd sample of a large study).
//
// Numerical trouble inside one run is the outcome's status (counted by the statistics); an
// exception thrown by the per-sample function (a bug, or a config error) aborts the study.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "abuopt/common/config_fields.hpp"
#include "abuopt/common/yaml_reader.hpp"
#include "abuopt/core/batch_runner.hpp"
#include "abuopt/core/initial_conditions.hpp"
#include "abuopt/core/outcome.hpp"
#include "abuopt/core/simulator.hpp"
#include "abuopt/core/uncertain_parameters.hpp"

namespace abuopt {

struct MonteCarloStudy {
  SimulationSetup setup;
  // Initial ball angles. The engine takes the number of balls from setup.abu.balls and, for every
  // kind but Grid, the number of points from `runs` (see study_design()).
  InitialConditionDesign design;
  UncertainParameters uncertain;
  std::uint64_t seed = 0;   // stream of the uncertain parameters (the design has its own seed)
  std::size_t runs = 1024;  // Grid: must equal grid^balls
  // Identical balls are exchangeable: a run whose initial angles are a permutation of an earlier
  // run's (with the same uncertain parameters) has the same outcome with the final angles
  // permuted alike. With this on (the default) such a run reuses the earlier simulation instead
  // of paying for it again: the report's 32 x 32 grid holds 528 distinct starts of its 1024. The
  // statistics weight every run as before (the report's figures count all grid points) but the
  // %MI interval uses the number of distinct runs (monte_carlo_stats.hpp).
  bool reuse_exchangeable = true;
};

// True when the setup's balls are all identical (same mass and diameter), i.e. exchangeable.
bool balls_exchangeable(const SimulationSetup& setup);

// True when run i's start angles come from the envelope's joint scrambled Sobol' point (not the
// design): envelope.sampling sobol, a varying envelope parameter, and design random or sobol.
// Then the runs form Envelope::kReplicates independent scramblings (run i in i mod 16), and
// mean_interval95 (monte_carlo_stats.hpp) takes the interval from their means.
bool joint_sampling(const MonteCarloStudy& s);

// The design the study actually uses: `design` with balls = setup.abu.balls.size() and, unless it
// is a grid, count = runs.
InitialConditionDesign study_design(const MonteCarloStudy& s);

// Throws ConfigError (keys below `path`): runs < 1, grid^balls != runs, invalid design or
// uncertain parameters, no balls.
void validate(const MonteCarloStudy& s, const std::string& path = "montecarlo");

// One run's inputs and result.
struct MonteCarloSample {
  std::size_t index = 0;
  bool reused = false;        // true: the outcome is run `reused_from`'s with the balls exchanged
  std::size_t reused_from = 0;
  std::vector<double> beta0;  // initial ball angles [rad]
  RunOverrides overrides;
  double friction_mu = 0;     // effective mu of this run (override or nominal)
  double imbalance_kgm = 0;   // effective m_I e of this run: the %MI threshold
  double stiffness_N_per_m = 0;  // effective k of this run
  double restitution = 0;        // effective ball-ball restitution of this run
  RunOutcome outcome;
};

struct MonteCarloResult {
  std::vector<MonteCarloSample> samples;  // samples[i].index == i
  double wall_time_s = 0;
  std::size_t concurrency = 1;            // workers of the batch runner
};

// The per-sample function: one startup from beta0 with the given overrides. Called from several
// threads at once: it must be thread-safe and deterministic in its arguments.
using SampleFunction = std::function<RunOutcome(const std::vector<double>& beta0, const RunOverrides& overrides)>;

// The inputs of run `index` (outcome left default): for replaying or inspecting one run.
// `reused`/`reused_from` are set as the engine sets them (the earliest run with a permutation of
// these inputs).
MonteCarloSample prepare_sample(const MonteCarloStudy& s, std::size_t index);

// The engine with an injected per-sample function (tests, other models, surrogate screening).
MonteCarloResult run_monte_carlo(const MonteCarloStudy& s, const SampleFunction& sample, BatchRunner& runner,
                                 const ProgressCallback& progress = {});

// Run `index` alone with an injected per-sample function.
MonteCarloSample run_one(const MonteCarloStudy& s, std::size_t index, const SampleFunction& sample);

// --- Studies run by a runner of their own (other processes) ------------------------------------
// The inputs of every run (samples[i].index == i, outcome unset) and the runs that are paid for
// (the others reuse an exchanged run: `reused_from`), exactly as the engine prepares them. A process
// that rebuilds the study (an MPI rank) gets the same inputs, bit for bit.
struct PreparedStudy {
  std::vector<MonteCarloSample> samples;
  std::vector<std::size_t> simulate;
};
PreparedStudy prepare_study(const MonteCarloStudy& s);

// A BatchRunner that runs the simulator's runs of a whole study itself, possibly in other
// processes (MPI ranks: abuopt::parallel), which rebuild the study from its description: a task
// closure cannot cross a process boundary. run_monte_carlo(s, runner) below hands such a runner
// the study instead of tasks.
class StudyRunner : public BatchRunner {
 public:
  // Sets p.samples[k].outcome = Simulator(s.setup).run(beta0, overrides) for every k in
  // p.simulate (the others are filled by the engine). Progress and exceptions as in run().
  virtual void run_study(const MonteCarloStudy& s, PreparedStudy& p, const ProgressCallback& progress) = 0;
};

// The engine for a StudyRunner (validates s).
MonteCarloResult run_monte_carlo_study(const MonteCarloStudy& s, StudyRunner& runner,
                                       const ProgressCallback& progress = {});

// --- Simulator-backed defaults ----------------------------------------------------------------
// These are inline so that the engine's object file has no link-time dependency on the
// simulator: programs that inject their own SampleFunction link without it.

// A SampleFunction running Simulator::run on one shared, const Simulator (validates the setup:
// throws ConfigError).
inline SampleFunction simulator_sample_function(const SimulationSetup& setup) {
  auto sim = std::make_shared<const Simulator>(setup);
  return [sim](const std::vector<double>& beta0, const RunOverrides& o) { return sim->run(beta0, o); };
}

inline MonteCarloResult run_monte_carlo(const MonteCarloStudy& s, BatchRunner& runner,
                                        const ProgressCallback& progress = {}) {
  if (auto* study_runner = dynamic_cast<StudyRunner*>(&runner))
    return run_monte_carlo_study(s, *study_runner, progress);
  validate(s);
  return run_monte_carlo(s, simulator_sample_function(s.setup), runner, progress);
}

inline MonteCarloSample run_one(const MonteCarloStudy& s, std::size_t index) {
  validate(s);
  return run_one(s, index, simulator_sample_function(s.setup));
}

// --- Configuration ----------------------------------------------------------------------------
struct MonteCarloConfig {
  MonteCarloStudy study;
  std::size_t threads = 0;  // 0: all hardware threads
};

// Reads the `montecarlo` section of `root` (every key optional; docs/montecarlo.md):
//   design: grid | random | lhs | halton | sobol   (default grid)
//   grid: 32          points per axis of the grid design (grid^balls runs)
//   runs: 1024        number of runs (grid: optional, must equal grid^balls)
//   seed: 0           seeds the design and the uncertain parameters (whole number 0..2^53)
//   shift: true       halton/sobol: Cranley-Patterson random shift from the seed
//   threads: 0        0 = all cores
//   friction: {...}, imbalance: {...}   (uncertain_parameters.hpp)
// and the top-level `envelope` section (envelope.hpp) into study.uncertain.envelope.
// `setup` (read before, e.g. by read_simulation_setup) becomes study.setup. Validates the study.
// The caller still calls root.finish().
MonteCarloConfig read_monte_carlo_config(YamlReader& root, SimulationSetup setup);
// The same without the structural check (grid^balls = runs, the run cap, the uncertain parameters): for a
// caller that replaces some values first (the command line's --design/--runs/--grid) and then calls
// validate(cfg.study, "montecarlo"). Each field's own rule is still checked as it is read.
MonteCarloConfig read_monte_carlo_config_unchecked(YamlReader& root, SimulationSetup setup);

extern const EnumNames<InitialConditionKind> kInitialConditionKindNames;  // grid, random, lhs, halton, sobol

// The keys of the `montecarlo` section (not the setup): one field list for reading, writing,
// validation and identity. `threads` is not part of the identity (results do not depend on it);
// the design's seed is (it equals `seed` when read, and may differ in a study built in code).
void describe_montecarlo_fields(FieldArchive& a, MonteCarloStudy& study, std::size_t& threads);
void describe_fields(FieldArchive& a, MonteCarloConfig& c);

}  // namespace abuopt
