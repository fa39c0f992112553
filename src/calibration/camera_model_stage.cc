#include "src/calibration/camera_model_stage.h"

#include <omp.h>

#include <algorithm>
#include <iostream>
#include <set>
#include <unordered_map>

#include "src/calibration/pipeline_stages.h"
#include "src/calibration/points_without_camera.h"
#include "src/geometry/frameset_motion.h"
#include "src/geometry/timed_rig_reprojection_cost.h"

namespace rig_calibrator {
namespace {

CameraModelReport& CameraModelReportOf(const RigDataset& dataset,
                                       int camera_index,
                                       PipelineReport* report) {
  report->camera_models.resize(dataset.cameras.size());
  return report->camera_models[camera_index];
}

// The final inliers of camera `camera_index`: observed pixels, points in
// the rig frame (refined map points where the map was refined; with
// `point_positions`, those instead, by point3D_id), framesets.
// With the capture-time model's kept kinds (capture_time_model.h) the point
// is in the rig frame of the row's own instant, t_f + tau with tau =
// delta_c + rho_c (y - 0.5) (frameset_motion.h: the adjustment's motion
// model), so that the rows fit the camera as the adjustment did.
AdjustedCameraRows AdjustedRowsOf(const RigDataset& dataset,
                                  const RigCalibration& calibration,
                                  const CaptureTimeModel& time_model,
                                  const int camera_index,
                                  const std::unordered_map<int64_t,
                                                           Eigen::Vector3d>*
                                      point_positions = nullptr) {
  const bool timed =
      time_model.time_offsets_kept || time_model.line_delays_kept;
  std::vector<FramesetMotion> motions;
  double offset = 0, line_delay = 0;
  if (timed) {
    motions = AdjustedFramesetMotions(dataset, calibration);
    const CameraCaptureTime& time = time_model.cameras[camera_index];
    offset = time_model.time_offsets_kept ? time.time_offset_s : 0;
    line_delay = time_model.line_delays_kept ? time.line_delay_s : 0;
  }
  AdjustedCameraRows rows;
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    const RigImage& image = dataset.images[i];
    const ImageResult& result = calibration.images[i];
    if (image.camera_index != camera_index || !result.used ||
        !calibration.rig_from_world[image.frameset_index]) {
      continue;
    }
    const Rigid3d& rig_from_world =
        *calibration.rig_from_world[image.frameset_index];
    for (size_t k = 0;
         k < image.correspondences.size() && k < result.inlier_mask.size();
         ++k) {
      if (!result.inlier_mask[k]) continue;
      const Correspondence& correspondence = image.correspondences[k];
      const std::unordered_map<int64_t, Eigen::Vector3d>& positions =
          point_positions != nullptr ? *point_positions
                                     : calibration.refined_points3D;
      const auto found = positions.find(correspondence.point3D_id);
      const Eigen::Vector3d& point =
          found != positions.end() ? found->second : correspondence.point3D;
      rows.points2D.push_back(correspondence.point2D);
      if (timed) {
        const PoseParams pose = ToPoseParams(rig_from_world);
        const double tau = CaptureTimeOfRow(offset, line_delay,
                                            correspondence.point2D.y());
        Eigen::Vector3d point_rig;
        WorldToRigAtOffset(pose.data(), point.data(),
                           motions[image.frameset_index],
                           &motions[image.frameset_index][9], tau,
                           point_rig.data());
        rows.points_rig.push_back(point_rig);
      } else {
        rows.points_rig.push_back(rig_from_world * point);
      }
      rows.framesets.push_back(image.frameset_index);
    }
  }
  return rows;
}

// The same observed and projected through the final calibration, with the
// frameset of each (one image of this camera: the clusters of the ring
// check's standard error).
void FinalInlierPixels(const RigDataset& dataset,
                       const RigCalibration& calibration,
                       const CaptureTimeModel& time_model,
                       const int camera_index,
                       std::vector<Eigen::Vector2d>* observed,
                       std::vector<Eigen::Vector2d>* projected,
                       std::vector<int>* framesets) {
  const colmap::Camera& camera = calibration.cameras[camera_index];
  const AdjustedCameraRows rows =
      AdjustedRowsOf(dataset, calibration, time_model, camera_index);
  for (size_t r = 0; r < rows.points2D.size(); ++r) {
    const Eigen::Vector3d point_cam =
        calibration.cam_from_rig[camera_index] * rows.points_rig[r];
    if (!(point_cam.z() > 0)) continue;
    observed->push_back(rows.points2D[r]);
    projected->push_back(camera.WorldToImage(point_cam.hnormalized()));
    framesets->push_back(rows.framesets[r]);
  }
}

// The map's own systematic level (see the header): the largest |ring mean|
// of a significant ring over the map cameras' profiles; 0 without map
// images in the adjustment.
double MapSystematicFloorPx(const PipelineOptions& options,
                            const RigDataset& dataset,
                            const RigCalibration& calibration) {
  if (calibration.map_cam_from_world.size() != dataset.map_images.size() ||
      calibration.map_observation_rejected.size() !=
          dataset.map_images.size() ||
      calibration.map_cameras.size() != dataset.map_cameras.size()) {
    return 0;
  }
  RadialResidualProfileOptions profile_options =
      options.model_selection.validity.residual_profile;
  double floor = 0;
  for (size_t mc = 0; mc < calibration.map_cameras.size(); ++mc) {
    const colmap::Camera& camera = calibration.map_cameras[mc];
    std::vector<Eigen::Vector2d> observed, projected;
    std::vector<int> images;
    for (size_t m = 0; m < dataset.map_images.size(); ++m) {
      const MapImage& image = dataset.map_images[m];
      if (image.camera_index != static_cast<int>(mc)) continue;
      for (size_t k = 0; k < image.observations.size(); ++k) {
        const auto point = calibration.refined_points3D.find(
            image.observations[k].point3D_id);
        if (calibration.map_observation_rejected[m][k] ||
            point == calibration.refined_points3D.end()) {
          continue;
        }
        const Eigen::Vector3d point_cam =
            calibration.map_cam_from_world[m] * point->second;
        if (!(point_cam.z() > 0)) continue;
        observed.push_back(image.observations[k].point2D);
        projected.push_back(camera.WorldToImage(point_cam.hnormalized()));
        images.push_back(static_cast<int>(m));
      }
    }
    const RadialResidualProfile profile = ComputeRadialResidualProfile(
        Eigen::Vector2d(camera.PrincipalPointX(), camera.PrincipalPointY()),
        observed, projected, images, profile_options);
    for (const RadialResidualRing& ring : profile.rings) {
      if (std::abs(ring.z) >= ring.z_threshold) {
        floor = std::max(floor, std::abs(ring.mean_radial_px));
      }
    }
  }
  return floor;
}

}  // namespace

