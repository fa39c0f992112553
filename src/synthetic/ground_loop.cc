#include "src/synthetic/ground_loop.h"

#include <algorithm>
#include <cmath>

namespace rig_calibrator {
namespace {

// 5-point Gauss-Legendre on [-1, 1]: nodes and weights.
constexpr double kNodes[5] = {-0.9061798459386640, -0.5384693101056831, 0.0,
                              0.5384693101056831, 0.9061798459386640};
constexpr double kWeights[5] = {0.2369268850561891, 0.4786286704993665,
                                0.5688888888888889, 0.4786286704993665,
                                0.2369268850561891};

}  // namespace

GroundLoop::GroundLoop(const Eigen::Vector2d& center,
                       const Eigen::Vector2d& radii, double start_angle)
    : center_(center), radii_(radii), start_angle_(start_angle) {
  const double step = 2 * M_PI / kKnots;
  knot_lengths_.assign(kKnots + 1, 0.0);
  for (int k = 0; k < kKnots; ++k) {
    const double middle = start_angle_ + (k + 0.5) * step;
    double length = 0;
    for (int i = 0; i < 5; ++i) {
      length += kWeights[i] * TangentAt(middle + 0.5 * step * kNodes[i]).norm();
    }
    knot_lengths_[k + 1] = knot_lengths_[k] + 0.5 * step * length;
  }
}

Eigen::Vector2d GroundLoop::PointAt(double angle) const {
  return center_ + Eigen::Vector2d(radii_.x() * std::cos(angle),
                                   radii_.y() * std::sin(angle));
}

Eigen::Vector2d GroundLoop::TangentAt(double angle) const {
  return Eigen::Vector2d(-radii_.x() * std::sin(angle),
                         radii_.y() * std::cos(angle));
}

double GroundLoop::AngleAt(double arc_length, double* angle_rate_per_m) const {
  const double perimeter = Perimeter();
  const double laps = std::floor(arc_length / perimeter);
  const double s = std::clamp(arc_length - laps * perimeter, 0.0, perimeter);
  const int k = std::clamp(
      static_cast<int>(std::upper_bound(knot_lengths_.begin(),
                                        knot_lengths_.end(), s) -
                       knot_lengths_.begin()) -
          1,
      0, kKnots - 1);
  const double step = 2 * M_PI / kKnots;
  const double angle0 = start_angle_ + k * step;
  const double angle1 = angle0 + step;
  // Cubic Hermite in s on [S_k, S_k+1] with the slopes 1 / |p'(phi)|.
  const double h = knot_lengths_[k + 1] - knot_lengths_[k];
  const double slope0 = h / TangentAt(angle0).norm();
  const double slope1 = h / TangentAt(angle1).norm();
  const double u = (s - knot_lengths_[k]) / h;
  const double u2 = u * u, u3 = u2 * u;
  *angle_rate_per_m = ((6 * u2 - 6 * u) * angle0 +
                       (3 * u2 - 4 * u + 1) * slope0 +
                       (-6 * u2 + 6 * u) * angle1 + (3 * u2 - 2 * u) * slope1) /
                      h;
  return 2 * M_PI * laps + (2 * u3 - 3 * u2 + 1) * angle0 +
         (u3 - 2 * u2 + u) * slope0 + (-2 * u3 + 3 * u2) * angle1 +
         (u3 - u2) * slope1;
}

}  // namespace rig_calibrator
