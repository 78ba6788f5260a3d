#pragma once
// Physical parameters of an ABU (SI units), defaults from the 2003 report's table 3.2 with the
// design friction mu = 0.02 (report section 4.2). Any number of balls, each its own mass/diameter.
#include <cmath>
#include <vector>

namespace abuopt {

struct Ball {
  double mass_kg = 1.4e-4;
  double diameter_m = 3.0e-3;
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
