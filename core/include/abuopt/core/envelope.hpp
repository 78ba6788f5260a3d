#pragma once
// The envelope of uncertain ABU parameters: one config section, read by `montecarlo`, the design
// problem (problems/) and the studies, drawn per run of a Monte Carlo (docs/montecarlo.md).
//
//   envelope:
//     friction_mu: {uniform: [0.02, 0.04]}          # Coulomb mu (absolute)
//     imbalance_mass_factor: {uniform: [0.5, 1.5]}  # x abu.imbalance_mass_kg (e fixed)
//     stiffness_factor: {uniform: [0.95, 1.05]}     # x abu.stiffness_N_per_m (moves omega_n)
//     restitution: {uniform: [0.5, 0.95]}           # ball-ball, absolute (hard contact)
//     sampling: stratified                          # or random, sobol (EnvelopeSampling)
//
// Each parameter is absent (nominal: the abu section's value), fixed ({fixed: v} or a plain
// number) or uniform ({uniform: [lo, hi]}). With sampling: random, run i of a study with seed S
// draws parameter p from u = unit_double(hash_seed(S, tag_p, i)); stratified: (bit + u) / 2, bit
// the parameter's bit of run i's cell; sobol: coordinate p of the joint point
// (joint_sobol_coordinate). Either way: replayable from (S, i) alone, independent of the thread
// count, of the ranks and of which other parameters are uncertain. Friction and imbalance mass use
// the streams of montecarlo.friction.range / montecarlo.imbalance.mass_relative_range, so with
// sampling: random an envelope uniform equals the old key's range draw for draw; the default,
// stratified, moves each draw into its run's cell and so gives other draws (same distribution).
#include <cstdint>
#include <string>

#include "abuopt/common/config_fields.hpp"
#include "abuopt/common/yaml_reader.hpp"
#include "abuopt/core/parameters.hpp"

namespace abuopt {

enum class DistributionKind { Nominal, Fixed, Uniform };
// How the varying parameters are drawn (measured against each other in docs/montecarlo.md):
//   Stratified (default): the range of each of the P varying parameters is cut in two halves, 2^P
//     cells; run i lies in cell i mod 2^P (proportional allocation) and is uniform inside it (the
//     random stream's draw u becomes (bit + u) / 2). Never a wider interval than Random; about
//     1.2x fewer runs for the same interval over the issue-30 envelope.
//   Random: each parameter from its own hashed stream (the old keys' draws).
//   Sobol: one joint scrambled Sobol' point per run for the parameters and, with montecarlo.design
//     random or sobol, the start angles (randomised QMC, 16 interleaved independent scramblings);
//     no gain measured here (the response is discontinuous), kept for smooth responses.
enum class EnvelopeSampling { Random, Stratified, Sobol };
extern const EnumNames<EnvelopeSampling> kEnvelopeSamplingNames;  // random, stratified, sobol
std::string to_string(DistributionKind k);

// One uncertain parameter: nominal (absent), fixed at lo (== hi), or uniform in [lo, hi].
struct ParameterDistribution {
  DistributionKind kind = DistributionKind::Nominal;
  double lo = 0, hi = 0;

  static ParameterDistribution fixed(double v) { return {DistributionKind::Fixed, v, v}; }
  static ParameterDistribution uniform(double lo, double hi) { return {DistributionKind::Uniform, lo, hi}; }
  bool given() const { return kind != DistributionKind::Nominal; }
  // True when the value differs from run to run.
  bool varies() const { return kind == DistributionKind::Uniform && hi > lo; }
  // The value for a unit draw u in [0, 1) (inverse CDF; Fixed ignores u).
  double at(double u) const { return kind == DistributionKind::Uniform ? lo + (hi - lo) * u : lo; }
  // "nominal", "fixed 0.03", "uniform [0.02, 0.04]".
  std::string text() const;
  bool operator==(const ParameterDistribution&) const = default;
};

struct Envelope {
  ParameterDistribution friction_mu;            // absolute mu
  ParameterDistribution imbalance_mass_factor;  // x abu.imbalance_mass_kg
  ParameterDistribution stiffness_factor;       // x abu.stiffness_N_per_m
  ParameterDistribution restitution;            // absolute ball-ball restitution
  EnvelopeSampling sampling = EnvelopeSampling::Stratified;
  // Stratified: the number of cells, 2^(varying parameters); otherwise 1.
  std::size_t strata() const;
  // Scrambled Sobol': run i is point i / kReplicates of scrambling i mod kReplicates.
  static constexpr std::size_t kReplicates = 16;
  // Joint coordinates: the kParameters parameters first, then the start angles (at most
  // kMaxJointBalls balls: the Sobol' directions shipped cover 10 dimensions).
  static constexpr std::size_t kMaxJointBalls = 6;

  // Number of parameters in the section, the names of the keys, and access by position (the
  // order of the keys above).
  static constexpr std::size_t kParameters = 4;
  static const char* key(std::size_t k);
  ParameterDistribution& parameter(std::size_t k);
  const ParameterDistribution& parameter(std::size_t k) const;

  bool empty() const;          // no parameter given
  bool deterministic() const;  // no parameter varies
  bool operator==(const Envelope&) const = default;

  // The issue-30 envelope of the report's ABU: mu U[0.02, 0.04], m_I x U[0.5, 1.5],
  // k x U[0.95, 1.05], restitution U[0.5, 0.95].
  static Envelope report();
};

// Stream tags of the per-run draws (hash_seed(seed, tag, index)).
inline constexpr std::uint64_t kTagFriction = 0x4652494354494f4eULL;     // "FRICTION"
inline constexpr std::uint64_t kTagMass = 0x494d42414c4d4153ULL;         // "IMBALMAS"
inline constexpr std::uint64_t kTagStiffness = 0x53544946464e4553ULL;    // "STIFFNES"
inline constexpr std::uint64_t kTagRestitution = 0x5245535449545554ULL;  // "RESTITUT"
std::uint64_t envelope_tag(std::size_t k);  // the tag of parameter k (Envelope::key order)

// Coordinate `dim` of run `index`'s joint point in [0, 1) (scrambled Sobol': Owen's nested
// uniform scrambling by hashing, Burley 2020, seeded by (seed, replicate, dim)); dim < 10. A pure
// function of its arguments.
double joint_sobol_coordinate(std::uint64_t seed, std::size_t index, std::size_t dim);

// Throws ConfigError (keys below `path`, e.g. "envelope.stiffness_factor.uniform") for lo > hi,
// non-finite values, mu outside [0, 1), factors <= 0, restitution outside [0, 1].
void validate(const Envelope& e, const std::string& path = "envelope");

// The keys of the `envelope` section (one field list: reading, writing, validation, identity).
void describe_fields(FieldArchive& a, Envelope& e);

// Reads the top-level `envelope` section of `root` (absent: an empty envelope) and validates it.
Envelope read_envelope(YamlReader& root);

}  // namespace abuopt
