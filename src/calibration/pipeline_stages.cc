#include "src/calibration/pipeline_stages.h"

#include <colmap/util/math.h>

#include <algorithm>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <utility>

#include "src/calibration/camera_model_stage.h"
#include "src/calibration/complete_frameset_initialization.h"
#include "src/calibration/inlier_selection.h"
#include "src/calibration/model_choice_spread.h"

namespace rig_calibrator {
namespace {

RigInitializerOptions RigInitializerOptionsFor(const PipelineOptions& options,
                                               bool radial) {
  RigInitializerOptions init_options = options.rig_initializer;
  init_options.radial = radial;
  init_options.num_threads = options.num_threads;
  init_options.seed = options.seed;
  return init_options;
}

// The camera upgrade's input for one camera: its radial inliers pooled over
// all its images of posed framesets, the map points in the camera frame, and
// where each row came from.
struct UpgradeInput {
  std::vector<Eigen::Vector2d> points2D;
  std::vector<Eigen::Vector3d> points_cam;
  std::vector<std::pair<int, int>> rows;  // (image, correspondence)
};

UpgradeInput GatherUpgradeInput(const RigDataset& dataset,
                                const RigCalibration& calibration, int camera) {
  UpgradeInput input;
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    const RigImage& image = dataset.images[i];
    if (image.camera_index != camera || !FramesetPosed(calibration, image)) {
      continue;
    }
    const Rigid3d cam_from_world =
        calibration.CamFromWorld(camera, image.frameset_index);
    for (size_t k = 0; k < image.correspondences.size(); ++k) {
      if (!calibration.images[i].inlier_mask[k]) continue;
      input.points2D.push_back(image.correspondences[k].point2D);
      input.points_cam.push_back(cam_from_world *
                                 image.correspondences[k].point3D);
      input.rows.emplace_back(static_cast<int>(i), static_cast<int>(k));
    }
  }
  return input;
}

// A successful upgrade of `camera`: its forward offset, and as inliers of its
// images exactly the upgrade's inliers.
void ApplyUpgrade(const RigDataset& dataset, int camera,
                  const UpgradeInput& input, const CameraUpgradeResult& result,
                  RigCalibration* calibration) {
  calibration->cam_from_rig[camera].translation.z() = result.tz;
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    if (dataset.images[i].camera_index != camera) continue;
    calibration->images[i].inlier_mask.assign(
        dataset.images[i].correspondences.size(), 0);
    calibration->images[i].num_inliers = 0;
  }
  for (size_t r = 0; r < input.rows.size(); ++r) {
    if (!result.inlier_mask[r]) continue;
    ImageResult& image = calibration->images[input.rows[r].first];
    image.inlier_mask[input.rows[r].second] = 1;
    ++image.num_inliers;
  }
}

// Diagnostics and progress of one camera's upgrade.
void ReportUpgrade(const PipelineOptions& options, const RigDataset& dataset,
                   int camera, const UpgradeInput& input, bool success,
                   const CameraUpgradeResult& result,
                   const RigCalibration& calibration, PipelineReport* report) {
  const std::string& name = dataset.cameras[camera].name;
  if (!success) {
    AddDiagnostic(report, Diagnostic::Level::kWarning, "upgrade_failed",
                  "the intrinsics of camera " + name +
                      " could not be estimated from its " +
                      std::to_string(input.rows.size()) +
                      " radial inliers: " + result.error_message,
                  {camera});
    return;
  }
  if (!result.well_conditioned) {
    AddDiagnostic(report, Diagnostic::Level::kWarning,
                  "focal_tz_ill_conditioned",
                  "camera " + name +
                      ": focal length and forward offset are poorly separated "
                      "(correlation " +
                      std::to_string(result.tz_focal_correlation) +
                      "); the scene seen by this camera has too little depth "
                      "variation. Record closer and farther structure.",
                  {camera});
  }
  if (options.print_progress) {
    const colmap::Camera& intrinsics = calibration.cameras[camera];
    std::cout << "  " << name << ": " << result.num_inliers << " inliers, tz "
              << result.tz << ", " << intrinsics.ModelName() << " "
              << intrinsics.ParamsToString() << ", RMS " << result.rms_px
              << " px" << std::endl;
  }
}

