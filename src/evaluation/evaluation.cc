#include "src/evaluation/evaluation.h"

#include <colmap/base/camera_models.h>
#include <glog/logging.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace rig_calibrator {
namespace {

// Reprojection residual (px) up to which an unprojected ray is accepted.
constexpr double kMaxUnprojectionResidualPx = 1e-6;

Eigen::Vector2d Project(const colmap::Camera& camera,
                        const Eigen::Vector2d& normalized) {
  Eigen::Vector2d xy;
  colmap::CameraModelWorldToImage(camera.ModelId(), camera.Params(),
                                  normalized.x(), normalized.y(), &xy.x(),
                                  &xy.y());
  return xy;
}

// d pixel / d (u, v) by central differences.
Eigen::Matrix2d ProjectionJacobian(const colmap::Camera& camera,
                                   const Eigen::Vector2d& normalized) {
  const double step = 1e-7 * std::max(1.0, normalized.norm());
  Eigen::Matrix2d jacobian;
  for (int k = 0; k < 2; ++k) {
    Eigen::Vector2d delta = Eigen::Vector2d::Zero();
    delta(k) = step;
    jacobian.col(k) = (Project(camera, normalized + delta) -
                       Project(camera, normalized - delta)) /
                      (2 * step);
  }
  return jacobian;
}

// A ray is inside a model's valid field of view where the projection is
// finite and locally orientation-preserving (beyond the turning point of a
// radial polynomial the mapping folds back and its determinant changes sign).
bool IsValidProjection(const colmap::Camera& camera,
                       const Eigen::Vector2d& normalized, Eigen::Vector2d* xy) {
  *xy = Project(camera, normalized);
  return xy->allFinite() &&
         ProjectionJacobian(camera, normalized).determinant() > 0;
}

bool IsUsableCamera(const colmap::Camera& camera, std::string* why) {
  if (!colmap::ExistsCameraModelWithId(camera.ModelId())) {
    *why = "unknown camera model id " + std::to_string(camera.ModelId());
    return false;
  }
  if (!camera.VerifyParams()) {
    *why = camera.ModelName() + " needs " +
           std::to_string(colmap::CameraModelNumParams(camera.ModelId())) +
           " parameters, has " + std::to_string(camera.NumParams());
    return false;
  }
  if (camera.Width() == 0 || camera.Height() == 0) {
    *why = "image size is zero";
    return false;
  }
  for (const double param : camera.Params()) {
    if (!std::isfinite(param)) {
      *why = "non-finite parameter";
      return false;
    }
  }
  return true;
}

double FocalErrorPercent(const colmap::Camera& reference,
                         const colmap::Camera& estimate) {
  const std::vector<size_t>& reference_idxs = reference.FocalLengthIdxs();
  const std::vector<size_t>& estimate_idxs = estimate.FocalLengthIdxs();
  if (reference_idxs.size() == 2 && estimate_idxs.size() == 2) {
    double sum = 0;
    for (int k = 0; k < 2; ++k) {
      const double f_ref = reference.Params()[reference_idxs[k]];
      const double f_est = estimate.Params()[estimate_idxs[k]];
      sum += std::abs(f_est - f_ref) / f_ref;
    }
    return 50.0 * sum;
  }
  const double f_ref = reference.MeanFocalLength();
  return std::abs(estimate.MeanFocalLength() - f_ref) / f_ref * 100.0;
}

// The scale s of x_ref - o_ref ~ s R (x_est - o_est) over camera centers
// about the origins o: least squares for >= 3 centers, the ratio of the
// baseline lengths for 2. Falls back to 1 when undefined.
double AlignmentScale(const std::vector<Eigen::Vector3d>& reference_centers,
                      const Eigen::Vector3d& reference_origin,
                      const std::vector<Eigen::Vector3d>& estimated_centers,
                      const Eigen::Vector3d& estimated_origin,
                      const Eigen::Matrix3d& rotation) {
  const int num_cameras = reference_centers.size();
  double numerator = 0, denominator = 0;
  for (int i = 0; i < num_cameras; ++i) {
    const Eigen::Vector3d reference = reference_centers[i] - reference_origin;
    const Eigen::Vector3d estimated =
        rotation * (estimated_centers[i] - estimated_origin);
    if (num_cameras == 2) {
      numerator += reference.norm();
      denominator += estimated.norm();
    } else {
      numerator += reference.dot(estimated);
      denominator += estimated.squaredNorm();
    }
  }
  const double scale = numerator / denominator;
  if (num_cameras < 2 || !std::isfinite(scale) || scale <= 0) {
    LOG_IF(WARNING, num_cameras >= 2)
        << "Cannot determine the alignment scale from the camera centers; "
           "using 1";
    return 1.0;
  }
  return scale;
}

Eigen::Vector3d Mean(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& point : points) {
    sum += point;
  }
  return sum / points.size();
}

