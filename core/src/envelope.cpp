#include "abuopt/core/envelope.hpp"

#include <cmath>
#include <optional>
#include <sstream>
#include <vector>

#include "abuopt/common/config_error.hpp"
#include "abuopt/core/initial_conditions.hpp"

namespace abuopt {

namespace {

constexpr const char* kKeys[Envelope::kParameters] = {"friction_mu", "imbalance_mass_factor", "stiffness_factor",
                                                      "restitution"};
constexpr std::uint64_t kTags[Envelope::kParameters] = {kTagFriction, kTagMass, kTagStiffness, kTagRestitution};

std::string range_text(double lo, double hi) {
  return "[" + format_shortest(lo) + ", " + format_shortest(hi) + "]";
}

std::string list_text(const std::vector<double>& v) {
  std::string t = "[";
  for (std::size_t i = 0; i < v.size(); ++i) t += (i ? ", " : "") + format_shortest(v[i]);
  return t + "]";
}

// One parameter: a plain number (fixed), {fixed: v} or {uniform: [lo, hi]}.
void describe_parameter(FieldArchive& a, const char* key, ParameterDistribution& d) {
  bool is_section = d.kind == DistributionKind::Uniform;
  double number = d.lo;
  std::optional<double> fixed;
  std::optional<std::vector<double>> uniform;
  if (d.kind == DistributionKind::Uniform) uniform = std::vector<double>{d.lo, d.hi};
  FieldOptions o;
  o.enabled = a.reading() || d.given();
  a.number_or_section(key, is_section, number, Rule::any(), [&] {
    if (YamlReader* r = a.reader()) {
      if (int(r->has("fixed")) + int(r->has("uniform")) != 1)
        throw ConfigError(r->path(), yaml_value_text(r->node()),
                          "must have exactly one of: fixed, uniform (or be a plain number: fixed)");
    }
    FieldOptions in_use;
    in_use.enabled = a.reading();  // written as a plain number when fixed
    a.field("fixed", fixed, Rule::any(), in_use);
    a.field("uniform", uniform);
    if (a.reading() && uniform && uniform->size() != 2)
      throw ConfigError(a.path("uniform"), list_text(*uniform), "must be a list [lo, hi]");
  }, o);
  if (!a.reading()) return;
  if (!a.has(key)) return;
  if (!is_section) {
    d = ParameterDistribution::fixed(number);
  } else if (fixed) {
    d = ParameterDistribution::fixed(*fixed);
  } else if (uniform && uniform->size() == 2) {
    d = ParameterDistribution::uniform((*uniform)[0], (*uniform)[1]);
  }
}

std::uint32_t reverse_bits(std::uint32_t x) {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
  x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
  return (x >> 16) | (x << 16);
}

// Nested uniform (Owen) scrambling of x's bits: a hash that only mixes lower bits into higher ones
// (Laine and Karras) applied to the bit-reversed value (Burley, "Practical hash-based Owen
// scrambling", JCGT 9(4), 2020), so that each bit is flipped by a function of the bits above it.
std::uint32_t owen_scramble(std::uint32_t x, std::uint32_t seed) {
  x = reverse_bits(x);
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return reverse_bits(x);
}

constexpr std::uint64_t kTagScramble = 0x534352414d424c45ULL;  // "SCRAMBLE"
constexpr std::uint64_t kTagLowBits = 0x4c4f57424954534eULL;   // "LOWBITSN"

}  // namespace

const EnumNames<EnvelopeSampling> kEnvelopeSamplingNames = {
    {EnvelopeSampling::Random, "random"}, {EnvelopeSampling::Stratified, "stratified"}, {EnvelopeSampling::Sobol, "sobol"}};

std::size_t Envelope::strata() const {
  if (sampling != EnvelopeSampling::Stratified) return 1;
  std::size_t cells = 1;
  for (std::size_t k = 0; k < kParameters; ++k)
    if (parameter(k).varies()) cells *= 2;
  return cells;
}

double joint_sobol_coordinate(std::uint64_t seed, std::size_t index, std::size_t dim) {
  const std::size_t r = index % Envelope::kReplicates, k = index / Envelope::kReplicates;
  const double u = sobol_unit_point(k, dim + 1)[dim];
  const auto x = static_cast<std::uint32_t>(u * 4294967296.0);  // the sequence's 32 bits, exactly
  const auto scramble = static_cast<std::uint32_t>(hash_seed(seed, kTagScramble, r * 64 + dim));
  // below the 32 scrambled bits, uniform ones (what a full-depth scrambling gives)
  const double low = unit_double(hash_seed(seed ^ kTagLowBits, index, dim));
  return (static_cast<double>(owen_scramble(x, scramble)) + low) / 4294967296.0;
}

std::string to_string(DistributionKind k) {
  switch (k) {
    case DistributionKind::Nominal: return "nominal";
    case DistributionKind::Fixed: return "fixed";
    case DistributionKind::Uniform: return "uniform";
  }
  return "?";
}

std::string ParameterDistribution::text() const {
  switch (kind) {
    case DistributionKind::Nominal: return "nominal";
    case DistributionKind::Fixed: return "fixed " + format_shortest(lo);
    case DistributionKind::Uniform: return "uniform " + range_text(lo, hi);
  }
  return "?";
}

const char* Envelope::key(std::size_t k) { return kKeys[k]; }

ParameterDistribution& Envelope::parameter(std::size_t k) {
  switch (k) {
    case 0: return friction_mu;
    case 1: return imbalance_mass_factor;
    case 2: return stiffness_factor;
    default: return restitution;
  }
}
const ParameterDistribution& Envelope::parameter(std::size_t k) const {
  return const_cast<Envelope*>(this)->parameter(k);
}

bool Envelope::empty() const {
  for (std::size_t k = 0; k < kParameters; ++k)
    if (parameter(k).given()) return false;
  return true;
}

bool Envelope::deterministic() const {
  for (std::size_t k = 0; k < kParameters; ++k)
    if (parameter(k).varies()) return false;
  return true;
}

Envelope Envelope::report() {
  Envelope e;
  e.friction_mu = ParameterDistribution::uniform(0.02, 0.04);
  e.imbalance_mass_factor = ParameterDistribution::uniform(0.5, 1.5);
  e.stiffness_factor = ParameterDistribution::uniform(0.95, 1.05);
  e.restitution = ParameterDistribution::uniform(0.5, 0.95);
  return e;
}

std::uint64_t envelope_tag(std::size_t k) { return kTags[k]; }

void validate(const Envelope& e, const std::string& path) {
  const std::string p = path.empty() ? "" : path + ".";
  for (std::size_t k = 0; k < Envelope::kParameters; ++k) {
    const ParameterDistribution& d = e.parameter(k);
    if (!d.given()) continue;
    const bool uniform = d.kind == DistributionKind::Uniform;
    const std::string key = p + Envelope::key(k) + (uniform ? ".uniform" : "");
    const std::string value = uniform ? range_text(d.lo, d.hi) : format_shortest(d.lo);
    if (!std::isfinite(d.lo) || !std::isfinite(d.hi)) throw ConfigError(key, value, "must be finite");
    if (d.lo > d.hi) throw ConfigError(key, value, "must be [lo, hi] with lo <= hi");
    switch (k) {
      case 0:
        if (d.lo < 0 || d.hi >= 1) throw ConfigError(key, value, "must lie in [0, 1) (a friction coefficient)");
        break;
      case 1:
      case 2:
        if (d.lo <= 0 || d.hi > 1e3)
          throw ConfigError(key, value, "must lie in (0, 1000] (a factor on the abu section's value)");
        break;
      default:
        if (d.lo < 0 || d.hi > 1) throw ConfigError(key, value, "must lie in [0, 1] (a coefficient of restitution)");
        break;
    }
  }
}

void describe_fields(FieldArchive& a, Envelope& e) {
  for (std::size_t k = 0; k < Envelope::kParameters; ++k) describe_parameter(a, Envelope::key(k), e.parameter(k));
  a.field("sampling", e.sampling, kEnvelopeSamplingNames);
}

Envelope read_envelope(YamlReader& root) {
  Envelope e;
  if (!root.has("envelope")) return e;
  YamlReader r = root.child("envelope");
  read_fields(r, e);
  validate(e, r.path());
  return e;
}

}  // namespace abuopt
