#include "abuopt/core/uncertain_parameters.hpp"

#include <cmath>
#include <sstream>

#include "abuopt/common/config_error.hpp"
#include "abuopt/core/initial_conditions.hpp"

namespace abuopt {

namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;
constexpr std::uint64_t kTagFriction = 0x4652494354494f4eULL;   // "FRICTION"
constexpr std::uint64_t kTagMass = 0x494d42414c4d4153ULL;       // "IMBALMAS"
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
         imbalance_angle.sampling == ImbalanceAngleSampling::Fixed;
}

void validate(const UncertainParameters& u, const std::string& path) {
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
  if (u.imbalance_angle.sampling == ImbalanceAngleSampling::Uniform)
    o.imbalance_angle_rad = kTwoPi * unit_double(hash_seed(seed, kTagAngle, index));
  else
    o.imbalance_angle_rad = u.imbalance_angle.angle_rad;
  return o;
}

UncertainParameters read_uncertain_parameters(YamlReader& mc) {
  UncertainParameters u;
  YamlReader f = mc.child("friction");
  if (f.present()) {
    int given = int(f.has("fixed")) + int(f.has("list")) + int(f.has("range"));
    if (given != 1)
      throw ConfigError(f.path(), yaml_value_text(f.node()), "must have exactly one of: fixed, list, range");
    if (f.has("fixed")) {
      u.friction.sampling = FrictionSampling::Fixed;
      u.friction.value = f.get_double("fixed", Rule::non_negative());
    } else if (f.has("list")) {
      u.friction.sampling = FrictionSampling::List;
      u.friction.values = f.get_double_list("list", Rule::non_negative());
    } else {
      u.friction.sampling = FrictionSampling::Range;
      auto r = f.get_double_list("range", Rule::non_negative());
      if (r.size() != 2)
        throw ConfigError(f.key_path("range"), yaml_value_text(f.node()["range"]), "must be a list [lo, hi]");
      u.friction.lo = r[0];
      u.friction.hi = r[1];
    }
    f.finish();
  }
  YamlReader im = mc.child("imbalance");
  if (im.present()) {
    if (im.has("mass_relative_range")) {
      auto r = im.get_double_list("mass_relative_range");
      if (r.size() != 2)
        throw ConfigError(im.key_path("mass_relative_range"), yaml_value_text(im.node()["mass_relative_range"]),
                          "must be a list [lo, hi]");
      u.imbalance_mass.sampling = ImbalanceMassSampling::RelativeRange;
      u.imbalance_mass.relative_lo = r[0];
      u.imbalance_mass.relative_hi = r[1];
    } else {
      im.get_string_or("mass_relative_range", "");  // marks a null value as read
    }
    const std::string a = im.get_choice_or("angle", "fixed", {"fixed", "uniform"});
    u.imbalance_angle.sampling = a == "uniform" ? ImbalanceAngleSampling::Uniform : ImbalanceAngleSampling::Fixed;
    if (u.imbalance_angle.sampling == ImbalanceAngleSampling::Fixed) {
      u.imbalance_angle.angle_rad = im.get_double_or("angle_rad", 0.0);
    } else if (im.has("angle_rad")) {
      throw ConfigError(im.key_path("angle_rad"), yaml_value_text(im.node()["angle_rad"]),
                        "is only valid with angle: fixed (angle: uniform draws it)");
    }
    im.finish();
  }
  validate(u, mc.path());
  return u;
}

}  // namespace abuopt
