#include "src/calibration/pipeline.h"

#include <colmap/util/timer.h>
#include <sys/resource.h>

#include <algorithm>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>

#include "src/geometry/radial_error.h"

namespace rig_calibrator {
namespace {

const std::vector<std::pair<CalibrationMethod, std::string>>& MethodNames() {
  static const std::vector<std::pair<CalibrationMethod, std::string>> names = {
      {CalibrationMethod::kKnown, "known"},
      {CalibrationMethod::kKnownRefine, "known_refine"},
      {CalibrationMethod::kRd, "rd"},
      {CalibrationMethod::kRdRa, "rd_ra"},
      {CalibrationMethod::kRadial1D, "1dr"}};
  return names;
}

bool UsesKnownIntrinsics(CalibrationMethod method) {
  return method == CalibrationMethod::kKnown ||
         method == CalibrationMethod::kKnownRefine;
}

std::string CameraList(const RigDataset& dataset,
                       const std::vector<int>& cameras) {
  std::string list;
  for (const int camera : cameras) {
    list += (list.empty() ? "" : ", ") + dataset.cameras[camera].name;
  }
  return list;
}

// User + system CPU time of the process so far (all threads).
double ProcessCpuSeconds() {
  rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
         1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

// Times a stage and prints its heading; the destructor records the wall and
// CPU times.
class Stage {
 public:
  Stage(const std::string& name, bool print, PipelineReport* report)
      : name_(name), report_(report), cpu_start_(ProcessCpuSeconds()) {
    if (print) std::cout << "== " << name << std::endl;
    timer_.Start();
  }
  ~Stage() {
    report_->timings.push_back(
        {name_, timer_.ElapsedSeconds(), ProcessCpuSeconds() - cpu_start_});
  }

 private:
  std::string name_;
  PipelineReport* report_;
  colmap::Timer timer_;
  double cpu_start_;
};

void AddDiagnostic(PipelineReport* report, Diagnostic::Level level,
                   const std::string& code, const std::string& message,
                   std::vector<int> cameras = {},
                   std::vector<int> framesets = {}) {
  report->diagnostics.push_back(
      {level, code, message, std::move(cameras), std::move(framesets)});
}

// Reports cameras with no localized image, and cameras that were localized
// but never in a frameset together with another localized camera (nothing
// ties them to the rig).
void DiagnoseLocalization(const RigDataset& dataset,
                          const RigCalibration& calibration,
                          PipelineReport* report) {
  const int num_cameras = static_cast<int>(dataset.cameras.size());
  std::vector<int> num_localized(num_cameras, 0);
  std::vector<int> num_shared(num_cameras, 0);
  std::map<int, std::vector<int>> localized_by_frameset;
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    if (!calibration.images[i].localized) continue;
    ++num_localized[dataset.images[i].camera_index];
    localized_by_frameset[dataset.images[i].frameset_index].push_back(
        dataset.images[i].camera_index);
  }
  for (const auto& [frameset, cameras] : localized_by_frameset) {
    if (cameras.size() < 2) continue;
    for (const int camera : cameras) ++num_shared[camera];
  }
  std::vector<int> never_localized, never_shared;
  for (int c = 0; c < num_cameras; ++c) {
    if (num_localized[c] == 0) {
      never_localized.push_back(c);
    } else if (num_shared[c] == 0) {
      never_shared.push_back(c);
    }
  }
  if (!never_localized.empty()) {
    AddDiagnostic(report, Diagnostic::Level::kWarning, "camera_not_localized",
                  "no image of camera(s) " +
                      CameraList(dataset, never_localized) +
                      " could be localized in the map (too few 2D-3D inliers): "
                      "they cannot be calibrated. Record more of the mapped "
                      "scene with them, or check their images and features.",
                  never_localized);
  }
  if (!never_shared.empty()) {
    AddDiagnostic(report, Diagnostic::Level::kWarning,
                  "camera_not_in_shared_frameset",
                  "camera(s) " + CameraList(dataset, never_shared) +
                      " were localized, but never in a frameset where another "
                      "camera was localized too: nothing ties them to the rig.",
                  never_shared);
  }
}

// Rig pose of a frameset from full camera poses and known cam_from_rig:
// rig_from_world = cam_from_rig^-1 * cam_from_world for each camera, averaged
// (rotation: chordal L2 mean, i.e. the nearest rotation of the summed
// matrices; translation: mean of the rig centers mapped back).
Rigid3d AverageRigFromWorld(const std::vector<Rigid3d>& estimates) {
  Eigen::Matrix3d rotation_sum = Eigen::Matrix3d::Zero();
  Eigen::Vector3d center_sum = Eigen::Vector3d::Zero();
  for (const Rigid3d& estimate : estimates) {
    rotation_sum += estimate.RotationMatrix();
    center_sum += estimate.Center();
  }
  const Eigen::Matrix3d rotation = NearestRotation(rotation_sum);
  const Eigen::Vector3d center = center_sum / estimates.size();
  return Rigid3d(rotation, -rotation * center);
}

// Heng et al.'s rig initialization (the rd method): the extrinsics come from
// the complete frameset (every camera localized) with the most inliers, the
// rig poses of the other framesets from their localized cameras.
bool InitializeRigFromCompleteFrameset(const RigDataset& dataset,
                                       RigCalibration* calibration,
                                       std::string* error) {
  const int num_cameras = static_cast<int>(dataset.cameras.size());
  std::vector<std::vector<int>> images_by_frameset(
      dataset.frameset_names.size());
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    if (calibration->images[i].localized) {
      images_by_frameset[dataset.images[i].frameset_index].push_back(i);
    }
  }
  int best_frameset = -1;
  int best_num_inliers = 0;
  for (size_t j = 0; j < images_by_frameset.size(); ++j) {
    if (static_cast<int>(images_by_frameset[j].size()) != num_cameras) continue;
    int num_inliers = 0;
    for (const int i : images_by_frameset[j]) {
      num_inliers += calibration->images[i].num_inliers;
    }
    if (num_inliers > best_num_inliers) {
      best_num_inliers = num_inliers;
      best_frameset = static_cast<int>(j);
    }
  }
  if (best_frameset < 0) {
    *error =
        "method rd takes the rig from a frameset in which every camera was "
        "localized, and none of the " +
        std::to_string(images_by_frameset.size()) +
        " framesets has one: use rd_ra or 1dr, which need no complete "
        "frameset";
    return false;
  }
  std::vector<Rigid3d> cam_from_world(num_cameras);
  for (const int i : images_by_frameset[best_frameset]) {
    cam_from_world[dataset.images[i].camera_index] =
        *calibration->images[i].single_image_cam_from_world;
  }
  const Rigid3d world_from_ref =
      cam_from_world[dataset.reference_camera].Inverse();
  for (int c = 0; c < num_cameras; ++c) {
    calibration->cam_from_rig[c] = cam_from_world[c] * world_from_ref;
    calibration->camera_calibrated[c] = true;
  }
  calibration->cam_from_rig[dataset.reference_camera] = Rigid3d();
  for (size_t j = 0; j < images_by_frameset.size(); ++j) {
    std::vector<Rigid3d> estimates;
    for (const int i : images_by_frameset[j]) {
      estimates.push_back(
          calibration->cam_from_rig[dataset.images[i].camera_index].Inverse() *
          *calibration->images[i].single_image_cam_from_world);
    }
    if (!estimates.empty()) {
      calibration->rig_from_world[j] = AverageRigFromWorld(estimates);
    }
  }
  return true;
}

// Per-camera intrinsics for the full-pose methods that estimate them per
// image: the element-wise median of the localized images' parameters.
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
      std::nth_element(values[p].begin(),
                       values[p].begin() + values[p].size() / 2,
                       values[p].end());
      median[p] = values[p][values[p].size() / 2];
    }
    calibration->cameras[c].SetParams(median);
  }
}

