#include "src/calibration/rig_init_scoring.h"

#include <algorithm>

#include "src/geometry/radial_error.h"

namespace rig_calibrator {
namespace rig_init {
namespace {

// Scoring a hypothesis runs on several threads from this many images per
// thread on: below, starting threads costs more than it saves.
constexpr size_t kMinImagesPerThread = 256;

bool Agree(int num_own_inliers, int num_rig_inliers) {
  const int fewer = std::min(num_own_inliers, num_rig_inliers);
  const int more = std::max(num_own_inliers, num_rig_inliers);
  return fewer >= kMinAgreeingInliers && fewer >= kMinAgreementRatio * more;
}

}  // namespace

ImageFit FitImage(const Rigid3d& cam_from_world, const LocalizedImage& image,
                  double max_error) {
  ImageFit fit;
  for (size_t k = 0; k < image.points2D.size(); ++k) {
    const double error = RadialReprojectionError(
        cam_from_world, image.points2D[k], image.points3D[k]);
    if (error < max_error) {
      fit.truncated_sq_sum += error * error;
      ++fit.num_within;
    } else {
      fit.truncated_sq_sum += max_error * max_error;
    }
  }
  return fit;
}

std::vector<std::optional<ImageFit>> FitHypothesis(
    const InitProblem& problem, const Hypothesis& hypothesis) {
  std::vector<std::optional<ImageFit>> fits(problem.images.size());
#pragma omp parallel for schedule(dynamic) num_threads( \
    problem.num_threads) if (problem.images.size() >= kMinImagesPerThread * 2)
  for (size_t k = 0; k < problem.images.size(); ++k) {
    const LocalizedImage& image = problem.images[k];
    if (hypothesis.cam_from_rig[image.camera] &&
        hypothesis.rig_from_world[image.frameset]) {
      fits[k] = FitImage(*hypothesis.cam_from_rig[image.camera] *
                             *hypothesis.rig_from_world[image.frameset],
                         image, problem.options.max_radial_error_px);
    }
  }
  return fits;
}

double TruncatedScore(const InitProblem& problem,
                      const std::vector<std::optional<ImageFit>>& fits) {
  const double max_error_sq =
      problem.options.max_radial_error_px * problem.options.max_radial_error_px;
  double score = 0;
  for (size_t k = 0; k < fits.size(); ++k) {
    score += fits[k] ? fits[k]->truncated_sq_sum
                     : max_error_sq * problem.images[k].points2D.size();
  }
  return score;
}

std::vector<char> AgreeingImages(
    const InitProblem& problem,
    const std::vector<std::optional<ImageFit>>& fits) {
  std::vector<char> agree(problem.images.size(), 0);
  for (size_t k = 0; k < fits.size(); ++k) {
    agree[k] = fits[k] &&
               Agree(problem.images[k].num_own_inliers, fits[k]->num_within);
  }
  return agree;
}

}  // namespace rig_init
}  // namespace rig_calibrator
