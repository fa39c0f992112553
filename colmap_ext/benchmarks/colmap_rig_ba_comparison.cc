#include "colmap_ext/benchmarks/colmap_rig_ba_comparison.h"

#include <colmap/base/reconstruction.h>
#include <unistd.h>

#include <boost/filesystem.hpp>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <regex>
#include <sstream>
#include <thread>

#include "colmap_ext/benchmarks/child_process.h"
#include "colmap_ext/benchmarks/runtime_benchmark_options.h"
#include "colmap_ext/benchmarks/table_cells.h"
#include "colmap_ext/io/atomic_output.h"
#include "colmap_ext/io/rig_config_io.h"
#include "colmap_ext/io/rig_description.h"
#include "src/calibration/final_bundle_adjuster.h"
#include "src/calibration/initial_pose_estimation.h"
#include "src/calibration/inlier_selection.h"
#include "src/calibration/map_anchoring.h"
#include "src/calibration/pipeline.h"
#include "src/calibration/pipeline_stages.h"
#include "src/evaluation/evaluation.h"

namespace rig_calibrator {
namespace {

// How the final bundle adjustment solves its steps
// (src/solvers/bundle_levenberg_marquardt.h).
constexpr char kOurLinearSolver[] =
    "Schur complement of the points + CHOLMOD sparse Cholesky";

namespace fs = std::filesystem;

// The last match of `pattern`'s first group in `text`, or "".
std::string LastMatch(const std::string& text, const std::string& pattern) {
  const std::regex expression(pattern);
  std::string value;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), expression);
       it != std::sregex_iterator(); ++it) {
    value = (*it)[1].str();
  }
  return value;
}

// The start of the compared problem (see the header) and what each solver
// produced from it.
struct ComparisonData {
  SyntheticRig rig;      // its dataset without map images
  RigCalibration start;  // inlier masks: the compared observations
  std::vector<ObservedPoint> observations;
  std::vector<int> image_ids;  // per dataset image: COLMAP image id or 0
  int num_images = 0, num_framesets = 0, num_dropped_framesets = 0;
  size_t num_points = 0;
  // The start's inliers of posed framesets, and of them those of map points
  // seen once (dropped before the frameset rule).
  size_t num_start_inliers = 0, num_single_observations = 0;
};

struct SolverRun {
  std::string who;
  int64_t num_observations = 0;
  int num_iterations = 0;
  double wall_seconds = 0, cpu_seconds = 0;
  double ceres_seconds = -1;  // COLMAP's printed solver time
  double initial_rms_px = 0, final_rms_px = 0;
  // Compared observations behind their camera in the result (not in the RMS).
  int64_t num_behind = 0;
  // COLMAP's own final RMS over its residuals: 2 x its printed final cost.
  double reported_rms_px = -1;
  double max_rotation_error_deg = 0, max_center_error_m = 0;
  std::string termination;
};

struct Comparison {
  int framesets = 0, cameras = 0;
  ComparisonData* data = nullptr;
  SolverRun ours, colmap;
  std::string colmap_linear_solver;
  double colmap_io_seconds = 0;  // model_converter: read + write the model
};

// The 1dr pipeline up to the input of its final bundle adjustment
// (pipeline.cc's CalibrateRig before RunFinalBundleAdjustment).
bool CalibrateUpToFinalAdjustment(const RigDataset& dataset, int seed,
                                  RigCalibration* calibration,
                                  std::string* error) {
  PipelineOptions options;
  options.method = CalibrationMethod::kRadial1D;
  options.seed = static_cast<unsigned int>(seed);
  options.print_progress = false;
  InitializeCalibration(dataset, calibration);
  InitialPoseOptions pose_options = options.initial_pose;
  pose_options.seed = options.seed;
  pose_options.print_progress = false;
  InitialPoseSummary pose_summary;
  std::vector<colmap::Camera> per_image_cameras;
  EstimateInitialPoses(pose_options, InitialPoseModelOf(options.method),
                       dataset, calibration, &per_image_cameras, &pose_summary);
  PipelineReport report;
  if (!RunRadialStages(options, dataset, calibration, &report)) {
    *error = "the 1dr stages before the final bundle adjustment failed: " +
             report.error;
    return false;
  }
  SelectFullInliers(dataset, options.upgrade.max_error_px, calibration);
  return true;
}

