#include "src/calibration/radial_residual_profile.h"

#include <algorithm>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <limits>
#include <sstream>
#include <unordered_map>
#include <utility>

namespace rig_calibrator {

double StudentThresholdLikeNormal(const double normal_z,
                                  const int degrees_of_freedom) {
  if (degrees_of_freedom < 1) return std::numeric_limits<double>::infinity();
  const double tail =
      boost::math::cdf(boost::math::complement(
          boost::math::normal_distribution<double>(), normal_z));
  return boost::math::quantile(boost::math::complement(
      boost::math::students_t_distribution<double>(degrees_of_freedom),
      tail));
}

RadialResidualProfile ComputeRadialResidualProfile(
    const Eigen::Vector2d& principal_point,
    const std::vector<Eigen::Vector2d>& observed,
    const std::vector<Eigen::Vector2d>& projected,
    const std::vector<int>& groups,
    const RadialResidualProfileOptions& options) {
  RadialResidualProfile profile;
  struct Sample {
    double radius, radial;
    int group;
    bool operator<(const Sample& other) const {
      return radius < other.radius ||
             (radius == other.radius && radial < other.radial);
    }
  };
  std::vector<Sample> samples;
  const size_t num = std::min(observed.size(), projected.size());
  samples.reserve(num);
  for (size_t k = 0; k < num; ++k) {
    const Eigen::Vector2d offset = observed[k] - principal_point;
    const double radius = offset.norm();
    const double radial = (observed[k] - projected[k]).dot(offset) / radius;
    if (!(radius > 1.0) || !std::isfinite(radius) || !std::isfinite(radial)) {
      continue;
    }
    samples.push_back({radius, radial,
                       k < groups.size() ? groups[k] : -1 - static_cast<int>(k)});
  }
  profile.num_points = static_cast<int>(samples.size());
  profile.systematic_floor_px = options.systematic_floor_px;
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
    ring.min_radius_px = samples[begin].radius;
    ring.max_radius_px = samples[end - 1].radius;
    ring.num_points = static_cast<int>(end - begin);
    double sum = 0;
    for (size_t k = begin; k < end; ++k) sum += samples[k].radial;
    ring.mean_radial_px = sum / ring.num_points;
    // Per group, the sum of its deviations from the ring's mean (the order
    // of first appearance keeps the sum's rounding independent of hashing).
    std::unordered_map<int, size_t> group_slot;
    std::vector<double> group_sums;
    for (size_t k = begin; k < end; ++k) {
      const auto [it, inserted] =
          group_slot.emplace(samples[k].group, group_sums.size());
      if (inserted) group_sums.push_back(0);
      group_sums[it->second] += samples[k].radial - ring.mean_radial_px;
    }
    ring.num_groups = static_cast<int>(group_sums.size());
    double sum_squared = 0;
    for (const double group_sum : group_sums) sum_squared += group_sum * group_sum;
    ring.standard_error_px =
        ring.num_groups > 1
            ? std::sqrt(sum_squared * ring.num_groups / (ring.num_groups - 1)) /
                  ring.num_points
            : std::numeric_limits<double>::infinity();
    ring.z_threshold =
        StudentThresholdLikeNormal(options.min_z, ring.num_groups - 1);
    if (!std::isfinite(ring.standard_error_px)) {
      ring.z = 0;  // one image: no spread to compare with
    } else if (ring.standard_error_px > 0) {
      ring.z = ring.mean_radial_px / ring.standard_error_px;
    } else if (ring.mean_radial_px != 0) {
      ring.z = std::copysign(std::numeric_limits<double>::infinity(),
                             ring.mean_radial_px);
    }
    const double excess =
        std::abs(ring.mean_radial_px) - options.systematic_floor_px;
    const bool misfit =
        std::abs(ring.mean_radial_px) >= options.min_bias_px &&
        std::abs(ring.z) >= ring.z_threshold &&
        (options.systematic_floor_px <= 0 ||
         (excess > 0 && excess >= ring.z_threshold * ring.standard_error_px));
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