double MaxOf(const std::vector<CameraError>& cameras,
             double CameraError::*field) {
  double max_value = 0;
  for (const CameraError& camera : cameras) {
    max_value = std::max(max_value, camera.*field);
  }
  return max_value;
}

std::string CameraName(const std::vector<std::string>& names, size_t i) {
  return i < names.size() ? names[i] : "cam" + std::to_string(i);
}

}  // namespace

double CalibrationError::MaxRotationDeg() const {
  return MaxOf(cameras, &CameraError::rotation_deg);
}
double CalibrationError::MaxCenterError() const {
  return MaxOf(cameras, &CameraError::center_error);
}
double CalibrationError::MaxFocalErrorPercent() const {
  return MaxOf(cameras, &CameraError::focal_error_percent);
}
double CalibrationError::MaxPrincipalPointErrorPx() const {
  return MaxOf(cameras, &CameraError::principal_point_error_px);
}
double CalibrationError::MaxProjectionDiffPx() const {
  return MaxOf(cameras, &CameraError::max_projection_diff_px);
}

bool UnprojectPixel(const colmap::Camera& camera, const Eigen::Vector2d& pixel,
                    Eigen::Vector2d* normalized) {
  colmap::CameraModelImageToWorld(camera.ModelId(), camera.Params(), pixel.x(),
                                  pixel.y(), &normalized->x(),
                                  &normalized->y());
  if (!normalized->allFinite()) {
    return false;
  }
  // COLMAP's iterative undistortion stops at steps below 1e-5; Newton on
  // project(u, v) = pixel brings the residual to rounding level.
  for (int iteration = 0; iteration < 5; ++iteration) {
    const Eigen::Vector2d residual = Project(camera, *normalized) - pixel;
    if (!residual.allFinite() || residual.norm() < 1e-12) {
      break;
    }
    const Eigen::Matrix2d jacobian = ProjectionJacobian(camera, *normalized);
    if (!(std::abs(jacobian.determinant()) > 0)) {
      break;
    }
    *normalized -= jacobian.inverse() * residual;
  }
  Eigen::Vector2d xy;
  return normalized->allFinite() &&
         IsValidProjection(camera, *normalized, &xy) &&
         (xy - pixel).norm() < kMaxUnprojectionResidualPx;
}

void CompareProjections(const colmap::Camera& reference,
                        const colmap::Camera& estimate, int grid_cols,
                        int grid_rows, CameraError* error) {
  error->mean_projection_diff_px = 0;
  error->max_projection_diff_px = 0;
  error->num_projection_samples = 0;
  error->num_projection_skipped = 0;
  double sum = 0;
  for (int row = 0; row < grid_rows; ++row) {
    for (int col = 0; col < grid_cols; ++col) {
      const Eigen::Vector2d pixel((col + 0.5) * reference.Width() / grid_cols,
                                  (row + 0.5) * reference.Height() / grid_rows);
      Eigen::Vector2d normalized, estimated_pixel;
      if (!UnprojectPixel(reference, pixel, &normalized) ||
          !IsValidProjection(estimate, normalized, &estimated_pixel)) {
        ++error->num_projection_skipped;
        continue;
      }
      const double difference = (estimated_pixel - pixel).norm();
      sum += difference;
      error->max_projection_diff_px =
          std::max(error->max_projection_diff_px, difference);
      ++error->num_projection_samples;
    }
  }
  if (error->num_projection_samples > 0) {
    error->mean_projection_diff_px = sum / error->num_projection_samples;
  }
}