// Keeps, of the start's inliers, the observations of map points in front of
// their camera; then, until nothing changes, drops those of points seen
// fewer than twice and every observation of a frameset without one of the
// reference camera (COLMAP's snapshots need its image).
void SelectComparedObservations(ComparisonData* data) {
  const RigDataset& dataset = data->rig.dataset;
  RigCalibration& start = data->start;
  std::vector<std::vector<char>> kept(dataset.images.size());
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    const RigImage& image = dataset.images[i];
    kept[i].assign(image.correspondences.size(), 0);
    if (!FramesetPosed(start, image)) continue;
    const Rigid3d cam_from_world =
        start.CamFromWorld(image.camera_index, image.frameset_index);
    for (size_t k = 0; k < image.correspondences.size(); ++k) {
      const Correspondence& correspondence = image.correspondences[k];
      kept[i][k] = start.images[i].inlier_mask.size() > k &&
                   start.images[i].inlier_mask[k] &&
                   correspondence.point3D_id >= 0 &&
                   (cam_from_world * correspondence.point3D).z() > 0;
      data->num_start_inliers += kept[i][k];
    }
  }
  for (bool changed = true, first = true; changed; first = false) {
    changed = false;
    std::unordered_map<int64_t, int> point_count;
    std::vector<char> frameset_has_reference(dataset.frameset_names.size(), 0);
    for (size_t i = 0; i < dataset.images.size(); ++i) {
      for (size_t k = 0; k < kept[i].size(); ++k) {
        if (!kept[i][k]) continue;
        ++point_count[dataset.images[i].correspondences[k].point3D_id];
        if (dataset.images[i].camera_index == dataset.reference_camera) {
          frameset_has_reference[dataset.images[i].frameset_index] = 1;
        }
      }
    }
    for (size_t i = 0; i < dataset.images.size(); ++i) {
      for (size_t k = 0; k < kept[i].size(); ++k) {
        const bool single =
            point_count[dataset.images[i].correspondences[k].point3D_id] < 2;
        if (kept[i][k] &&
            (single ||
             !frameset_has_reference[dataset.images[i].frameset_index])) {
          data->num_single_observations += first && single;
          kept[i][k] = 0;
          changed = true;
        }
      }
    }
  }
  std::vector<char> frameset_used(dataset.frameset_names.size(), 0);
  std::vector<char> frameset_posed(dataset.frameset_names.size(), 0);
  std::unordered_map<int64_t, int> points;
  data->observations.clear();
  data->image_ids.assign(dataset.images.size(), 0);
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    const RigImage& image = dataset.images[i];
    start.images[i].inlier_mask = kept[i];
    frameset_posed[image.frameset_index] |= FramesetPosed(start, image);
    bool used = false;
    for (size_t k = 0; k < kept[i].size(); ++k) {
      if (!kept[i][k]) continue;
      used = true;
      data->observations.push_back({static_cast<int>(i),
                                    image.correspondences[k].point3D_id,
                                    image.correspondences[k].point2D});
      points.emplace(image.correspondences[k].point3D_id, 0);
    }
    if (used) {
      data->image_ids[i] = static_cast<int>(i) + 1;
      ++data->num_images;
      frameset_used[image.frameset_index] = 1;
    }
  }
  data->num_points = points.size();
  for (size_t f = 0; f < frameset_used.size(); ++f) {
    data->num_framesets += frameset_used[f];
    data->num_dropped_framesets += frameset_posed[f] && !frameset_used[f];
  }
}

// The start points: the first compared observation's map point per id (as
// RigAdjustment's SelectRefinedPoints takes them).
std::unordered_map<int64_t, Eigen::Vector3d> StartPoints(
    const ComparisonData& data) {
  std::unordered_map<int64_t, Eigen::Vector3d> points;
  const RigDataset& dataset = data.rig.dataset;
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    const std::vector<char>& mask = data.start.images[i].inlier_mask;
    for (size_t k = 0; k < mask.size(); ++k) {
      if (mask[k]) {
        const Correspondence& correspondence =
            dataset.images[i].correspondences[k];
        points.emplace(correspondence.point3D_id, correspondence.point3D);
      }
    }
  }
  return points;
}

// The view of a RigCalibration of the comparison's dataset (points: `points`).
ModelView ViewOfCalibration(
    const ComparisonData& data, const RigCalibration& calibration,
    const std::unordered_map<int64_t, Eigen::Vector3d>& points) {
  ModelView view;
  for (const RigImage& image : data.rig.dataset.images) {
    view.image_cameras.push_back(calibration.cameras[image.camera_index]);
    view.image_cam_from_world.push_back(
        calibration.rig_from_world[image.frameset_index]
            ? calibration.CamFromWorld(image.camera_index, image.frameset_index)
            : Rigid3d());
  }
  view.points3D = points;
  return view;
}

