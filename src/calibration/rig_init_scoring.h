// Internal to the rig initialization (rig_init_problem.h): how well a pose
// explains an image's scored inliers, the truncated radial score of a
// hypothesis, and which images agree with it.
//
// Scores use the radial reprojection error e (src/geometry/radial_error.h),
// truncated at tau = max_radial_error_px: sum min(e, tau)^2.
#pragma once

#include <optional>
#include <vector>

#include "src/calibration/rig_init_problem.h"

namespace rig_calibrator {
namespace rig_init {

// An image agrees with a rig hypothesis if its own pose and the rig's pose
// P_i Q_j each put at least this many of its scored inliers within the
// truncation, and neither explains less than kMinAgreementRatio of what the
// other explains. Both poses explaining the same >= 5 correspondences makes
// them the same radial pose; the ratio (rather than an absolute share) keeps
// the test meaningful when the principal point is still off.
constexpr int kMinAgreeingInliers = 5;
constexpr double kMinAgreementRatio = 0.5;

struct ImageFit {
  double truncated_sq_sum = 0;  // sum of min(e, tau)^2, pixels^2
  int num_within = 0;           // e < tau on the correct half-line
};

// The fit of an image's scored inliers under cam_from_world, tau = max_error.
ImageFit FitImage(const Rigid3d& cam_from_world, const LocalizedImage& image,
                  double max_error);

// Per localized image: its fit under the hypothesis, or nullopt if its camera
// or frameset is unassigned. Runs on problem.num_threads threads for large
// problems; the result does not depend on their number.
std::vector<std::optional<ImageFit>> FitHypothesis(
    const InitProblem& problem, const Hypothesis& hypothesis);

// Sum of min(e, tau)^2 over all scored correspondences; tau^2 for those of
// images the hypothesis does not cover. Summed in image order, so the result
// does not depend on the number of threads.
double TruncatedScore(const InitProblem& problem,
                      const std::vector<std::optional<ImageFit>>& fits);

// Per localized image: 1 if its own pose and the hypothesis' pose agree (see
// kMinAgreeingInliers).
std::vector<char> AgreeingImages(
    const InitProblem& problem,
    const std::vector<std::optional<ImageFit>>& fits);

}  // namespace rig_init
}  // namespace rig_calibrator