// Paper §3.5: per camera, all its frames pooled, the forward translation tz
// and the intrinsics of its model from the radial rig. Cameras are upgraded
// in parallel; the results are applied in camera order.
void UpgradeCameras(const PipelineOptions& options, const RigDataset& dataset,
                    RigCalibration* calibration, PipelineReport* report) {
  const int num_cameras = static_cast<int>(dataset.cameras.size());
  std::vector<UpgradeInput> inputs(num_cameras);
  std::vector<CameraUpgradeResult> results(num_cameras);
  std::vector<char> success(num_cameras, 0);
  std::vector<std::optional<ModelChoice>> choices(num_cameras);
#pragma omp parallel for schedule(dynamic) num_threads( \
    std::max(1, options.num_threads > 0 ? options.num_threads : num_cameras))
  for (int c = 0; c < num_cameras; ++c) {
    if (!calibration->camera_calibrated[c]) continue;
    inputs[c] = GatherUpgradeInput(dataset, *calibration, c);
    success[c] = UpgradeOrChooseCameraModel(
        options, dataset, c, inputs[c].points2D, inputs[c].points_cam,
        inputs[c].rows, &calibration->cameras[c], &results[c], &choices[c]);
  }
  for (int c = 0; c < num_cameras; ++c) {
    if (!calibration->camera_calibrated[c]) continue;
    ReportModelChoice(options, dataset, c, choices[c], report);
    if (success[c]) {
      ApplyUpgrade(dataset, c, inputs[c], results[c], calibration);
    } else {
      calibration->camera_calibrated[c] = false;
    }
    ReportUpgrade(options, dataset, c, inputs[c], success[c], results[c],
                  *calibration, report);
  }
}

// The rig frame is the reference camera's frame. The radial stages fix the
// reference camera's tz at 0; after the upgrade it has a forward offset,
// which moves into the rig poses: P_i <- P_i P_ref^-1, Q_j <- P_ref Q_j.
void AnchorRigAtReferenceCamera(int reference_camera,
                                RigCalibration* calibration) {
  const Rigid3d ref_from_rig = calibration->cam_from_rig[reference_camera];
  const Rigid3d rig_from_ref = ref_from_rig.Inverse();
  for (Rigid3d& cam_from_rig : calibration->cam_from_rig) {
    cam_from_rig = cam_from_rig * rig_from_ref;
  }
  calibration->cam_from_rig[reference_camera] = Rigid3d();
  for (std::optional<Rigid3d>& rig_from_world : calibration->rig_from_world) {
    if (rig_from_world) rig_from_world = ref_from_rig * *rig_from_world;
  }
}

// Per-camera intrinsics for the full-pose methods that estimate them per
// image: the element-wise median (colmap::Median: the mean of the two middle
// values for an even count) of the localized images' parameters; the held
// ones are the dataset camera's.
void MedianIntrinsics(const RigDataset& dataset,
                      const std::vector<colmap::Camera>& per_image_cameras,
                      RigCalibration* calibration) {
  for (size_t c = 0; c < dataset.cameras.size(); ++c) {
    std::vector<std::vector<double>> values;
    for (size_t i = 0; i < dataset.images.size(); ++i) {
      if (dataset.images[i].camera_index != static_cast<int>(c) ||
          !calibration->images[i].localized) {
        continue;
      }
      const std::vector<double>& params = per_image_cameras[i].Params();
      if (values.empty()) values.resize(params.size());
      for (size_t p = 0; p < params.size(); ++p) values[p].push_back(params[p]);
    }
    if (values.empty()) continue;
    std::vector<double> median(values.size());
    for (size_t p = 0; p < values.size(); ++p) {
      median[p] = colmap::Median(values[p]);
    }
    calibration->cameras[c].SetParams(median);
    RestoreHeldParams(dataset.cameras[c].camera, dataset.cameras[c].refinement,
                      &calibration->cameras[c]);
  }
}

}  // namespace