// The start as a COLMAP 3.8 model: camera id = camera index + 1, image id =
// dataset index + 1 at cam_from_rig * rig_from_world with the compared
// observations as its points2D, one 3D point per compared map point (its
// COLMAP id into *colmap_to_point_id); and rig_bundle_adjuster's config.
bool WriteStartModel(
    const ComparisonData& data, const std::string& folder,
    std::unordered_map<colmap::point3D_t, int64_t>* colmap_to_point_id,
    std::string* error) {
  const RigDataset& dataset = data.rig.dataset;
  const RigCalibration& start = data.start;
  colmap::Reconstruction model;
  RigDescription rig;
  rig.reference_camera = dataset.reference_camera;
  for (size_t c = 0; c < dataset.cameras.size(); ++c) {
    colmap::Camera camera = start.cameras[c];
    camera.SetCameraId(static_cast<colmap::camera_t>(c + 1));
    model.AddCamera(camera);
    RigDescriptionCamera rig_camera;
    rig_camera.name = dataset.cameras[c].name;
    rig_camera.image_prefix = dataset.cameras[c].name + "/";
    rig_camera.camera = camera;
    rig_camera.cam_from_rig = start.cam_from_rig[c];
    rig.cameras.push_back(rig_camera);
  }
  // Per point: its track (image id, point2D index).
  std::unordered_map<int64_t, colmap::Track> tracks;
  std::vector<int64_t> point_ids;
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    if (data.image_ids[i] == 0) continue;
    const RigImage& rig_image = dataset.images[i];
    colmap::Image image;
    image.SetImageId(static_cast<colmap::image_t>(data.image_ids[i]));
    image.SetName(rig_image.name);
    image.SetCameraId(
        static_cast<colmap::camera_t>(rig_image.camera_index + 1));
    const Rigid3d cam_from_world =
        start.CamFromWorld(rig_image.camera_index, rig_image.frameset_index);
    image.SetQvec(cam_from_world.Qvec());
    image.SetTvec(cam_from_world.translation);
    std::vector<Eigen::Vector2d> points2D;
    const std::vector<char>& mask = start.images[i].inlier_mask;
    for (size_t k = 0; k < mask.size(); ++k) {
      if (!mask[k]) continue;
      const int64_t point3D_id = rig_image.correspondences[k].point3D_id;
      auto [it, inserted] = tracks.emplace(point3D_id, colmap::Track());
      if (inserted) point_ids.push_back(point3D_id);
      it->second.AddElement(image.ImageId(),
                            static_cast<colmap::point2D_t>(points2D.size()));
      points2D.push_back(rig_image.correspondences[k].point2D);
    }
    image.SetPoints2D(points2D);
    model.AddImage(std::move(image));
    model.RegisterImage(static_cast<colmap::image_t>(data.image_ids[i]));
  }
  const std::unordered_map<int64_t, Eigen::Vector3d> points = StartPoints(data);
  for (const int64_t point3D_id : point_ids) {
    const colmap::point3D_t colmap_id =
        model.AddPoint3D(points.at(point3D_id), tracks.at(point3D_id));
    (*colmap_to_point_id)[colmap_id] = point3D_id;
  }
  model.WriteBinary(folder + "/start");
  return WriteRigBundleAdjusterConfig(folder + "/rig_config.json", rig, error);
}

std::string Number(double value) {
  std::ostringstream text;
  text << std::setprecision(17) << value;
  return text.str();
}

// COLMAP's choice in RigBundleAdjuster::Solve (sparse library present).
std::string ColmapLinearSolver(int num_images) {
  if (num_images <= 50) return "DENSE_SCHUR";
  if (num_images <= 1000) return "SPARSE_SCHUR";
  return "ITERATIVE_SCHUR + SCHUR_JACOBI";
}

// `colmap ARGS... > log 2>&1` through /bin/sh's exec (the same process,
// so its rusage is COLMAP's).
ChildOutcome RunColmap(const std::string& colmap,
                       const std::vector<std::string>& arguments,
                       const std::string& log_path) {
  std::vector<std::string> argv = {
      "sh", "-c",     "log=\"$1\"; shift; exec \"$@\" > \"$log\" 2>&1",
      "sh", log_path, colmap};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  return RunChildProcess(argv, log_path, "/bin/sh");
}

