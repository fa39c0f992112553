// Checks that a calibration's COLMAP model tells the truth about itself, as
// COLMAP would recompute it:
//
//   check_output_model OUTPUT INPUT_MAP
//
// * every observation of the written model (read back from OUTPUT's files)
//   is reprojected here, x = pi(R(q) X + t) with COLMAP's camera models, and
//   the mean over the points of their mean |x - x_observed| equals the
//   model's stored mean reprojection error (COLMAP 3.8's model_analyzer
//   value: the mean of the points' stored errors) within 1 %;
// * no map image's observation of a point the calibration moved is above
//   4 px unless the same observation was already above 4 px in INPUT_MAP.
// Prints the numbers; exit status 1 if a check fails, 2 on unreadable input.
#include <colmap/base/reconstruction.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <string>

#include "tests/e2e/calibration_output.h"

namespace rig_calibrator {
namespace {

constexpr double kMaxRelativeMeanDifference = 0.01;
constexpr double kMaxMapErrorPx = 4.0;
// A point whose position changed by more than this (map units) was refined.
constexpr double kMovedPoint = 1e-9;

// |pi(R(q) X + t) - x| computed here, not by COLMAP's projection helpers.
double ReprojectionError(const colmap::Reconstruction& model,
                         const colmap::Image& image,
                         colmap::point2D_t point2D_idx) {
  const colmap::Point2D& point2D = image.Point2D(point2D_idx);
  const Eigen::Quaterniond rotation(image.Qvec()(0), image.Qvec()(1),
                                    image.Qvec()(2), image.Qvec()(3));
  const Eigen::Vector3d in_camera =
      rotation.normalized() * model.Point3D(point2D.Point3DId()).XYZ() +
      image.Tvec();
  if (!(in_camera.z() > 0)) return std::numeric_limits<double>::infinity();
  return (model.Camera(image.CameraId()).WorldToImage(in_camera.hnormalized()) -
          point2D.XY())
      .norm();
}

void CheckMeanError(const colmap::Reconstruction& model) {
  double sum = 0, sum_of_point_means = 0;
  int64_t count = 0;
  double max_point_difference = 0;
  for (const auto& [point3D_id, point3D] : model.Points3D()) {
    double point_sum = 0;
    for (const colmap::TrackElement& element : point3D.Track().Elements()) {
      point_sum += ReprojectionError(model, model.Image(element.image_id),
                                     element.point2D_idx);
    }
    sum += point_sum;
    sum_of_point_means += point_sum / point3D.Track().Length();
    count += point3D.Track().Length();
    max_point_difference = std::max(
        max_point_difference,
        std::abs(point_sum / point3D.Track().Length() - point3D.Error()));
  }
  const double recomputed =
      model.NumPoints3D() > 0 ? sum_of_point_means / model.NumPoints3D() : 0;
  const double stored = model.ComputeMeanReprojectionError();
  const double relative =
      std::abs(recomputed - stored) / std::max(stored, 1e-12);
  Report("mean reprojection error recomputed = stored",
         "recomputed " + Number(recomputed) + " px (per observation " +
             Number(count > 0 ? sum / count : 0) + " px over " +
             std::to_string(count) + " observations), stored " +
             Number(stored) + " px (relative difference " + Number(relative) +
             ", largest per-point difference " + Number(max_point_difference) +
             " px)",
         count > 0 && relative <= kMaxRelativeMeanDifference);
}

void CheckMapObservations(const colmap::Reconstruction& model,
                          const colmap::Reconstruction& map) {
  int64_t num_checked = 0, num_above = 0, num_above_before = 0;
  double max_error = 0;
  for (const auto& [point3D_id, point3D] : model.Points3D()) {
    if (!map.ExistsPoint3D(point3D_id) ||
        (map.Point3D(point3D_id).XYZ() - point3D.XYZ()).norm() <= kMovedPoint) {
      continue;
    }
    for (const colmap::TrackElement& element : point3D.Track().Elements()) {
      if (!map.ExistsImage(element.image_id) ||
          map.Image(element.image_id).Name() !=
              model.Image(element.image_id).Name()) {
        continue;  // a rig image
      }
      ++num_checked;
      const double error = ReprojectionError(
          model, model.Image(element.image_id), element.point2D_idx);
      max_error = std::max(max_error, error);
      if (error <= kMaxMapErrorPx) continue;
      const colmap::Image& input_image = map.Image(element.image_id);
      const bool above_before =
          input_image.Point2D(element.point2D_idx).HasPoint3D() &&
          ReprojectionError(map, input_image, element.point2D_idx) >
              kMaxMapErrorPx;
      (above_before ? num_above_before : num_above) += 1;
    }
  }
  Report("map observations of refined points <= 4 px",
         std::to_string(num_checked) + " observations, max " +
             Number(max_error) + " px, " + std::to_string(num_above) +
             " above 4 px (and " + std::to_string(num_above_before) +
             " already above 4 px in the input map)",
         num_checked > 0 && num_above == 0);
}

}  // namespace
}  // namespace rig_calibrator

int main(int argc, char** argv) {
  using namespace rig_calibrator;
  if (argc != 3) {
    std::cerr << "usage: " << argv[0] << " OUTPUT INPUT_MAP" << std::endl;
    return 2;
  }
  const colmap::Reconstruction model = ReadModel(argv[1]);
  const colmap::Reconstruction map = ReadModel(argv[2]);
  std::cout << "[check] " << argv[1] << ": " << model.NumRegImages()
            << " registered images, " << model.NumPoints3D()
            << " points; input map " << map.NumRegImages() << " images"
            << std::endl;
  CheckMeanError(model);
  CheckMapObservations(model, map);
  std::cout << "[check] "
            << (NumFailedChecks() == 0
                    ? "all checks passed"
                    : std::to_string(NumFailedChecks()) + " check(s) FAILED")
            << std::endl;
  return NumFailedChecks() == 0 ? 0 : 1;
}