CalibrationError CompareCalibrations(
    const std::vector<colmap::Camera>& reference_cameras,
    const std::vector<Rigid3d>& reference_cam_from_rig,
    const std::vector<colmap::Camera>& estimated_cameras,
    const std::vector<Rigid3d>& estimated_cam_from_rig,
    const CompareOptions& options) {
  CalibrationError result;
  const int num_cameras = reference_cameras.size();
  std::ostringstream message;
  if (num_cameras == 0) {
    message << "no cameras to compare";
  } else if (reference_cam_from_rig.size() != num_cameras ||
             estimated_cameras.size() != num_cameras ||
             estimated_cam_from_rig.size() != num_cameras) {
    message << "sizes differ: " << num_cameras << " reference cameras, "
            << reference_cam_from_rig.size() << " reference poses, "
            << estimated_cameras.size() << " estimated cameras, "
            << estimated_cam_from_rig.size() << " estimated poses";
  } else if (options.alignment == RigAlignment::kReferenceCamera &&
             (options.reference_camera < 0 ||
              options.reference_camera >= num_cameras)) {
    message << "reference camera " << options.reference_camera
            << " out of range";
  } else if (options.grid_cols < 1 || options.grid_rows < 1) {
    message << "projection grid must be at least 1x1";
  }
  for (int i = 0; i < num_cameras && message.str().empty(); ++i) {
    std::string why;
    if (!IsUsableCamera(reference_cameras[i], &why)) {
      message << "reference camera " << i << ": " << why;
    } else if (i < estimated_cameras.size() &&
               !IsUsableCamera(estimated_cameras[i], &why)) {
      message << "estimated camera " << i << ": " << why;
    }
  }
  if (!message.str().empty()) {
    result.error = message.str();
    LOG(ERROR) << "Cannot compare calibrations: " << result.error;
    return result;
  }

  std::vector<Eigen::Vector3d> reference_centers, estimated_centers;
  Eigen::Matrix3d rotation_sum = Eigen::Matrix3d::Zero();
  for (int i = 0; i < num_cameras; ++i) {
    reference_centers.push_back(reference_cam_from_rig[i].Center());
    estimated_centers.push_back(estimated_cam_from_rig[i].Center());
    rotation_sum += reference_cam_from_rig[i].RotationMatrix().transpose() *
                    estimated_cam_from_rig[i].RotationMatrix();
  }

  // rigref_from_rigest: x_ref = scale * rotation * x_est + translation.
  Eigen::Matrix3d rotation;
  Eigen::Vector3d reference_origin, estimated_origin;
  if (options.alignment == RigAlignment::kReferenceCamera) {
    const int k = options.reference_camera;
    rotation = reference_cam_from_rig[k].RotationMatrix().transpose() *
               estimated_cam_from_rig[k].RotationMatrix();
    reference_origin = reference_centers[k];
    estimated_origin = estimated_centers[k];
  } else {
    rotation = NearestRotation(rotation_sum);
    reference_origin = Mean(reference_centers);
    estimated_origin = Mean(estimated_centers);
  }
  result.scale =
      options.align_scale
          ? AlignmentScale(reference_centers, reference_origin,
                           estimated_centers, estimated_origin, rotation)
          : 1.0;
  const Eigen::Vector3d translation =
      reference_origin - result.scale * rotation * estimated_origin;

  for (int i = 0; i < num_cameras; ++i) {
    CameraError error;
    const Eigen::Quaterniond aligned_rotation(
        estimated_cam_from_rig[i].RotationMatrix() * rotation.transpose());
    error.rotation_deg = RotationDifferenceDeg(
        aligned_rotation, reference_cam_from_rig[i].rotation);
    const Eigen::Vector3d aligned_center =
        result.scale * rotation * estimated_centers[i] + translation;
    error.center_error = (aligned_center - reference_centers[i]).norm();

    const colmap::Camera& reference = reference_cameras[i];
    const colmap::Camera& estimate = estimated_cameras[i];
    error.focal_error_percent = FocalErrorPercent(reference, estimate);
    error.principal_point_error_px =
        std::hypot(estimate.PrincipalPointX() - reference.PrincipalPointX(),
                   estimate.PrincipalPointY() - reference.PrincipalPointY());
    CompareProjections(reference, estimate, options.grid_cols,
                       options.grid_rows, &error);
    result.cameras.push_back(error);
  }
  return result;
}