void InitializeCalibration(const RigDataset& dataset,
                           RigCalibration* calibration) {
  const int num_cameras = static_cast<int>(dataset.cameras.size());
  *calibration = RigCalibration();
  for (const RigCamera& camera : dataset.cameras) {
    calibration->cameras.push_back(camera.camera);
  }
  calibration->cam_from_rig.assign(num_cameras, Rigid3d());
  calibration->camera_calibrated.assign(num_cameras, false);
  calibration->rig_from_world.assign(dataset.frameset_names.size(),
                                     std::nullopt);
  calibration->images.assign(dataset.images.size(), ImageResult());
}

bool RunRadialStages(const PipelineOptions& options, const RigDataset& dataset,
                     RigCalibration* calibration, PipelineReport* report) {
  {
    StageTimer stage("Radial rig initialization", options.print_progress,
                     report);
    RigInitializerSummary summary;
    if (!InitializeRig(RigInitializerOptionsFor(options, /*radial=*/true),
                       dataset, calibration, &summary)) {
      report->error =
          "the radial rig initialization failed: " + summary.message;
      return false;
    }
  }
  {
    StageTimer stage("Radial bundle adjustment", options.print_progress,
                     report);
    RadialBundleAdjustmentOptions ba_options = options.radial_bundle_adjustment;
    ba_options.num_threads = options.num_threads;
    RadialBundleAdjustmentSummary summary;
    if (!AdjustRadialRig(ba_options, dataset, calibration, &summary)) {
      report->error = "the radial bundle adjustment failed (see above)";
      return false;
    }
    stage.SetNumIterations(summary.num_iterations);
    if (options.print_progress) {
      std::cout << "  radial RMS " << summary.initial_rms_px << " -> "
                << summary.final_rms_px << " px over " << summary.num_residuals
                << " residuals, " << summary.num_iterations << " iterations"
                << std::endl;
    }
  }
  StageTimer stage("Camera upgrade", options.print_progress, report);
  SelectRadialInliers(dataset, options.upgrade_radial_max_error_px,
                      calibration);
  UpgradeCameras(options, dataset, calibration, report);
  if (!calibration->camera_calibrated[dataset.reference_camera]) {
    report->error = "the reference camera " +
                    dataset.cameras[dataset.reference_camera].name +
                    " could not be upgraded; choose another reference camera";
    return false;
  }
  AnchorRigAtReferenceCamera(dataset.reference_camera, calibration);
  return true;
}

bool RunFullPoseRigInitialization(
    const PipelineOptions& options, CalibrationMethod method,
    const RigDataset& dataset,
    const std::vector<colmap::Camera>& per_image_cameras,
    RigCalibration* calibration, PipelineReport* report) {
  StageTimer stage("Rig initialization", options.print_progress, report);
  if (!UsesKnownIntrinsics(method)) {
    MedianIntrinsics(dataset, per_image_cameras, calibration);
  }
  std::string error;
  if (UsesCompleteFramesetInitialization(method)) {
    if (InitializeRigFromCompleteFrameset(dataset, calibration, &error)) {
      return true;
    }
    report->error =
        "method " + CalibrationMethodName(method) +
        " takes the rig from a frameset in which every camera was localized, "
        "and " +
        error + ": use " +
        (UsesKnownIntrinsics(method) ? "known_ra" : "rd_ra or 1dr") +
        ", which need no complete frameset";
    return false;
  }
  RigInitializerSummary summary;
  if (!InitializeRig(RigInitializerOptionsFor(options, /*radial=*/false),
                     dataset, calibration, &summary)) {
    report->error = "the rig initialization failed: " + summary.message;
    return false;
  }
  return true;
}