bool UpgradeOrChooseCameraModel(
    const PipelineOptions& options, const RigDataset& dataset,
    const int camera_index, const std::vector<Eigen::Vector2d>& points2D,
    const std::vector<Eigen::Vector3d>& points_cam,
    const std::vector<std::pair<int, int>>& rows, colmap::Camera* camera,
    CameraUpgradeResult* result, std::optional<ModelChoice>* choice) {
  choice->reset();
  // The parameters the user holds (--RigCalibrator.refine_*) are held in
  // the upgrade of every candidate model too.
  CameraUpgradeOptions upgrade_options = options.upgrade;
  const IntrinsicsRefinement& refinement =
      dataset.cameras[camera_index].refinement;
  upgrade_options.refine_focal_length &= refinement.focal_length;
  upgrade_options.refine_principal_point &= refinement.principal_point;
  upgrade_options.refine_extra_params &= refinement.extra_params;
  if (!dataset.cameras[camera_index].choose_model) {
    return UpgradeCamera(upgrade_options, points2D, points_cam, camera, result);
  }
  std::vector<int> groups;
  groups.reserve(rows.size());
  for (const auto& [image, correspondence] : rows) {
    groups.push_back(dataset.images[image].frameset_index);
  }
  ModelChoice model_choice;
  const bool success =
      SelectCameraModel(options.model_selection, upgrade_options, points2D,
                        points_cam, groups, camera, result, &model_choice);
  *choice = model_choice;
  return success;
}