CalibrationError CompareCalibrations(
    const std::vector<colmap::Camera>& reference_cameras,
    const std::vector<Rigid3d>& reference_cam_from_rig,
    const std::vector<colmap::Camera>& estimated_cameras,
    const std::vector<Rigid3d>& estimated_cam_from_rig, bool align_scale) {
  CompareOptions options;
  options.align_scale = align_scale;
  return CompareCalibrations(reference_cameras, reference_cam_from_rig,
                             estimated_cameras, estimated_cam_from_rig,
                             options);
}

std::string FormatCalibrationErrorTable(const CalibrationError& error,
                                        const std::vector<std::string>& names) {
  if (!error.ok()) {
    return "calibration error: " + error.error + "\n";
  }
  std::ostringstream table;
  char line[256];
  std::snprintf(line, sizeof(line), "%-12s %9s %10s %8s %8s %9s %9s %7s\n",
                "camera", "rot(deg)", "center", "f(%)", "pp(px)", "proj(px)",
                "max(px)", "rays");
  table << line;
  for (size_t i = 0; i < error.cameras.size(); ++i) {
    const CameraError& camera = error.cameras[i];
    std::snprintf(
        line, sizeof(line), "%-12s %9.4f %10.5f %8.3f %8.3f %9.3f %9.3f %7d\n",
        CameraName(names, i).c_str(), camera.rotation_deg, camera.center_error,
        camera.focal_error_percent, camera.principal_point_error_px,
        camera.mean_projection_diff_px, camera.max_projection_diff_px,
        camera.num_projection_samples);
    table << line;
  }
  std::snprintf(line, sizeof(line),
                "%-12s %9.4f %10.5f %8.3f %8.3f %9s %9.3f\n", "max",
                error.MaxRotationDeg(), error.MaxCenterError(),
                error.MaxFocalErrorPercent(), error.MaxPrincipalPointErrorPx(),
                "", error.MaxProjectionDiffPx());
  table << line;
  std::snprintf(line, sizeof(line), "alignment scale %.6f\n", error.scale);
  table << line;
  return table.str();
}

nlohmann::json CalibrationErrorToJson(const CalibrationError& error,
                                      const std::vector<std::string>& names) {
  nlohmann::json json;
  if (!error.ok()) {
    json["error"] = error.error;
    return json;
  }
  json["scale"] = error.scale;
  json["cameras"] = nlohmann::json::array();
  for (size_t i = 0; i < error.cameras.size(); ++i) {
    const CameraError& camera = error.cameras[i];
    json["cameras"].push_back(
        {{"name", CameraName(names, i)},
         {"rotation_deg", camera.rotation_deg},
         {"center_error", camera.center_error},
         {"focal_error_percent", camera.focal_error_percent},
         {"principal_point_error_px", camera.principal_point_error_px},
         {"mean_projection_diff_px", camera.mean_projection_diff_px},
         {"max_projection_diff_px", camera.max_projection_diff_px},
         {"num_projection_samples", camera.num_projection_samples},
         {"num_projection_skipped", camera.num_projection_skipped}});
  }
  json["max"] = {{"rotation_deg", error.MaxRotationDeg()},
                 {"center_error", error.MaxCenterError()},
                 {"focal_error_percent", error.MaxFocalErrorPercent()},
                 {"principal_point_error_px", error.MaxPrincipalPointErrorPx()},
                 {"projection_diff_px", error.MaxProjectionDiffPx()}};
  return json;
}

}  // namespace rig_calibrator