FinalBundleAdjustmentOptions FinalBundleAdjustmentOptionsFor(
    const PipelineOptions& options, CalibrationMethod method,
    const RigDataset& dataset) {
  FinalBundleAdjustmentOptions ba_options = options.final_bundle_adjustment;
  // Its solver's result does not depend on the thread count.
  ba_options.num_threads = options.num_threads;
  // Map images can all be missing although there is a map (e.g. its cameras
  // are of models this build cannot project): nothing to adjust then.
  if (dataset.map_images.empty()) {
    ba_options.refine_map = false;
    ba_options.refine_map_intrinsics = false;
  }
  if (!RefinesIntrinsics(method)) {
    ba_options.refine_focal_length = false;
    ba_options.refine_principal_point = false;
    ba_options.refine_extra_params = false;
  }
  return ba_options;
}

bool RunFinalBundleAdjustment(const PipelineOptions& options,
                              CalibrationMethod method,
                              const RigDataset& dataset,
                              RigCalibration* calibration,
                              PipelineReport* report,
                              const std::string& stage_name) {
  StageTimer stage(stage_name, options.print_progress, report);
  // With the capture-time model's kept kinds once it ran (they are
  // estimated again, from its values), and the inliers at their instants.
  const FinalBundleAdjustmentOptions ba_options =
      WithCaptureTimes(FinalBundleAdjustmentOptionsFor(options, method, dataset),
                       report->capture_time_model);
  SelectFullInliers(dataset, options.upgrade.max_error_px, calibration,
                    ba_options.initial_time_offsets_s,
                    ba_options.initial_line_delays_s);
  // What was estimated of each camera's intrinsics in the whole pipeline:
  // the final adjustment's refinement (the known* methods estimate nothing
  // before it, the others hold the same parameters in every stage).
  report->refined_intrinsics.clear();
  for (size_t c = 0; c < dataset.cameras.size(); ++c) {
    report->refined_intrinsics.push_back(
        IntrinsicsRefinement{ba_options.refine_focal_length,
                             ba_options.refine_principal_point,
                             ba_options.refine_extra_params}
            .And(dataset.cameras[c].refinement));
  }
  FinalBundleAdjustmentSummary summary;
  if (!AdjustRig(ba_options, dataset, calibration, &summary)) {
    report->error = "the final bundle adjustment failed (see above)";
    return false;
  }
  stage.SetNumIterations(summary.num_iterations);
  report->final_rms_px = summary.final_rms_px;
  if (ba_options.HasTimeModel()) {
    // The new values; their sigmas: the uncertainty step's.
    CaptureTimeModel& time_model = report->capture_time_model;
    for (size_t c = 0; c < summary.capture_times.size(); ++c) {
      time_model.cameras[c].time_offset_s =
          summary.capture_times[c].time_offset_s;
      time_model.cameras[c].line_delay_s = summary.capture_times[c].line_delay_s;
    }
    time_model.rms_px = summary.final_rms_px;
  }
  if (options.print_progress) {
    std::cout << "  RMS " << summary.initial_rms_px << " -> "
              << summary.final_rms_px << " px over " << summary.num_residuals
              << " residuals, " << summary.num_outliers << " outliers removed, "
              << summary.num_iterations << " iterations" << std::endl;
    if (summary.num_map_residuals > 0) {
      std::cout << "  map images: RMS " << summary.map_initial_rms_px << " -> "
                << summary.map_final_rms_px << " px over "
                << summary.num_map_residuals
                << " observations of refined "
                   "points, "
                << summary.num_map_outliers << " rejected" << std::endl;
    }
  }
  return true;
}

