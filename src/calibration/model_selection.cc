#include "src/calibration/model_selection.h"

#include <ceres/ceres.h>
#include <colmap/base/camera_models.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <numeric>
#include <optional>
#include <random>
#include <set>
#include <sstream>

namespace rig_calibrator {
namespace {

// Full reprojection residual of one row with the forward offset tz, as in
// the camera upgrade: WorldToImage(params, x / (z + tz), y / (z + tz)) - x_obs.
template <typename CameraModel>
struct HeldOutResidual {
  HeldOutResidual(const Eigen::Vector2d& point2D,
                  const Eigen::Vector3d& point_cam)
      : point2D(point2D), point_cam(point_cam) {}

  template <typename T>
  bool operator()(const T* const tz, const T* const params,
                  T* residuals) const {
    const T depth = T(point_cam.z()) + tz[0];
    if (!(depth > T(0))) return false;
    T x, y;
    CameraModel::WorldToImage(params, T(point_cam.x()) / depth,
                              T(point_cam.y()) / depth, &x, &y);
    residuals[0] = x - T(point2D.x());
    residuals[1] = y - T(point2D.y());
    return true;
  }

  const Eigen::Vector2d point2D;
  const Eigen::Vector3d point_cam;
};

// Squared reprojection error of a row truncated at max_error^2 (also for a
// point behind the camera).
double TruncatedSquaredError(const colmap::Camera& camera, double tz,
                             const Eigen::Vector2d& point2D,
                             const Eigen::Vector3d& point_cam,
                             double max_error) {
  const double depth = point_cam.z() + tz;
  const double max_squared_error = max_error * max_error;
  if (!(depth > 0)) return max_squared_error;
  const Eigen::Vector2d projection = camera.WorldToImage(
      Eigen::Vector2d(point_cam.x() / depth, point_cam.y() / depth));
  const double squared_error = (projection - point2D).squaredNorm();
  return std::isfinite(squared_error)
             ? std::min(squared_error, max_squared_error)
             : max_squared_error;
}

// LM over tz and the model's parameters (principal point held unless the
// upgrade refines it) on `rows`, from the given values; false if the solve
// is unusable (values unchanged).
template <typename CameraModel>
bool RefineOnRows(const CameraUpgradeOptions& upgrade_options,
                  int max_num_iterations,
                  const std::vector<Eigen::Vector2d>& points2D,
                  const std::vector<Eigen::Vector3d>& points_cam,
                  const std::vector<int>& rows, double* tz,
                  std::vector<double>* params) {
  double refined_tz = *tz;
  std::vector<double> refined_params = *params;
  ceres::Problem problem;
  problem.AddParameterBlock(&refined_tz, 1);
  problem.AddParameterBlock(refined_params.data(), CameraModel::kNumParams);
  if (!upgrade_options.refine_principal_point) {
    const std::vector<size_t>& idxs = CameraModel::principal_point_idxs;
    problem.SetManifold(
        refined_params.data(),
        new ceres::SubsetManifold(CameraModel::kNumParams,
                                  std::vector<int>(idxs.begin(), idxs.end())));
  }
  ceres::LossFunction* loss =
      new ceres::CauchyLoss(upgrade_options.loss_scale_px);
  for (const int row : rows) {
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<HeldOutResidual<CameraModel>, 2, 1,
                                        CameraModel::kNumParams>(
            new HeldOutResidual<CameraModel>(points2D[row], points_cam[row])),
        loss, &refined_tz, refined_params.data());
  }
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = max_num_iterations;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  if (!summary.IsSolutionUsable() || !std::isfinite(refined_tz) ||
      !std::all_of(refined_params.begin(), refined_params.end(),
                   [](double p) { return std::isfinite(p); })) {
    return false;
  }
  *tz = refined_tz;
  *params = refined_params;
  return true;
}

bool RefineOnRowsForModel(int model_id,
                          const CameraUpgradeOptions& upgrade_options,
                          int max_num_iterations,
                          const std::vector<Eigen::Vector2d>& points2D,
                          const std::vector<Eigen::Vector3d>& points_cam,
                          const std::vector<int>& rows, double* tz,
                          std::vector<double>* params) {
  switch (model_id) {
#define CAMERA_MODEL_CASE(CameraModel)                                     \
  case colmap::CameraModel::kModelId:                                      \
    return RefineOnRows<colmap::CameraModel>(upgrade_options,              \
                                             max_num_iterations, points2D, \
                                             points_cam, rows, tz, params);
    CAMERA_MODEL_CASES
#undef CAMERA_MODEL_CASE
    default:
      return false;
  }
}

// The start of a candidate's upgrade: `model` with the camera's size, mean
// focal length and principal point (the upgrade estimates the rest).
colmap::Camera CandidateStart(const std::string& model,
                              const colmap::Camera& camera) {
  colmap::Camera start;
  start.InitializeWithName(model, camera.MeanFocalLength(), camera.Width(),
                           camera.Height());
  start.SetPrincipalPointX(camera.PrincipalPointX());
  start.SetPrincipalPointY(camera.PrincipalPointY());
  return start;
}

// A candidate's full fit.
struct CandidateFit {
  colmap::Camera camera;
  CameraUpgradeResult result;
  ModelValidity validity;
};

// The rows the held-out evaluation uses: the valid ones, at most
// max_num_rows of them drawn with a fixed seed, in increasing order.
std::vector<int> EvaluationSubset(
    const std::vector<Eigen::Vector2d>& points2D,
    const std::vector<Eigen::Vector3d>& points_cam, int max_num_rows) {
  std::vector<int> rows;
  for (size_t i = 0; i < points2D.size(); ++i) {
    if (points2D[i].allFinite() && points_cam[i].allFinite()) {
      rows.push_back(static_cast<int>(i));
    }
  }
  if (rows.size() > static_cast<size_t>(max_num_rows)) {
    std::mt19937 generator(0);
    std::shuffle(rows.begin(), rows.end(), generator);
    rows.resize(max_num_rows);
    std::sort(rows.begin(), rows.end());
  }
  return rows;
}

// Per evaluation row, the candidate's truncated squared held-out error.
std::vector<double> HeldOutSquaredErrors(
    const ModelSelectionOptions& options,
    const CameraUpgradeOptions& upgrade_options, const CandidateFit& fit,
    const std::vector<Eigen::Vector2d>& points2D,
    const std::vector<Eigen::Vector3d>& points_cam,
    const std::vector<int>& groups, const std::vector<int>& subset,
    const std::vector<int>& evaluation_rows) {
  const int num_folds = std::max(2, options.num_folds);
  std::vector<double> squared_errors(evaluation_rows.size(), 0);
  for (int fold = 0; fold < num_folds; ++fold) {
    std::vector<int> training;
    for (const int row : subset) {
      if (fit.result.inlier_mask[row] && groups[row] % num_folds != fold) {
        training.push_back(row);
      }
    }
    double tz = fit.result.tz;
    std::vector<double> params = fit.camera.Params();
    if (static_cast<int>(training.size()) > fit.camera.NumParams() + 1) {
      RefineOnRowsForModel(fit.camera.ModelId(), upgrade_options,
                           options.max_num_fold_iterations, points2D,
                           points_cam, training, &tz, &params);
    }
    colmap::Camera fold_camera = fit.camera;
    fold_camera.SetParams(params);
    for (size_t e = 0; e < evaluation_rows.size(); ++e) {
      const int row = evaluation_rows[e];
      if (groups[row] % num_folds != fold) continue;
      squared_errors[e] =
          TruncatedSquaredError(fold_camera, tz, points2D[row], points_cam[row],
                                upgrade_options.max_error_px);
    }
  }
  return squared_errors;
}

double Mean(const std::vector<double>& values) {
  return values.empty() ? 0
                        : std::accumulate(values.begin(), values.end(), 0.0) /
                              values.size();
}

std::string Fixed(double value, int precision) {
  std::ostringstream stream;
  stream << std::fixed << std::setprecision(precision) << value;
  return stream.str();
}

// The residual profile of a fit over its inliers (radial_residual_profile.h),
// the points projected with the fit's tz as in the upgrade, clustered by
// `groups` (the frameset of every row: one image of this camera each).
RadialResidualProfile FitResidualProfile(
    const ModelSelectionOptions& options, const CandidateFit& fit,
    const std::vector<Eigen::Vector2d>& points2D,
    const std::vector<Eigen::Vector3d>& points_cam,
    const std::vector<int>& groups) {
  std::vector<Eigen::Vector2d> observed, projected;
  std::vector<int> observed_groups;
  for (size_t row = 0; row < points2D.size(); ++row) {
    if (row >= fit.result.inlier_mask.size() || !fit.result.inlier_mask[row]) {
      continue;
    }
    const double depth = points_cam[row].z() + fit.result.tz;
    if (!(depth > 0)) continue;
    observed.push_back(points2D[row]);
    projected.push_back(fit.camera.WorldToImage(Eigen::Vector2d(
        points_cam[row].x() / depth, points_cam[row].y() / depth)));
    observed_groups.push_back(groups[row]);
  }
  return ComputeRadialResidualProfile(
      Eigen::Vector2d(fit.camera.PrincipalPointX(),
                      fit.camera.PrincipalPointY()),
      observed, projected, observed_groups, options.validity.residual_profile);
}

// Fits `model` by the upgrade from `camera`'s size and principal point and
// fills its row of the table: parameters, inliers and training RMS, or why
// it could not be fitted or is not valid (checks 1 and 2 of
// model_validity.h, and with `check_data` check 3 on its inliers).
CandidateFit FitCandidate(const std::string& model,
                          const ModelSelectionOptions& options,
                          const CameraUpgradeOptions& upgrade_options,
                          const std::vector<Eigen::Vector2d>& points2D,
                          const std::vector<Eigen::Vector3d>& points_cam,
                          const std::vector<int>& groups,
                          const colmap::Camera& camera, bool check_data,
                          ModelCandidate* candidate) {
  CandidateFit fit;
  fit.camera = CandidateStart(model, camera);
  candidate->num_params = static_cast<int>(fit.camera.NumParams());
  candidate->fitted = UpgradeCamera(upgrade_options, points2D, points_cam,
                                    &fit.camera, &fit.result);
  if (!candidate->fitted) {
    candidate->note = "no fit: " + fit.result.error_message;
    return fit;
  }
  candidate->num_inliers = fit.result.num_inliers;
  candidate->train_rms_px = fit.result.rms_px;
  fit.validity = CheckModelValidity(fit.camera, options.validity);
  if (check_data) {
    AddResidualProfileCheck(
        fit.camera,
        FitResidualProfile(options, fit, points2D, points_cam, groups),
        /*parameters_held=*/false, &fit.validity);
  }
  candidate->valid = fit.validity.valid;
  if (!candidate->valid) candidate->note = "invalid: " + fit.validity.message;
  return fit;
}

// SelectCameraModel on all the given rows.
bool SelectCameraModelOnRows(const ModelSelectionOptions& options,
                             const CameraUpgradeOptions& upgrade_options,
                             const std::vector<Eigen::Vector2d>& points2D,
                             const std::vector<Eigen::Vector3d>& points_cam,
                             const std::vector<int>& groups,
                             colmap::Camera* camera,
                             CameraUpgradeResult* result, ModelChoice* choice) {
  std::vector<CandidateFit> fits;
  for (const std::string& model : options.candidate_models) {
    ModelCandidate candidate;
    candidate.model = model;
    CandidateFit fit;
    if (!colmap::ExistsCameraModelWithName(model)) {
      candidate.note = "not a COLMAP model";
      choice->candidates.push_back(candidate);
      fits.push_back(fit);
      continue;
    }
    fit = FitCandidate(model, options, upgrade_options, points2D, points_cam,
                       groups, *camera, /*check_data=*/false, &candidate);
    choice->candidates.push_back(candidate);
    fits.push_back(fit);
  }

  const std::vector<int> subset =
      EvaluationSubset(points2D, points_cam, options.max_num_rows);
  std::vector<int> evaluation_rows;
  for (const int row : subset) {
    for (size_t m = 0; m < fits.size(); ++m) {
      if (choice->candidates[m].valid && fits[m].result.inlier_mask[row]) {
        evaluation_rows.push_back(row);
        break;
      }
    }
  }
  if (evaluation_rows.empty()) {
    result->error_message =
        "none of the candidate models (" +
        std::to_string(options.candidate_models.size()) +
        ") could be fitted and is valid over the whole image";
    choice->reason = result->error_message;
    return false;
  }

  // Every row its own cluster: the upgrade's rows are compared as
  // independent (its poses are the upgrade's, not yet adjusted).
  std::vector<int> clusters(evaluation_rows.size());
  std::iota(clusters.begin(), clusters.end(), 0);
  std::vector<std::vector<double>> training_errors(fits.size());
  for (size_t m = 0; m < fits.size(); ++m) {
    if (!choice->candidates[m].valid) continue;
    for (const int row : evaluation_rows) {
      training_errors[m].push_back(TruncatedSquaredError(
          fits[m].camera, fits[m].result.tz, points2D[row], points_cam[row],
          upgrade_options.max_error_px));
    }
  }
  const std::vector<std::vector<double>> squared_errors =
      HeldOutErrorsOfContenders(
          options.significance, training_errors, clusters,
          [&](size_t m) {
            return HeldOutSquaredErrors(options, upgrade_options, fits[m],
                                        points2D, points_cam, groups, subset,
                                        evaluation_rows);
          },
          choice);
  const int chosen = ChooseByHeldOutError(
      options.significance, squared_errors, clusters,
      std::to_string(evaluation_rows.size()) + " correspondences, " +
          std::to_string(std::max(2, options.num_folds)) +
          "-fold over framesets",
      choice);
  int num_invalid = 0;
  for (const ModelCandidate& candidate : choice->candidates) {
    if (candidate.fitted && !candidate.valid) ++num_invalid;
  }
  if (num_invalid > 0) {
    choice->reason += "; " + std::to_string(num_invalid) +
                      " fitted candidate(s) were not valid over the whole "
                      "image and were dropped";
  }
  *camera = fits[chosen].camera;
  *result = fits[chosen].result;
  return true;
}

// How far a fit's worst ring is beyond the data check's threshold (|z| over
// the threshold; 0 when the profile was not evaluated).
double MisfitRatio(const std::optional<RadialResidualProfile>& profile) {
  double worst = 0;
  if (!profile) return worst;
  for (const RadialResidualRing& ring : profile->rings) {
    if (ring.z_threshold > 0 && std::isfinite(ring.z_threshold)) {
      worst = std::max(worst, std::abs(ring.z) / ring.z_threshold);
    }
  }
  return worst;
}

// Too few framesets for the held-out comparison: kFewFramesetsModels in
// order, the first that is valid over the image and follows the lens where
// there are data (model_validity.h, checks 1-3) wins. When none follows the
// lens, the data check has failed for every candidate that is valid over the
// image: the one whose worst ring is least far beyond its threshold is used,
// with the reason saying so (a statistical test is no reason to leave a
// camera uncalibrated; the final check reports the misfit again).
bool SelectCameraModelFromFewFramesets(
    const ModelSelectionOptions& options,
    const CameraUpgradeOptions& upgrade_options,
    const std::vector<Eigen::Vector2d>& points2D,
    const std::vector<Eigen::Vector3d>& points_cam,
    const std::vector<int>& groups, int num_framesets, colmap::Camera* camera,
    CameraUpgradeResult* result, ModelChoice* choice) {
  const std::string why = std::to_string(num_framesets) +
                          " framesets see this camera, too few to compare "
                          "models by held-out error (at least " +
                          std::to_string(options.min_num_framesets) + ")";
  std::vector<CandidateFit> fits;
  for (const char* model : kFewFramesetsModels) {
    ModelCandidate candidate;
    candidate.model = model;
    fits.push_back(FitCandidate(model, options, upgrade_options, points2D,
                                points_cam, groups, *camera,
                                /*check_data=*/true, &candidate));
    choice->candidates.push_back(candidate);
    if (!candidate.valid) continue;
    choice->candidates.back().chosen = true;
    choice->candidates.back().note = "the first valid one";
    choice->chosen = model;
    choice->reason = why + ": " + model +
                     ", the first of OPENCV, OPENCV_FISHEYE that is valid "
                     "over the image and follows the lens where there are "
                     "data";
    *camera = fits.back().camera;
    *result = fits.back().result;
    return true;
  }
  int best = -1;
  for (size_t m = 0; m < fits.size(); ++m) {
    const ModelValidity& validity = fits[m].validity;
    const bool geometry_valid =
        choice->candidates[m].fitted && validity.monotonic &&
        validity.max_roundtrip_error_px <=
            options.validity.max_roundtrip_error_px;
    if (geometry_valid &&
        (best < 0 || MisfitRatio(validity.residual_profile) <
                         MisfitRatio(fits[best].validity.residual_profile))) {
      best = static_cast<int>(m);
    }
  }
  if (best < 0) {
    result->error_message = why + ", and neither OPENCV nor OPENCV_FISHEYE " +
                            "could be fitted and is valid over the whole image";
    choice->reason = result->error_message;
    return false;
  }
  ModelCandidate& candidate = choice->candidates[best];
  candidate.chosen = true;
  candidate.note += " (used: the smaller misfit)";
  choice->chosen = candidate.model;
  choice->reason =
      why + ": neither OPENCV nor OPENCV_FISHEYE follows the lens where there "
            "are data by the ring check; " +
      candidate.model +
      " is used, valid over the image and the closer of the two (worst ring " +
      Fixed(MisfitRatio(fits[best].validity.residual_profile), 1) +
      "x its threshold). The choice is not sure: check the camera's "
      "residuals, or give a model";
  choice->uncertain = true;
  *camera = fits[best].camera;
  *result = fits[best].result;
  return true;
}

}  // namespace