// Solution accuracy against the truth after anchoring on the map (as
// AdjustRig's own free-gauge result): worst rotation and centre error.
void CompareWithTruth(const ComparisonData& data, RigCalibration calibration,
                      bool anchor, SolverRun* run) {
  if (anchor) AnchorRefinedPointsToMap(data.rig.dataset, &calibration);
  const CalibrationError accuracy = CompareCalibrations(
      data.rig.truth.cameras, data.rig.truth.cam_from_rig, calibration.cameras,
      calibration.cam_from_rig, /*align_scale=*/false);
  run->max_rotation_error_deg = accuracy.MaxRotationDeg();
  run->max_center_error_m = accuracy.MaxCenterError();
}

bool RunColmapSide(
    const ColmapRigBaComparisonOptions& options, const std::string& colmap,
    const std::string& folder, const ComparisonData& data,
    const std::unordered_map<colmap::point3D_t, int64_t>& colmap_to_point_id,
    Comparison* comparison, std::string* error) {
  SolverRun& run = comparison->colmap;
  run.who = "COLMAP 3.8 rig_bundle_adjuster";
  std::error_code code;
  fs::create_directories(folder + "/colmap", code);
  fs::create_directories(folder + "/converted", code);
  const std::vector<std::string> arguments = {
      "rig_bundle_adjuster", "--input_path", folder + "/start", "--output_path",
      folder + "/colmap", "--rig_config_path", folder + "/rig_config.json",
      "--estimate_rig_relative_poses", "0",
      "--RigBundleAdjustment.refine_relative_poses", "1",
      "--BundleAdjustment.max_num_iterations",
      std::to_string(options.max_num_iterations),
      "--BundleAdjustment.function_tolerance",
      Number(options.function_tolerance),
      // AdjustRig's: Ceres' default gradient tolerance, parameter tolerance
      // 1e-12 (rig_adjustment_problem.cc).
      "--BundleAdjustment.gradient_tolerance", "1e-10",
      "--BundleAdjustment.parameter_tolerance", "1e-12",
      "--BundleAdjustment.refine_focal_length", "1",
      "--BundleAdjustment.refine_principal_point", "1",
      "--BundleAdjustment.refine_extra_params", "1",
      "--BundleAdjustment.refine_extrinsics", "1"};
  const ChildOutcome outcome =
      RunColmap(colmap, arguments, folder + "/colmap_log.txt");
  if (!outcome.ok) {
    *error = "colmap rig_bundle_adjuster: " + outcome.error +
             " (log: " + folder + "/colmap_log.txt)";
    return false;
  }
  ColmapSolverSummary summary;
  if (!ParseColmapSolverSummary(outcome.result_text, &summary, error)) {
    *error = "colmap rig_bundle_adjuster's output (" + folder +
             "/colmap_log.txt): " + *error;
    return false;
  }
  if (summary.num_snapshots != data.num_framesets) {
    *error = "colmap rig_bundle_adjuster made " +
             std::to_string(summary.num_snapshots) + " snapshots of " +
             std::to_string(data.num_framesets) + " framesets";
    return false;
  }
  run.wall_seconds = outcome.wall_seconds;
  run.cpu_seconds = outcome.cpu_seconds;
  run.ceres_seconds = summary.seconds;
  run.num_iterations = summary.num_iterations;
  run.num_observations = summary.num_residuals / 2;
  run.termination = summary.termination;
  comparison->colmap_linear_solver = ColmapLinearSolver(data.num_images);

  // The cost of COLMAP's model input and output alone.
  const ChildOutcome io = RunColmap(
      colmap,
      {"model_converter", "--input_path", folder + "/start", "--output_path",
       folder + "/converted", "--output_type", "BIN"},
      folder + "/converter_log.txt");
  comparison->colmap_io_seconds = io.ok ? io.wall_seconds : -1;

  colmap::Reconstruction result;
  result.ReadBinary(folder + "/colmap");
  const RigDataset& dataset = data.rig.dataset;
  ModelView view;
  RigCalibration calibration = data.start;
  calibration.refined_points3D.clear();
  for (size_t c = 0; c < dataset.cameras.size(); ++c) {
    calibration.cameras[c].SetParams(
        result.Camera(static_cast<colmap::camera_t>(c + 1)).Params());
  }
  // Per frameset its reference image's pose (= rig_from_world, the reference
  // camera's cam_from_rig being held at the identity), then each camera's
  // cam_from_rig from any of its images (COLMAP composes them exactly).
  const auto pose_of = [&](size_t i) {
    const colmap::Image& image =
        result.Image(static_cast<colmap::image_t>(data.image_ids[i]));
    const Eigen::Vector4d& q = image.Qvec();
    return Rigid3d(Eigen::Quaterniond(q(0), q(1), q(2), q(3)), image.Tvec());
  };
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    if (data.image_ids[i] != 0 &&
        dataset.images[i].camera_index == dataset.reference_camera) {
      calibration.rig_from_world[dataset.images[i].frameset_index] = pose_of(i);
    }
  }
  std::vector<char> camera_done(dataset.cameras.size(), 0);
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    const RigImage& image = dataset.images[i];
    view.image_cameras.push_back(calibration.cameras[image.camera_index]);
    view.image_cam_from_world.push_back(data.image_ids[i] != 0 ? pose_of(i)
                                                               : Rigid3d());
    if (data.image_ids[i] != 0 && !camera_done[image.camera_index]) {
      camera_done[image.camera_index] = 1;
      calibration.cam_from_rig[image.camera_index] =
          pose_of(i) *
          calibration.rig_from_world[image.frameset_index]->Inverse();
    }
  }
  for (const auto& [colmap_id, point3D_id] : colmap_to_point_id) {
    view.points3D[point3D_id] = result.Point3D(colmap_id).XYZ();
    calibration.refined_points3D[point3D_id] = result.Point3D(colmap_id).XYZ();
  }
  const ReprojectionRms rms = RmsReprojectionError(data.observations, view);
  run.final_rms_px = rms.rms_px;
  run.num_behind = rms.num_unusable;
  run.reported_rms_px = 2 * summary.final_cost_px;
  CompareWithTruth(data, calibration, /*anchor=*/true, &run);
  return true;
}

