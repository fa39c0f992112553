#include "src/radial_bundle_adjuster.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <colmap/util/threading.h>
#include <glog/logging.h>

#include <Eigen/Eigenvalues>
#include <array>
#include <chrono>
#include <cmath>
#include <sstream>
#include <vector>

#include "src/radial_cost_functions.h"
#include "src/rig_initializer.h"

namespace rig_calibrator {
namespace {

// An image with fewer inliers says little about its frameset's rig pose.
constexpr int kMinInliersPerImage = 5;

// Radial residual (RadialResidual) of one correspondence of camera i in
// frameset j: the camera-frame point is P_i Q_j X, the observation is taken
// relative to the principal point c_i. Parameters: cam_from_rig and
// rig_from_world as (angle-axis, translation), c_i (2).
class RadialRigCost {
 public:
  RadialRigCost(const Eigen::Vector2d& point2D, const Eigen::Vector3d& point3D)
      : point2D_(point2D), point3D_(point3D) {}

  static ceres::CostFunction* Create(const Eigen::Vector2d& point2D,
                                     const Eigen::Vector3d& point3D) {
    return new ceres::AutoDiffCostFunction<RadialRigCost, 2, 6, 6, 2>(
        new RadialRigCost(point2D, point3D));
  }

  template <typename T>
  bool operator()(const T* cam_from_rig, const T* rig_from_world,
                  const T* principal_point, T* residuals) const {
    const T point3D[3] = {T(point3D_(0)), T(point3D_(1)), T(point3D_(2))};
    T point_in_rig[3];
    ceres::AngleAxisRotatePoint(rig_from_world, point3D, point_in_rig);
    for (int r = 0; r < 3; ++r) point_in_rig[r] += rig_from_world[3 + r];
    T point_in_cam[3];
    ceres::AngleAxisRotatePoint(cam_from_rig, point_in_rig, point_in_cam);
    for (int r = 0; r < 3; ++r) point_in_cam[r] += cam_from_rig[3 + r];
    const T centered[2] = {T(point2D_(0)) - principal_point[0],
                           T(point2D_(1)) - principal_point[1]};
    RadialResidual(centered, point_in_cam, residuals);
    return true;
  }