bool RunCaptureTimeModel(const PipelineOptions& options,
                         CalibrationMethod method, const RigDataset& dataset,
                         RigCalibration* calibration, PipelineReport* report) {
  const CaptureTimeModelOptions& model_options = options.capture_time_model;
  const bool runs =
      (model_options.time_offsets != CaptureTimeMode::kOff ||
       model_options.rolling_shutter != CaptureTimeMode::kOff) &&
      !dataset.frameset_times_s.empty();
  CaptureTimeModelOptions effective = model_options;
  effective.inlier_max_error_px = options.upgrade.max_error_px;
  effective.start_estimate = options.capture_timing;
  std::string error;
  if (!runs) {
    // Only the error of a mode that is on without frameset times.
    if (!AdjustRigWithCaptureTimeModel(
            effective, FinalBundleAdjustmentOptionsFor(options, method, dataset),
            dataset, calibration, &report->capture_time_model, &error)) {
      report->error = error;
      return false;
    }
    return true;
  }
  StageTimer stage("Capture-time model", options.print_progress, report);
  if (!AdjustRigWithCaptureTimeModel(
          effective, FinalBundleAdjustmentOptionsFor(options, method, dataset),
          dataset, calibration, &report->capture_time_model, &error)) {
    report->error = error;
    return false;
  }
  const CaptureTimeModel& model = report->capture_time_model;
  if (model.time_offsets_kept || model.line_delays_kept) {
    report->final_rms_px = model.rms_px;
  }
  if (model.time_offsets_kept &&
      model.frameset_interval_s >
          model_options.max_followed_frameset_interval_s) {
    std::ostringstream message;
    message << "the framesets are " << std::setprecision(3)
            << model.frameset_interval_s << " s apart (median), more than "
            << model_options.max_followed_frameset_interval_s
            << " s: they do not follow the rig's motion, and the time "
               "model's offsets hold each camera's centre against the rig's "
               "velocity only as well as its prior does; the sigmas of "
               "cam_from_rig can be too small (on synthetic rigs at 5 and 10 "
               "Hz the rotation errors were up to 1.5 sigma RMS). Record "
               "framesets at 15 Hz or faster, or compare with a calibration "
               "from other framesets";
    AddDiagnostic(report, Diagnostic::Level::kWarning,
                  "time_model_framesets_sparse", message.str(), {});
  }
  if (options.print_progress) {
    std::cout << "  " << model.message << std::endl;
  }
  return true;
}

void RunUncertaintyEstimation(const PipelineOptions& options,
                              CalibrationMethod method,
                              const RigDataset& dataset,
                              const RigCalibration& calibration,
                              PipelineReport* report) {
  StageTimer stage("Uncertainty", options.print_progress, report);
  // With the capture-time model's kept kinds: the uncertainty of the
  // adjustment the calibration comes from.
  report->uncertainty = EstimateCalibrationUncertainty(
      WithCaptureTimes(FinalBundleAdjustmentOptionsFor(options, method, dataset),
                       report->capture_time_model),
      dataset, calibration);
  SetCaptureTimeSigmas(report->uncertainty,
                       &report->capture_time_model.cameras);
  // The model choice's share (model_choice_spread.h): for the cameras whose
  // model the choice on the adjusted rig set.
  for (size_t c = 0; c < report->camera_models.size() &&
                     c < report->uncertainty.cameras.size();
       ++c) {
    const std::optional<ModelChoice>& choice = report->camera_models[c].choice;
    if (choice && choice->chosen == calibration.cameras[c].ModelName()) {
      AddModelChoiceSpread(choice->parameter_spread,
                           &report->uncertainty.cameras[c]);
    }
  }
  for (const Diagnostic& diagnostic :
       UncertaintyDiagnostics(dataset, calibration, report->uncertainty)) {
    report->diagnostics.push_back(diagnostic);
  }
  if (options.print_progress) {
    const CalibrationUncertainty& uncertainty = report->uncertainty;
    if (uncertainty.computed) {
      std::cout << "  residual scale " << uncertainty.residual_scale_px
                << " px (effective " << uncertainty.effective_scale_px
                << " px), " << uncertainty.num_residuals << " residuals, "
                << uncertainty.num_parameters << " parameters, "
                << uncertainty.seconds << " s" << std::endl;
    } else {
      std::cout << "  not computed: " << uncertainty.message << std::endl;
    }
  }
}

