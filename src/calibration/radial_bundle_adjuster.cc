#include "src/calibration/radial_bundle_adjuster.h"

#include <ceres/ceres.h>
#include <colmap/util/threading.h>
#include <glog/logging.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <memory>
#include <sstream>
#include <vector>

#include "src/calibration/principal_axes.h"
#include "src/geometry/radial_rig_cost_function.h"
#include "src/solvers/bundle_solver.h"

namespace rig_calibrator {
namespace {

// An image with fewer inliers says little about its frameset's rig pose.
constexpr int kMinInliersPerImage = 5;
// After the first solve, an image whose correspondences are mostly beyond
// max_radial_error_px is taken as mis-localized and dropped whole.
constexpr double kMinInlierShare = 0.5;

// One correspondence in the adjustment.
struct RadialObservation {
  int image;  // dataset image index
  int camera;
  int frameset;
  Eigen::Vector2d point2D;
  Eigen::Vector3d point3D;
};

// The adjusted quantities, as Ceres parameter blocks.
struct Parameters {
  std::vector<PoseParams> cam_from_rig;
  std::vector<PoseParams> rig_from_world;
  std::vector<std::array<double, 2>> principal_points;
};

// |pi_r(...) - (x - c)|: the radial reprojection error of an observation.
double RadialError(const RadialObservation& observation,
                   const Parameters& parameters) {
  const double* blocks[] = {
      parameters.cam_from_rig[observation.camera].data(),
      parameters.rig_from_world[observation.frameset].data(),
      parameters.principal_points[observation.camera].data()};
  double residual[2];
  RadialRigCostFunction(observation.point2D, observation.point3D)
      .Evaluate(blocks, residual, nullptr);
  return std::hypot(residual[0], residual[1]);
}

double RmsRadialError(const std::vector<RadialObservation>& observations,
                      const Parameters& parameters) {
  if (observations.empty()) return 0;
  double sum_sq = 0;
  for (const RadialObservation& observation : observations) {
    const double error = RadialError(observation, parameters);
    sum_sq += error * error;
  }
  return std::sqrt(sum_sq / observations.size());
}

// The observations of the framesets whose rig pose they determine
// (AxesDetermineTranslation over the principal axes, in the rig frame, of the
// cameras observing it: parallel and anti-parallel axes do not); only
// cameras with kMinInliersPerImage observations in the frameset count.
std::vector<RadialObservation> KeepDeterminedFramesets(
    const std::vector<RadialObservation>& observations,
    const RigCalibration& calibration) {
  const int num_framesets = calibration.rig_from_world.size();
  std::vector<std::vector<int>> count_of_camera(
      num_framesets, std::vector<int>(calibration.cam_from_rig.size(), 0));
  for (const RadialObservation& observation : observations) {
    ++count_of_camera[observation.frameset][observation.camera];
  }
  std::vector<char> determined(num_framesets, 0);
  for (int j = 0; j < num_framesets; ++j) {
    std::vector<Eigen::Vector3d> axes;
    for (size_t i = 0; i < count_of_camera[j].size(); ++i) {
      if (count_of_camera[j][i] >= kMinInliersPerImage) {
        axes.push_back(PrincipalAxis(calibration.cam_from_rig[i]));
      }
    }
    determined[j] = AxesDetermineTranslation(axes);
  }
  std::vector<RadialObservation> kept;
  for (const RadialObservation& observation : observations) {
    if (determined[observation.frameset]) kept.push_back(observation);
  }
  return kept;
}

// One Levenberg-Marquardt solve over the observations (bundle_solver.h,
// options.bundle_solver's backend; no points: every rig pose is a block row of
// the reduced system, which the sparse Cholesky's ordering eliminates
// first, as no residual links two). Gauge: the reference camera's pose is
// constant, every camera's tz is held, and so is the t_z of one rig pose
// (the rig origin's slide along the reference axis moves every rig pose's
// t_z; holding one removes that null direction). The principal points of
// the cameras whose refinement holds them stay constant. A camera's
// cam_from_rig and principal point are one block row.
BundleSolverSummary Solve(
    const RadialBundleAdjustmentOptions& options,
    const std::vector<RadialObservation>& observations, int reference_camera,
    const std::vector<RigCamera>& cameras, Parameters* parameters) {
  const int num_cameras = parameters->cam_from_rig.size();
  const int num_framesets = parameters->rig_from_world.size();
  std::vector<char> cam_added(num_cameras, 0);
  std::vector<char> rig_added(num_framesets, 0);
  for (const RadialObservation& observation : observations) {
    cam_added[observation.camera] = 1;
    rig_added[observation.frameset] = 1;
  }
  BundleSolverOptions solver_options;
  solver_options.max_num_iterations = options.max_num_iterations;
  solver_options.function_tolerance = options.function_tolerance;
  // Noisy problems stop on the relative cost change (1e-6); this lets exact
  // ones converge to the last digits of map-unit poses.
  solver_options.parameter_tolerance = 1e-10;
  solver_options.num_threads = options.num_threads;
  solver_options.print_progress = options.print_progress;
  const std::unique_ptr<BundleSolver> solver_pointer =
      MakeBundleSolver(options.bundle_solver, solver_options);
  BundleSolver& solver = *solver_pointer;
  // The cost's tangent Jacobians (RadialRigCostFunction) are for these
  // manifolds; the gauge pose's residuals (t_z held) take the ambient path.
  const RigPoseManifold rig_pose_manifold;
  const RadialCameraPoseManifold tz_held = MakeRadialCameraPoseManifold();
  int group = 0;
  bool tz_gauge_held = false;
  for (int j = 0; j < num_framesets; ++j) {
    if (!rig_added[j]) continue;
    solver.AddParameterBlock(
        parameters->rig_from_world[j].data(), 7,
        tz_gauge_held ? static_cast<const ceres::Manifold*>(&rig_pose_manifold)
                      : &tz_held,
        group++);
    tz_gauge_held = true;
  }
  for (int i = 0; i < num_cameras; ++i) {
    if (!cam_added[i]) continue;
    bool in_group = false;
    if (i != reference_camera) {
      solver.AddParameterBlock(parameters->cam_from_rig[i].data(), 7, &tz_held,
                               group);
      in_group = true;
    }
    if (options.refine_principal_points &&
        cameras[i].refinement.principal_point) {
      solver.AddParameterBlock(parameters->principal_points[i].data(), 2,
                               nullptr, group);
      in_group = true;
    }
    group += in_group ? 1 : 0;
  }
  const ceres::CauchyLoss loss(options.loss_scale_px);
  // The costs are made on all threads (10^6 allocations); the solver takes
  // them in observation order.
  const int64_t num_observations = static_cast<int64_t>(observations.size());
  std::vector<std::unique_ptr<ceres::CostFunction>> costs(num_observations);
#pragma omp parallel for schedule(static) \
    num_threads(colmap::GetEffectiveNumThreads(options.num_threads))
  for (int64_t k = 0; k < num_observations; ++k) {
    costs[k] = std::make_unique<RadialRigCostFunction>(
        observations[k].point2D, observations[k].point3D);
  }
  solver.Reserve(observations.size(), 0);
  for (int64_t k = 0; k < num_observations; ++k) {
    const RadialObservation& observation = observations[k];
    solver.AddResidualBlock(
        costs[k].get(), &loss,
        {parameters->cam_from_rig[observation.camera].data(),
         parameters->rig_from_world[observation.frameset].data(),
         parameters->principal_points[observation.camera].data()});
  }
  BundleSolverSummary summary;
  solver.Solve(&summary);
  VLOG(1) << "Radial bundle adjustment: " << summary.BriefReport();
  return summary;
}

bool ObservesReference(const std::vector<RadialObservation>& observations,
                       int reference_camera) {
  for (const RadialObservation& observation : observations) {
    if (observation.camera == reference_camera) return true;
  }
  return false;
}

bool Fail(const std::string& message, RadialBundleAdjustmentSummary* summary) {
  LOG(ERROR) << "AdjustRadialRig: " << message;
  if (summary) summary->message = message;
  return false;
}

// Sizes and indices the adjustment relies on; an error message, empty if
// the input is consistent.
std::string CheckInput(const RigDataset& dataset,
                       const RigCalibration& calibration) {
  const size_t num_cameras = dataset.cameras.size();
  std::ostringstream error;
  if (num_cameras == 0) return "the dataset has no cameras";
  if (calibration.cameras.size() != num_cameras ||
      calibration.cam_from_rig.size() != num_cameras ||
      calibration.camera_calibrated.size() != num_cameras ||
      calibration.rig_from_world.size() != dataset.frameset_names.size() ||
      calibration.images.size() != dataset.images.size()) {
    error << "calibration sizes (" << calibration.cameras.size() << " cameras, "
          << calibration.cam_from_rig.size() << " cam_from_rig, "
          << calibration.camera_calibrated.size() << " calibrated flags, "
          << calibration.rig_from_world.size() << " rig poses, "
          << calibration.images.size() << " images) do not match the dataset ("
          << num_cameras << " cameras, " << dataset.frameset_names.size()
          << " framesets, " << dataset.images.size() << " images)";
    return error.str();
  }
  if (dataset.reference_camera < 0 ||
      dataset.reference_camera >= static_cast<int>(num_cameras)) {
    error << "reference camera index " << dataset.reference_camera
          << " is out of range";
    return error.str();
  }
  if (!calibration.camera_calibrated[dataset.reference_camera]) {
    return "the reference camera " +
           dataset.cameras[dataset.reference_camera].name +
           " is not calibrated";
  }
  for (size_t i = 0; i < num_cameras; ++i) {
    if (!calibration.cameras[i].VerifyParams()) {
      return "camera " + dataset.cameras[i].name +
             " has no valid model parameters";
    }
  }
  for (size_t k = 0; k < dataset.images.size(); ++k) {
    const RigImage& image = dataset.images[k];
    if (image.camera_index < 0 ||
        image.camera_index >= static_cast<int>(num_cameras) ||
        image.frameset_index < 0 ||
        image.frameset_index >=
            static_cast<int>(dataset.frameset_names.size())) {
      error << "image " << image.name << " has camera index "
            << image.camera_index << " and frameset index "
            << image.frameset_index << ", out of range";
      return error.str();
    }
    const std::vector<char>& mask = calibration.images[k].inlier_mask;
    if (!mask.empty() && mask.size() != image.correspondences.size()) {
      error << "image " << image.name << " has an inlier mask of size "
            << mask.size() << " for " << image.correspondences.size()
            << " correspondences";
      return error.str();
    }
  }
  return "";
}

// Inlier correspondences of the images of calibrated cameras in posed
// framesets; per image at most max_per_image (0: all), the k-th of m taken
// at inlier floor(k * n / m) of n.
std::vector<RadialObservation> InlierObservations(const RigDataset& dataset,
                                            const RigCalibration& calibration,
                                            int max_per_image) {
  std::vector<RadialObservation> observations;
  for (size_t k = 0; k < dataset.images.size(); ++k) {
    const RigImage& image = dataset.images[k];
    const std::vector<char>& mask = calibration.images[k].inlier_mask;
    if (!calibration.camera_calibrated[image.camera_index] ||
        !calibration.rig_from_world[image.frameset_index]) {
      continue;
    }
    std::vector<int> inliers;
    for (size_t c = 0; c < mask.size(); ++c) {
      if (mask[c]) inliers.push_back(static_cast<int>(c));
    }
    const size_t n = inliers.size();
    const size_t m =
        max_per_image > 0 ? std::min(n, static_cast<size_t>(max_per_image)) : n;
    for (size_t i = 0; i < m; ++i) {
      const Correspondence& correspondence =
          image.correspondences[inliers[i * n / m]];
      observations.push_back({static_cast<int>(k), image.camera_index,
                              image.frameset_index, correspondence.point2D,
                              correspondence.point3D});
    }
  }
  return observations;
}

// The calibration's poses and principal points as parameter blocks.
Parameters ParametersOf(const RigCalibration& calibration) {
  Parameters parameters;
  for (size_t i = 0; i < calibration.cam_from_rig.size(); ++i) {
    parameters.cam_from_rig.push_back(
        ToPoseParams(calibration.cam_from_rig[i]));
    parameters.principal_points.push_back(
        {calibration.cameras[i].PrincipalPointX(),
         calibration.cameras[i].PrincipalPointY()});
  }
  parameters.rig_from_world.resize(calibration.rig_from_world.size());
  for (size_t j = 0; j < calibration.rig_from_world.size(); ++j) {
    if (calibration.rig_from_world[j]) {
      parameters.rig_from_world[j] =
          ToPoseParams(*calibration.rig_from_world[j]);
    }
  }
  return parameters;
}

// The observations within max_error of the solution whose image has at
// least kMinInlierShare of its observations within it (see AdjustRadialRig).
std::vector<RadialObservation> KeepInliers(
    const std::vector<RadialObservation>& observations, const Parameters& parameters,
    int num_images, double max_error) {
  std::vector<char> within(observations.size(), 0);
  std::vector<int> num_selected(num_images, 0);
  std::vector<int> num_within(num_images, 0);
  for (size_t n = 0; n < observations.size(); ++n) {
    within[n] = RadialError(observations[n], parameters) <= max_error;
    ++num_selected[observations[n].image];
    num_within[observations[n].image] += within[n];
  }
  std::vector<RadialObservation> inliers;
  for (size_t n = 0; n < observations.size(); ++n) {
    const int image = observations[n].image;
    if (within[n] &&
        num_within[image] >= kMinInlierShare * num_selected[image]) {
      inliers.push_back(observations[n]);
    }
  }
  return inliers;
}

// Writes back what the final solve adjusted (tz = 0, the reference camera
// the identity). Returns the number of rig poses it did not adjust.
int WriteAdjusted(const std::vector<RadialObservation>& observations,
                  const Parameters& parameters, int reference,
                  RigCalibration* calibration) {
  const int num_cameras = calibration->cam_from_rig.size();
  const int num_framesets = calibration->rig_from_world.size();
  std::vector<char> cam_adjusted(num_cameras, 0);
  std::vector<char> rig_adjusted(num_framesets, 0);
  for (const RadialObservation& observation : observations) {
    cam_adjusted[observation.camera] = 1;
    rig_adjusted[observation.frameset] = 1;
  }
  for (int i = 0; i < num_cameras; ++i) {
    if (!cam_adjusted[i]) continue;
    calibration->cam_from_rig[i] = FromPoseParams(parameters.cam_from_rig[i]);
    calibration->cam_from_rig[i].translation.z() = 0;
    calibration->cameras[i].SetPrincipalPointX(
        parameters.principal_points[i][0]);
    calibration->cameras[i].SetPrincipalPointY(
        parameters.principal_points[i][1]);
  }
  calibration->cam_from_rig[reference] = Rigid3d();
  int num_skipped = 0;
  for (int j = 0; j < num_framesets; ++j) {
    if (rig_adjusted[j]) {
      calibration->rig_from_world[j] =
          FromPoseParams(parameters.rig_from_world[j]);
    } else if (calibration->rig_from_world[j]) {
      ++num_skipped;
    }
  }
  return num_skipped;
}

}  // namespace

bool AdjustRadialRig(const RadialBundleAdjustmentOptions& options,
                     const RigDataset& dataset, RigCalibration* calibration,
                     RadialBundleAdjustmentSummary* summary) {
  const auto start_time = std::chrono::steady_clock::now();
  if (summary) *summary = RadialBundleAdjustmentSummary();
  if (calibration == nullptr) return Fail("no calibration given", summary);
  const std::string error = CheckInput(dataset, *calibration);
  if (!error.empty()) return Fail(error, summary);
  if (!(options.loss_scale_px > 0) || options.max_num_iterations < 0 ||
      !(options.max_radial_error_px >= 0) ||
      options.max_correspondences_per_image < 0) {
    return Fail(
        "loss_scale_px must be positive, max_num_iterations, "
        "max_radial_error_px and max_correspondences_per_image non-negative",
        summary);
  }
  const int reference = dataset.reference_camera;
  std::vector<RadialObservation> observations = KeepDeterminedFramesets(
      InlierObservations(dataset, *calibration,
                         options.max_correspondences_per_image),
      *calibration);
  const std::string no_reference_message =
      "the reference camera " + dataset.cameras[reference].name +
      " has no inlier correspondences in framesets with a determined rig pose";
  if (!ObservesReference(observations, reference)) {
    return Fail(no_reference_message, summary);
  }
  Parameters parameters = ParametersOf(*calibration);
  const double initial_rms = RmsRadialError(observations, parameters);

  // The Cauchy loss bounds the pull of each wrong correspondence, but the
  // correspondences of a mis-localized image agree with one another, and a
  // principal point shift is nearly a pan/tilt of the camera, a weakly
  // constrained direction in which small coherent pulls add up. So after a
  // first solve, the images with fewer than kMinInlierShare of their
  // correspondences within max_radial_error_px are dropped whole (a few of a
  // wrong image's points always fall near the predicted lines), the
  // remaining correspondences beyond it too, and the rest solved again.
  BundleSolverSummary solver_summary =
      Solve(options, observations, reference, dataset.cameras, &parameters);
  int num_iterations = solver_summary.num_successful_steps +
                       solver_summary.num_unsuccessful_steps;
  int num_outliers = 0;
  if (solver_summary.IsSolutionUsable() && options.max_radial_error_px > 0) {
    const std::vector<RadialObservation> inliers =
        KeepInliers(observations, parameters, dataset.images.size(),
                    options.max_radial_error_px);
    num_outliers = observations.size() - inliers.size();
    if (num_outliers > 0) {
      observations = KeepDeterminedFramesets(inliers, *calibration);
      if (!ObservesReference(observations, reference)) {
        return Fail(no_reference_message + " after removing outliers", summary);
      }
      solver_summary =
          Solve(options, observations, reference, dataset.cameras, &parameters);
      num_iterations += solver_summary.num_successful_steps +
                        solver_summary.num_unsuccessful_steps;
    }
  }
  if (!solver_summary.IsSolutionUsable()) {
    return Fail("the solver failed: " + solver_summary.message, summary);
  }
  const int num_skipped =
      WriteAdjusted(observations, parameters, reference, calibration);
  NormalizeRadialRigOrigin(reference, calibration);

  if (summary) {
    summary->initial_rms_px = initial_rms;
    summary->final_rms_px = RmsRadialError(observations, parameters);
    summary->num_residuals = observations.size();
    summary->num_outliers = num_outliers;
    summary->num_iterations = num_iterations;
    summary->num_framesets_skipped = num_skipped;
    summary->seconds = std::chrono::duration<double>(
                           std::chrono::steady_clock::now() - start_time)
                           .count();
  }
  return true;
}

}  // namespace rig_calibrator