bool FramesetPosed(const RigCalibration& calibration, const RigImage& image) {
  return calibration.camera_calibrated[image.camera_index] &&
         calibration.rig_from_world[image.frameset_index].has_value();
}

// Marks, for every image of a posed frameset, the correspondences that
// `is_inlier(camera, cam_from_world, correspondence)` accepts; images of
// other framesets get none. This also brings in images that could not be
// localized on their own but whose frameset was posed by the other cameras.
template <typename Predicate>
void SelectInliers(const RigDataset& dataset, RigCalibration* calibration,
                   const Predicate& is_inlier) {
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    const RigImage& image = dataset.images[i];
    ImageResult& result = calibration->images[i];
    result.inlier_mask.assign(image.correspondences.size(), 0);
    result.num_inliers = 0;
    if (!FramesetPosed(*calibration, image)) continue;
    const Rigid3d cam_from_world =
        calibration->CamFromWorld(image.camera_index, image.frameset_index);
    const colmap::Camera& camera = calibration->cameras[image.camera_index];
    for (size_t k = 0; k < image.correspondences.size(); ++k) {
      if (is_inlier(camera, cam_from_world, image.correspondences[k])) {
        result.inlier_mask[k] = 1;
        ++result.num_inliers;
      }
    }
  }
}

// Inliers of the radial rig: radial reprojection error below max_error_px.
void SelectRadialInliers(const RigDataset& dataset, double max_error_px,
                         RigCalibration* calibration) {
  SelectInliers(dataset, calibration,
                [&](const colmap::Camera& camera, const Rigid3d& cam_from_world,
                    const Correspondence& correspondence) {
                  const Eigen::Vector2d principal_point(
                      camera.PrincipalPointX(), camera.PrincipalPointY());
                  return RadialReprojectionError(
                             cam_from_world,
                             correspondence.point2D - principal_point,
                             correspondence.point3D) < max_error_px;
                });
}

