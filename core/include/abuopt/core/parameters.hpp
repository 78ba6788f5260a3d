#pragma once
// Physical parameters of an ABU (SI units), defaults from the 2003 report's table 3.2 with the
// design friction mu = 0.02 (report section 4.2). Any number of balls, each its own mass/diameter.
#include <cmath>
#include <string>
#include <vector>

namespace abuopt {

struct Ball {
  double mass_kg = 1.4e-4;
  double diameter_m = 3.0e-3;
};

// Ball-ball contact along the rim (docs/model.md section 11). None: the report's model, the balls
// pass through each other. Hard: neighbouring balls keep their centres at least
// 2 asin((d_i + d_j) / 4L) apart; impacts with restitution, touching balls move as clusters.
enum class BallContact { None, Hard };
std::string to_string(BallContact c);

// Upper limits of the physical parameters a config may give (docs/config.md, "Limits"): orders of
// magnitude beyond any balancing unit, so that no product of the model's quantities overflows a
// double (an amplitude of 1e308 m is not a result).
struct AbuLimits {
  static constexpr double kMassKg = 1e4;             // table, each ball, the imbalance mass
  static constexpr double kLengthM = 10.0;           // track radius, eccentricity, ball diameter
  static constexpr double kStiffnessNPerM = 1e9;
  static constexpr double kDampingNsPerM = 1e6;
  static constexpr double kBallDampingNms = 1e3;
};

struct AbuParameters {
  double table_mass_kg = 3.24e-1;        // M_T: table + motor + disc + CD (no imbalance, no balls)
  double damping_Ns_per_m = 1.28;        // b
  double stiffness_N_per_m = 1.07e4;     // k
  double ball_track_radius_m = 1.15e-2;  // L: radius of the ball centres
  double imbalance_mass_kg = 5.6e-4;     // m_I
  double eccentricity_m = 3.7e-3;        // e
  double friction_mu = 0.02;             // Coulomb coefficient (design value of the report)
  // Optional viscous damping of each ball relative to the rim, as a torque per angular speed
  // [N m s/rad] about the disc centre. Zero for dry ABUs; fluid-filled ABUs have some.
  double ball_damping_Nms = 0.0;
  BallContact ball_contact = BallContact::None;
  // Newton's coefficient of restitution of a ball-ball impact (hard contact). 0.8: hardened
  // steel balls at impact speeds below ~1 m/s rebound with 0.8-0.95 (Goldsmith, Impact, 1960);
  // the lower end because the balls roll in a track and the rim contact dissipates too.
  double ball_restitution = 0.8;
  std::vector<Ball> balls = {Ball{}, Ball{}};

  double total_mass_kg() const {
    double m = table_mass_kg + imbalance_mass_kg;
    for (const auto& b : balls) m += b.mass_kg;
    return m;
  }
  double natural_frequency_rad_s() const { return std::sqrt(stiffness_N_per_m / total_mass_kg()); }
  double natural_frequency_hz() const { return natural_frequency_rad_s() / (2.0 * M_PI); }
  // I = m_I e: the imbalance without balls [kg m] (report eq 4.1).
  double imbalance_kgm() const { return imbalance_mass_kg * eccentricity_m; }
};

// Throws ConfigError (path prefix `path`) when a value is out of its physical range.
void validate(const AbuParameters& p, const char* path = "abu");

}  // namespace abuopt
