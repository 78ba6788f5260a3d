#include "abuopt/core/parameters.hpp"

#include <cmath>
#include <sstream>
#include <string>

#include "abuopt/common/config_error.hpp"

namespace abuopt {

namespace {
std::string num(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}
void require_positive(double v, const std::string& path) {
  if (!(std::isfinite(v) && v > 0)) throw ConfigError(path, num(v), "must be > 0");
}
void require_non_negative(double v, const std::string& path) {
  if (!(std::isfinite(v) && v >= 0)) throw ConfigError(path, num(v), "must be >= 0");
}
}  // namespace

void validate(const AbuParameters& p, const char* path_c) {
  const std::string path(path_c);
  require_positive(p.table_mass_kg, path + ".table_mass_kg");
  require_non_negative(p.damping_Ns_per_m, path + ".damping_Ns_per_m");
  require_positive(p.stiffness_N_per_m, path + ".stiffness_N_per_m");
  require_positive(p.ball_track_radius_m, path + ".ball_track_radius_m");
  require_non_negative(p.imbalance_mass_kg, path + ".imbalance_mass_kg");
  require_non_negative(p.eccentricity_m, path + ".eccentricity_m");
  require_non_negative(p.friction_mu, path + ".friction_mu");
  if (p.friction_mu >= 1.0) throw ConfigError(path + ".friction_mu", num(p.friction_mu), "must be < 1");
  require_non_negative(p.ball_damping_Nms, path + ".ball_damping_Nms");
  for (std::size_t i = 0; i < p.balls.size(); ++i) {
    const std::string b = path + ".balls[" + std::to_string(i) + "]";
    require_positive(p.balls[i].mass_kg, b + ".mass_kg");
    require_positive(p.balls[i].diameter_m, b + ".diameter_m");
    if (p.balls[i].diameter_m >= p.ball_track_radius_m)
      throw ConfigError(b + ".diameter_m", num(p.balls[i].diameter_m),
                        "must be smaller than abu.ball_track_radius_m (" + num(p.ball_track_radius_m) + ")");
  }
}

}  // namespace abuopt
