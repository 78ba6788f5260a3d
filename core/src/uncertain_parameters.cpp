#include "abuopt/core/uncertain_parameters.hpp"

#include <cmath>
#include <sstream>

#include "abuopt/common/config_error.hpp"
#include "abuopt/core/initial_conditions.hpp"

namespace abuopt {

namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;
// kTagFriction and kTagMass: envelope.hpp (the envelope draws from the same streams)
constexpr std::uint64_t kTagAngle = 0x494d42414c414e47ULL;      // "IMBALANG"

std::string num(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

std::string pair_text(double lo, double hi) {
  std::ostringstream os;
  os << '[' << lo << ", " << hi << ']';
  return os.str();
}

std::string pair_list_text(const std::vector<double>& v) {
  std::string t = "[";
  for (std::size_t i = 0; i < v.size(); ++i) t += (i ? ", " : "") + format_shortest(v[i]);
  return t + "]";
}

double lerp(double lo, double hi, double u) { return lo + (hi - lo) * u; }

}  // namespace

std::string to_string(FrictionSampling s) {
  switch (s) {
    case FrictionSampling::Nominal: return "nominal";
    case FrictionSampling::Fixed: return "fixed";
    case FrictionSampling::List: return "list";
    case FrictionSampling::Range: return "range";
  }
  return "?";
}
std::string to_string(ImbalanceMassSampling s) {
  return s == ImbalanceMassSampling::Nominal ? "nominal" : "relative_range";
}
std::string to_string(ImbalanceAngleSampling s) { return s == ImbalanceAngleSampling::Fixed ? "fixed" : "uniform"; }

bool UncertainParameters::deterministic() const {
  return (friction.sampling == FrictionSampling::Nominal || friction.sampling == FrictionSampling::Fixed ||
          (friction.sampling == FrictionSampling::List && friction.values.size() <= 1)) &&
         imbalance_mass.sampling == ImbalanceMassSampling::Nominal &&
         imbalance_angle.sampling == ImbalanceAngleSampling::Fixed && envelope.deterministic();
}

void validate(const UncertainParameters& u, const std::string& path) {
  validate_fields(u, path);
  const std::string f = (path.empty() ? "" : path + ".") + "friction";
  const std::string im = (path.empty() ? "" : path + ".") + "imbalance";
  auto check_mu = [](const std::string& key, double v) {
    if (!std::isfinite(v) || v < 0) throw ConfigError(key, num(v), "must be >= 0 (a friction coefficient)");
  };
  switch (u.friction.sampling) {
    case FrictionSampling::Nominal: break;
    case FrictionSampling::Fixed: check_mu(f + ".fixed", u.friction.value); break;
    case FrictionSampling::List:
      if (u.friction.values.empty()) throw ConfigError(f + ".list", "[]", "must hold at least one value");
      for (std::size_t i = 0; i < u.friction.values.size(); ++i)
        check_mu(f + ".list[" + std::to_string(i) + "]", u.friction.values[i]);
      break;
    case FrictionSampling::Range:
      check_mu(f + ".range[0]", u.friction.lo);
      check_mu(f + ".range[1]", u.friction.hi);
      if (u.friction.lo > u.friction.hi)
        throw ConfigError(f + ".range", pair_text(u.friction.lo, u.friction.hi), "must be [lo, hi] with lo <= hi");
      break;
  }
  if (u.imbalance_mass.sampling == ImbalanceMassSampling::RelativeRange) {
    const double lo = u.imbalance_mass.relative_lo, hi = u.imbalance_mass.relative_hi;
    if (!std::isfinite(lo) || !std::isfinite(hi) || lo > hi)
      throw ConfigError(im + ".mass_relative_range", pair_text(lo, hi), "must be [lo, hi] with lo <= hi, finite");
    if (lo <= -1.0)
      throw ConfigError(im + ".mass_relative_range", pair_text(lo, hi),
                        "lo must be > -1 (the imbalance mass m_I (1 + u) must stay > 0)");
  }
  if (u.imbalance_angle.sampling == ImbalanceAngleSampling::Fixed && !std::isfinite(u.imbalance_angle.angle_rad))
    throw ConfigError(im + ".angle_rad", num(u.imbalance_angle.angle_rad), "must be finite");
  validate(u.envelope, "envelope");
  if (u.envelope.friction_mu.given() && u.friction.sampling != FrictionSampling::Nominal)
    throw ConfigError("envelope.friction_mu", u.envelope.friction_mu.text(),
                      "cannot be combined with " + f + " (give each uncertain parameter in one place: the envelope)");
  if (u.envelope.imbalance_mass_factor.given() && u.imbalance_mass.sampling != ImbalanceMassSampling::Nominal)
    throw ConfigError("envelope.imbalance_mass_factor", u.envelope.imbalance_mass_factor.text(),
                      "cannot be combined with " + im +
                          ".mass_relative_range (give each uncertain parameter in one place: the envelope)");
}

RunOverrides sample_overrides(const UncertainParameters& u, const AbuParameters& nominal, std::uint64_t seed,
                              std::size_t index) {
  RunOverrides o;
  switch (u.friction.sampling) {
    case FrictionSampling::Nominal: break;
    case FrictionSampling::Fixed: o.friction_mu = u.friction.value; break;
    case FrictionSampling::List: o.friction_mu = u.friction.values[index % u.friction.values.size()]; break;
    case FrictionSampling::Range:
      o.friction_mu = lerp(u.friction.lo, u.friction.hi, unit_double(hash_seed(seed, kTagFriction, index)));
      break;
  }
  if (u.imbalance_mass.sampling == ImbalanceMassSampling::RelativeRange) {
    const double r = lerp(u.imbalance_mass.relative_lo, u.imbalance_mass.relative_hi,
                          unit_double(hash_seed(seed, kTagMass, index)));
    o.imbalance_mass_kg = nominal.imbalance_mass_kg * (1.0 + r);
  }
  // The envelope: each parameter from its own stream (the same streams as the keys above for
  // friction and imbalance mass, which validate() keeps exclusive), folded into its half of the
  // range by run i's cell (stratified), or the joint scrambled Sobol' point (sobol).
  const Envelope& e = u.envelope;
  const std::size_t cell = index % e.strata();
  auto draw = [&](std::size_t k) {
    const ParameterDistribution& d = e.parameter(k);
    if (!d.varies()) return d.at(0.0);
    if (e.sampling == EnvelopeSampling::Sobol) return d.at(joint_sobol_coordinate(seed, index, k));
    const double v = unit_double(hash_seed(seed, envelope_tag(k), index));
    if (e.sampling == EnvelopeSampling::Random) return d.at(v);
    std::size_t bit = 0;  // this parameter's position among the varying ones: its bit of the cell
    for (std::size_t q = 0; q < k; ++q) bit += e.parameter(q).varies() ? 1 : 0;
    return d.at(0.5 * (static_cast<double>((cell >> bit) & 1u) + v));
  };
  if (e.friction_mu.given()) o.friction_mu = draw(0);
  if (e.imbalance_mass_factor.given()) o.imbalance_mass_kg = nominal.imbalance_mass_kg * draw(1);
  if (e.stiffness_factor.given()) o.stiffness_N_per_m = nominal.stiffness_N_per_m * draw(2);
  if (e.restitution.given()) o.ball_restitution = draw(3);
  if (u.imbalance_angle.sampling == ImbalanceAngleSampling::Uniform)
    o.imbalance_angle_rad = kTwoPi * unit_double(hash_seed(seed, kTagAngle, index));
  else
    o.imbalance_angle_rad = u.imbalance_angle.angle_rad;
  return o;
}

const EnumNames<ImbalanceAngleSampling> kImbalanceAngleNames = {{ImbalanceAngleSampling::Fixed, "fixed"},
                                                                 {ImbalanceAngleSampling::Uniform, "uniform"}};

void describe_fields(FieldArchive& a, UncertainParameters& u) {
  // friction: exactly one of {fixed: mu}, {list: [...]}, {range: [lo, hi]}; absent: nominal.
  FrictionUncertainty& f = u.friction;
  std::optional<double> fixed;
  std::optional<std::vector<double>> list, range;
  if (f.sampling == FrictionSampling::Fixed) fixed = f.value;
  if (f.sampling == FrictionSampling::List) list = f.values;
  if (f.sampling == FrictionSampling::Range) range = std::vector<double>{f.lo, f.hi};
  const bool friction_given = a.reading() ? a.has("friction") : f.sampling != FrictionSampling::Nominal;
  FieldOptions friction_options;
  friction_options.enabled = a.reading() || friction_given;
  a.section("friction", [&] {
    if (YamlReader* r = a.reader()) {
      if (int(r->has("fixed")) + int(r->has("list")) + int(r->has("range")) != 1)
        throw ConfigError(r->path(), yaml_value_text(r->node()), "must have exactly one of: fixed, list, range");
    }
    // Reading accepts any one of them; the other archives see the one in use.
    auto in_use = [&](FrictionSampling k) {
      FieldOptions o;
      o.enabled = a.reading() || f.sampling == k;
      return o;
    };
    a.field("fixed", fixed, Rule::non_negative(), in_use(FrictionSampling::Fixed));
    a.field("list", list, Rule::non_negative(), in_use(FrictionSampling::List));
    a.field("range", range, Rule::non_negative(), in_use(FrictionSampling::Range));
    if (a.reading() && range && range->size() != 2)
      throw ConfigError(a.path("range"), pair_list_text(*range), "must be a list [lo, hi]");
  }, friction_options);
  // Back into the struct (a mirror of the keys; also when another archive changed them).
  if (friction_given) {
    if (fixed) {
      f.sampling = FrictionSampling::Fixed;
      f.value = *fixed;
    } else if (list) {
      f.sampling = FrictionSampling::List;
      f.values = *list;
    } else if (range && range->size() == 2) {
      f.sampling = FrictionSampling::Range;
      f.lo = (*range)[0];
      f.hi = (*range)[1];
    }
  }

  // imbalance: {mass_relative_range: [lo, hi], angle: fixed | uniform, angle_rad: 0}
  std::optional<std::vector<double>> mass_range;
  if (u.imbalance_mass.sampling == ImbalanceMassSampling::RelativeRange)
    mass_range = std::vector<double>{u.imbalance_mass.relative_lo, u.imbalance_mass.relative_hi};
  a.section("imbalance", [&] {
    a.field("mass_relative_range", mass_range);
    if (a.reading() && mass_range && mass_range->size() != 2)
      throw ConfigError(a.path("mass_relative_range"), pair_list_text(*mass_range), "must be a list [lo, hi]");
    a.field("angle", u.imbalance_angle.sampling, kImbalanceAngleNames);
    a.field("angle_rad", u.imbalance_angle.angle_rad, Rule::any(),
            FieldOptions::only_if(u.imbalance_angle.sampling == ImbalanceAngleSampling::Fixed,
                                  "is only valid with angle: fixed (angle: uniform draws it)"));
  });
  if (mass_range && mass_range->size() == 2) {
    u.imbalance_mass.sampling = ImbalanceMassSampling::RelativeRange;
    u.imbalance_mass.relative_lo = (*mass_range)[0];
    u.imbalance_mass.relative_hi = (*mass_range)[1];
  }
}

UncertainParameters read_uncertain_parameters(YamlReader& mc) {
  UncertainParameters u;
  YamlReadArchive a(mc);
  describe_fields(a, u);
  validate(u, mc.path());
  return u;
}

}  // namespace abuopt
