// The calibration problem and its solution, independent of where the data
// came from (a COLMAP database, a correspondence file or the synthetic
// generator). Cameras use COLMAP's camera models and parameter orders; pixel
// coordinates follow COLMAP (the center of the top-left pixel is (0.5, 0.5)).
#pragma once

#include <colmap/base/camera.h>

#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "src/geometry/frameset_motion.h"
#include "src/geometry/rigid3d.h"
#include "src/rig/intrinsics_refinement.h"

namespace rig_calibrator {

// One 2D-3D correspondence: a keypoint of a rig image and a map point.
struct Correspondence {
  Eigen::Vector2d point2D = Eigen::Vector2d::Zero();  // pixels
  Eigen::Vector3d point3D = Eigen::Vector3d::Zero();  // map coordinates
  int64_t point3D_id = -1;                            // -1: not a map point id
};

// One image of one rig camera in one frameset.
struct RigImage {
  std::string name;  // database/model name, e.g. "cam0/000012.png"
  int camera_index = -1;
  int frameset_index = -1;
  std::vector<Correspondence> correspondences;
};

// One camera of the rig. `camera` carries the model, the image size and the
// parameters: initial values (principal point at the image center) or, with
// `intrinsics_known`, the given intrinsics (the `known*` methods).
// `refinement`: COLMAP's refine_* switches for this camera; the parameters
// it holds keep camera's values in every stage (intrinsics_refinement.h).
struct RigCamera {
  std::string name;  // the folder, e.g. "cam0"
  colmap::Camera camera;
  bool intrinsics_known = false;
  // The model is chosen by the pipeline among candidates
  // (--RigCalibrator.camera_model auto; model_selection.h): `camera`'s model
  // is a placeholder then.
  bool choose_model = false;
  IntrinsicsRefinement refinement;
};

// One observation of a map point by a map image: the keypoint and its index
// among the image's points2D (in the map model and its database).
struct MapObservation {
  Eigen::Vector2d point2D = Eigen::Vector2d::Zero();  // pixels
  int64_t point3D_id = -1;
  uint32_t point2D_idx = 0;
};

// One registered image of the map that the rig is calibrated against, with
// its observations of map points: the map's own evidence of where its points
// are, used when the final bundle adjustment refines them.
struct MapImage {
  std::string name;
  int64_t image_id = -1;  // in the map model
  int camera_index = -1;  // into RigDataset::map_cameras
  Rigid3d cam_from_world;
  std::vector<MapObservation> observations;
};

struct RigDataset {
  std::vector<RigCamera> cameras;
  std::vector<std::string> frameset_names;  // one per frameset
  // Per frameset its nominal capture time (seconds, any origin; strictly
  // increasing), or empty when unknown (every source but the synthetic
  // generator's time model): the clock that per-camera time offsets and
  // line delays are relative to.
  std::vector<double> frameset_times_s;
  std::vector<RigImage> images;
  int reference_camera = 0;  // its cam_from_rig is the identity
  // The map's cameras and images (empty when there is no map, e.g. a run
  // from a correspondence file alone). The map point positions are those of
  // the correspondences and `map_points3D`.
  std::vector<colmap::Camera> map_cameras;
  std::vector<MapImage> map_images;
  // Every map point observed by a map image, by point3D_id.
  std::unordered_map<int64_t, Eigen::Vector3d> map_points3D;
};

// What became of one image.
struct ImageResult {
  bool localized = false;  // a radial (or full) pose was found on its own
  bool used = false;       // part of the final calibration
  std::vector<char> inlier_mask;  // per correspondence, after the final BA
  int num_inliers = 0;
  double radial_rms_px = 0;  // radial reprojection RMS over inliers
  double rms_px = 0;         // full reprojection RMS over inliers
  std::optional<Rigid3d> single_image_cam_from_world;  // its own estimate
};

struct RigCalibration {
  std::vector<colmap::Camera> cameras;  // calibrated intrinsics, per camera
  std::vector<Rigid3d> cam_from_rig;    // per camera
  std::vector<bool> camera_calibrated;  // false: the camera could not be fitted
  std::vector<std::optional<Rigid3d>> rig_from_world;  // per frameset
  std::vector<ImageResult> images;                     // per dataset image
  // Map points moved by a final bundle adjustment that refines points, by
  // point3D_id; empty when the map is held fixed (the default).
  std::unordered_map<int64_t, Eigen::Vector3d> refined_points3D;
  // After a final bundle adjustment with map images (else empty): per map
  // camera its intrinsics, per map image its cam_from_world (the map's
  // unless the map was refined) and per observation whether it was rejected
  // (its point refined, the observation no longer fitting: the output model
  // drops it from the point's track).
  std::vector<colmap::Camera> map_cameras;
  std::vector<Rigid3d> map_cam_from_world;
  std::vector<std::vector<char>> map_observation_rejected;
  // After a final bundle adjustment with a time model (else empty): per
  // frameset the rig's estimated translational velocity and acceleration
  // at the frameset's time, in the rig frame there, map units per second
  // and per second squared (frameset_motion.h).
  std::vector<TranslationDerivatives> rig_translation_derivatives;
  // With it, per frameset whether its motion leaves its own pose out
  // (ComputeFramesetMotions' without_own_pose, as the adjustment's last
  // motions did); else empty.
  std::vector<char> frameset_motions_without_own_pose;

  Rigid3d CamFromWorld(int camera_index, int frameset_index) const {
    return cam_from_rig[camera_index] * *rig_from_world[frameset_index];
  }
};

// The one check of a calibration problem, whatever its source: at least two
// cameras, a valid reference camera, every camera with an image size and
// parameters valid for its model, every image with a valid camera and
// frameset, and finite correspondences; frameset times empty or one finite
// value per frameset, strictly increasing; every map image with a valid map
// camera, a finite pose and finite observations of points in map_points3D.
// Returns false with `error` naming the camera or image and what is wrong.
bool ValidateDataset(const RigDataset& dataset, std::string* error);

// ValidateDataset, and a calibration shaped like the dataset: one entry per
// camera (intrinsics, cam_from_rig, calibrated flag), per frameset
// (rig_from_world) and per image (result); finite cam_from_rig and
// rig_from_world; every non-empty inlier mask one flag per correspondence;
// the map results empty or one entry per map camera, map image and
// observation.
// Returns false with `error` naming the camera, frameset or image.
bool ValidateCalibration(const RigDataset& dataset,
                         const RigCalibration& calibration, std::string* error);

}  // namespace rig_calibrator
