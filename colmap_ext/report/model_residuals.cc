#include "colmap_ext/report/model_residuals.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <unordered_map>

namespace rig_calibrator {
namespace {

struct ModelRigImage {
  colmap::image_t image_id = 0;
  int camera = 0;
  std::string frameset_key;
  std::string frameset_name;
};

bool StartsWith(const std::string& text, const std::string& prefix) {
  return text.compare(0, prefix.size(), prefix) == 0;
}

// The registered images of each camera (by name prefix and the camera of the
// first such image), with the key that groups them into framesets.
std::vector<ModelRigImage> FindRigImages(
    const colmap::Reconstruction& model,
    const std::optional<ColmapRigsAndFrames>& rigs_frames,
    const std::vector<ReportCamera>& cameras, ModelResiduals* residuals) {
  std::unordered_map<uint64_t, uint32_t> frame_of_image;
  if (rigs_frames) {
    for (const ColmapFrame& frame : rigs_frames->frames) {
      for (const ColmapFrameData& data : frame.data) {
        if (data.sensor.type == kSensorCamera) {
          frame_of_image[data.data_id] = frame.frame_id;
        }
      }
    }
  }
  std::vector<colmap::image_t> image_ids = model.RegImageIds();
  std::sort(image_ids.begin(), image_ids.end());
  std::vector<ModelRigImage> rig_images;
  for (const colmap::image_t image_id : image_ids) {
    const colmap::Image& image = model.Image(image_id);
    for (size_t c = 0; c < cameras.size(); ++c) {
      if (cameras[c].image_prefix.empty() ||
          !StartsWith(image.Name(), cameras[c].image_prefix)) {
        continue;
      }
      CameraResiduals& camera = residuals->cameras[c];
      if (camera.camera_id == colmap::kInvalidCameraId) {
        camera.camera_id = image.CameraId();
      }
      if (image.CameraId() != camera.camera_id) continue;
      ModelRigImage rig_image;
      rig_image.image_id = image_id;
      rig_image.camera = static_cast<int>(c);
      rig_image.frameset_name =
          image.Name().substr(cameras[c].image_prefix.size());
      const auto frame = frame_of_image.find(image_id);
      if (frame != frame_of_image.end()) {
        char key[16];
        std::snprintf(key, sizeof(key), "%010u", frame->second);
        rig_image.frameset_key = key;
      } else {
        rig_image.frameset_key = rig_image.frameset_name;
      }
      rig_images.push_back(rig_image);
      break;
    }
  }
  return rig_images;
}

// The observed points and their residuals (observed - projected) of one
// image: of its observations of 3D points, or of its correspondence rows.
constexpr double kMinInlierThresholdPx = 0.01;

struct Observation {
  Eigen::Vector2d point, residual;
};

std::vector<Observation> ImageObservations(const colmap::Reconstruction& model,
                                           const colmap::Image& image,
                                           const ImageCorrespondences* rows) {
  const colmap::Camera& camera = model.Camera(image.CameraId());
  const Eigen::Matrix3d rotation = image.RotationMatrix();
  std::vector<Observation> observations;
  const auto add = [&](const Eigen::Vector2d& point,
                       const Eigen::Vector3d& point3D) {
    const Eigen::Vector3d in_camera = rotation * point3D + image.Tvec();
    if (!(in_camera.z() > 0)) return;
    const Eigen::Vector2d residual =
        point - camera.WorldToImage(in_camera.hnormalized());
    if (residual.allFinite()) observations.push_back({point, residual});
  };
  if (rows == nullptr) {
    for (const colmap::Point2D& point2D : image.Points2D()) {
      if (point2D.HasPoint3D()) {
        add(point2D.XY(), model.Point3D(point2D.Point3DId()).XYZ());
      }
    }
  } else {
    for (const Correspondence& row : rows->correspondences) {
      add(row.point2D, row.point3D);
    }
  }
  return observations;
}

}  // namespace

ModelResiduals ComputeModelResiduals(
    const colmap::Reconstruction& model,
    const std::optional<ColmapRigsAndFrames>& rigs_frames,
    const std::vector<ReportCamera>& cameras, const int grid_cols,
    const std::vector<ImageCorrespondences>& correspondences) {
  ModelResiduals residuals;
  residuals.cameras.resize(cameras.size());
  std::vector<ModelRigImage> rig_images =
      FindRigImages(model, rigs_frames, cameras, &residuals);
  for (CameraResiduals& camera : residuals.cameras) {
    if (camera.camera_id == colmap::kInvalidCameraId) continue;
    const colmap::Camera& model_camera = model.Camera(camera.camera_id);
    camera.width = static_cast<int>(model_camera.Width());
    camera.height = static_cast<int>(model_camera.Height());
    camera.cols = std::max(1, grid_cols);
    camera.rows = std::max(
        1, static_cast<int>(std::lround(camera.cols * double(camera.height) /
                                        std::max(1, camera.width))));
    camera.cells.assign(camera.cols * camera.rows, ResidualCell());
    camera.min_radius_px = std::numeric_limits<double>::infinity();
  }

  // Framesets in key order: frame ids, or names.
  std::map<std::string, int> frameset_index;
  for (const ModelRigImage& image : rig_images) {
    frameset_index.emplace(image.frameset_key, 0);
  }
  int index = 0;
  for (auto& [key, value] : frameset_index) value = index++;
  residuals.framesets.resize(frameset_index.size());
  for (FramesetError& frameset : residuals.framesets) {
    frameset.camera_rms_px.assign(cameras.size(),
                                  std::numeric_limits<double>::quiet_NaN());
  }
  std::stable_sort(rig_images.begin(), rig_images.end(),
                   [&](const ModelRigImage& a, const ModelRigImage& b) {
                     const int fa = frameset_index.at(a.frameset_key);
                     const int fb = frameset_index.at(b.frameset_key);
                     return fa != fb ? fa < fb : a.camera < b.camera;
                   });

  // Cameras without observations of 3D points take their correspondence
  // rows, within 3 x the median residual of the camera's rows (at least
  // kMinInlierThresholdPx, for exact data).
  std::unordered_map<std::string, const ImageCorrespondences*> rows_of_image;
  for (const ImageCorrespondences& rows : correspondences) {
    rows_of_image[rows.image_name] = &rows;
  }
  std::vector<bool> has_points3D(cameras.size(), false);
  for (const ModelRigImage& rig_image : rig_images) {
    has_points3D[rig_image.camera] =
        has_points3D[rig_image.camera] ||
        model.Image(rig_image.image_id).NumPoints3D() > 0;
  }
  const auto rows_for =
      [&](const ModelRigImage& rig_image) -> const ImageCorrespondences* {
    if (has_points3D[rig_image.camera]) return nullptr;
    const colmap::Image& image = model.Image(rig_image.image_id);
    const auto rows = rows_of_image.find(image.Name());
    return rows != rows_of_image.end() &&
                   rows->second->correspondences.size() == image.NumPoints2D()
               ? rows->second
               : nullptr;
  };
  std::vector<std::vector<double>> row_errors(cameras.size());
  for (const ModelRigImage& rig_image : rig_images) {
    const ImageCorrespondences* rows = rows_for(rig_image);
    if (rows == nullptr) continue;
    for (const Observation& observation :
         ImageObservations(model, model.Image(rig_image.image_id), rows)) {
      row_errors[rig_image.camera].push_back(observation.residual.norm());
    }
  }
  for (size_t c = 0; c < cameras.size(); ++c) {
    std::vector<double>& errors = row_errors[c];
    if (errors.empty()) continue;
    std::nth_element(errors.begin(), errors.begin() + errors.size() / 2,
                     errors.end());
    residuals.cameras[c].from_correspondences = true;
    residuals.cameras[c].inlier_threshold_px =
        std::max(3 * errors[errors.size() / 2], kMinInlierThresholdPx);
  }

  // Sums of squared residuals: rms = sqrt(sum / n).
  std::vector<double> camera_sum(cameras.size(), 0);
  std::vector<double> frameset_sum(residuals.framesets.size(), 0);
  for (const ModelRigImage& rig_image : rig_images) {
    const colmap::Image& image = model.Image(rig_image.image_id);
    const colmap::Camera& model_camera = model.Camera(image.CameraId());
    CameraResiduals& camera = residuals.cameras[rig_image.camera];
    const Eigen::Vector2d principal_point(model_camera.PrincipalPointX(),
                                          model_camera.PrincipalPointY());
    const ImageCorrespondences* rows = rows_for(rig_image);
    if (camera.from_correspondences && rows == nullptr) continue;
    double image_sum = 0;
    int64_t image_count = 0;
    for (const Observation& observation :
         ImageObservations(model, image, rows)) {
      const double squared = observation.residual.squaredNorm();
      if (camera.from_correspondences &&
          !(std::sqrt(squared) <= camera.inlier_threshold_px)) {
        continue;
      }
      const Eigen::Vector2d& point = observation.point;
      const int col = std::clamp(
          static_cast<int>(std::floor(point.x() / camera.width * camera.cols)),
          0, camera.cols - 1);
      const int row = std::clamp(
          static_cast<int>(std::floor(point.y() / camera.height * camera.rows)),
          0, camera.rows - 1);
      ResidualCell& cell = camera.cells[row * camera.cols + col];
      cell.sum_dx += observation.residual.x();
      cell.sum_dy += observation.residual.y();
      cell.sum_squared += squared;
      ++cell.count;
      const double radius = (point - principal_point).norm();
      camera.min_radius_px = std::min(camera.min_radius_px, radius);
      camera.max_radius_px = std::max(camera.max_radius_px, radius);
      camera.max_error_px = std::max(camera.max_error_px, std::sqrt(squared));
      image_sum += squared;
      ++image_count;
    }
    camera.num_observations += image_count;
    camera_sum[rig_image.camera] += image_sum;
    ImageError error;
    error.name = image.Name();
    error.camera = rig_image.camera;
    error.frameset = frameset_index.at(rig_image.frameset_key);
    error.num_observations = image_count;
    error.rms_px = image_count > 0 ? std::sqrt(image_sum / image_count) : 0;
    FramesetError& frameset = residuals.framesets[error.frameset];
    if (frameset.name.empty()) frameset.name = rig_image.frameset_name;
    frameset.num_observations += image_count;
    frameset_sum[error.frameset] += image_sum;
    if (image_count > 0) frameset.camera_rms_px[error.camera] = error.rms_px;
    residuals.images.push_back(error);
  }
  for (size_t c = 0; c < cameras.size(); ++c) {
    CameraResiduals& camera = residuals.cameras[c];
    if (camera.num_observations > 0) {
      camera.rms_px = std::sqrt(camera_sum[c] / camera.num_observations);
    } else {
      camera.min_radius_px = 0;
    }
  }
  for (size_t f = 0; f < residuals.framesets.size(); ++f) {
    FramesetError& frameset = residuals.framesets[f];
    if (frameset.num_observations > 0) {
      frameset.rms_px = std::sqrt(frameset_sum[f] / frameset.num_observations);
    }
  }
  return residuals;
}

}  // namespace rig_calibrator
