#include "src/estimators/radial_pose_estimator.h"

#include <colmap/optim/loransac.h>
#include <colmap/optim/support_measurement.h>
#include <glog/logging.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "src/geometry/point_normalization.h"
#include "src/geometry/radial_error.h"
#include "src/solvers/radial_pose_solver.h"

namespace rig_calibrator {
namespace {

constexpr double kMinCurvatureShare = 0.25;

using Vector8d = Eigen::Matrix<double, 8, 1>;
using Matrix5d = Eigen::Matrix<double, 5, 5>;
using Vector5d = Eigen::Matrix<double, 5, 1>;

// A radial pose in the normalized world frame X_n = (X - c) / s
// (CenterAndScalePoints): rotation and (tx, ty).
struct RadialPose {
  Eigen::Matrix3d rotation;
  Eigen::Vector2d translation;
};

// Cauchy loss rho(e^2) = s^2 log(1 + e^2 / s^2) and its IRLS weight
// rho'(e^2) = 1 / (1 + e^2 / s^2).
double CauchyLoss(double error_sq, double scale_sq) {
  return scale_sq * std::log1p(error_sq / scale_sq);
}

// Radial error of one point for the Levenberg-Marquardt refinement, as the
// signed scalar e = (a x_2 - b x_1) / |(a, b)| (|e| is the radial error) with
// its derivatives by (a, b). On the wrong half-line or on the optical axis
// the error is |x| with zero derivatives, as in RadialResidual
// (radial_residual.h).
struct PointError {
  double error;
  double d_a;
  double d_b;
};

PointError ComputePointError(const Eigen::Vector3d& point_in_cam,
                             const Eigen::Vector2d& point2D) {
  const double a = point_in_cam.x();
  const double b = point_in_cam.y();
  if (!(a * point2D.x() + b * point2D.y() > 0) ||
      IsOnOpticalAxis(point_in_cam)) {
    return {point2D.norm(), 0, 0};
  }
  const double inv_norm = 1 / std::sqrt(a * a + b * b);
  const double error = (a * point2D.y() - b * point2D.x()) * inv_norm;
  // d/da [c / n] = x_2 / n - c a / n^3 = (x_2 - e a / n) / n, likewise for b.
  return {error, (point2D.y() - error * a * inv_norm) * inv_norm,
          (-point2D.x() - error * b * inv_norm) * inv_norm};
}

double RobustCost(const RadialPose& pose,
                  const std::vector<Eigen::Vector2d>& points2D,
                  const std::vector<Eigen::Vector3d>& points3D,
                  double scale_sq) {
  double cost = 0;
  for (size_t i = 0; i < points2D.size(); ++i) {
    Eigen::Vector3d point_in_cam = pose.rotation * points3D[i];
    point_in_cam.head<2>() += pose.translation;
    const double error = ComputePointError(point_in_cam, points2D[i]).error;
    cost += CauchyLoss(error * error, scale_sq);
  }
  return cost;
}

// Normal equations for the update R <- exp([w]x) R, t <- t + dt of the cost
// sum rho(e_i^2), rho(s) = c^2 log(1 + s / c^2). With Y = R X:
//   d(a, b)/dw = [0, Y_3, -Y_2; -Y_3, 0, Y_1],  d(a, b)/dt = I.
// Gradient: sum rho' e_i J_i^T (halved), rho' = 1 / (1 + u), u = e^2 / c^2.
// Hessian: sum w_i J_i^T J_i with the loss' curvature in the weight,
//   w = rho' + 2 rho'' e^2 = rho' (1 - u) / (1 + u),
// kept at >= kMinCurvatureShare rho' (positive definite where the loss is
// concave, u > 1). The IRLS weight rho' alone overstates the curvature of
// points with u near 1 and makes convergence linear: at c = 1 px and 0.5 px
// noise ~30 iterations to the last digits, against ~12.
// Returns the robust cost at `pose`.
double Linearize(const RadialPose& pose,
                 const std::vector<Eigen::Vector2d>& points2D,
                 const std::vector<Eigen::Vector3d>& points3D, double scale_sq,
                 Matrix5d* hessian, Vector5d* gradient) {
  hessian->setZero();
  gradient->setZero();
  double cost = 0;
  for (size_t i = 0; i < points2D.size(); ++i) {
    const Eigen::Vector3d rotated = pose.rotation * points3D[i];
    Eigen::Vector3d point_in_cam = rotated;
    point_in_cam.head<2>() += pose.translation;
    const PointError e = ComputePointError(point_in_cam, points2D[i]);
    const double error_sq = e.error * e.error;
    cost += CauchyLoss(error_sq, scale_sq);
    const double u = error_sq / scale_sq;
    const double rho1 = 1 / (1 + u);
    const double curvature_weight =
        rho1 * std::max((1 - u) / (1 + u), kMinCurvatureShare);
    Vector5d jacobian;
    jacobian << -e.d_b * rotated.z(), e.d_a * rotated.z(),
        e.d_b * rotated.x() - e.d_a * rotated.y(), e.d_a, e.d_b;
    hessian->selfadjointView<Eigen::Upper>().rankUpdate(jacobian,
                                                        curvature_weight);
    *gradient += (rho1 * e.error) * jacobian;
  }
  *hessian = hessian->selfadjointView<Eigen::Upper>();
  return cost;
}

// Levenberg-Marquardt over (rotation, tx, ty) minimizing the Cauchy cost
// sum s^2 log(1 + e_i^2 / s^2) of the radial errors e_i, s = loss_scale.
// Stops when an accepted step lowers the cost by less than
// function_tolerance of it or moves less than 1e-12, or when a rejected
// step raises it by no more than its rounding (1e-14 of it: no step can be
// told from no step any more).
void MinimizeCauchyRadialCost(const std::vector<Eigen::Vector2d>& points2D,
                              const std::vector<Eigen::Vector3d>& points3D,
                              double loss_scale, int max_num_iterations,
                              double function_tolerance, RadialPose* pose) {
  const double scale_sq = loss_scale * loss_scale;
  Matrix5d hessian;
  Vector5d gradient;
  double cost =
      Linearize(*pose, points2D, points3D, scale_sq, &hessian, &gradient);
  double lambda = 1e-4;
  for (int iter = 0; iter < max_num_iterations; ++iter) {
    Matrix5d damped = hessian;
    damped.diagonal() += lambda * hessian.diagonal().cwiseMax(1e-12);
    const Vector5d step = damped.ldlt().solve(-gradient);
    if (!step.allFinite()) return;
    const Eigen::Vector3d omega = step.head<3>();
    const double angle = omega.norm();
    RadialPose candidate;
    candidate.rotation =
        angle > 0 ? Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix() *
                        pose->rotation
                  : pose->rotation;
    candidate.translation = pose->translation + step.tail<2>();
    const double candidate_cost =
        RobustCost(candidate, points2D, points3D, scale_sq);
    if (candidate_cost < cost) {
      const double decrease = cost - candidate_cost;
      *pose = candidate;
      if (decrease < function_tolerance * cost || step.norm() < 1e-12) {
        return;
      }
      cost =
          Linearize(*pose, points2D, points3D, scale_sq, &hessian, &gradient);
      lambda = std::max(lambda * 0.1, 1e-12);
    } else {
      if (candidate_cost - cost <= 1e-14 * cost) return;
      lambda *= 10;
      if (lambda > 1e8) return;
    }
  }
}

// Fixes the sign of p = (r1, t1, r2, t2) so that most points lie on their
// half-line, and converts it to a pose; false if [r1; r2] is degenerate.
bool RadialPoseFromRows(const Vector8d& rows,
                        const std::vector<Eigen::Vector2d>& points2D,
                        const std::vector<Eigen::Vector3d>& points3D,
                        RadialPose* pose) {
  Vector8d p = rows;
  if (!NormalizeRadialRows(&p)) return false;
  int num_positive = 0;
  for (size_t i = 0; i < points2D.size(); ++i) {
    const double a = p.segment<3>(0).dot(points3D[i]) + p(3);
    const double b = p.segment<3>(4).dot(points3D[i]) + p(7);
    if (a * points2D[i].x() + b * points2D[i].y() > 0) ++num_positive;
  }
  if (2 * num_positive < static_cast<int>(points2D.size())) p = -p;
  pose->rotation.row(0) = p.segment<3>(0).transpose();
  pose->rotation.row(1) = p.segment<3>(4).transpose();
  pose->rotation.row(2) = pose->rotation.row(0).cross(pose->rotation.row(1));
  pose->translation << p(3), p(7);
  return true;
}

RadialPose ToNormalizedFrame(const Rigid3d& cam_from_world,
                             const Eigen::Vector3d& centroid, double scale) {
  RadialPose pose;
  pose.rotation = cam_from_world.RotationMatrix();
  pose.translation =
      (cam_from_world.translation + pose.rotation * centroid).head<2>() / scale;
  return pose;
}

// Inverse of ToNormalizedFrame, t = s t_n - R c, with the given tz.
Rigid3d FromNormalizedFrame(const RadialPose& pose,
                            const Eigen::Vector3d& centroid, double scale,
                            double tz) {
  const Eigen::Vector3d rotated_centroid = pose.rotation * centroid;
  return Rigid3d(
      pose.rotation,
      Eigen::Vector3d(scale * pose.translation.x() - rotated_centroid.x(),
                      scale * pose.translation.y() - rotated_centroid.y(), tz));
}

bool IsValidOptions(const RadialPoseEstimationOptions& options) {
  return options.max_error_px > 0 && options.confidence >= 0 &&
         options.confidence <= 1 && options.min_inlier_ratio >= 0 &&
         options.min_inlier_ratio <= 1 && options.min_num_trials >= 0 &&
         options.min_num_trials <= options.max_num_trials &&
         options.loss_scale_px > 0;
}

}  // namespace

std::vector<Rigid3d> RadialPoseEstimator::Estimate(
    const std::vector<X_t>& points2D, const std::vector<Y_t>& points3D) {
  std::vector<Rigid3d> models;
  models.reserve(4);
  SolveRadialPose5(points2D, points3D, &models);
  return models;
}

void RadialPoseEstimator::Residuals(const std::vector<X_t>& points2D,
                                    const std::vector<Y_t>& points3D,
                                    const M_t& model,
                                    std::vector<double>* residuals) {
  const Eigen::Matrix3d rotation = model.rotation.toRotationMatrix();
  const Eigen::Vector3d& translation = model.translation;
  residuals->resize(points2D.size());
  for (size_t i = 0; i < points2D.size(); ++i) {
    const double error_sq = SquaredRadialErrorInCamera(
        rotation * points3D[i] + translation, points2D[i]);
    (*residuals)[i] = error_sq < std::numeric_limits<double>::infinity()
                          ? error_sq
                          : std::numeric_limits<double>::max();
  }
}

std::vector<Rigid3d> RadialPoseLocalEstimator::Estimate(
    const std::vector<X_t>& points2D, const std::vector<Y_t>& points3D) {
  const size_t num_points = points2D.size();
  if (num_points < kMinNumSamples || points3D.size() != num_points) return {};

  Eigen::Vector3d centroid;
  double scale;
  if (!CenterAndScalePoints(points3D, &points3D_normalized_, &centroid,
                            &scale)) {
    return {};
  }

  // Normal equations A^T A of the homogeneous system, one row
  // (-v X_n, -v, u X_n, u) per point.
  Eigen::Matrix<double, 8, 8> normal = Eigen::Matrix<double, 8, 8>::Zero();
  for (size_t i = 0; i < num_points; ++i) {
    const Eigen::Vector3d& X_n = points3D_normalized_[i];
    const double u = points2D[i].x();
    const double v = points2D[i].y();
    Vector8d row;
    row << -v * X_n, -v, u * X_n, u;
    normal.selfadjointView<Eigen::Upper>().rankUpdate(row);
  }
  normal = normal.selfadjointView<Eigen::Upper>();
  if (!normal.allFinite()) return {};
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 8, 8>> eigen(
      normal);
  if (eigen.info() != Eigen::Success) return {};
  const Eigen::Matrix<double, 8, 8>& vectors = eigen.eigenvectors();

  Vector8d candidates[5];
  candidates[0] = vectors.col(0);
  Eigen::Matrix<double, 8, 3> subspace;
  subspace << vectors.col(1), vectors.col(2), vectors.col(0);
  const int num_candidates =
      1 + RadialPosesInSubspace(subspace, candidates + 1);

  const double scale_sq = loss_scale_px * loss_scale_px;
  RadialPose best_pose;
  double best_cost = std::numeric_limits<double>::infinity();
  for (int c = 0; c < num_candidates; ++c) {
    RadialPose pose;
    if (!RadialPoseFromRows(candidates[c], points2D, points3D_normalized_,
                            &pose)) {
      continue;
    }
    const double cost =
        RobustCost(pose, points2D, points3D_normalized_, scale_sq);
    if (cost < best_cost) {
      best_cost = cost;
      best_pose = pose;
    }
  }
  if (!(best_cost < std::numeric_limits<double>::infinity())) return {};

  MinimizeCauchyRadialCost(points2D, points3D_normalized_, loss_scale_px,
                           max_num_iterations, function_tolerance,
                           &best_pose);

  const Rigid3d cam_from_world =
      FromNormalizedFrame(best_pose, centroid, scale, 0);
  if (!cam_from_world.rotation.coeffs().allFinite() ||
      !cam_from_world.translation.allFinite()) {
    return {};
  }
  return {cam_from_world};
}

bool RefineRadialPose(const RadialPoseEstimationOptions& options,
                      const std::vector<Eigen::Vector2d>& points2D_centered,
                      const std::vector<Eigen::Vector3d>& points3D,
                      const std::vector<char>& inlier_mask,
                      Rigid3d* cam_from_world) {
  if (points2D_centered.size() != points3D.size() ||
      inlier_mask.size() != points3D.size()) {
    LOG(ERROR) << "RefineRadialPose: " << points2D_centered.size()
               << " 2D points, " << points3D.size() << " 3D points and "
               << inlier_mask.size() << " mask entries differ in number";
    return false;
  }
  if (!(options.loss_scale_px > 0)) {
    LOG(ERROR) << "RefineRadialPose: loss_scale_px must be positive, got "
               << options.loss_scale_px;
    return false;
  }
  std::vector<Eigen::Vector2d> inlier_points2D;
  std::vector<Eigen::Vector3d> inlier_points3D;
  for (size_t i = 0; i < points3D.size(); ++i) {
    if (inlier_mask[i] && points2D_centered[i].allFinite() &&
        points3D[i].allFinite()) {
      inlier_points2D.push_back(points2D_centered[i]);
      inlier_points3D.push_back(points3D[i]);
    }
  }
  // 3 rotation + 2 translation unknowns.
  if (inlier_points2D.size() < 5) return false;
  std::vector<Eigen::Vector3d> normalized_points3D;
  Eigen::Vector3d centroid;
  double scale;
  if (!CenterAndScalePoints(inlier_points3D, &normalized_points3D, &centroid,
                            &scale)) {
    return false;
  }
  RadialPose pose = ToNormalizedFrame(*cam_from_world, centroid, scale);
  if (!pose.rotation.allFinite() || !pose.translation.allFinite()) {
    return false;
  }
  // The final estimate: to the last digits.
  constexpr int kMaxNumIterations = 50;
  constexpr double kFunctionTolerance = 1e-14;
  MinimizeCauchyRadialCost(inlier_points2D, normalized_points3D,
                           options.loss_scale_px, kMaxNumIterations,
                           kFunctionTolerance, &pose);
  const Rigid3d refined = FromNormalizedFrame(pose, centroid, scale,
                                              cam_from_world->translation.z());
  if (!refined.rotation.coeffs().allFinite() ||
      !refined.translation.allFinite()) {
    return false;
  }
  *cam_from_world = refined;
  return true;
}

bool EstimateRadialPose(const RadialPoseEstimationOptions& options,
                        const std::vector<Eigen::Vector2d>& points2D_centered,
                        const std::vector<Eigen::Vector3d>& points3D,
                        RadialPoseEstimate* estimate) {
  if (points2D_centered.size() != points3D.size()) {
    LOG(ERROR) << "EstimateRadialPose: " << points2D_centered.size()
               << " 2D points but " << points3D.size() << " 3D points";
    return false;
  }
  if (!IsValidOptions(options)) {
    LOG(ERROR) << "EstimateRadialPose: invalid options (need max_error_px > "
                  "0, loss_scale_px > 0, confidence and min_inlier_ratio in "
                  "[0, 1], 0 <= min_num_trials <= max_num_trials)";
    return false;
  }
  const size_t num_points = points3D.size();
  if (num_points <
      static_cast<size_t>(std::max(RadialPoseEstimator::kMinNumSamples,
                                   options.min_num_inliers))) {
    VLOG(2) << "EstimateRadialPose: only " << num_points << " correspondences";
    return false;
  }

  colmap::RANSACOptions ransac_options;
  ransac_options.max_error = options.max_error_px;
  ransac_options.confidence = options.confidence;
  ransac_options.min_num_trials = options.min_num_trials;
  ransac_options.max_num_trials = options.max_num_trials;
  ransac_options.min_inlier_ratio = options.min_inlier_ratio;
  ransac_options.dyn_num_trials_multiplier = options.dyn_num_trials_multiplier;
  colmap::LORANSAC<RadialPoseEstimator, RadialPoseLocalEstimator,
                   colmap::MEstimatorSupportMeasurer>
      ransac(ransac_options);
  ransac.local_estimator.loss_scale_px = options.max_error_px;
  const auto report = ransac.Estimate(points2D_centered, points3D);
  estimate->num_trials = static_cast<int>(report.num_trials);
  if (!report.success) return false;

  estimate->cam_from_world = report.model;
  if (options.refine) {
    // On failure the RANSAC pose stands.
    RefineRadialPose(options, points2D_centered, points3D, report.inlier_mask,
                     &estimate->cam_from_world);
  }

  std::vector<double> residuals;
  RadialPoseEstimator::Residuals(points2D_centered, points3D,
                                 estimate->cam_from_world, &residuals);
  const double max_residual = options.max_error_px * options.max_error_px;
  estimate->inlier_mask.assign(num_points, 0);
  estimate->num_inliers = 0;
  double sum_sq = 0;
  for (size_t i = 0; i < num_points; ++i) {
    if (residuals[i] <= max_residual) {
      estimate->inlier_mask[i] = 1;
      ++estimate->num_inliers;
      sum_sq += residuals[i];
    }
  }
  if (estimate->num_inliers < options.min_num_inliers) return false;
  estimate->radial_rms_px = std::sqrt(sum_sq / estimate->num_inliers);
  return true;
}

}  // namespace rig_calibrator
