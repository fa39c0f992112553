#include "src/calibration/principal_axes.h"

#include <colmap/util/math.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <utility>

namespace rig_calibrator {
namespace {

// Per pair of cameras (lower index first), the angles of their principal
// axes from parallel in the framesets where both are localized, degrees.
std::map<std::pair<int, int>, std::vector<double>> AxisAnglesOfCameraPairs(
    const RigDataset& dataset, const RigCalibration& calibration) {
  std::map<int, std::vector<std::pair<int, Eigen::Vector3d>>> axes_of_frameset;
  const size_t num_images =
      std::min(dataset.images.size(), calibration.images.size());
  for (size_t k = 0; k < num_images; ++k) {
    const std::optional<Rigid3d>& pose =
        calibration.images[k].single_image_cam_from_world;
    if (!pose || !pose->rotation.coeffs().allFinite()) continue;
    axes_of_frameset[dataset.images[k].frameset_index].emplace_back(
        dataset.images[k].camera_index, PrincipalAxis(*pose));
  }
  std::map<std::pair<int, int>, std::vector<double>> angles_of_pair;
  for (const auto& [frameset, axes] : axes_of_frameset) {
    for (size_t a = 0; a < axes.size(); ++a) {
      for (size_t b = a + 1; b < axes.size(); ++b) {
        if (axes[a].first == axes[b].first) continue;
        angles_of_pair[std::minmax(axes[a].first, axes[b].first)].push_back(
            AxisAngleFromParallelDeg(axes[a].second, axes[b].second));
      }
    }
  }
  return angles_of_pair;
}

}  // namespace

Eigen::Vector3d PrincipalAxis(const Rigid3d& cam_from_x) {
  return cam_from_x.RotationMatrix().row(2).transpose();
}

double AxisAngleFromParallelDeg(const Eigen::Vector3d& a,
                                const Eigen::Vector3d& b) {
  return colmap::RadToDeg(std::acos(std::min(1.0, std::abs(a.dot(b)))));
}

double SmallestAxisEigenvalue(const std::vector<Eigen::Vector3d>& axes) {
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& axis : axes) {
    normal += Eigen::Matrix3d::Identity() - axis * axis.transpose();
  }
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(normal,
                                                        Eigen::EigenvaluesOnly)
      .eigenvalues()(0);
}

double AxisEigenvalueOfAngle(double min_angle_deg) {
  return 1.0 - std::cos(colmap::DegToRad(min_angle_deg));
}

bool AxesDetermineTranslation(const std::vector<Eigen::Vector3d>& axes,
                              double min_angle_deg) {
  return axes.size() >= 2 &&
         SmallestAxisEigenvalue(axes) >= AxisEigenvalueOfAngle(min_angle_deg);
}

bool PrincipalAxesAreParallel(const RigDataset& dataset,
                              const RigCalibration& calibration,
                              double max_angle_deg, std::string* explanation) {
  std::map<std::pair<int, int>, std::vector<double>> angles_of_pair =
      AxisAnglesOfCameraPairs(dataset, calibration);
  auto camera_name = [&](int index) {
    return index >= 0 && index < static_cast<int>(dataset.cameras.size())
               ? dataset.cameras[index].name
               : "#" + std::to_string(index);
  };
  std::ostringstream message;
  if (angles_of_pair.empty()) {
    message << "no frameset has two localized images of different cameras: "
               "the principal axes cannot be compared";
    if (explanation) *explanation = message.str();
    return false;
  }
  double widest_angle = -1;
  std::pair<int, int> widest_pair;
  int widest_count = 0;
  for (auto& [pair, angles] : angles_of_pair) {
    const double median = colmap::Median(angles);
    if (median > widest_angle) {
      widest_angle = median;
      widest_pair = pair;
      widest_count = angles.size();
    }
  }
  const bool parallel = widest_angle <= max_angle_deg;
  if (parallel) {
    message << "all principal axes are within " << max_angle_deg
            << " degrees of parallel or anti-parallel";
  } else {
    message << "the principal axes are not parallel";
  }
  message << " (largest median angle from parallel " << widest_angle
          << " degrees, between " << camera_name(widest_pair.first) << " and "
          << camera_name(widest_pair.second) << " over " << widest_count
          << " framesets)";
  if (explanation) *explanation = message.str();
  return parallel;
}

void NormalizeRadialRigOrigin(int reference_camera,
                              RigCalibration* calibration) {
  double numerator = 0;
  double denominator = 0;
  for (size_t i = 0; i < calibration->cam_from_rig.size(); ++i) {
    if (static_cast<int>(i) == reference_camera ||
        i >= calibration->camera_calibrated.size() ||
        !calibration->camera_calibrated[i]) {
      continue;
    }
    const Rigid3d& cam_from_rig = calibration->cam_from_rig[i];
    const Eigen::Vector2d axis_xy =
        cam_from_rig.RotationMatrix().col(2).head<2>();
    numerator += axis_xy.dot(cam_from_rig.translation.head<2>());
    denominator += axis_xy.squaredNorm();
  }
  // All parallel: the slide is undetermined and changes nothing.
  const double slide = denominator > 1e-12 ? -numerator / denominator : 0.0;
  for (Rigid3d& cam_from_rig : calibration->cam_from_rig) {
    cam_from_rig.translation += slide * cam_from_rig.RotationMatrix().col(2);
    cam_from_rig.translation.z() = 0;
  }
  for (std::optional<Rigid3d>& rig_from_world : calibration->rig_from_world) {
    if (rig_from_world) rig_from_world->translation.z() -= slide;
  }
}

}  // namespace rig_calibrator