void ReportModelChoice(const PipelineOptions& options,
                       const RigDataset& dataset, const int camera_index,
                       const std::optional<ModelChoice>& choice,
                       PipelineReport* report) {
  if (!choice) return;
  CameraModelReportOf(dataset, camera_index, report).choice = *choice;
  if (choice->uncertain) {
    AddDiagnostic(report, Diagnostic::Level::kWarning,
                  "uncertain_model_choice",
                  "camera " + dataset.cameras[camera_index].name + ": " +
                      choice->reason,
                  {camera_index});
  }
  if (options.print_progress) {
    std::cout << "  " << dataset.cameras[camera_index].name
              << ": automatic model choice\n"
              << FormatModelChoice(*choice, "    ") << std::flush;
  }
}

void ChooseCameraModelsFromPoses(const PipelineOptions& options,
                                 const RigDataset& dataset,
                                 RigCalibration* calibration,
                                 PipelineReport* report) {
  for (size_t c = 0; c < dataset.cameras.size(); ++c) {
    if (!dataset.cameras[c].choose_model ||
        !calibration->camera_calibrated[c]) {
      continue;
    }
    std::vector<Eigen::Vector2d> points2D;
    std::vector<Eigen::Vector3d> points_cam;
    std::vector<std::pair<int, int>> rows;
    for (size_t i = 0; i < dataset.images.size(); ++i) {
      const RigImage& image = dataset.images[i];
      if (image.camera_index != static_cast<int>(c) ||
          !calibration->rig_from_world[image.frameset_index]) {
        continue;
      }
      const Rigid3d cam_from_world =
          calibration->CamFromWorld(image.camera_index, image.frameset_index);
      for (size_t k = 0; k < image.correspondences.size(); ++k) {
        points2D.push_back(image.correspondences[k].point2D);
        points_cam.push_back(cam_from_world * image.correspondences[k].point3D);
        rows.emplace_back(static_cast<int>(i), static_cast<int>(k));
      }
    }
    colmap::Camera camera = calibration->cameras[c];
    CameraUpgradeResult result;
    std::optional<ModelChoice> choice;
    if (UpgradeOrChooseCameraModel(options, dataset, static_cast<int>(c),
                                   points2D, points_cam, rows, &camera, &result,
                                   &choice)) {
      calibration->cameras[c] = camera;
    } else {
      calibration->camera_calibrated[c] = false;
      AddDiagnostic(report, Diagnostic::Level::kWarning, "upgrade_failed",
                    "no camera model could be chosen for camera " +
                        dataset.cameras[c].name + ": " + result.error_message,
                    {static_cast<int>(c)});
    }
    ReportModelChoice(options, dataset, static_cast<int>(c), choice, report);
  }
}


