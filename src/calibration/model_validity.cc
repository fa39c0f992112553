#include "src/calibration/model_validity.h"

#include <colmap/base/camera_models.h>
#include <colmap/util/math.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>
#include <vector>

namespace rig_calibrator {
namespace {

// Largest off-axis angle sampled: COLMAP's models project (u, v) = (x/z, y/z),
// so a ray at 90 degrees has no normalized coordinates.
constexpr double kMaxAngleDeg = 89.95;

bool InsideImage(const colmap::Camera& camera, const Eigen::Vector2d& pixel) {
  return pixel.x() >= 0 && pixel.y() >= 0 && pixel.x() <= camera.Width() &&
         pixel.y() <= camera.Height();
}

// det(d pixel / d(u, v)) by central differences.
double ProjectionJacobianDeterminant(const colmap::Camera& camera,
                                     const Eigen::Vector2d& uv) {
  const double h = 1e-6 * std::max(1.0, uv.norm());
  const Eigen::Vector2d du(h, 0), dv(0, h);
  const Eigen::Vector2d d_du =
      (camera.WorldToImage(uv + du) - camera.WorldToImage(uv - du)) / (2 * h);
  const Eigen::Vector2d d_dv =
      (camera.WorldToImage(uv + dv) - camera.WorldToImage(uv - dv)) / (2 * h);
  return d_du.x() * d_dv.y() - d_du.y() * d_dv.x();
}

// The points of the image border the rays aim at: the corners and
// num_per_edge points inside every edge.
std::vector<Eigen::Vector2d> BorderPoints(const colmap::Camera& camera,
                                          int num_per_edge) {
  const double w = camera.Width(), h = camera.Height();
  const Eigen::Vector2d corners[4] = {{0, 0}, {w, 0}, {w, h}, {0, h}};
  std::vector<Eigen::Vector2d> points;
  for (int e = 0; e < 4; ++e) {
    const Eigen::Vector2d& a = corners[e];
    const Eigen::Vector2d& b = corners[(e + 1) % 4];
    points.push_back(a);
    for (int k = 1; k <= num_per_edge; ++k) {
      points.push_back(a + (b - a) * k / (num_per_edge + 1.0));
    }
  }
  return points;
}

struct RayFold {
  bool folds = false;
  bool beyond_hemisphere = false;  // inside the image at 90 degrees
  double radius_px = 0;
  double angle_deg = 0;
};

// Check 1 along the ray from the principal point towards `border_point`:
// the normalized direction d has the pixel direction through the focal
// lengths (exact for the radially symmetric models; for the others the ray
// ends wherever its pixel leaves the image).
RayFold CheckRay(const colmap::Camera& camera, const Eigen::Vector2d& pp,
                 double fx, double fy, const Eigen::Vector2d& border_point,
                 int num_samples) {
  RayFold fold;
  const Eigen::Vector2d pixel_direction = border_point - pp;
  if (pixel_direction.norm() == 0) return fold;
  const Eigen::Vector2d d =
      Eigen::Vector2d(pixel_direction.x() / fx, pixel_direction.y() / fy)
          .normalized();
  double previous_radius = 0;
  double previous_angle_deg = 0;
  for (int k = 1; k <= num_samples; ++k) {
    const double angle_deg = kMaxAngleDeg * k / num_samples;
    const Eigen::Vector2d uv = std::tan(colmap::DegToRad(angle_deg)) * d;
    const Eigen::Vector2d pixel = camera.WorldToImage(uv);
    const double radius = (pixel - pp).norm();
    if (!pixel.allFinite() || !(radius > previous_radius) ||
        !(ProjectionJacobianDeterminant(camera, uv) > 0)) {
      fold.folds = true;
      fold.radius_px = previous_radius;
      fold.angle_deg = previous_angle_deg;
      return fold;
    }
    if (!InsideImage(camera, pixel)) return fold;
    previous_radius = radius;
    previous_angle_deg = angle_deg;
  }
  fold.beyond_hemisphere = true;
  return fold;
}

// Check 2: the worst |WorldToImage(ImageToWorld(x)) - x| over the grid;
// infinity where a pixel comes back non-finite.
double MaxRoundTripError(const colmap::Camera& camera, int step_px) {
  std::vector<double> xs, ys;
  for (double x = 0; x < camera.Width(); x += step_px) xs.push_back(x);
  xs.push_back(camera.Width());
  for (double y = 0; y < camera.Height(); y += step_px) ys.push_back(y);
  ys.push_back(camera.Height());
  double max_error = 0;
  for (const double y : ys) {
    for (const double x : xs) {
      const Eigen::Vector2d pixel(x, y);
      const Eigen::Vector2d back =
          camera.WorldToImage(camera.ImageToWorld(pixel));
      const double error = (back - pixel).norm();
      if (!std::isfinite(error)) {
        return std::numeric_limits<double>::infinity();
      }
      max_error = std::max(max_error, error);
    }
  }
  return max_error;
}

std::string FormatNumber(double value, int precision) {
  std::ostringstream stream;
  stream.setf(std::ios::fixed);
  stream.precision(precision);
  stream << value;
  return stream.str();
}

// Off-axis angle (degrees) of the pixel `radius_px` to the right of the
// principal point, through the model's undistortion.
double OffAxisAngleDeg(const colmap::Camera& camera, double radius_px) {
  const Eigen::Vector2d pixel(camera.PrincipalPointX() + radius_px,
                              camera.PrincipalPointY());
  return colmap::RadToDeg(std::atan(camera.ImageToWorld(pixel).norm()));
}

// The next COLMAP model of the same kind with more distortion terms; empty
// for the richest ones.
std::string RicherCameraModel(const std::string& model) {
  static const std::pair<const char*, const char*> kNext[] = {
      {"SIMPLE_PINHOLE", "SIMPLE_RADIAL"},
      {"PINHOLE", "OPENCV"},
      {"SIMPLE_RADIAL", "RADIAL"},
      {"RADIAL", "OPENCV"},
      {"OPENCV", "FULL_OPENCV"},
      {"SIMPLE_RADIAL_FISHEYE", "RADIAL_FISHEYE"},
      {"RADIAL_FISHEYE", "OPENCV_FISHEYE"},
      {"FOV", "OPENCV_FISHEYE"},
      {"OPENCV_FISHEYE", "THIN_PRISM_FISHEYE"}};
  for (const auto& [from, to] : kNext) {
    if (model == from) return to;
  }
  return "";
}

// Off-axis angle beyond which a pinhole-type model's misfit is taken for a
// wide lens (a diagonal field of view above 100 degrees): tan(theta) grows
// faster than any few-term polynomial of the image radius follows.
constexpr double kWideLensAngleDeg = 50;

}  // namespace

void AddResidualProfileCheck(const colmap::Camera& camera,
                             const RadialResidualProfile& profile,
                             const bool parameters_held,
                             ModelValidity* validity) {
  validity->residual_profile = profile;
  validity->fits_data = !profile.systematic;
  // Held parameters (possibly wrong given values) leave the model family
  // untested: the caller warns instead.
  if (validity->fits_data || parameters_held) return;
  const bool already_invalid = !validity->valid;
  validity->valid = false;
  if (already_invalid) return;
  const double max_radius_px = profile.rings.back().max_radius_px;
  const double max_angle_deg = OffAxisAngleDeg(camera, max_radius_px);
  validity->suggested_model = !IsFisheyeCameraModel(camera.ModelId()) &&
                                      !(max_angle_deg <= kWideLensAngleDeg)
                                  ? "OPENCV_FISHEYE"
                                  : RicherCameraModel(camera.ModelName());
  std::string message =
      "the fitted " + camera.ModelName() +
      " model does not follow the lens: " + DescribeRadialMisfit(profile) +
      ", where a model that fits leaves no such bias (its inliers reach " +
      FormatNumber(max_radius_px, 0) + " px, " +
      FormatNumber(max_angle_deg, 0) +
      " deg off axis; the observations it cannot follow are rejected as "
      "outliers and its projections beyond are extrapolated from a wrong "
      "curve)";
  message += validity->suggested_model.empty()
                 ? ". Try --RigCalibrator.camera_model auto."
                 : ". Use " + validity->suggested_model +
                       " or --RigCalibrator.camera_model auto.";
  validity->message = message;
}

bool IsFisheyeCameraModel(const int model_id) {
  return model_id == colmap::SimpleRadialFisheyeCameraModel::kModelId ||
         model_id == colmap::RadialFisheyeCameraModel::kModelId ||
         model_id == colmap::OpenCVFisheyeCameraModel::kModelId ||
         model_id == colmap::ThinPrismFisheyeCameraModel::kModelId ||
         model_id == colmap::FOVCameraModel::kModelId;
}

ModelValidity CheckModelValidity(const colmap::Camera& camera,
                                 const ModelValidityOptions& options) {
  ModelValidity validity;
  const Eigen::Vector2d pp(camera.PrincipalPointX(), camera.PrincipalPointY());
  const std::vector<size_t>& focal_idxs = camera.FocalLengthIdxs();
  const double fx = camera.Params()[focal_idxs[0]];
  const double fy = camera.Params()[focal_idxs.back()];
  for (const Eigen::Vector2d& corner :
       {Eigen::Vector2d(0, 0), Eigen::Vector2d(camera.Width(), 0),
        Eigen::Vector2d(camera.Width(), camera.Height()),
        Eigen::Vector2d(0, camera.Height())}) {
    validity.corner_radius_px =
        std::max(validity.corner_radius_px, (corner - pp).norm());
  }
  if (!(fx > 0 && fy > 0) || !pp.allFinite()) {
    validity.max_roundtrip_error_px = std::numeric_limits<double>::infinity();
    validity.message = "the focal length or principal point is not valid";
    return validity;
  }
  validity.monotonic = true;
  bool beyond_hemisphere = false;
  for (const Eigen::Vector2d& border_point :
       BorderPoints(camera, options.num_rays_per_edge)) {
    const RayFold fold =
        CheckRay(camera, pp, fx, fy, border_point, options.num_angle_samples);
    beyond_hemisphere = beyond_hemisphere || fold.beyond_hemisphere;
    if (!fold.folds) continue;
    validity.monotonic = false;
    if (!validity.fold_radius_px || fold.radius_px < *validity.fold_radius_px) {
      validity.fold_radius_px = fold.radius_px;
      validity.fold_angle_deg = fold.angle_deg;
    }
  }
  validity.max_roundtrip_error_px =
      MaxRoundTripError(camera, options.grid_step_px);
  const bool round_trip_ok =
      validity.max_roundtrip_error_px <= options.max_roundtrip_error_px;
  validity.valid = validity.monotonic && round_trip_ok && !beyond_hemisphere;
  if (validity.valid) {
    validity.message = "the " + camera.ModelName() +
                       " model is one-to-one over the whole image";
    return validity;
  }
  if (!IsFisheyeCameraModel(camera.ModelId())) {
    validity.suggested_model = "OPENCV_FISHEYE";
  }
  std::string message = "the fitted " + camera.ModelName() +
                        " model is not valid over the whole image: ";
  if (!validity.monotonic) {
    message += "its distortion folds back at " +
               FormatNumber(*validity.fold_radius_px, 1) +
               " px from the principal point (" +
               FormatNumber(*validity.fold_angle_deg, 1) +
               " deg off axis), inside the image (corners at up to " +
               FormatNumber(validity.corner_radius_px, 1) +
               " px), so the pixels beyond have no ray or several";
  } else if (beyond_hemisphere) {
    message +=
        "parts of the image are more than 90 deg off axis, where "
        "COLMAP's models cannot project (focal length too short "
        "for the image)";
  } else {
    message +=
        "undistorting and distorting the image grid comes back " +
        (std::isfinite(validity.max_roundtrip_error_px)
             ? "up to " + FormatNumber(validity.max_roundtrip_error_px, 3) +
                   " px off"
             : std::string("non-finite")) +
        " (at most " + FormatNumber(options.max_roundtrip_error_px, 3) +
        " px allowed)";
  }
  message += validity.suggested_model.empty()
                 ? ". Give a model with fewer distortion terms, or "
                   "--RigCalibrator.camera_model auto."
                 : ". A wide lens needs a fisheye model: use " +
                       validity.suggested_model +
                       " or --RigCalibrator.camera_model auto.";
  validity.message = message;
  return validity;
}

}  // namespace rig_calibrator