bool SelectCameraModel(const ModelSelectionOptions& options,
                       const CameraUpgradeOptions& upgrade_options,
                       const std::vector<Eigen::Vector2d>& points2D,
                       const std::vector<Eigen::Vector3d>& points_cam,
                       const std::vector<int>& groups, colmap::Camera* camera,
                       CameraUpgradeResult* result, ModelChoice* choice) {
  *choice = ModelChoice();
  *result = CameraUpgradeResult();
  if (groups.size() != points2D.size() ||
      points_cam.size() != points2D.size()) {
    result->error_message = "one frameset per correspondence needed";
    choice->reason = result->error_message;
    return false;
  }
  const int num_framesets =
      static_cast<int>(std::set<int>(groups.begin(), groups.end()).size());
  if (num_framesets < options.min_num_framesets) {
    return SelectCameraModelFromFewFramesets(options, upgrade_options, points2D,
                                             points_cam, groups, num_framesets,
                                             camera, result, choice);
  }
  if (points2D.size() <= static_cast<size_t>(options.max_num_fit_rows)) {
    return SelectCameraModelOnRows(options, upgrade_options, points2D,
                                   points_cam, groups, camera, result, choice);
  }
  // The candidates are compared on a fixed random subset; the winner is
  // then fitted to every row, as a model given by hand would be.
  const std::vector<int> subset =
      EvaluationSubset(points2D, points_cam, options.max_num_fit_rows);
  std::vector<Eigen::Vector2d> subset_points2D;
  std::vector<Eigen::Vector3d> subset_points_cam;
  std::vector<int> subset_groups;
  for (const int row : subset) {
    subset_points2D.push_back(points2D[row]);
    subset_points_cam.push_back(points_cam[row]);
    subset_groups.push_back(groups[row]);
  }
  colmap::Camera chosen_camera = *camera;
  CameraUpgradeResult subset_result;
  if (!SelectCameraModelOnRows(options, upgrade_options, subset_points2D,
                               subset_points_cam, subset_groups, &chosen_camera,
                               &subset_result, choice)) {
    *result = subset_result;
    return false;
  }
  chosen_camera = CandidateStart(choice->chosen, *camera);
  if (!UpgradeCamera(upgrade_options, points2D, points_cam, &chosen_camera,
                     result)) {
    choice->reason += "; fitting it to all " + std::to_string(points2D.size()) +
                      " correspondences failed: " + result->error_message;
    return false;
  }
  choice->reason += " (candidates compared on " +
                    std::to_string(subset.size()) + " of " +
                    std::to_string(points2D.size()) +
                    " correspondences drawn at random; the chosen model "
                    "fitted to all of them)";
  *camera = chosen_camera;
  return true;
}