bool ChooseCameraModelsOnAdjustedRig(const PipelineOptions& options,
                                     const CalibrationMethod method,
                                     const RigDataset& dataset,
                                     RigCalibration* calibration,
                                     PipelineReport* report) {
  const FinalBundleAdjustmentOptions ba_options =
      FinalBundleAdjustmentOptionsFor(options, method, dataset);
  std::vector<int> cameras;
  for (size_t c = 0; c < dataset.cameras.size(); ++c) {
    if (dataset.cameras[c].choose_model && calibration->camera_calibrated[c] &&
        ba_options.refine_focal_length && ba_options.refine_extra_params) {
      cameras.push_back(static_cast<int>(c));
    }
  }
  if (cameras.empty()) return false;
  StageTimer stage("Model choice on the adjusted rig", options.print_progress,
                   report);
  ModelChoiceAfterAdjustmentOptions choice_options =
      options.model_choice_after_adjustment;
  choice_options.loss_scale_px = ba_options.loss_scale_px;
  choice_options.max_error_px = options.upgrade.max_error_px;
  choice_options.validity = options.model_selection.validity;
  choice_options.min_num_framesets = options.model_selection.min_num_framesets;

  // The cameras' choices are independent: one thread each, the results
  // applied in camera order below (the same whatever the thread count).
  const int num_cameras = static_cast<int>(cameras.size());
  std::vector<AdjustedCameraRows> rows(num_cameras);
  std::vector<colmap::Camera> fitted(num_cameras);
  std::vector<Rigid3d> fitted_cam_from_rig(num_cameras);
  std::vector<ModelChoice> choices(num_cameras);
  std::vector<char> chosen(num_cameras, 0);
#pragma omp parallel for schedule(dynamic) \
    num_threads(options.num_threads > 0 ? options.num_threads : omp_get_max_threads())
  for (int j = 0; j < num_cameras; ++j) {
    const int c = cameras[j];
    ModelChoiceAfterAdjustmentOptions camera_options = choice_options;
    camera_options.refine_principal_point =
        ba_options.refine_principal_point &&
        dataset.cameras[c].refinement.principal_point;
    // After the capture-time model kept offsets or line delays, refined
    // points as the other images place them (points_without_camera.h): the
    // adjustment refined them through the camera upgrade's models, chosen on
    // the data before the time model changed them. Not otherwise: there the
    // refined points are the better reference. On the real ring
    // (scripts/real_data_check.sh) the points placed without the camera
    // raised the candidates' training errors from 1.4 to 2.2 px (the real
    // map's own errors) and turned 6 of 25 cameras' choices to fisheye
    // models against the map's OPENCV.
    const bool retriangulate =
        ba_options.refine_points &&
        (report->capture_time_model.time_offsets_kept ||
         report->capture_time_model.line_delays_kept);
    std::unordered_map<int64_t, Eigen::Vector3d> points;
    if (retriangulate) {
      PointsWithoutCameraOptions points_options;
      points_options.map_observations = ba_options.use_map_observations;
      points = PointsWithoutCamera(dataset, *calibration,
                                   report->capture_time_model, c,
                                   points_options);
    }
    rows[j] = AdjustedRowsOf(dataset, *calibration,
                             report->capture_time_model, c,
                             retriangulate ? &points : nullptr);
    fitted[j] = calibration->cameras[c];
    fitted_cam_from_rig[j] = calibration->cam_from_rig[c];
    chosen[j] = ChooseModelOnAdjustedRig(camera_options, rows[j], &fitted[j],
                                         &fitted_cam_from_rig[j], &choices[j]);
  }

  bool changed = false;
  for (int j = 0; j < num_cameras; ++j) {
    const int c = cameras[j];
    ModelChoice& choice = choices[j];
    CameraModelReport& model_report = CameraModelReportOf(dataset, c, report);
    if (!chosen[j]) {
      // The upgrade's choice stands, and says why.
      if (model_report.choice) {
        model_report.choice->reason +=
            "; not chosen again on the adjusted rig: " + choice.reason;
      }
      continue;
    }
    const std::string first_choice =
        model_report.choice ? model_report.choice->chosen : "";
    const bool first_uncertain =
        model_report.choice && model_report.choice->uncertain;
    const int num_framesets = static_cast<int>(
        std::set<int>(rows[j].framesets.begin(), rows[j].framesets.end())
            .size());
    choice.reason += "; the first choice, at the camera upgrade, was " +
                     (first_choice.empty() ? std::string("none")
                                           : first_choice);
    if (num_framesets < options.model_selection.min_num_framesets ||
        first_uncertain) {
      choice.uncertain = true;
      choice.reason += ". The choice is not sure: " +
                       std::to_string(num_framesets) +
                       " framesets see this camera (held-out comparisons "
                       "need at least " +
                       std::to_string(options.model_selection.min_num_framesets) +
                       "); give a model if you know the lens's";
    }
    // The same model: the adjustment's values stand (the fit held the rig
    // and the points); another: the fit starts the adjustment's second run.
    if (choice.chosen != calibration->cameras[c].ModelName()) {
      calibration->cameras[c] = fitted[j];
      calibration->cam_from_rig[c] = fitted_cam_from_rig[j];
      changed = true;
    }
    // The upgrade's warning, if any, is replaced by this choice's.
    report->diagnostics.erase(
        std::remove_if(report->diagnostics.begin(), report->diagnostics.end(),
                       [&](const Diagnostic& diagnostic) {
                         return diagnostic.code == "uncertain_model_choice" &&
                                diagnostic.cameras == std::vector<int>{c};
                       }),
        report->diagnostics.end());
    model_report.choice.reset();
    ReportModelChoice(options, dataset, c, choice, report);
  }
  return changed;
}

