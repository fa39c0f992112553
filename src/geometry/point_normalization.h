// Conditioning of 3D point sets for the linear solvers: center and scale.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <vector>

namespace rig_calibrator {

// Centers and scales world points: X_n = (X - c) / s, with c the centroid
// and s the RMS distance from it, so the X_n have unit RMS radius. A pose maps
// as R X + t = s (R X_n + t_n), t_n = (t + R c) / s. Returns false, leaving
// *normalized unspecified, for an empty set, coincident points (a spread at
// rounding level of the coordinates: s <= 1e-12 |c|) or non-finite points.
inline bool CenterAndScalePoints(const std::vector<Eigen::Vector3d>& points,
                                 std::vector<Eigen::Vector3d>* normalized,
                                 Eigen::Vector3d* centroid, double* scale) {
  if (points.empty()) return false;
  *centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& X : points) *centroid += X;
  *centroid /= points.size();
  double mean_sq_radius = 0;
  for (const Eigen::Vector3d& X : points) {
    mean_sq_radius += (X - *centroid).squaredNorm();
  }
  *scale = std::sqrt(mean_sq_radius / points.size());
  if (!(*scale > 1e-12 * centroid->norm()) || !(*scale > 0) ||
      !std::isfinite(*scale)) {
    return false;
  }
  normalized->resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    (*normalized)[i] = (points[i] - *centroid) / *scale;
  }
  return true;
}

}  // namespace rig_calibrator