namespace {

// mean(d) and its standard error, d_i = a_i - b_i, clustered by `clusters`:
// sqrt(G / (G - 1) sum_g (S_g - n_g mean(d))^2) / n over the G clusters (the
// sample standard deviation / sqrt(n) when every row is its own cluster).
struct PairedDifference {
  double mean = 0, standard_error = 0;
};
PairedDifference ComparePaired(const std::vector<double>& a,
                               const std::vector<double>& b,
                               const std::vector<int>& clusters) {
  std::map<int, std::pair<double, double>> sum_and_count;
  double sum = 0;
  for (size_t e = 0; e < clusters.size(); ++e) {
    const double d = a[e] - b[e];
    sum += d;
    auto& [cluster_sum, cluster_count] = sum_and_count[clusters[e]];
    cluster_sum += d;
    cluster_count += 1;
  }
  PairedDifference difference;
  const double n = clusters.size();
  const double num_clusters = sum_and_count.size();
  difference.mean = n > 0 ? sum / n : 0;
  double spread = 0;
  for (const auto& [cluster, sums] : sum_and_count) {
    spread += std::pow(sums.first - sums.second * difference.mean, 2);
  }
  difference.standard_error =
      num_clusters > 1 ? std::sqrt(num_clusters / (num_clusters - 1) * spread) / n
                       : 0;
  return difference;
}

}  // namespace

