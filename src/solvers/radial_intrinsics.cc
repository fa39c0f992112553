#include "src/solvers/radial_intrinsics.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rig_calibrator {

double RadialIntrinsics::DistortedRadius(const double q) const {
  const double phi = profile == RadialProfile::kPolynomial ? q : std::atan(q);
  const double phi2 = phi * phi;
  return focal * phi * (1 + k[0] * phi2 + k[1] * phi2 * phi2);
}

bool RadialIntrinsics::Project(const Eigen::Vector3d& point_cam,
                               Eigen::Vector2d* x) const {
  const double depth = point_cam.z() + tz;
  if (!(depth > 0)) {
    return false;
  }
  // x = r_d(q) (a, b) / |(a, b)| with q = |(a, b)| / depth, written as
  // (r_d(q) / q) (a, b) / depth so that it stays finite on the optical axis,
  // where r_d(q) / q -> f.
  const double q = point_cam.head<2>().norm() / depth;
  const double radius_over_q = q > std::numeric_limits<double>::epsilon()
                                   ? DistortedRadius(q) / q
                                   : focal;
  *x = radius_over_q / depth * point_cam.head<2>();
  return true;
}

double SignedRadialCoordinate(const Eigen::Vector2d& x,
                              const Eigen::Vector3d& point_cam) {
  const double rho = x.norm();
  return rho > 0 ? x.dot(point_cam.head<2>()) / rho : 0.0;
}

double ProfileAngle(const RadialProfile profile, const double s,
                    const double depth) {
  return profile == RadialProfile::kPolynomial ? s / depth
                                               : std::atan2(s, depth);
}

bool RadiusGrowsOverPoints(const std::vector<Eigen::Vector2d>& x,
                           const std::vector<Eigen::Vector3d>& points_cam,
                           const RadialIntrinsics& model) {
  double max_phi = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    const double s = std::abs(SignedRadialCoordinate(x[i], points_cam[i]));
    max_phi = std::max(
        max_phi, ProfileAngle(model.profile, s, points_cam[i].z() + model.tz));
  }
  // g(t) = 1 + 3 k1 t + 5 k2 t^2 on t = phi^2 in [0, max_phi^2]: its minimum
  // is at an end or at the vertex.
  const double t_max = max_phi * max_phi;
  const auto g = [&](double t) {
    return 1 + 3 * model.k[0] * t + 5 * model.k[1] * t * t;
  };
  double min_g = std::min(g(0), g(t_max));
  if (model.k[1] != 0) {
    const double vertex = -3 * model.k[0] / (10 * model.k[1]);
    if (vertex > 0 && vertex < t_max) min_g = std::min(min_g, g(vertex));
  }
  return model.focal > 0 && min_g > 0;
}

}  // namespace rig_calibrator
