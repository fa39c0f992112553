#include "colmap_ext/io/model_errors.h"

#include <colmap/base/projection.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace rig_calibrator {

double ObservationError(const colmap::Reconstruction& model,
                        const colmap::Point3D& point3D,
                        const colmap::TrackElement& element) {
  const colmap::Image& image = model.Image(element.image_id);
  const double squared_error = colmap::CalculateSquaredReprojectionError(
      image.Point2D(element.point2D_idx).XY(), point3D.XYZ(), image.Qvec(),
      image.Tvec(), model.Camera(image.CameraId()));
  return squared_error == std::numeric_limits<double>::max()
             ? std::numeric_limits<double>::infinity()
             : std::sqrt(squared_error);
}

ReprojectionStats ComputeReprojectionStats(
    const colmap::Reconstruction& model,
    const std::unordered_set<colmap::image_t>& image_ids) {
  ReprojectionStats stats;
  double sum = 0;
  for (const auto& [point3D_id, point3D] : model.Points3D()) {
    for (const colmap::TrackElement& element : point3D.Track().Elements()) {
      if (!image_ids.empty() && image_ids.count(element.image_id) == 0) {
        continue;
      }
      const double error = ObservationError(model, point3D, element);
      ++stats.num_observations;
      sum += error;
      stats.max_px = std::max(stats.max_px, error);
      stats.num_above_4px += error > 4 ? 1 : 0;
    }
  }
  stats.mean_px = stats.num_observations > 0 ? sum / stats.num_observations : 0;
  return stats;
}

void RecomputePointErrors(
    colmap::Reconstruction* model,
    const std::unordered_set<colmap::image_t>& excluded_image_ids) {
  for (const colmap::point3D_t point3D_id : model->Point3DIds()) {
    colmap::Point3D& point3D = model->Point3D(point3D_id);
    double sum = 0;
    int num_observations = 0;
    for (const colmap::TrackElement& element : point3D.Track().Elements()) {
      if (excluded_image_ids.count(element.image_id) > 0) continue;
      sum += ObservationError(*model, point3D, element);
      ++num_observations;
    }
    if (num_observations > 0) {
      point3D.SetError(sum / num_observations);
    } else if (excluded_image_ids.empty()) {
      point3D.SetError(0);
    }
  }
}

}  // namespace rig_calibrator
