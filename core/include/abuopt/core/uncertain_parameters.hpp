#pragma once
// Uncertain parameters of a Monte Carlo study, drawn per run as RunOverrides.
//
// Every run is replayable alone: run i of a study with seed S draws each uncertain parameter from
// its own uniform u = unit_double(hash_seed(S, tag_of_parameter, i)) (splitmix64 hashing), never
// from a generator shared across runs. So the values of run i depend only on (S, i, the settings),
// not on the thread count, the order of execution, or on which other parameters are uncertain.
//
//   friction mu:       Nominal (no override: the setup's abu.friction_mu), Fixed value, List
//                      (CYCLED: run i uses values[i mod size], no randomness), or Range: uniform
//                      in [lo, hi].
//   imbalance mass:    Nominal, or RelativeRange: m_I (1 + u), u uniform in [lo, hi] (e.g.
//                      [-0.1, 0.1] for +-10 %), m_I being the setup's abu.imbalance_mass_kg.
//   imbalance angle:   Fixed angle_rad (default 0: the model's frame), or Uniform in [0, 2 pi).
//                      Outcomes stay imbalance-relative (see RunOverrides).
//   envelope:          the top-level `envelope` section (envelope.hpp): friction, imbalance mass,
//                      stiffness, restitution, drawn with the same hashing. The place new configs
//                      use; a parameter given both here and in montecarlo.friction /
//                      montecarlo.imbalance.mass_relative_range is a ConfigError.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "abuopt/common/config_fields.hpp"
#include "abuopt/common/yaml_reader.hpp"
#include "abuopt/core/envelope.hpp"
#include "abuopt/core/parameters.hpp"
#include "abuopt/core/simulator.hpp"

namespace abuopt {

enum class FrictionSampling { Nominal, Fixed, List, Range };
enum class ImbalanceMassSampling { Nominal, RelativeRange };
enum class ImbalanceAngleSampling { Fixed, Uniform };

std::string to_string(FrictionSampling s);
std::string to_string(ImbalanceMassSampling s);
std::string to_string(ImbalanceAngleSampling s);

struct FrictionUncertainty {
  FrictionSampling sampling = FrictionSampling::Nominal;
  double value = 0.02;           // Fixed
  std::vector<double> values;    // List (cycled by run index)
  double lo = 0.02, hi = 0.02;   // Range: uniform in [lo, hi]
};

struct ImbalanceMassUncertainty {
  ImbalanceMassSampling sampling = ImbalanceMassSampling::Nominal;
  double relative_lo = 0.0, relative_hi = 0.0;  // RelativeRange: m_I (1 + u), u in [lo, hi]
};

struct ImbalanceAngleUncertainty {
  ImbalanceAngleSampling sampling = ImbalanceAngleSampling::Fixed;
  double angle_rad = 0.0;  // Fixed
};

struct UncertainParameters {
  FrictionUncertainty friction;
  ImbalanceMassUncertainty imbalance_mass;
  ImbalanceAngleUncertainty imbalance_angle;
  Envelope envelope;  // the `envelope` section (not a key of `montecarlo`)

  // True when every run gets the same overrides (no randomness, no list).
  bool deterministic() const;
};

// Throws ConfigError (keys below `path`) for negative or non-finite friction, an empty list,
// lo > hi, a relative range reaching m_I <= 0 (lo <= -1), an invalid envelope, or a parameter
// given both in the envelope and in the `montecarlo` keys.
void validate(const UncertainParameters& u, const std::string& path = "montecarlo");

// The overrides of run `index` of a study with seed `seed`. `nominal` gives m_I for the relative
// range and the envelope's factors. Pure function of its arguments.
RunOverrides sample_overrides(const UncertainParameters& u, const AbuParameters& nominal, std::uint64_t seed,
                              std::size_t index);

extern const EnumNames<ImbalanceAngleSampling> kImbalanceAngleNames;  // fixed, uniform

// The keys `friction` and `imbalance` of the `montecarlo` section (one field list: reading,
// writing, validation, identity). The envelope is its own section (describe_fields(a, Envelope&)).
void describe_fields(FieldArchive& a, UncertainParameters& u);

// Reads the uncertain parameters from the `montecarlo` section (keys `friction`, `imbalance`):
//   friction: {fixed: 0.02} | {list: [0.02, 0.03]} | {range: [0.02, 0.04]}   (absent: nominal)
//   imbalance: {mass_relative_range: [-0.1, 0.1], angle: fixed | uniform, angle_rad: 0}
// Exactly one of fixed/list/range under friction. The caller calls mc.finish().
UncertainParameters read_uncertain_parameters(YamlReader& mc);

}  // namespace abuopt
