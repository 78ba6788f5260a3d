#include "abuopt/core/profile.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "abuopt/common/config_error.hpp"

using abuopt::StartupProfile;

TEST(StartupProfile, ReportFinalProfileHitsItsCornerFrequencies) {
  const StartupProfile p = StartupProfile::report_final();
  EXPECT_DOUBLE_EQ(p.duration_s(), 19.0);
  EXPECT_DOUBLE_EQ(p.frequency_hz(0.0), 0.0);
  EXPECT_NEAR(p.frequency_hz(1.0), 25.0, 1e-12);
  EXPECT_NEAR(p.frequency_hz(11.0), 29.5, 1e-12);
  EXPECT_NEAR(p.frequency_hz(19.0), 100.0, 1e-12);
  EXPECT_DOUBLE_EQ(p.frequency_hz(30.0), 100.0);  // held after the last segment
  // zero slope at every corner
  for (double t : {1.0, 11.0, 19.0}) {
    EXPECT_NEAR(p.sample(t - 1e-9).rate_hz_per_s, 0.0, 1e-6);
    EXPECT_NEAR(p.sample(t + 1e-9).rate_hz_per_s, 0.0, 1e-6);
  }
  // mid-segment: f = f0 + H/2, f' = 2 H / dt (the inclined sine's steepest point)
  EXPECT_NEAR(p.frequency_hz(6.0), 25.0 + 4.5 / 2, 1e-12);
  EXPECT_NEAR(p.sample(6.0).rate_hz_per_s, 2 * 4.5 / 10, 1e-12);
}

TEST(StartupProfile, KeepsPrecisionNearSegmentStart) {
  // f - f0 = H/(2 pi) (phi - sin phi) ~ H phi^3 / (12 pi): the naive difference would be 0 here.
  const StartupProfile p({{25.0, 1.0}});
  for (double t : {1e-7, 1e-5, 1e-3}) {
    const double phi = 2 * M_PI * t;
    const long double ph = phi;  // series to phi^9: exact to long double precision here
    const long double exact = 25.0L / (2 * M_PI) * (std::pow(ph, 3) / 6 - std::pow(ph, 5) / 120 + std::pow(ph, 7) / 5040 - std::pow(ph, 9) / 362880);
    EXPECT_NEAR(p.frequency_hz(t) / static_cast<double>(exact), 1.0, 1e-12) << "t = " << t;
  }
  EXPECT_GT(p.frequency_hz(1e-9), 0.0);
}

TEST(StartupProfile, DerivativesMatchFiniteDifferences) {
  const StartupProfile p = StartupProfile::report_final();
  for (double t : {0.3, 2.7, 9.9, 14.2}) {
    const double h = 1e-6;
    const double fd1 = (p.frequency_hz(t + h) - p.frequency_hz(t - h)) / (2 * h);
    const double fd2 = (p.sample(t + h).rate_hz_per_s - p.sample(t - h).rate_hz_per_s) / (2 * h);
    EXPECT_NEAR(p.sample(t).rate_hz_per_s, fd1, 1e-6 * (1 + std::fabs(fd1)));
    EXPECT_NEAR(p.sample(t).accel_hz_per_s2, fd2, 1e-5 * (1 + std::fabs(fd2)));
  }
}

TEST(StartupProfile, ValidationNamesTheSegment) {
  StartupProfile bad({{25.0, 1.0}, {30.0, -2.0}});
  try {
    validate(bad);
    FAIL() << "no error";
  } catch (const abuopt::ConfigError& e) {
    EXPECT_STREQ(e.what(), "profile.segments[1].duration_s = -2: must be > 0");
  }
}

// The disc's turns: the integral of f. Whole segments are trapezoids (the sine term integrates to
// zero over a period); inside a segment the derivative is f; after the profile f_final t.
TEST(StartupProfile, RevolutionsIntegrateTheFrequency) {
  const StartupProfile p = StartupProfile::report_final();
  EXPECT_DOUBLE_EQ(p.revolutions(0.0), 0.0);
  EXPECT_NEAR(p.revolutions(1.0), 12.5, 1e-12);
  EXPECT_NEAR(p.revolutions(11.0), 12.5 + 272.5, 1e-11);
  EXPECT_NEAR(p.revolutions(19.0), 12.5 + 272.5 + 518.0, 1e-10);
  EXPECT_NEAR(p.revolutions(21.0), 803.0 + 200.0, 1e-10);
  for (double t : {0.3, 0.9999, 1.0001, 2.7, 9.9, 14.2, 18.9999}) {
    const double h = 1e-5;
    const double fd = (p.revolutions(t + h) - p.revolutions(t - h)) / (2 * h);
    EXPECT_NEAR(fd, p.frequency_hz(t), 1e-7 * (1 + p.frequency_hz(t))) << t;
  }
  // Simpson on a segment against the closed form
  const int n = 2000;
  double s = 0;
  for (int i = 0; i <= n; ++i) s += (i == 0 || i == n ? 1 : (i % 2 ? 4 : 2)) * p.frequency_hz(11.0 + 3.3 * i / n);
  EXPECT_NEAR(s * 3.3 / n / 3, p.revolutions(14.3) - p.revolutions(11.0), 1e-9);
}
