// The arc-length parameterized ellipse of the rendered rig's walk: its
// perimeter, its arc length against a direct integration, its derivative
// and its laps.
#include "src/synthetic/ground_loop.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rig_calibrator {
namespace ground_loop_test {

// The arc length from `from` to `to` (to >= from) by the sum of 200 000
// chords: exact to about 1e-10 relative for these ellipses.
double ChordLength(const GroundLoop& loop, double from, double to) {
  constexpr int kChords = 200000;
  double length = 0;
  Eigen::Vector2d previous = loop.PointAt(from);
  for (int i = 1; i <= kChords; ++i) {
    const Eigen::Vector2d point = loop.PointAt(from + (to - from) * i / kChords);
    length += (point - previous).norm();
    previous = point;
  }
  return length;
}

TEST(GroundLoop, CirclePerimeterAndAngleAreExact) {
  const GroundLoop circle(Eigen::Vector2d(1, -2), Eigen::Vector2d(3, 3), 0.7);
  EXPECT_NEAR(circle.Perimeter(), 6 * M_PI, 1e-11);  // 4096 sums rounded
  EXPECT_DOUBLE_EQ(circle.MaxAngleRatePerMeter(), 1.0 / 3);
  for (double s = -20; s < 40; s += 1.3) {
    double rate = 0;
    EXPECT_NEAR(circle.AngleAt(s, &rate), 0.7 + s / 3, 1e-12) << s;
    EXPECT_NEAR(rate, 1.0 / 3, 1e-12) << s;
  }
  EXPECT_NEAR((circle.PointAt(0.7) - Eigen::Vector2d(1 + 3 * std::cos(0.7),
                                                     -2 + 3 * std::sin(0.7)))
                  .norm(),
              0, 1e-15);
}

// A thin ellipse (the street's proportions): the arc length to AngleAt(s)
// is s, the rate is the derivative of the angle (central differences) and
// 1 / |p'(phi)|, and a lap adds 2 pi.
TEST(GroundLoop, ArcLengthInvertsOnAThinEllipse) {
  const GroundLoop loop(Eigen::Vector2d(0.5, 0), Eigen::Vector2d(7.8, 1.17),
                        2.0);
  EXPECT_NEAR(loop.Perimeter(), ChordLength(loop, 2.0, 2.0 + 2 * M_PI),
              1e-8 * loop.Perimeter());
  for (double s = 0.01; s < loop.Perimeter(); s += 1.7) {
    double rate = 0;
    const double angle = loop.AngleAt(s, &rate);
    EXPECT_NEAR(ChordLength(loop, 2.0, angle), s, 1e-8 * loop.Perimeter())
        << s;
    constexpr double h = 1e-5;
    double unused = 0;
    const double difference =
        (loop.AngleAt(s + h, &unused) - loop.AngleAt(s - h, &unused)) /
        (2 * h);
    EXPECT_NEAR(rate, difference, 1e-7) << s;
    EXPECT_NEAR(rate, 1 / loop.TangentAt(angle).norm(), 1e-8) << s;
    EXPECT_LE(rate, loop.MaxAngleRatePerMeter() * (1 + 1e-9));
    double lap_rate = 0;
    EXPECT_NEAR(loop.AngleAt(s + 2 * loop.Perimeter(), &lap_rate),
                angle + 4 * M_PI, 1e-9);
    EXPECT_NEAR(loop.AngleAt(s - loop.Perimeter(), &lap_rate),
                angle - 2 * M_PI, 1e-9);
  }
}

}  // namespace ground_loop_test
}  // namespace rig_calibrator