bool AsGoodAs(double significance, const std::vector<double>& a,
              const std::vector<double>& b, const std::vector<int>& clusters,
              std::string* comparison) {
  const PairedDifference difference = ComparePaired(a, b, clusters);
  if (comparison) {
    *comparison = "mean squared error " +
                  std::string(difference.mean < 0 ? "" : "+") +
                  Fixed(difference.mean, 5) + " px^2, standard error " +
                  Fixed(difference.standard_error, 5);
  }
  return difference.mean <=
         significance * difference.standard_error + kMinMseDifference;
}

int ChooseByHeldOutError(double significance,
                         const std::vector<std::vector<double>>& squared_errors,
                         const std::vector<int>& clusters,
                         const std::string& evaluation, ModelChoice* choice) {
  const size_t num_candidates = choice->candidates.size();
  int best = -1;
  for (size_t m = 0; m < num_candidates; ++m) {
    if (squared_errors[m].empty()) continue;
    choice->candidates[m].heldout_rms_px = std::sqrt(Mean(squared_errors[m]));
    if (best < 0 || Mean(squared_errors[m]) < Mean(squared_errors[best])) {
      best = static_cast<int>(m);
    }
  }
  if (best < 0) return -1;
  int chosen = best;
  for (size_t m = 0; m < num_candidates; ++m) {
    if (squared_errors[m].empty()) continue;
    std::string comparison;
    const bool as_good = AsGoodAs(significance, squared_errors[m],
                                  squared_errors[best], clusters, &comparison);
    ModelCandidate& candidate = choice->candidates[m];
    candidate.as_good_as_best = as_good;
    if (static_cast<int>(m) != best) {
      candidate.note = std::string(as_good ? "as good as" : "worse than") +
                       " the best (" + comparison + ")";
    }
    // Fewest parameters; on a tie the earlier candidate (candidates come
    // pinhole-type first: a lens they fit as well needs no fisheye model).
    if (as_good && (candidate.num_params < choice->candidates[chosen].num_params ||
                    (candidate.num_params ==
                         choice->candidates[chosen].num_params &&
                     static_cast<int>(m) < chosen))) {
      chosen = static_cast<int>(m);
    }
  }
  if (chosen == best) {
    choice->candidates[best].note = "lowest held-out error";
  }
  ModelCandidate& winner = choice->candidates[chosen];
  winner.chosen = true;
  choice->chosen = winner.model;
  const ModelCandidate& best_candidate = choice->candidates[best];
  if (chosen == best) {
    choice->reason = winner.model + " has the lowest held-out error (" +
                     Fixed(winner.heldout_rms_px, 3) + " px over " +
                     evaluation + ") and no model with fewer parameters is "
                     "as good";
  } else {
    choice->reason =
        winner.model + " (" + std::to_string(winner.num_params) +
        " parameters, held-out " + Fixed(winner.heldout_rms_px, 3) +
        " px) is within " + Fixed(significance, 1) +
        " standard errors of the best, " + best_candidate.model + " (" +
        std::to_string(best_candidate.num_params) + " parameters, " +
        Fixed(best_candidate.heldout_rms_px, 3) + " px over " + evaluation +
        "), with " +
        (winner.num_params < best_candidate.num_params
             ? "fewer parameters"
             : "as many parameters, earlier in the candidates' order");
  }
  return chosen;
}