bool RunOurSide(const ColmapRigBaComparisonOptions& options, int num_threads,
                const ComparisonData& data, SolverRun* run,
                std::string* error) {
  run->who = "ours (AdjustRig)";
  FinalBundleAdjustmentOptions ba;
  ba.loss_scale_px = options.loss_scale_px;
  ba.max_num_iterations = options.max_num_iterations;
  ba.refine_focal_length = ba.refine_principal_point = ba.refine_extra_params =
      true;
  ba.refine_extrinsics = ba.refine_rig_poses = ba.refine_points = true;
  ba.use_map_observations = false;
  ba.refine_map = ba.refine_map_intrinsics = false;
  ba.num_pruning_rounds = 0;
  ba.num_threads = num_threads;
  RigCalibration calibration = data.start;
  FinalBundleAdjustmentSummary summary;
  const double cpu_start = ProcessCpuSeconds();
  const auto start_time = std::chrono::steady_clock::now();
  const bool ok = AdjustRig(ba, data.rig.dataset, &calibration, &summary);
  run->wall_seconds = std::chrono::duration<double>(
                          std::chrono::steady_clock::now() - start_time)
                          .count();
  run->cpu_seconds = ProcessCpuSeconds() - cpu_start;
  if (!ok) {
    *error = "AdjustRig failed (see the log)";
    return false;
  }
  run->num_iterations = summary.num_iterations;
  run->num_observations = summary.num_residuals;
  run->termination =
      summary.solver_report.find("CONVERGENCE") != std::string::npos
          ? (summary.solver_report.find("NO_CONVERGENCE") != std::string::npos
                 ? "No convergence"
                 : "Convergence")
          : summary.solver_report;
  const ReprojectionRms rms = RmsReprojectionError(
      data.observations,
      ViewOfCalibration(data, calibration, calibration.refined_points3D));
  run->final_rms_px = rms.rms_px;
  run->num_behind = rms.num_unusable;
  // AdjustRig anchored its free-gauge solution on the map already.
  CompareWithTruth(data, calibration, /*anchor=*/false, run);
  return true;
}

