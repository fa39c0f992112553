#include "src/calibration/camera_upgrader.h"

#include <ceres/ceres.h>
#include <colmap/base/camera_models.h>
#include <colmap/util/math.h>
#include <colmap/util/threading.h>
#include <glog/logging.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>

#include "src/estimators/radial_intrinsics_estimator.h"
#include "src/geometry/full_reprojection_cost.h"

namespace rig_calibrator {
namespace {

// LM runs, each followed by a re-evaluation of the inliers on all points.
constexpr int kMaxNumRefinementRounds = 3;
// Below this reciprocal condition number of the equilibrated J^T J the
// covariance is treated as singular.
constexpr double kMinReciprocalCondition = 1e-14;

// The radial profile and number of radial terms of a model's initialization.
struct Initialization {
  RadialProfile profile = RadialProfile::kPolynomial;
  int num_radial_terms = 0;
};

bool InitializationForModel(const int model_id, Initialization* init) {
  switch (model_id) {
    case colmap::SimplePinholeCameraModel::kModelId:
    case colmap::PinholeCameraModel::kModelId:
      *init = {RadialProfile::kPolynomial, 0};
      return true;
    case colmap::SimpleRadialCameraModel::kModelId:
      *init = {RadialProfile::kPolynomial, 1};
      return true;
    case colmap::RadialCameraModel::kModelId:
    case colmap::OpenCVCameraModel::kModelId:
    case colmap::FullOpenCVCameraModel::kModelId:
      *init = {RadialProfile::kPolynomial, 2};
      return true;
    case colmap::SimpleRadialFisheyeCameraModel::kModelId:
      *init = {RadialProfile::kEquidistant, 1};
      return true;
    case colmap::RadialFisheyeCameraModel::kModelId:
    case colmap::OpenCVFisheyeCameraModel::kModelId:
    case colmap::ThinPrismFisheyeCameraModel::kModelId:
      *init = {RadialProfile::kEquidistant, 2};
      return true;
    default:
      return false;
  }
}

// Correspondences the RANSAC's local optimization needs: one more than the
// minimal sample, n + 2 unknowns (tz, f, k1..kn) or n + 1 with f known.
size_t MinNumPoints(const Initialization& init,
                    const std::optional<double>& known_focal) {
  return init.num_radial_terms + (known_focal ? 2 : 3);
}

// Entries of C = (J^T J)^-1 (variances at 1 px noise); see
// CameraUpgradeResult.
struct Conditioning {
  bool singular = true;
  double tz_focal_correlation = 1;
  double tz_variance = 0;
  double focal_variance = 0;
};

// The covariance C = (J^T J)^-1 over tz and the refined (tangent) parameters,
// from the robustified Jacobian of every residual block of the problem.
Conditioning ComputeConditioning(const ceres::Problem& problem,
                                 const std::vector<ceres::ResidualBlockId>& ids,
                                 const std::vector<int>& focal_tangent_idxs,
                                 const int num_tangent_params) {
  const int n = 1 + num_tangent_params;
  Eigen::MatrixXd JtJ = Eigen::MatrixXd::Zero(n, n);
  Eigen::Matrix<double, 2, Eigen::Dynamic, Eigen::RowMajor> J(2, n);
  Eigen::Matrix<double, 2, 1> J_tz;
  Eigen::Matrix<double, 2, Eigen::Dynamic, Eigen::RowMajor> J_params(
      2, num_tangent_params);
  double* jacobians[2] = {J_tz.data(), J_params.data()};
  double residuals[2];
  double cost = 0;
  for (const ceres::ResidualBlockId id : ids) {
    if (!problem.EvaluateResidualBlock(id, /*apply_loss_function=*/true, &cost,
                                       residuals, jacobians)) {
      continue;
    }
    J << J_tz, J_params;
    JtJ.noalias() += J.transpose() * J;
  }

  Conditioning conditioning;
  // Correlations do not depend on the units of the parameters: equilibrate
  // J^T J so that the singularity test does not either.
  const Eigen::VectorXd diagonal = JtJ.diagonal();
  if (!JtJ.allFinite() || (diagonal.array() <= 0).any()) {
    return conditioning;
  }
  const Eigen::VectorXd scales = diagonal.cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd normalized =
      scales.asDiagonal() * JtJ * scales.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(normalized);
  const Eigen::VectorXd& eigenvalues = eigen.eigenvalues();
  if (eigen.info() != Eigen::Success ||
      !(eigenvalues(0) > kMinReciprocalCondition * eigenvalues(n - 1))) {
    return conditioning;
  }
  const Eigen::MatrixXd covariance =
      scales.asDiagonal() *
      (eigen.eigenvectors() * eigenvalues.cwiseInverse().asDiagonal() *
       eigen.eigenvectors().transpose()) *
      scales.asDiagonal();
  // f = mean of the focal lengths: var(f) = mean of their covariances,
  // cov(tz, f) = mean of their covariances with tz.
  double tz_focal_covariance = 0;
  double focal_variance = 0;
  for (const int i : focal_tangent_idxs) {
    tz_focal_covariance += covariance(0, 1 + i);
    for (const int j : focal_tangent_idxs) {
      focal_variance += covariance(1 + i, 1 + j);
    }
  }
  conditioning.singular = false;
  conditioning.tz_variance = covariance(0, 0);
  // A held focal length is not traded against tz.
  if (focal_tangent_idxs.empty()) {
    conditioning.tz_focal_correlation = 0;
    return conditioning;
  }
  const double num_focals = focal_tangent_idxs.size();
  tz_focal_covariance /= num_focals;
  focal_variance /= num_focals * num_focals;
  conditioning.focal_variance = focal_variance;
  conditioning.tz_focal_correlation =
      tz_focal_covariance / std::sqrt(covariance(0, 0) * focal_variance);
  return conditioning;
}

// Marks the points whose full reprojection error is below the threshold and
// that the model projects on the side of the principal point given by the
// radial pose, (x - c).(a, b) >= 0 (a distortion whose radial factor turns
// negative mirrors points through the principal point); returns their
// number.
template <typename CameraModel>
int EvaluateInliers(const std::vector<Eigen::Vector2d>& points2D,
                    const std::vector<Eigen::Vector3d>& points_cam,
                    const std::vector<char>& valid, const double tz,
                    const std::vector<double>& params,
                    const double max_error_px, std::vector<char>* inlier_mask,
                    double* rms_px) {
  const double max_squared_error = max_error_px * max_error_px;
  const Eigen::Vector2d principal_point(
      params[CameraModel::principal_point_idxs[0]],
      params[CameraModel::principal_point_idxs[1]]);
  inlier_mask->assign(points2D.size(), 0);
  int num_inliers = 0;
  double sum_squared_error = 0;
  for (size_t i = 0; i < points2D.size(); ++i) {
    const double depth = points_cam[i].z() + tz;
    if (!valid[i] || !(depth > 0)) {
      continue;
    }
    Eigen::Vector2d projection;
    CameraModel::WorldToImage(params.data(), points_cam[i].x() / depth,
                              points_cam[i].y() / depth, &projection.x(),
                              &projection.y());
    const double squared_error = (projection - points2D[i]).squaredNorm();
    if (squared_error <= max_squared_error &&
        (projection - principal_point).dot(points_cam[i].head<2>()) >= 0) {
      (*inlier_mask)[i] = 1;
      ++num_inliers;
      sum_squared_error += squared_error;
    }
  }
  *rms_px = num_inliers > 0 ? std::sqrt(sum_squared_error / num_inliers) : 0;
  return num_inliers;
}

// The parameter indices the LM holds (the refine_* options), ascending.
template <typename CameraModel>
std::vector<int> HeldParamIdxsOfModel(const CameraUpgradeOptions& options) {
  std::vector<int> held;
  const auto hold = [&held](const std::vector<size_t>& idxs) {
    held.insert(held.end(), idxs.begin(), idxs.end());
  };
  if (!options.refine_focal_length) hold(CameraModel::focal_length_idxs);
  if (!options.refine_principal_point) hold(CameraModel::principal_point_idxs);
  if (!options.refine_extra_params) hold(CameraModel::extra_params_idxs);
  std::sort(held.begin(), held.end());
  return held;
}

// The parameters the LM refines: parameter index -> tangent index (-1 for a
// held parameter), and the tangent indices of the refined focal lengths.
struct RefinedParams {
  std::vector<int> tangent_idxs;
  std::vector<int> focal_tangent_idxs;
  int num_tangent_params = 0;
};

template <typename CameraModel>
RefinedParams RefinedParamsOfModel(const CameraUpgradeOptions& options) {
  const std::vector<int> held = HeldParamIdxsOfModel<CameraModel>(options);
  RefinedParams refined;
  for (size_t i = 0; i < CameraModel::kNumParams; ++i) {
    const bool fixed =
        std::count(held.begin(), held.end(), static_cast<int>(i)) > 0;
    refined.tangent_idxs.push_back(fixed ? -1 : refined.num_tangent_params++);
  }
  for (const size_t i : CameraModel::focal_length_idxs) {
    if (refined.tangent_idxs[i] >= 0) {
      refined.focal_tangent_idxs.push_back(refined.tangent_idxs[i]);
    }
  }
  return refined;
}

// The rows the LM of a round runs on: of its n inliers in index order, the
// floor(j n / m)-th for j = 0..m-1, m = min(n, max_num_refinement_points):
// spread evenly over the input (a camera's rows come frame after frame) and
// the same for the same input.
std::vector<int> RefinementRows(const CameraUpgradeOptions& options,
                                const std::vector<char>& inlier_mask,
                                const int num_inliers) {
  const int64_t num_rows =
      std::min(num_inliers, options.max_num_refinement_points);
  std::vector<int> rows;
  rows.reserve(num_rows);
  int64_t inlier_idx = 0;
  for (size_t i = 0;
       i < inlier_mask.size() && static_cast<int64_t>(rows.size()) < num_rows;
       ++i) {
    if (!inlier_mask[i]) continue;
    // The next row to take is the floor(j n / m)-th inlier, j = rows.size().
    if (inlier_idx ==
        static_cast<int64_t>(rows.size()) * num_inliers / num_rows) {
      rows.push_back(static_cast<int>(i));
    }
    ++inlier_idx;
  }
  return rows;
}

// The LM problem of one refinement round: tz and the model's parameters (the
// held ones fixed), a Cauchy-robustified full reprojection residual per row.
template <typename CameraModel>
void BuildRefinementProblem(const CameraUpgradeOptions& options,
                            const std::vector<Eigen::Vector2d>& points2D,
                            const std::vector<Eigen::Vector3d>& points_cam,
                            const std::vector<int>& rows, double* tz,
                            std::vector<double>* params,
                            ceres::Problem* problem,
                            std::vector<ceres::ResidualBlockId>* blocks) {
  problem->AddParameterBlock(tz, 1);
  problem->AddParameterBlock(params->data(), CameraModel::kNumParams);
  const std::vector<int> held = HeldParamIdxsOfModel<CameraModel>(options);
  if (static_cast<int>(held.size()) == CameraModel::kNumParams) {
    problem->SetParameterBlockConstant(params->data());
  } else if (!held.empty()) {
    problem->SetManifold(params->data(), new ceres::SubsetManifold(
                                             CameraModel::kNumParams, held));
  }
  ceres::LossFunction* loss = new ceres::CauchyLoss(options.loss_scale_px);
  blocks->clear();
  for (const int row : rows) {
    blocks->push_back(problem->AddResidualBlock(
        new FullReprojectionCost<CameraModel>(points2D[row], points_cam[row]),
        loss, tz, params->data()));
  }
}

// The conditioning fields of `result` from the final round's problem, whose
// `blocks` are an even subsample of that round's `num_inliers` inliers.
template <typename CameraModel>
void SetConditioning(const ceres::Problem& problem,
                     const std::vector<ceres::ResidualBlockId>& blocks,
                     const int num_inliers, const RefinedParams& refined,
                     const std::vector<Eigen::Vector3d>& points_cam,
                     const double tz, const std::vector<double>& params,
                     CameraUpgradeResult* result) {
  Conditioning conditioning = ComputeConditioning(
      problem, blocks, refined.focal_tangent_idxs, refined.num_tangent_params);
  // J^T J is a sum over rows, so that of all n inliers is about n / m times
  // that of an even subsample of m of them, and C = (J^T J)^-1 about m / n
  // times: var_n = (m / n) var_m, stddev_n = sqrt(m / n) stddev_m. The
  // correlation, a ratio of entries of C, does not change.
  const double subsample_fraction =
      static_cast<double>(blocks.size()) / num_inliers;
  conditioning.tz_variance *= subsample_fraction;
  conditioning.focal_variance *= subsample_fraction;
  double mean_focal = 0;
  for (const size_t i : CameraModel::focal_length_idxs) {
    mean_focal += params[i] / CameraModel::focal_length_idxs.size();
  }
  std::vector<double> depths;
  for (size_t i = 0; i < points_cam.size(); ++i) {
    if (result->inlier_mask[i]) depths.push_back(points_cam[i].z() + tz);
  }
  const double median_depth = depths.empty() ? 0 : colmap::Median(depths);
  result->tz_focal_correlation = conditioning.tz_focal_correlation;
  result->tz_stddev_at_1px = std::sqrt(conditioning.tz_variance);
  result->focal_stddev_at_1px = std::sqrt(conditioning.focal_variance);
  result->well_conditioned =
      !conditioning.singular &&
      result->focal_stddev_at_1px <= kMaxRelativeStddevAt1px * mean_focal &&
      result->tz_stddev_at_1px <= kMaxRelativeStddevAt1px * median_depth;
}

// Step 3: LM over tz and the model's parameters on the inliers (at most
// max_num_refinement_points of them), inliers re-evaluated on all points,
// repeated while they change.
template <typename CameraModel>
bool RefineUpgrade(const CameraUpgradeOptions& options,
                   const std::vector<Eigen::Vector2d>& points2D,
                   const std::vector<Eigen::Vector3d>& points_cam,
                   const std::vector<char>& valid, double* tz,
                   std::vector<double>* params, CameraUpgradeResult* result) {
  const RefinedParams refined = RefinedParamsOfModel<CameraModel>(options);
  const int num_unknowns = 1 + refined.num_tangent_params;
  if (options.max_num_refinement_points < num_unknowns) {
    result->error_message = "max_num_refinement_points " +
                            std::to_string(options.max_num_refinement_points) +
                            " is below the " + std::to_string(num_unknowns) +
                            " unknowns of the refinement";
    return false;
  }

  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  solver_options.max_num_iterations = options.max_num_iterations;
  solver_options.num_threads =
      colmap::GetEffectiveNumThreads(options.num_threads);
  // Noisy data stop on the cost (Ceres' default function tolerance); exact
  // data, whose cost keeps falling by orders of magnitude, on the step.
  solver_options.parameter_tolerance = 1e-12;
  solver_options.logging_type = ceres::SILENT;

  std::vector<char>& inlier_mask = result->inlier_mask;
  std::vector<double> refined_params = *params;
  double refined_tz = *tz;
  for (int round = 0; round < kMaxNumRefinementRounds; ++round) {
    const int num_inliers =
        std::count(inlier_mask.begin(), inlier_mask.end(), 1);
    if (num_inliers < num_unknowns) {
      result->error_message = "only " + std::to_string(num_inliers) +
                              " inliers for " + std::to_string(num_unknowns) +
                              " unknowns";
      return false;
    }
    ceres::Problem problem;
    std::vector<ceres::ResidualBlockId> residual_blocks;
    BuildRefinementProblem<CameraModel>(
        options, points2D, points_cam,
        RefinementRows(options, inlier_mask, num_inliers), &refined_tz,
        &refined_params, &problem, &residual_blocks);
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &problem, &summary);
    if (!summary.IsSolutionUsable() || !std::isfinite(refined_tz) ||
        !std::all_of(refined_params.begin(), refined_params.end(),
                     [](double p) { return std::isfinite(p); })) {
      result->error_message = "the refinement failed: " + summary.message;
      return false;
    }

    const std::vector<char> previous_mask = inlier_mask;
    result->num_inliers = EvaluateInliers<CameraModel>(
        points2D, points_cam, valid, refined_tz, refined_params,
        options.max_error_px, &inlier_mask, &result->rms_px);
    if (inlier_mask == previous_mask || round + 1 == kMaxNumRefinementRounds) {
      SetConditioning<CameraModel>(problem, residual_blocks, num_inliers,
                                   refined, points_cam, refined_tz,
                                   refined_params, result);
      break;
    }
  }
  for (const size_t i : CameraModel::focal_length_idxs) {
    if (!(refined_params[i] > 0)) {
      result->error_message =
          "the refinement produced a non-positive focal length";
      return false;
    }
  }
  if (result->num_inliers < num_unknowns) {
    result->error_message = "only " + std::to_string(result->num_inliers) +
                            " inliers after the refinement";
    return false;
  }
  *tz = refined_tz;
  *params = refined_params;
  return true;
}

bool RefineUpgradeForModel(const int model_id,
                           const CameraUpgradeOptions& options,
                           const std::vector<Eigen::Vector2d>& points2D,
                           const std::vector<Eigen::Vector3d>& points_cam,
                           const std::vector<char>& valid, double* tz,
                           std::vector<double>* params,
                           CameraUpgradeResult* result) {
  switch (model_id) {
#define RIG_CALIBRATOR_REFINE_CASE(CameraModel)                              \
  case colmap::CameraModel::kModelId:                                        \
    return RefineUpgrade<colmap::CameraModel>(options, points2D, points_cam, \
                                              valid, tz, params, result);
    RIG_CALIBRATOR_REFINE_CASE(SimplePinholeCameraModel)
    RIG_CALIBRATOR_REFINE_CASE(PinholeCameraModel)
    RIG_CALIBRATOR_REFINE_CASE(SimpleRadialCameraModel)
    RIG_CALIBRATOR_REFINE_CASE(RadialCameraModel)
    RIG_CALIBRATOR_REFINE_CASE(OpenCVCameraModel)
    RIG_CALIBRATOR_REFINE_CASE(FullOpenCVCameraModel)
    RIG_CALIBRATOR_REFINE_CASE(SimpleRadialFisheyeCameraModel)
    RIG_CALIBRATOR_REFINE_CASE(RadialFisheyeCameraModel)
    RIG_CALIBRATOR_REFINE_CASE(OpenCVFisheyeCameraModel)
    RIG_CALIBRATOR_REFINE_CASE(ThinPrismFisheyeCameraModel)
#undef RIG_CALIBRATOR_REFINE_CASE
    default:
      result->error_message = "unsupported camera model";
      return false;
  }
}

std::string CheckOptions(const CameraUpgradeOptions& options) {
  if (!(options.max_error_px > 0)) return "max_error_px must be > 0";
  if (!(options.confidence > 0 && options.confidence < 1)) {
    return "confidence must be in (0, 1)";
  }
  if (options.min_num_trials < 0 ||
      options.max_num_trials < options.min_num_trials) {
    return "need 0 <= min_num_trials <= max_num_trials";
  }
  if (options.max_num_ransac_points < 1) {
    return "max_num_ransac_points must be >= 1";
  }
  if (options.max_num_refinement_points < 1) {
    return "max_num_refinement_points must be >= 1";
  }
  if (!(options.loss_scale_px > 0)) return "loss_scale_px must be > 0";
  if (options.max_num_iterations < 1) return "max_num_iterations must be >= 1";
  return "";
}

// Why the upgrade cannot start ("" if it can); fills `init` for the model.
std::string CheckInput(const CameraUpgradeOptions& options,
                       const std::vector<Eigen::Vector2d>& points2D,
                       const std::vector<Eigen::Vector3d>& points_cam,
                       const colmap::Camera& camera, Initialization* init) {
  const std::string options_error = CheckOptions(options);
  if (!options_error.empty()) {
    return "invalid options: " + options_error;
  }
  if (points2D.size() != points_cam.size()) {
    return std::to_string(points2D.size()) + " 2D points but " +
           std::to_string(points_cam.size()) + " 3D points";
  }
  if (!InitializationForModel(camera.ModelId(), init)) {
    const std::string name = colmap::CameraModelIdToName(camera.ModelId());
    return "camera model " +
           (name.empty() ? "id " + std::to_string(camera.ModelId()) : name) +
           " is not supported (supported: SIMPLE_PINHOLE, PINHOLE, "
           "SIMPLE_RADIAL, RADIAL, OPENCV, FULL_OPENCV, "
           "SIMPLE_RADIAL_FISHEYE, RADIAL_FISHEYE, OPENCV_FISHEYE, "
           "THIN_PRISM_FISHEYE)";
  }
  if (!camera.VerifyParams()) {
    return "camera has " + std::to_string(camera.NumParams()) +
           " parameters, model " + camera.ModelName() + " needs " +
           std::to_string(colmap::CameraModelNumParams(camera.ModelId()));
  }
  if (!Eigen::Vector2d(camera.PrincipalPointX(), camera.PrincipalPointY())
           .allFinite()) {
    return "the principal point is not finite";
  }
  for (const size_t i : camera.FocalLengthIdxs()) {
    if (!options.refine_focal_length &&
        !(std::isfinite(camera.Params(i)) && camera.Params(i) > 0)) {
      return "the focal length to hold is not a finite positive value";
    }
  }
  for (const size_t i : camera.ExtraParamsIdxs()) {
    if (!options.refine_extra_params && !std::isfinite(camera.Params(i))) {
      return "the distortion to hold is not finite";
    }
  }
  return "";
}

// Step 1 on at most max_num_ransac_points of the valid correspondences, drawn
// with a fixed seed, with pixels relative to the principal point; with
// `known_focal` (a held focal length) every hypothesis has that f.
bool EstimateInitialization(const CameraUpgradeOptions& options,
                            const Initialization& init,
                            const std::optional<double>& known_focal,
                            const std::vector<Eigen::Vector2d>& points2D,
                            const std::vector<Eigen::Vector3d>& points_cam,
                            const Eigen::Vector2d& principal_point,
                            std::vector<size_t> valid_idxs,
                            RadialIntrinsics* initial, std::string* error) {
  if (valid_idxs.size() > static_cast<size_t>(options.max_num_ransac_points)) {
    std::mt19937 generator(0);
    std::shuffle(valid_idxs.begin(), valid_idxs.end(), generator);
    valid_idxs.resize(options.max_num_ransac_points);
  }
  std::vector<Eigen::Vector2d> ransac_x;
  std::vector<Eigen::Vector3d> ransac_points_cam;
  for (const size_t i : valid_idxs) {
    ransac_x.push_back(points2D[i] - principal_point);
    ransac_points_cam.push_back(points_cam[i]);
  }
  colmap::RANSACOptions ransac_options;
  ransac_options.max_error = options.max_error_px;
  ransac_options.confidence = options.confidence;
  ransac_options.min_num_trials = options.min_num_trials;
  ransac_options.max_num_trials = options.max_num_trials;
  if (!EstimateRadialIntrinsicsRansac(ransac_options, init.profile,
                                      init.num_radial_terms, known_focal,
                                      ransac_x, ransac_points_cam, initial)) {
    *error = std::string(known_focal ? "no initial tz for the held focal "
                                       "length consistent with "
                                     : "no initial tz and focal length "
                                       "consistent with ") +
             std::to_string(MinNumPoints(init, known_focal)) +
             " or more of the " + std::to_string(valid_idxs.size()) +
             " correspondences";
    return false;
  }
  return true;
}

// Step 2: the model's parameters from the initialization: fx = fy = f, the
// principal point, k1, k2 where the model has them, every other term 0; a
// held focal length or distortion is the camera's.
std::vector<double> InitialParams(const CameraUpgradeOptions& options,
                                  const colmap::Camera& camera,
                                  const Initialization& init,
                                  const RadialIntrinsics& initial,
                                  const Eigen::Vector2d& principal_point) {
  std::vector<double> params(camera.NumParams(), 0.0);
  for (const size_t i : camera.FocalLengthIdxs()) {
    params[i] = options.refine_focal_length ? initial.focal : camera.Params(i);
  }
  params[camera.PrincipalPointIdxs()[0]] = principal_point.x();
  params[camera.PrincipalPointIdxs()[1]] = principal_point.y();
  if (options.refine_extra_params) {
    for (int j = 0; j < init.num_radial_terms; ++j) {
      params[camera.ExtraParamsIdxs()[j]] = initial.k[j];
    }
  } else {
    for (const size_t i : camera.ExtraParamsIdxs()) {
      params[i] = camera.Params(i);
    }
  }
  return params;
}

bool Fail(const std::string& message, CameraUpgradeResult* result) {
  result->error_message = message;
  LOG(ERROR) << "Camera upgrade: " << message;
  return false;
}

}  // namespace