std::vector<std::vector<double>> HeldOutErrorsOfContenders(
    const double significance,
    const std::vector<std::vector<double>>& training_errors,
    const std::vector<int>& clusters,
    const std::function<std::vector<double>(size_t)>& held_out,
    ModelChoice* choice) {
  std::vector<size_t> order;
  for (size_t m = 0; m < training_errors.size(); ++m) {
    if (!training_errors[m].empty()) order.push_back(m);
  }
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return Mean(training_errors[a]) < Mean(training_errors[b]);
  });
  std::vector<std::vector<double>> squared_errors(training_errors.size());
  int best = -1;
  for (const size_t m : order) {
    if (best >= 0) {
      const PairedDifference difference =
          ComparePaired(training_errors[m], squared_errors[best], clusters);
      if (difference.mean >
          significance * difference.standard_error + kMinMseDifference) {
        ModelCandidate& candidate = choice->candidates[m];
        candidate.heldout_rms_px = std::numeric_limits<double>::quiet_NaN();
        candidate.note =
            "worse than the best on its training error alone (mean squared "
            "error +" + Fixed(difference.mean, 5) +
            " px^2 over the best's held-out, standard error " +
            Fixed(difference.standard_error, 5) + "); not held out";
        continue;
      }
    }
    squared_errors[m] = held_out(m);
    if (best < 0 || Mean(squared_errors[m]) < Mean(squared_errors[best])) {
      best = static_cast<int>(m);
    }
  }
  return squared_errors;
}

std::string FormatModelChoice(const ModelChoice& choice,
                              const std::string& indent) {
  std::ostringstream out;
  out << indent << std::left << std::setw(22) << "candidate" << std::right
      << std::setw(7) << "params" << std::setw(9) << "inliers" << std::setw(11)
      << "train px" << std::setw(13) << "held-out px"
      << "  \n";
  for (const ModelCandidate& candidate : choice.candidates) {
    out << indent << (candidate.chosen ? "* " : "  ") << std::left
        << std::setw(20) << candidate.model << std::right << std::setw(7)
        << candidate.num_params << std::setw(9) << candidate.num_inliers
        << std::setw(11)
        << (candidate.fitted ? Fixed(candidate.train_rms_px, 3) : "-")
        << std::setw(13)
        << (candidate.valid && std::isfinite(candidate.heldout_rms_px)
                ? Fixed(candidate.heldout_rms_px, 3)
                : "-")
        << "  "
        << candidate.note << "\n";
  }
  out << indent
      << "chosen: " << (choice.chosen.empty() ? "none" : choice.chosen) << ": "
      << choice.reason << "\n";
  return out.str();
}

}  // namespace rig_calibrator