std::string Csv(const std::vector<Comparison>& comparisons) {
  std::ostringstream csv;
  csv << "framesets,cameras,images,framesets_used,points,who,observations,"
         "iterations,wall_s,cpu_s,ceres_s,wall_s_per_iteration,"
         "initial_rms_px,final_rms_px,max_rotation_error_deg,"
         "max_center_error_m,termination,linear_solver,start_inliers,"
         "single_observations,behind_camera,reported_rms_px\n";
  for (const Comparison& c : comparisons) {
    for (const SolverRun* run : {&c.ours, &c.colmap}) {
      csv << c.framesets << "," << c.cameras << "," << c.data->num_images << ","
          << c.data->num_framesets << "," << c.data->num_points << ",\""
          << run->who << "\"," << run->num_observations << ","
          << run->num_iterations << "," << Number(run->wall_seconds) << ","
          << Number(run->cpu_seconds) << ","
          << (run->ceres_seconds >= 0 ? Number(run->ceres_seconds) : "") << ","
          << Number(run->wall_seconds / std::max(1, run->num_iterations)) << ","
          << Number(run->initial_rms_px) << "," << Number(run->final_rms_px)
          << "," << Number(run->max_rotation_error_deg) << ","
          << Number(run->max_center_error_m) << ",\"" << run->termination
          << "\",\""
          << (run == &c.ours ? kOurLinearSolver : c.colmap_linear_solver)
          << "\"," << c.data->num_start_inliers << ","
          << c.data->num_single_observations << "," << run->num_behind << ","
          << (run->reported_rms_px >= 0 ? Number(run->reported_rms_px) : "")
          << "\n";
    }
  }
  return csv.str();
}

std::string Markdown(const ColmapRigBaComparisonOptions& options,
                     int num_threads, const std::string& machine_start,
                     const std::string& machine_end,
                     const std::vector<Comparison>& comparisons) {
  std::ostringstream md;
  md << "# Rig bundle adjustment: ours vs COLMAP 3.8 rig_bundle_adjuster\n\n"
     << "Same start (synthetic ring rig, 1dr pipeline up to its final bundle "
        "adjustment, inlier observations of points seen twice or more), all "
        "intrinsics, cam_from_rig, rig poses and points refined, function "
        "tolerance "
     << options.function_tolerance << ", at most " << options.max_num_iterations
     << " iterations, " << num_threads
     << " threads each (COLMAP: all cores). Ours: AdjustRig in process "
        "(Cauchy scale "
     << options.loss_scale_px
     << " px, no pruning); COLMAP: the command as a child process (trivial "
        "loss), wall and CPU including reading and writing its model. RMS: "
        "recomputed over the same observations from each result.\n\n"
     << "Machine at start: " << machine_start << "  \n"
     << "Machine at end: " << machine_end << "\n\n"
     << "| size | who | observations | iterations | wall s | CPU s | "
        "Ceres s | wall s / iteration | RMS start -> final px | "
        "max rotation error deg | max centre error mm | termination |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Comparison& c : comparisons) {
    const std::string size = std::to_string(c.framesets) + " x " +
                             std::to_string(c.cameras) + " (" +
                             std::to_string(c.data->num_images) + " images, " +
                             std::to_string(c.data->num_points) + " points)";
    for (const SolverRun* run : {&c.ours, &c.colmap}) {
      md << "| " << size << " | " << run->who << " | " << run->num_observations
         << " | " << run->num_iterations << " | " << FixedCell(run->wall_seconds, 2)
         << " | " << FixedCell(run->cpu_seconds, 2) << " | "
         << (run->ceres_seconds >= 0 ? FixedCell(run->ceres_seconds, 2) : "-")
         << " | "
         << FixedCell(run->wall_seconds / std::max(1, run->num_iterations), 3)
         << " | " << FixedCell(run->initial_rms_px, 4) << " -> "
         << FixedCell(run->final_rms_px, 6)
         << (run->num_behind > 0
                 ? " (" + std::to_string(run->num_behind) + " behind camera)"
                 : "")
         << " | " << FixedCell(run->max_rotation_error_deg, 4) << " | "
         << FixedCell(1000 * run->max_center_error_m, 3) << " | "
         << run->termination << " |\n";
    }
    md << "| " << size << " | **COLMAP / ours** | | "
       << RatioCell(c.colmap.num_iterations, c.ours.num_iterations) << " | **"
       << RatioCell(c.colmap.wall_seconds, c.ours.wall_seconds) << "** | "
       << RatioCell(c.colmap.cpu_seconds, c.ours.cpu_seconds) << " | | "
       << RatioCell(c.colmap.wall_seconds / std::max(1, c.colmap.num_iterations),
                c.ours.wall_seconds / std::max(1, c.ours.num_iterations))
       << " | " << RatioCell(c.colmap.final_rms_px, c.ours.final_rms_px)
       << " | | | |\n";
  }
  md << "\nPer size: COLMAP's linear solver (its choice by image count) and "
        "the wall time of `colmap model_converter` on the start model (the "
        "input and output part of COLMAP's wall time); framesets dropped for "
        "lacking a reference-camera image.\n\n";
  for (const Comparison& c : comparisons) {
    md << "- " << c.framesets << " x " << c.cameras << ": COLMAP "
       << c.colmap_linear_solver << ", ours " << kOurLinearSolver << "; "
       << "model_converter " << FixedCell(c.colmap_io_seconds, 2) << " s; "
       << c.data->num_framesets << " framesets compared, "
       << c.data->num_dropped_framesets << " dropped; "
       << c.data->observations.size() << " of the start's "
       << c.data->num_start_inliers << " inliers compared ("
       << c.data->num_single_observations
       << " of points seen once left out); COLMAP's own final RMS (2 x its "
          "printed final cost) "
       << FixedCell(c.colmap.reported_rms_px, 6) << " px\n";
  }
  return md.str();
}

}  // namespace

