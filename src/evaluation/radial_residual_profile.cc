#include "src/evaluation/radial_residual_profile.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

namespace rig_calibrator {

RadialResidualProfile ComputeRadialResidualProfile(
    const Eigen::Vector2d& principal_point,
    const std::vector<Eigen::Vector2d>& observed,
    const std::vector<Eigen::Vector2d>& projected,
    const RadialResidualProfileOptions& options) {
  RadialResidualProfile profile;
  // (radius, radial residual) per usable observation.
  std::vector<std::pair<double, double>> samples;
  const size_t num = std::min(observed.size(), projected.size());
  samples.reserve(num);
  for (size_t k = 0; k < num; ++k) {
    const Eigen::Vector2d offset = observed[k] - principal_point;
    const double radius = offset.norm();
    const double radial = (observed[k] - projected[k]).dot(offset) / radius;
    if (!(radius > 1.0) || !std::isfinite(radius) || !std::isfinite(radial)) {
      continue;
    }
    samples.emplace_back(radius, radial);
  }
  profile.num_points = static_cast<int>(samples.size());
  const int num_rings =
      options.min_points_per_ring > 0
          ? std::min(options.max_num_rings,
                     profile.num_points / options.min_points_per_ring)
          : 0;
  if (num_rings < 2) return profile;
  profile.evaluated = true;
  std::sort(samples.begin(), samples.end());

  double worst_misfit_z = -1, worst_z = -1;
  int worst_misfit = -1, worst = -1;
  for (int r = 0; r < num_rings; ++r) {
    const size_t begin = samples.size() * r / num_rings;
    const size_t end = samples.size() * (r + 1) / num_rings;
    RadialResidualRing ring;
    ring.min_radius_px = samples[begin].first;
    ring.max_radius_px = samples[end - 1].first;
    ring.num_points = static_cast<int>(end - begin);
    double sum = 0;
    for (size_t k = begin; k < end; ++k) sum += samples[k].second;
    ring.mean_radial_px = sum / ring.num_points;
    double sum_squared_deviation = 0;
    for (size_t k = begin; k < end; ++k) {
      sum_squared_deviation +=
          std::pow(samples[k].second - ring.mean_radial_px, 2);
    }
    const double stddev =
        std::sqrt(sum_squared_deviation / (ring.num_points - 1));
    ring.standard_error_px = stddev / std::sqrt(ring.num_points);
    if (ring.standard_error_px > 0) {
      ring.z = ring.mean_radial_px / ring.standard_error_px;
    } else if (ring.mean_radial_px != 0) {
      ring.z = std::copysign(std::numeric_limits<double>::infinity(),
                             ring.mean_radial_px);
    }
    const bool misfit = std::abs(ring.mean_radial_px) >= options.min_bias_px &&
                        std::abs(ring.z) >= options.min_z;
    if (misfit && std::abs(ring.z) > worst_misfit_z) {
      worst_misfit_z = std::abs(ring.z);
      worst_misfit = r;
    }
    if (std::abs(ring.z) > worst_z) {
      worst_z = std::abs(ring.z);
      worst = r;
    }
    profile.rings.push_back(ring);
  }
  profile.systematic = worst_misfit >= 0;
  profile.worst_ring = profile.systematic ? worst_misfit : worst;
  return profile;
}

std::string DescribeRadialMisfit(const RadialResidualProfile& profile) {
  if (!profile.systematic) return "";
  const RadialResidualRing& ring = profile.rings[profile.worst_ring];
  std::ostringstream text;
  text.setf(std::ios::fixed);
  text.precision(0);
  text << "over radii " << ring.min_radius_px << "-" << ring.max_radius_px
       << " px its " << ring.num_points << " inliers sit ";
  text.precision(2);
  text << std::abs(ring.mean_radial_px) << " px "
       << (ring.mean_radial_px > 0 ? "outwards" : "inwards")
       << " of the model on average (";
  text.precision(0);
  text << std::abs(ring.z) << " standard errors)";
  return text.str();
}

}  // namespace rig_calibrator
