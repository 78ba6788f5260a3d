#include "abuopt/core/parameters.hpp"

#include <algorithm>
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

std::string to_string(BallContact c) { return c == BallContact::Hard ? "hard" : "none"; }

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
  if (!(p.ball_restitution >= 0 && p.ball_restitution <= 1))
    throw ConfigError(path + ".ball_restitution", num(p.ball_restitution), "must be in [0, 1]");
  for (std::size_t i = 0; i < p.balls.size(); ++i) {
    const std::string b = path + ".balls[" + std::to_string(i) + "]";
    require_positive(p.balls[i].mass_kg, b + ".mass_kg");
    require_positive(p.balls[i].diameter_m, b + ".diameter_m");
    if (p.balls[i].diameter_m >= p.ball_track_radius_m)
      throw ConfigError(b + ".diameter_m", num(p.balls[i].diameter_m),
                        "must be smaller than abu.ball_track_radius_m (" + num(p.ball_track_radius_m) + ")");
  }
  if (p.ball_contact == BallContact::Hard && p.balls.size() > 1) {
    // the balls must fit on the track side by side: sum of the neighbour spacings < 2 pi
    double need = 0;
    for (std::size_t i = 0; i < p.balls.size(); ++i) {
      const double s = (p.balls[i].diameter_m + p.balls[(i + 1) % p.balls.size()].diameter_m) /
                       (4.0 * p.ball_track_radius_m);
      need += 2.0 * std::asin(std::min(1.0, s));
    }
    if (!(need < 2.0 * M_PI))
      throw ConfigError(path + ".ball_contact", "hard",
                        "the " + std::to_string(p.balls.size()) + " balls do not fit side by side on the track (they need " +
                            num(need) + " rad of the 2 pi)");
  }
}

}  // namespace abuopt