bool ParseColmapSolverSummary(const std::string& text,
                              ColmapSolverSummary* summary,
                              std::string* error) {
  *summary = ColmapSolverSummary();
  const size_t report = text.rfind("Rig Bundle adjustment report");
  if (report == std::string::npos) {
    *error = "no \"Rig Bundle adjustment report\"";
    return false;
  }
  const std::string tail = text.substr(report);
  const std::string number = R"(([-+0-9.eEinfa]+))";
  const struct {
    const char* name;
    std::string pattern;
  } fields[] = {{"Residuals", R"(Residuals : (\d+))"},
                {"Iterations", R"(Iterations : (\d+))"},
                {"Time", "Time : " + number + R"( \[s\])"},
                {"Initial cost", "Initial cost : *" + number + R"( \[px\])"},
                {"Final cost", "Final cost : *" + number + R"( \[px\])"},
                {"Termination", R"(Termination : *([^\r\n]+))"}};
  std::vector<std::string> values;
  for (const auto& field : fields) {
    values.push_back(LastMatch(tail, field.pattern));
    if (values.back().empty()) {
      *error = std::string("no \"") + field.name + " : \" in the report";
      return false;
    }
  }
  try {
    summary->num_residuals = std::stoll(values[0]);
    summary->num_iterations = std::stoi(values[1]);
    summary->seconds = std::stod(values[2]);
    summary->initial_cost_px = std::stod(values[3]);
    summary->final_cost_px = std::stod(values[4]);
  } catch (const std::exception&) {
    *error = "a number of the report does not parse";
    return false;
  }
  summary->termination = values[5];
  const std::string snapshots = LastMatch(text, R"(Snapshots: (\d+))");
  summary->num_snapshots = snapshots.empty() ? 0 : std::stoi(snapshots);
  return true;
}

ReprojectionRms RmsReprojectionError(
    const std::vector<ObservedPoint>& observations, const ModelView& view) {
  ReprojectionRms result;
  double sum = 0;
  for (const ObservedPoint& observation : observations) {
    const auto point = view.points3D.find(observation.point3D_id);
    const bool known =
        observation.image >= 0 &&
        observation.image < static_cast<int>(view.image_cameras.size()) &&
        observation.image <
            static_cast<int>(view.image_cam_from_world.size()) &&
        point != view.points3D.end();
    const Eigen::Vector3d in_camera =
        known ? view.image_cam_from_world[observation.image] * point->second
              : Eigen::Vector3d::Zero();
    if (!(in_camera.z() > 0)) {
      ++result.num_unusable;
      continue;
    }
    sum += (view.image_cameras[observation.image].WorldToImage(
                in_camera.hnormalized()) -
            observation.point2D)
               .squaredNorm();
    ++result.num_used;
  }
  result.rms_px = result.num_used > 0 ? std::sqrt(sum / result.num_used) : 0;
  return result;
}