bool IsUpgradeSupportedCameraModel(const int model_id) {
  Initialization init;
  return InitializationForModel(model_id, &init);
}

bool UpgradeCamera(const CameraUpgradeOptions& options,
                   const std::vector<Eigen::Vector2d>& points2D,
                   const std::vector<Eigen::Vector3d>& points_cam,
                   colmap::Camera* camera, CameraUpgradeResult* result) {
  if (camera == nullptr || result == nullptr) {
    LOG(ERROR) << "Camera upgrade: null camera or result";
    return false;
  }
  *result = CameraUpgradeResult();
  Initialization init;
  const std::string input_error =
      CheckInput(options, points2D, points_cam, *camera, &init);
  if (!input_error.empty()) {
    return Fail(input_error, result);
  }
  const Eigen::Vector2d principal_point(camera->PrincipalPointX(),
                                        camera->PrincipalPointY());

  const size_t num_points = points2D.size();
  std::vector<char> valid(num_points, 0);
  std::vector<size_t> valid_idxs;
  for (size_t i = 0; i < num_points; ++i) {
    if (points2D[i].allFinite() && points_cam[i].allFinite()) {
      valid[i] = 1;
      valid_idxs.push_back(i);
    }
  }
  // The RANSAC's hypotheses have the held focal length (its mean for
  // PINHOLE-type models with two).
  const std::optional<double> known_focal =
      options.refine_focal_length
          ? std::nullopt
          : std::optional<double>(camera->MeanFocalLength());
  const size_t min_num_points = MinNumPoints(init, known_focal);
  if (valid_idxs.size() < min_num_points) {
    return Fail(std::to_string(valid_idxs.size()) +
                    " valid correspondences, need at least " +
                    std::to_string(min_num_points),
                result);
  }

  RadialIntrinsics initial;
  if (!EstimateInitialization(options, init, known_focal, points2D, points_cam,
                              principal_point, valid_idxs, &initial,
                              &result->error_message)) {
    return Fail(result->error_message, result);
  }
  result->inlier_mask.assign(num_points, 0);
  const double max_squared_error = options.max_error_px * options.max_error_px;
  for (const size_t i : valid_idxs) {
    Eigen::Vector2d projection;
    result->inlier_mask[i] =
        initial.Project(points_cam[i], &projection) &&
        (projection + principal_point - points2D[i]).squaredNorm() <=
            max_squared_error;
  }

  std::vector<double> params =
      InitialParams(options, *camera, init, initial, principal_point);
  double tz = initial.tz;
  if (!RefineUpgradeForModel(camera->ModelId(), options, points2D, points_cam,
                             valid, &tz, &params, result)) {
    result->tz = 0;
    result->num_inliers = 0;
    result->inlier_mask.assign(num_points, 0);
    return Fail(result->error_message, result);
  }
  result->tz = tz;
  camera->SetParams(params);
  return true;
}

}  // namespace rig_calibrator
