#include "src/estimators/radial_intrinsics_estimator.h"

#include <colmap/optim/loransac.h>

#include <cmath>
#include <limits>

#include "src/estimators/seeded_random_sampler.h"

namespace rig_calibrator {
namespace {

// Residual of a point the model cannot project. COLMAP's support measurers
// compare residuals against the squared threshold and MSAC truncates them,
// so the largest finite double marks an outlier without producing inf/NaN.
constexpr double kInvalidResidual = std::numeric_limits<double>::max();

template <int kNumRadialTerms, bool kKnownFocal>
bool RunRansac(const colmap::RANSACOptions& options,
               const RadialProfile profile, const double known_focal,
               const std::vector<Eigen::Vector2d>& x,
               const std::vector<Eigen::Vector3d>& points_cam,
               RadialIntrinsics* model) {
  colmap::LORANSAC<RadialIntrinsicsEstimator<kNumRadialTerms, kKnownFocal>,
                   RadialIntrinsicsLocalEstimator<kNumRadialTerms, kKnownFocal>,
                   colmap::InlierSupportMeasurer, SeededRandomSampler>
      ransac(options);
  ransac.estimator.profile = profile;
  ransac.local_estimator.profile = profile;
  ransac.estimator.known_focal = known_focal;
  ransac.local_estimator.known_focal = known_focal;
  const auto report = ransac.Estimate(x, points_cam);
  if (!report.success) {
    return false;
  }
  *model = report.model;
  return true;
}

template <int kNumRadialTerms>
bool RunRansac(const colmap::RANSACOptions& options,
               const RadialProfile profile,
               const std::optional<double>& known_focal,
               const std::vector<Eigen::Vector2d>& x,
               const std::vector<Eigen::Vector3d>& points_cam,
               RadialIntrinsics* model) {
  if (!known_focal) {
    return RunRansac<kNumRadialTerms, false>(options, profile, 0, x, points_cam,
                                             model);
  }
  if (!(std::isfinite(*known_focal) && *known_focal > 0)) {
    return false;
  }
  return RunRansac<kNumRadialTerms, true>(options, profile, *known_focal, x,
                                          points_cam, model);
}

}  // namespace

void RadialIntrinsicsResiduals(const std::vector<Eigen::Vector2d>& x,
                               const std::vector<Eigen::Vector3d>& points_cam,
                               const RadialIntrinsics& model,
                               std::vector<double>* residuals) {
  residuals->resize(x.size());
  Eigen::Vector2d projection;
  for (size_t i = 0; i < x.size(); ++i) {
    (*residuals)[i] = model.Project(points_cam[i], &projection)
                          ? (projection - x[i]).squaredNorm()
                          : kInvalidResidual;
  }
}

bool EstimateRadialIntrinsicsRansac(
    const colmap::RANSACOptions& options, const RadialProfile profile,
    const int num_radial_terms, const std::optional<double>& known_focal,
    const std::vector<Eigen::Vector2d>& x,
    const std::vector<Eigen::Vector3d>& points_cam, RadialIntrinsics* model) {
  switch (num_radial_terms) {
    case 0:
      return RunRansac<0>(options, profile, known_focal, x, points_cam, model);
    case 1:
      return RunRansac<1>(options, profile, known_focal, x, points_cam, model);
    case 2:
      return RunRansac<2>(options, profile, known_focal, x, points_cam, model);
    default:
      return false;
  }
}

}  // namespace rig_calibrator