bool RunColmapRigBaComparison(const ColmapRigBaComparisonOptions& options,
                              std::string* error) {
  std::vector<int> framesets, cameras;
  if (!ParseCountList(options.framesets, &framesets) ||
      !ParseCountList(options.cameras, &cameras)) {
    *error = "--framesets and --cameras take comma-separated positive integers";
    return false;
  }
  if (!(options.function_tolerance >= 0) || options.max_num_iterations < 1 ||
      !(options.loss_scale_px > 0)) {
    *error =
        "--function_tolerance must be >= 0, --max_num_iterations >= 1 and "
        "--loss_scale_px > 0";
    return false;
  }
  std::string colmap = options.colmap_executable;
  if (colmap.empty()) {
    colmap =
        (fs::read_symlink("/proc/self/exe").parent_path() / "colmap").string();
  }
  if (access(colmap.c_str(), X_OK) != 0) {
    *error = "--colmap_executable: " + colmap +
             " is not an executable (the extended colmap of this build)";
    return false;
  }
  std::error_code code;
  fs::create_directories(options.output_path, code);
  if (code) {
    *error = "--output_path: cannot create " + options.output_path + ": " +
             code.message();
    return false;
  }
  const std::string work =
      (fs::temp_directory_path(code) /
       boost::filesystem::unique_path("rig_calibrator_colmap_ba_%%%%-%%%%")
           .string())
          .string();
  if (code || !fs::create_directory(work, code)) {
    *error = "cannot create a temporary folder " + work;
    return false;
  }
  // COLMAP takes every core (its command has no thread option), so ours
  // does too.
  const int num_threads =
      std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  const std::string machine_start = MachineDescription();
  std::cout << "benchmark_colmap_rig_ba: " << machine_start << std::endl;
  std::vector<std::unique_ptr<ComparisonData>> datas;
  std::vector<Comparison> comparisons;
  bool ok = true;
  for (const int num_cameras : cameras) {
    for (const int num_framesets : framesets) {
      auto data = std::make_unique<ComparisonData>();
      SyntheticRigOptions rig_options = options.data;
      rig_options.preset = RigPreset::kRing5;
      rig_options.ring_num_cameras = num_cameras;
      rig_options.num_framesets = num_framesets;
      rig_options.seed = static_cast<unsigned int>(options.seed);
      if (!rig_options.Check(error)) {
        ok = false;
        break;
      }
      data->rig = GenerateSyntheticRig(rig_options);
      data->rig.dataset.map_images.clear();
      data->rig.dataset.map_cameras.clear();
      if (!CalibrateUpToFinalAdjustment(data->rig.dataset, options.seed,
                                        &data->start, error)) {
        ok = false;
        break;
      }
      data->start.refined_points3D.clear();
      SelectComparedObservations(data.get());
      Comparison comparison;
      comparison.framesets = num_framesets;
      comparison.cameras = num_cameras;
      comparison.data = data.get();
      const std::string folder = work + "/" + std::to_string(num_framesets) +
                                 "x" + std::to_string(num_cameras);
      fs::create_directories(folder + "/start", code);
      std::unordered_map<colmap::point3D_t, int64_t> colmap_to_point_id;
      if (!WriteStartModel(*data, folder, &colmap_to_point_id, error)) {
        ok = false;
        break;
      }
      const double initial_rms =
          RmsReprojectionError(
              data->observations,
              ViewOfCalibration(*data, data->start, StartPoints(*data)))
              .rms_px;
      std::cout << "  " << num_framesets << " x " << num_cameras << ": "
                << data->observations.size() << " observations, start RMS "
                << initial_rms << " px; COLMAP ..." << std::endl;
      if (!RunColmapSide(options, colmap, folder, *data, colmap_to_point_id,
                         &comparison, error)) {
        ok = false;
        break;
      }
      std::cout << "    COLMAP " << comparison.colmap.wall_seconds << " s, "
                << comparison.colmap.num_iterations << " iterations; ours ..."
                << std::endl;
      if (!RunOurSide(options, num_threads, *data, &comparison.ours, error)) {
        ok = false;
        break;
      }
      std::cout << "    ours " << comparison.ours.wall_seconds << " s, "
                << comparison.ours.num_iterations << " iterations" << std::endl;
      comparison.ours.initial_rms_px = comparison.colmap.initial_rms_px =
          initial_rms;
      comparisons.push_back(comparison);
      datas.push_back(std::move(data));
    }
    if (!ok) break;
  }
  if (options.keep_work_folder || !ok) {
    std::cout << "benchmark_colmap_rig_ba: models and logs in " << work
              << std::endl;
  } else {
    fs::remove_all(work, code);
  }
  if (!ok) return false;
  const std::string machine_end = MachineDescription();
  const std::string markdown =
      Markdown(options, num_threads, machine_start, machine_end, comparisons);
  if (!WriteFileAtomically(options.output_path + "/colmap_rig_ba.md", markdown,
                           error) ||
      !WriteFileAtomically(options.output_path + "/colmap_rig_ba.csv",
                           Csv(comparisons), error)) {
    return false;
  }
  std::cout << markdown;
  return true;
}

}  // namespace rig_calibrator