void CheckCameraModels(const PipelineOptions& options,
                       const RigDataset& dataset,
                       const RigCalibration& calibration,
                       PipelineReport* report) {
  RadialResidualProfileOptions profile_options =
      options.model_selection.validity.residual_profile;
  profile_options.systematic_floor_px =
      MapSystematicFloorPx(options, dataset, calibration);
  // The cameras' checks are independent: one thread each, reported in
  // camera order below (the same whatever the thread count).
  const int num_cameras = static_cast<int>(dataset.cameras.size());
  std::vector<ModelValidity> validities(num_cameras);
  std::vector<RadialResidualProfile> profiles(num_cameras);
#pragma omp parallel for schedule(dynamic) num_threads( \
    options.num_threads > 0 ? options.num_threads : omp_get_max_threads())
  for (int c = 0; c < num_cameras; ++c) {
    if (!calibration.camera_calibrated[c]) continue;
    const colmap::Camera& camera = calibration.cameras[c];
    validities[c] =
        CheckModelValidity(camera, options.model_selection.validity);
    std::vector<Eigen::Vector2d> observed, projected;
    std::vector<int> images;
    FinalInlierPixels(dataset, calibration, report->capture_time_model, c,
                      &observed, &projected, &images);
    profiles[c] = ComputeRadialResidualProfile(
        Eigen::Vector2d(camera.PrincipalPointX(), camera.PrincipalPointY()),
        observed, projected, images, profile_options);
  }
  for (int c = 0; c < num_cameras; ++c) {
    if (!calibration.camera_calibrated[c]) continue;
    const colmap::Camera& camera = calibration.cameras[c];
    ModelValidity& validity = validities[c];
    const RadialResidualProfile& profile = profiles[c];
    const IntrinsicsRefinement& refinement = dataset.cameras[c].refinement;
    const bool parameters_held = !refinement.focal_length ||
                                 !refinement.principal_point ||
                                 !refinement.extra_params;
    AddResidualProfileCheck(camera, profile, parameters_held, &validity);
    if (parameters_held && !validity.fits_data) {
      AddDiagnostic(
          report, Diagnostic::Level::kWarning, "held_intrinsics_misfit",
          "camera " + dataset.cameras[c].name +
              ": with intrinsics held at their given values "
              "(--RigCalibrator.refine_* 0), " +
              DescribeRadialMisfit(profile) +
              ", where a model that fits leaves no such bias: the given "
              "values (or the model) do not fit the data. Check them, or "
              "let the calibration refine them.",
          {c});
    }
    CameraModelReportOf(dataset, c, report).validity = validity;
    if (!validity.valid) {
      AddDiagnostic(
          report, Diagnostic::Level::kError, "invalid_camera_model",
          "camera " + dataset.cameras[c].name + ": " + validity.message, {c});
    }
  }
}

}  // namespace rig_calibrator