void RunCaptureTiming(const PipelineOptions& options, const RigDataset& dataset,
                      const RigCalibration& calibration,
                      PipelineReport* report) {
  const int num_calibrated = static_cast<int>(
      std::count(calibration.camera_calibrated.begin(),
                 calibration.camera_calibrated.end(), true));
  if (dataset.frameset_times_s.empty() || num_calibrated < 2) return;
  StageTimer stage("Capture-time offsets", options.print_progress, report);
  CaptureTiming& timing = report->capture_timing;
  std::vector<std::string> names;
  for (const RigCamera& camera : dataset.cameras) names.push_back(camera.name);
  // With offsets in the final adjustment's time model the measurement from
  // single-image poses is a weaker estimate of what the model estimated
  // (about 8 % of the command's time at 500 x 10): not made.
  if (report->capture_time_model.time_offsets_kept) {
    timing = CaptureTiming();
    timing.computed = true;
    timing.error =
        "the final adjustment's time model estimated the offsets";
    if (options.print_progress) {
      std::cout << "  "
                << CaptureTimingLine(names, dataset.reference_camera, timing)
                << std::endl;
    }
    return;
  }
  timing = MeasureCaptureTiming(dataset, calibration, report->uncertainty,
                                options.capture_timing);
  if (options.print_progress) {
    std::cout << "  "
              << CaptureTimingLine(names, dataset.reference_camera, timing)
              << std::endl;
  }
  std::vector<int> cameras;
  std::ostringstream offsets;
  for (size_t c = 0; c < timing.significant.size(); ++c) {
    if (!timing.significant[c]) continue;
    offsets << (cameras.empty() ? "" : ", ") << names[c] << " "
            << std::showpos << std::fixed << std::setprecision(1)
            << timing.offsets[c].offset_s * 1e3 << std::noshowpos
            << " +- " << timing.offsets[c].offset_sigma_s * 1e3 << " ms";
    cameras.push_back(static_cast<int>(c));
  }
  // With the final adjustment's time model the calibration is not biased by
  // the capture times: nothing to warn about. With line delays alone the
  // measurement takes each image at one instant, so it reads the readouts'
  // differences as offsets (about 1 ms between 20 and 26 us/row over 480
  // rows: the warning fired on every preset of the benchmark's line-delay
  // case, docs/time_model.md), while the model found no significant offset.
  const CaptureTimeModel& time_model = report->capture_time_model;
  if (cameras.empty() || time_model.time_offsets_kept ||
      time_model.line_delays_kept) {
    return;
  }
  std::ostringstream message;
  message << "the cameras were not synchronized: " << offsets.str()
          << " (capture time minus " << names[dataset.reference_camera]
          << "'s, from each image's own pose and the frameset times; the rig "
             "turns at "
          << std::fixed << std::setprecision(1)
          << timing.rig_angular_speed_rad_s * 180.0 / M_PI
          << " deg/s). The calibration assumes that every frameset was "
             "taken at one instant: the cam_from_rig and intrinsics of "
          << CameraList(dataset, cameras)
          << " are biased by the rig's motion during the offset (and the "
             "offsets, measured with those intrinsics, are lower bounds). "
             "Synchronize the cameras, or calibrate from framesets taken "
             "while the rig stands still.";
  AddDiagnostic(report, Diagnostic::Level::kWarning, "unsynchronized_cameras",
                message.str(), cameras);
}

}  // namespace rig_calibrator
