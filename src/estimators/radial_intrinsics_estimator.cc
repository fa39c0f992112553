#include "src/estimators/radial_intrinsics_estimator.h"

#include <colmap/optim/loransac.h>

#include <limits>

#include "src/estimators/seeded_random_sampler.h"

namespace rig_calibrator {
namespace {

// Residual of a point the model cannot project. COLMAP's support measurers
// compare residuals against the squared threshold and MSAC truncates them,
// so the largest finite double marks an outlier without producing inf/NaN.
constexpr double kInvalidResidual = std::numeric_limits<double>::max();

template <int kNumRadialTerms>
bool RunRansac(const colmap::RANSACOptions& options,
               const RadialProfile profile,
               const std::vector<Eigen::Vector2d>& x,
               const std::vector<Eigen::Vector3d>& points_cam,
               RadialIntrinsics* model) {
  colmap::LORANSAC<RadialIntrinsicsEstimator<kNumRadialTerms>,
                   RadialIntrinsicsLocalEstimator<kNumRadialTerms>,
                   colmap::InlierSupportMeasurer, SeededRandomSampler>
      ransac(options);
  ransac.estimator.profile = profile;
  ransac.local_estimator.profile = profile;
  const auto report = ransac.Estimate(x, points_cam);
  if (!report.success) {
    return false;
  }
  *model = report.model;
  return true;
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
    const int num_radial_terms, const std::vector<Eigen::Vector2d>& x,
    const std::vector<Eigen::Vector3d>& points_cam, RadialIntrinsics* model) {
  switch (num_radial_terms) {
    case 0:
      return RunRansac<0>(options, profile, x, points_cam, model);
    case 1:
      return RunRansac<1>(options, profile, x, points_cam, model);
    case 2:
      return RunRansac<2>(options, profile, x, points_cam, model);
    default:
      return false;
  }
}

}  // namespace rig_calibrator