// Inliers of the full calibration: in front of the camera and reprojected
// within max_error_px.
void SelectFullInliers(const RigDataset& dataset, double max_error_px,
                       RigCalibration* calibration) {
  SelectInliers(dataset, calibration,
                [&](const colmap::Camera& camera, const Rigid3d& cam_from_world,
                    const Correspondence& correspondence) {
                  const Eigen::Vector3d point_cam =
                      cam_from_world * correspondence.point3D;
                  return point_cam.z() > 1e-9 &&
                         (camera.WorldToImage(point_cam.hnormalized()) -
                          correspondence.point2D)
                                 .norm() < max_error_px;
                });
}

// Paper §3.5: per camera, all its frames pooled, the forward translation tz
// and the intrinsics of its model from the radial rig.
void UpgradeCameras(const PipelineOptions& options, const RigDataset& dataset,
                    RigCalibration* calibration, PipelineReport* report) {
  const int num_cameras = static_cast<int>(dataset.cameras.size());
  std::vector<CameraUpgradeResult> results(num_cameras);
  std::vector<char> success(num_cameras, 0);
  // (image index, correspondence index) of every upgrade input row.
  std::vector<std::vector<std::pair<int, int>>> rows(num_cameras);

#pragma omp parallel for schedule(dynamic) num_threads( \
    std::max(1, options.num_threads > 0 ? options.num_threads : num_cameras))
  for (int c = 0; c < num_cameras; ++c) {
    if (!calibration->camera_calibrated[c]) continue;
    std::vector<Eigen::Vector2d> points2D;
    std::vector<Eigen::Vector3d> points_cam;
    for (size_t i = 0; i < dataset.images.size(); ++i) {
      const RigImage& image = dataset.images[i];
      if (image.camera_index != c || !FramesetPosed(*calibration, image)) {
        continue;
      }
      const Rigid3d cam_from_world =
          calibration->CamFromWorld(c, image.frameset_index);
      for (size_t k = 0; k < image.correspondences.size(); ++k) {
        if (!calibration->images[i].inlier_mask[k]) continue;
        points2D.push_back(image.correspondences[k].point2D);
        points_cam.push_back(cam_from_world * image.correspondences[k].point3D);
        rows[c].emplace_back(static_cast<int>(i), static_cast<int>(k));
      }
    }
    success[c] = UpgradeCamera(options.upgrade, points2D, points_cam,
                               &calibration->cameras[c], &results[c]);
  }

  for (int c = 0; c < num_cameras; ++c) {
    if (!calibration->camera_calibrated[c]) continue;
    if (!success[c]) {
      calibration->camera_calibrated[c] = false;
      AddDiagnostic(report, Diagnostic::Level::kWarning, "upgrade_failed",
                    "the intrinsics of camera " + dataset.cameras[c].name +
                        " could not be estimated from its " +
                        std::to_string(rows[c].size()) +
                        " radial inliers: " + results[c].error_message,
                    {c});
      continue;
    }
    calibration->cam_from_rig[c].translation.z() = results[c].tz;
    for (size_t i = 0; i < dataset.images.size(); ++i) {
      if (dataset.images[i].camera_index != c) continue;
      calibration->images[i].inlier_mask.assign(
          dataset.images[i].correspondences.size(), 0);
      calibration->images[i].num_inliers = 0;
    }
    for (size_t r = 0; r < rows[c].size(); ++r) {
      if (!results[c].inlier_mask[r]) continue;
      ImageResult& image = calibration->images[rows[c][r].first];
      image.inlier_mask[rows[c][r].second] = 1;
      ++image.num_inliers;
    }
    if (!results[c].well_conditioned) {
      AddDiagnostic(
          report, Diagnostic::Level::kWarning, "focal_tz_ill_conditioned",
          "camera " + dataset.cameras[c].name +
              ": focal length and forward offset are poorly separated "
              "(correlation " +
              std::to_string(results[c].tz_focal_correlation) +
              "); the scene seen by this camera has too little depth "
              "variation. Record closer and farther structure.",
          {c});
    }
    if (options.print_progress) {
      std::cout << "  " << dataset.cameras[c].name << ": "
                << results[c].num_inliers << " inliers, tz " << results[c].tz
                << ", " << calibration->cameras[c].ModelName() << " "
                << calibration->cameras[c].ParamsToString() << ", RMS "
                << results[c].rms_px << " px" << std::endl;
    }
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

bool RunRadialStages(const PipelineOptions& options, const RigDataset& dataset,
                     RigCalibration* calibration, PipelineReport* report) {
  {
    Stage stage("Radial rig initialization", options.print_progress, report);
    RigInitializerOptions init_options = options.rig_initializer;
    init_options.radial = true;
    init_options.num_threads = options.num_threads;
    init_options.seed = options.seed;
    RigInitializerSummary summary;
    if (!InitializeRig(init_options, dataset, calibration, &summary)) {
      report->error =
          "the radial rig initialization failed: " + summary.message;
      return false;
    }
  }
  {
    Stage stage("Radial bundle adjustment", options.print_progress, report);
    RadialBundleAdjustmentOptions ba_options = options.radial_bundle_adjustment;
    ba_options.num_threads = options.num_threads;
    RadialBundleAdjustmentSummary summary;
    if (!AdjustRadialRig(ba_options, dataset, calibration, &summary)) {
      report->error = "the radial bundle adjustment failed (see above)";
      return false;
    }
    if (options.print_progress) {
      std::cout << "  radial RMS " << summary.initial_rms_px << " -> "
                << summary.final_rms_px << " px over " << summary.num_residuals
                << " residuals, " << summary.num_iterations << " iterations"
                << std::endl;
    }
  }
  {
    Stage stage("Camera upgrade", options.print_progress, report);
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
  }
  return true;
}

bool RunFullPoseRigInitialization(
    const PipelineOptions& options, CalibrationMethod method,
    const RigDataset& dataset,
    const std::vector<colmap::Camera>& per_image_cameras,
    RigCalibration* calibration, PipelineReport* report) {
  Stage stage("Rig initialization", options.print_progress, report);
  if (!UsesKnownIntrinsics(method)) {
    MedianIntrinsics(dataset, per_image_cameras, calibration);
  }
  if (method == CalibrationMethod::kRd) {
    return InitializeRigFromCompleteFrameset(dataset, calibration,
                                             &report->error);
  }
  RigInitializerOptions init_options = options.rig_initializer;
  init_options.radial = false;
  init_options.num_threads = options.num_threads;
  init_options.seed = options.seed;
  RigInitializerSummary summary;
  if (!InitializeRig(init_options, dataset, calibration, &summary)) {
    report->error = "the rig initialization failed: " + summary.message;
    return false;
  }
  return true;
}

}  // namespace