 private:
  const Eigen::Vector2d point2D_;
  const Eigen::Vector3d point3D_;
};

std::array<double, 6> ToParameters(const Rigid3d& pose) {
  std::array<double, 6> parameters;
  const double quaternion[4] = {pose.rotation.w(), pose.rotation.x(),
                                pose.rotation.y(), pose.rotation.z()};
  ceres::QuaternionToAngleAxis(quaternion, parameters.data());
  for (int r = 0; r < 3; ++r) parameters[3 + r] = pose.translation(r);
  return parameters;
}

Rigid3d FromParameters(const std::array<double, 6>& parameters) {
  double quaternion[4];
  ceres::AngleAxisToQuaternion(parameters.data(), quaternion);
  return Rigid3d(Eigen::Quaterniond(quaternion[0], quaternion[1], quaternion[2],
                                    quaternion[3]),
                 Eigen::Vector3d(parameters[3], parameters[4], parameters[5]));
}

// One correspondence in the adjustment.
struct Observation {
  int camera;
  int frameset;
  Eigen::Vector2d point2D;
  Eigen::Vector3d point3D;
};

double RmsRadialError(
    const std::vector<Observation>& observations,
    const std::vector<std::array<double, 6>>& cam_parameters,
    const std::vector<std::array<double, 6>>& rig_parameters,
    const std::vector<std::array<double, 2>>& principal_points) {
  if (observations.empty()) return 0;
  double sum_sq = 0;
  for (const Observation& observation : observations) {
    double residual[2];
    RadialRigCost(observation.point2D, observation.point3D)(
        cam_parameters[observation.camera].data(),
        rig_parameters[observation.frameset].data(),
        principal_points[observation.camera].data(), residual);
    sum_sq += residual[0] * residual[0] + residual[1] * residual[1];
  }
  return std::sqrt(sum_sq / observations.size());
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

}  // namespace

bool AdjustRadialRig(const RadialBundleAdjustmentOptions& options,
                     const RigDataset& dataset, RigCalibration* calibration,
                     RadialBundleAdjustmentSummary* summary) {
  const auto start_time = std::chrono::steady_clock::now();
  if (summary) *summary = RadialBundleAdjustmentSummary();
  if (calibration == nullptr) return Fail("no calibration given", summary);
  const std::string error = CheckInput(dataset, *calibration);
  if (!error.empty()) return Fail(error, summary);
  if (!(options.loss_scale_px > 0) || options.max_num_iterations < 0) {
    return Fail("loss_scale_px must be positive, max_num_iterations >= 0",
                summary);
  }

  const int num_cameras = dataset.cameras.size();
  const int num_framesets = dataset.frameset_names.size();
  const int reference = dataset.reference_camera;

  // Inlier correspondences of images of calibrated cameras in posed
  // framesets, and per frameset the principal axes (in the rig frame) of the
  // cameras that observe enough of them.
  std::vector<std::vector<Observation>> observations_of_frameset(num_framesets);
  std::vector<std::vector<Eigen::Vector3d>> axes_of_frameset(num_framesets);
  for (size_t k = 0; k < dataset.images.size(); ++k) {
    const RigImage& image = dataset.images[k];
    const std::vector<char>& mask = calibration->images[k].inlier_mask;
    if (!calibration->camera_calibrated[image.camera_index] ||
        !calibration->rig_from_world[image.frameset_index]) {
      continue;
    }
    int num_inliers = 0;
    for (size_t c = 0; c < mask.size(); ++c) {
      if (!mask[c]) continue;
      observations_of_frameset[image.frameset_index].push_back(
          {image.camera_index, image.frameset_index,
           image.correspondences[c].point2D, image.correspondences[c].point3D});
      ++num_inliers;
    }
    if (num_inliers >= kMinInliersPerImage) {
      axes_of_frameset[image.frameset_index].push_back(
          calibration->cam_from_rig[image.camera_index]
              .RotationMatrix()
              .row(2)
              .transpose());
    }
  }
  const double min_axis_eigenvalue =
      1.0 - std::cos(options.min_principal_axis_angle_deg * M_PI / 180.0);
  std::vector<Observation> observations;
  int num_skipped = 0;
  for (int j = 0; j < num_framesets; ++j) {
    if (!calibration->rig_from_world[j]) continue;
    // With radial projections the translation of Q_j is determined iff
    // sum_k (I - z_k z_k^T) over the observing cameras' axes is regular.
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    for (const Eigen::Vector3d& axis : axes_of_frameset[j]) {
      normal += Eigen::Matrix3d::Identity() - axis * axis.transpose();
    }
    const double smallest_eigenvalue =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(normal,
                                                       Eigen::EigenvaluesOnly)
            .eigenvalues()(0);
    if (axes_of_frameset[j].size() < 2 ||
        smallest_eigenvalue < min_axis_eigenvalue) {
      ++num_skipped;
      continue;
    }
    observations.insert(observations.end(), observations_of_frameset[j].begin(),
                        observations_of_frameset[j].end());
  }
  bool reference_observed = false;
  for (const Observation& observation : observations) {
    reference_observed |= observation.camera == reference;
  }
  if (!reference_observed) {
    return Fail("the reference camera " + dataset.cameras[reference].name +
                    " has no inlier correspondences in framesets with a "
                    "determined rig pose",
                summary);
  }

  std::vector<std::array<double, 6>> cam_parameters(num_cameras);
  std::vector<std::array<double, 2>> principal_points(num_cameras);
  for (int i = 0; i < num_cameras; ++i) {
    cam_parameters[i] = ToParameters(calibration->cam_from_rig[i]);
    principal_points[i] = {calibration->cameras[i].PrincipalPointX(),
                           calibration->cameras[i].PrincipalPointY()};
  }
  std::vector<std::array<double, 6>> rig_parameters(num_framesets);
  for (int j = 0; j < num_framesets; ++j) {
    if (calibration->rig_from_world[j]) {
      rig_parameters[j] = ToParameters(*calibration->rig_from_world[j]);
    }
  }

  ceres::Problem problem;
  ceres::LossFunction* loss = new ceres::CauchyLoss(options.loss_scale_px);
  std::vector<char> cam_added(num_cameras, 0);
  std::vector<char> rig_added(num_framesets, 0);
  for (const Observation& observation : observations) {
    problem.AddResidualBlock(
        RadialRigCost::Create(observation.point2D, observation.point3D), loss,
        cam_parameters[observation.camera].data(),
        rig_parameters[observation.frameset].data(),
        principal_points[observation.camera].data());
    cam_added[observation.camera] = 1;
    rig_added[observation.frameset] = 1;
  }

  // Rig poses form the eliminated group: no residual links two of them.
  auto* ordering = new ceres::ParameterBlockOrdering;
  bool tz_gauge_held = false;
  for (int j = 0; j < num_framesets; ++j) {
    if (!rig_added[j]) continue;
    ordering->AddElementToGroup(rig_parameters[j].data(), 0);
    if (!tz_gauge_held) {
      // The rig origin's slide along the reference axis moves every rig
      // pose's t_z; holding one removes that null direction.
      problem.SetManifold(rig_parameters[j].data(),
                          new ceres::SubsetManifold(6, {5}));
      tz_gauge_held = true;
    }
  }
  for (int i = 0; i < num_cameras; ++i) {
    if (!cam_added[i]) continue;
    ordering->AddElementToGroup(cam_parameters[i].data(), 1);
    ordering->AddElementToGroup(principal_points[i].data(), 1);
    if (i == reference) {
      problem.SetParameterBlockConstant(cam_parameters[i].data());
    } else {
      problem.SetManifold(cam_parameters[i].data(),
                          new ceres::SubsetManifold(6, {5}));
    }
    if (!options.refine_principal_points) {
      problem.SetParameterBlockConstant(principal_points[i].data());
    }
  }

  const double initial_rms = RmsRadialError(observations, cam_parameters,
                                            rig_parameters, principal_points);
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_SCHUR;
  solver_options.linear_solver_ordering.reset(ordering);
  solver_options.max_num_iterations = options.max_num_iterations;
  solver_options.function_tolerance = 1e-10;
  solver_options.parameter_tolerance = 1e-10;
  solver_options.num_threads =
      colmap::GetEffectiveNumThreads(options.num_threads);
  solver_options.minimizer_progress_to_stdout = options.print_progress;
  solver_options.logging_type =
      options.print_progress ? ceres::PER_MINIMIZER_ITERATION : ceres::SILENT;
  ceres::Solver::Summary solver_summary;
  ceres::Solve(solver_options, &problem, &solver_summary);
  if (!solver_summary.IsSolutionUsable()) {
    return Fail("the solver failed: " + solver_summary.message, summary);
  }

  for (int i = 0; i < num_cameras; ++i) {
    if (!cam_added[i]) continue;
    calibration->cam_from_rig[i] = FromParameters(cam_parameters[i]);
    calibration->cam_from_rig[i].translation.z() = 0;
    calibration->cameras[i].SetPrincipalPointX(principal_points[i][0]);
    calibration->cameras[i].SetPrincipalPointY(principal_points[i][1]);
  }
  calibration->cam_from_rig[reference] = Rigid3d();
  for (int j = 0; j < num_framesets; ++j) {
    if (rig_added[j]) {
      calibration->rig_from_world[j] = FromParameters(rig_parameters[j]);
    }
  }
  NormalizeRadialRigOrigin(reference, calibration);

  if (summary) {
    summary->initial_rms_px = initial_rms;
    summary->final_rms_px = RmsRadialError(observations, cam_parameters,
                                           rig_parameters, principal_points);
    summary->num_residuals = observations.size();
    summary->num_iterations = solver_summary.iterations.size();
    summary->num_framesets_skipped = num_skipped;
    summary->seconds = std::chrono::duration<double>(
                           std::chrono::steady_clock::now() - start_time)
                           .count();
  }
  return true;
}

}  // namespace rig_calibrator
