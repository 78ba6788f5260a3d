#pragma once
// Startup profiles: a sequence of "inclined sine" segments (report section 4.1.3). A segment of
// height H = f_end - f0 [Hz] and duration dt [s], starting at t0 from f0:
//   f(t)  = f0 + H (t - t0)/dt - H/(2 pi) sin(2 pi (t - t0)/dt)
//         = f0 + H/(2 pi) (phi - sin phi),                 phi = 2 pi (t - t0)/dt
//   f'(t) = H/dt (1 - cos phi) = 2 H/dt sin^2(phi/2)
//   f''(t)= 2 pi H/dt^2 sin phi
// phi - sin phi is evaluated with a series for small phi: near a segment start f - f0 grows like
// phi^3, and the naive difference rounds to zero (a model at rest would then stay at rest).
// After the last segment the speed is held at its final value.
#include <vector>

namespace abuopt {

// The largest rotor frequency and segment duration a config may ask for: far beyond any ABU (CD
// drives turn at up to ~200 Hz, hand tools ~1 kHz), small enough that no product of the model's
// quantities overflows a double (docs/config.md, "Limits").
inline constexpr double kMaxFrequencyHz = 1e4;
inline constexpr double kMaxSegmentDurationS = 1e5;

struct InclinedSineSegment {
  double end_frequency_hz = 0.0;
  double duration_s = 1.0;
};

struct ProfileSample {
  double frequency_hz = 0;       // f
  double rate_hz_per_s = 0;      // f'
  double accel_hz_per_s2 = 0;    // f''
};

class StartupProfile {
 public:
  StartupProfile() = default;
  explicit StartupProfile(std::vector<InclinedSineSegment> segments, double start_frequency_hz = 0.0);

  // The report's final design: 0 -> 25 Hz in 1 s, 25 -> 29.5 Hz in 10 s, 29.5 -> 100 Hz in 8 s.
  static StartupProfile report_final();

  ProfileSample sample(double t_s) const { return sample(t_s, nullptr); }
  // The same, and the revolutions (below) into *revolutions when given, from the same sine.
  ProfileSample sample(double t_s, double* revolutions) const;
  // Turns of the disc since t = 0: the integral of f from 0 to t_s, in closed form per segment
  //   int_0^tau f = f0 tau + H tau^2/(2 dt) - H dt/(2 pi^2) sin^2(pi tau/dt),
  // and f_final (t_s - duration) after the profile (the phase of the disc: 2 pi revolutions).
  double revolutions(double t_s) const;
  double frequency_hz(double t_s) const { return sample(t_s).frequency_hz; }
  double duration_s() const { return duration_s_; }
  double start_frequency_hz() const { return start_hz_; }
  double final_frequency_hz() const;
  const std::vector<InclinedSineSegment>& segments() const { return segments_; }
  // Start times of each segment, plus the end time (size segments()+1).
  const std::vector<double>& breakpoints_s() const { return breaks_; }
  // The time in segment k where f(t) = level, for a level strictly between the segment's end
  // frequencies (f is strictly monotone inside a rising or falling segment): phi - sin phi =
  // 2 pi (level - f0)/H solved by bisection to rounding. std::invalid_argument otherwise.
  double crossing_time_s(std::size_t k, double level_hz) const;

 private:
  std::vector<InclinedSineSegment> segments_;
  std::vector<double> breaks_{0.0};
  std::vector<double> revs_{0.0};  // revolutions at each breakpoint
  double start_hz_ = 0.0;
  double duration_s_ = 0.0;
};

// Throws ConfigError (path e.g. "profile") when a segment duration is not > 0 or a value is not
// finite.
void validate(const StartupProfile& p, const char* path = "profile");

}  // namespace abuopt