bool CalibrationMethodFromName(const std::string& name,
                               CalibrationMethod* method) {
  for (const auto& [value, value_name] : MethodNames()) {
    if (value_name == name) {
      *method = value;
      return true;
    }
  }
  return false;
}

std::string CalibrationMethodName(CalibrationMethod method) {
  for (const auto& [value, value_name] : MethodNames()) {
    if (value == method) return value_name;
  }
  return "unknown";
}

std::string DiagnosticLevelName(Diagnostic::Level level) {
  switch (level) {
    case Diagnostic::Level::kInfo:
      return "info";
    case Diagnostic::Level::kWarning:
      return "warning";
    case Diagnostic::Level::kError:
      return "error";
  }
  return "unknown";
}

bool PipelineReport::HasErrors() const {
  return !error.empty() ||
         std::any_of(diagnostics.begin(), diagnostics.end(),
                     [](const Diagnostic& diagnostic) {
                       return diagnostic.level == Diagnostic::Level::kError;
                     });
}

bool CalibrateRig(const PipelineOptions& options, const RigDataset& dataset,
                  RigCalibration* calibration, PipelineReport* report) {
  colmap::Timer total_timer;
  total_timer.Start();
  *report = PipelineReport();
  report->requested_method = options.method;
  report->used_method = options.method;
  report->num_images = static_cast<int>(dataset.images.size());
  if (!ValidateDataset(dataset, &report->error)) return false;

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

  CalibrationMethod method = options.method;
  InitialPoseOptions pose_options = options.initial_pose;
  pose_options.num_threads = options.num_threads;
  pose_options.seed = options.seed;
  pose_options.print_progress = options.print_progress;
  std::vector<colmap::Camera> per_image_cameras;

  auto estimate_initial_poses = [&](CalibrationMethod for_method) {
    Stage stage("Single-image localization", options.print_progress, report);
    const InitialPoseModel model =
        for_method == CalibrationMethod::kRadial1D
            ? InitialPoseModel::kRadial
            : (UsesKnownIntrinsics(for_method)
                   ? InitialPoseModel::kKnownIntrinsics
                   : InitialPoseModel::kPoseAndIntrinsics);
    InitialPoseSummary summary;
    EstimateInitialPoses(pose_options, model, dataset, calibration,
                         &per_image_cameras, &summary);
    report->num_localized = summary.num_localized;
  };

  estimate_initial_poses(method);
  DiagnoseLocalization(dataset, *calibration, report);
  if (report->num_localized == 0) {
    report->error =
        "no image could be localized in the map: check that the rig images "
        "see the mapped scene and that their features match the map's";
    return false;
  }

  if (method == CalibrationMethod::kRadial1D) {
    std::string explanation;
    if (PrincipalAxesAreParallel(dataset, *calibration,
                                 options.parallel_axes_max_angle_deg,
                                 &explanation)) {
      if (!options.fallback_on_parallel_axes) {
        report->error = explanation +
                        " The 1D radial rig cannot be fixed from such a rig; "
                        "use --RigCalibrator.method rd_ra.";
        return false;
      }
      AddDiagnostic(report, Diagnostic::Level::kWarning,
                    "parallel_principal_axes",
                    explanation +
                        " The 1D radial rig cannot be fixed from such a rig "
                        "(paper, Limitations): falling back to rd_ra "
                        "(per-image pose and intrinsics, robust rig "
                        "initialization).");
      if (options.print_progress) {
        std::cout << "  parallel principal axes: falling back to rd_ra"
                  << std::endl;
      }
      method = CalibrationMethod::kRdRa;
      report->used_method = method;
      estimate_initial_poses(method);
    }
  }

  if (method == CalibrationMethod::kRadial1D) {
    if (!RunRadialStages(options, dataset, calibration, report)) return false;
  } else if (!RunFullPoseRigInitialization(options, method, dataset,
                                           per_image_cameras, calibration,
                                           report)) {
    return false;
  }

  report->initial_cameras = calibration->cameras;
  report->initial_cam_from_rig = calibration->cam_from_rig;
  report->initial_camera_calibrated = calibration->camera_calibrated;
  {
    Stage stage("Final bundle adjustment", options.print_progress, report);
    SelectFullInliers(dataset, options.upgrade.max_error_px, calibration);
    FinalBundleAdjustmentOptions ba_options = options.final_bundle_adjustment;
    ba_options.num_threads = options.num_threads;
    if (method == CalibrationMethod::kKnown) {
      ba_options.refine_focal_length = false;
      ba_options.refine_principal_point = false;
      ba_options.refine_extra_params = false;
    }
    FinalBundleAdjustmentSummary summary;
    if (!AdjustRig(ba_options, dataset, calibration, &summary)) {
      report->error = "the final bundle adjustment failed (see above)";
      return false;
    }
    report->final_rms_px = summary.final_rms_px;
    if (options.print_progress) {
      std::cout << "  RMS " << summary.initial_rms_px << " -> "
                << summary.final_rms_px << " px over " << summary.num_residuals
                << " residuals, " << summary.num_outliers
                << " outliers removed, " << summary.num_iterations
                << " iterations" << std::endl;
    }
  }

  std::vector<int> uncalibrated;
  for (int c = 0; c < num_cameras; ++c) {
    if (!calibration->camera_calibrated[c]) uncalibrated.push_back(c);
  }
  if (!uncalibrated.empty()) {
    AddDiagnostic(report, Diagnostic::Level::kError, "camera_not_calibrated",
                  "camera(s) " + CameraList(dataset, uncalibrated) +
                      " are not calibrated (see the warnings above)",
                  uncalibrated);
  }
  for (const ImageResult& image : calibration->images) {
    if (image.used) ++report->num_used;
  }
  for (const auto& rig_from_world : calibration->rig_from_world) {
    if (rig_from_world) ++report->num_framesets_posed;
  }
  report->total_seconds = total_timer.ElapsedSeconds();
  return true;
}

}  // namespace rig_calibrator
