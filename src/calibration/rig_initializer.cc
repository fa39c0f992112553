// The RANSAC driver of the rig initialization; its pieces are listed in
// rig_init_problem.h.
#include "src/calibration/rig_initializer.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <sstream>
#include <utility>
#include <vector>

#include "src/calibration/rig_init_determinedness.h"
#include "src/calibration/rig_init_problem.h"
#include "src/calibration/rig_init_refinement.h"
#include "src/calibration/rig_init_rotations.h"
#include "src/calibration/rig_init_scoring.h"
#include "src/calibration/rig_init_translations.h"

namespace rig_calibrator {
namespace {

using rig_init::AgreeingImages;
using rig_init::FitHypothesis;
using rig_init::Hypothesis;
using rig_init::ImageFit;
using rig_init::InitProblem;
using rig_init::LocalizedImage;

// A kept camera needs this many agreeing images: a wrong per-image pose
// always agrees with the camera pose made from it.
constexpr int kMinAgreeingImagesPerCamera = 2;

// One RANSAC hypothesis: rotations by greedy assignment, then translations
// by least squares over the images whose rotation agrees with the rig, then
// again over those of them whose correspondences agree with the rig too (a
// per-image pose with a right rotation and a wrong translation).
Hypothesis MakeHypothesis(const InitProblem& problem, int seed_frameset) {
  int base_camera = 0;
  const rig_init::Rotations rotations =
      rig_init::AssignRotationsGreedily(problem, seed_frameset, &base_camera);
  std::vector<char> usable(problem.images.size(), 0);
  for (size_t k = 0; k < problem.images.size(); ++k) {
    const LocalizedImage& image = problem.images[k];
    usable[k] =
        rotations.cam_from_rig[image.camera] &&
        rotations.rig_from_world[image.frameset] &&
        RotationDifferenceRad(*rotations.cam_from_rig[image.camera] *
                                  *rotations.rig_from_world[image.frameset],
                              image.cam_from_world.rotation) <
            problem.max_rotation_deviation;
  }
  Hypothesis hypothesis =
      rig_init::SolveTranslations(problem, rotations, usable, base_camera);
  const std::vector<char> agree =
      AgreeingImages(problem, FitHypothesis(problem, hypothesis));
  std::vector<char> agreeing_usable(problem.images.size(), 0);
  for (size_t k = 0; k < problem.images.size(); ++k) {
    agreeing_usable[k] = usable[k] && agree[k];
  }
  if (agreeing_usable != usable) {
    hypothesis = rig_init::SolveTranslations(problem, rotations,
                                             agreeing_usable, base_camera);
  }
  return hypothesis;
}

struct RansacResult {
  Hypothesis best;
  double best_score = std::numeric_limits<double>::infinity();
  int num_trials = 0;
};

// RANSAC over the seed framesets, in the given (shuffled) order. A seed is
// good if all its localized images agree with the best hypothesis; with a
// share w of good seeds, the probability that k trials all miss one is
// (1 - w)^k, so trials stop once that is below 1 - confidence.
RansacResult RunRansac(const InitProblem& problem,
                       const std::vector<int>& seeds) {
  RansacResult result;
  result.best = rig_init::EmptyHypothesis(problem);
  double required_trials = std::numeric_limits<double>::infinity();
  const int max_trials = std::min<int>(problem.options.max_num_trials,
                                       static_cast<int>(seeds.size()));
  while (result.num_trials < max_trials &&
         result.num_trials < required_trials) {
    Hypothesis hypothesis = MakeHypothesis(problem, seeds[result.num_trials]);
    ++result.num_trials;
    const std::vector<std::optional<ImageFit>> fits =
        FitHypothesis(problem, hypothesis);
    const double score = rig_init::TruncatedScore(problem, fits);
    if (score >= result.best_score) continue;
    result.best = std::move(hypothesis);
    result.best_score = score;
    const std::vector<char> agree = AgreeingImages(problem, fits);
    int num_good_seeds = 0;
    for (const int seed : seeds) {
      bool good = true;
      for (const int index : problem.images_of_frameset[seed]) {
        good = good && agree[index];
      }
      num_good_seeds += good;
    }
    const double good_share =
        static_cast<double>(num_good_seeds) / seeds.size();
    if (good_share >= 1) {
      required_trials = 1;
    } else if (good_share > 0) {
      required_trials = std::ceil(std::log(1 - problem.options.confidence) /
                                  std::log(1 - good_share));
    }
  }
  return result;
}

// Re-expresses a hypothesis in the reference camera's frame (with its tz = 0
// when radial): Q_j <- P_ref Q_j, P_i <- P_i P_ref^-1.
void ExpressInReferenceFrame(const InitProblem& problem,
                             Hypothesis* hypothesis) {
  const Rigid3d ref_from_rig =
      *hypothesis->cam_from_rig[problem.reference_camera];
  const Rigid3d rig_from_ref = ref_from_rig.Inverse();
  for (std::optional<Rigid3d>& cam_from_rig : hypothesis->cam_from_rig) {
    if (!cam_from_rig) continue;
    *cam_from_rig = *cam_from_rig * rig_from_ref;
    if (problem.num_rows == 2) cam_from_rig->translation.z() = 0;
  }
  hypothesis->cam_from_rig[problem.reference_camera] = Rigid3d();
  for (std::optional<Rigid3d>& rig_from_world : hypothesis->rig_from_world) {
    if (rig_from_world) *rig_from_world = ref_from_rig * *rig_from_world;
  }
}

// Which images, cameras and rig poses the final rig keeps: the images that
// agree with the hypothesis, the framesets they determine, the cameras with
// two of them in such framesets and no undetermined translation direction
// (FindTranslationDeterminedParts). The others are unassigned in the
// hypothesis.
std::vector<char> KeepDeterminedParts(const InitProblem& problem,
                                      const std::vector<char>& agree,
                                      Hypothesis* hypothesis) {
  std::vector<std::optional<Eigen::Quaterniond>> cam_rotations(
      problem.num_cameras);
  for (int i = 0; i < problem.num_cameras; ++i) {
    if (hypothesis->cam_from_rig[i]) {
      cam_rotations[i] = hypothesis->cam_from_rig[i]->rotation;
    }
  }
  std::vector<std::optional<Eigen::Quaterniond>> rig_rotations(
      problem.num_framesets);
  for (int j = 0; j < problem.num_framesets; ++j) {
    if (hypothesis->rig_from_world[j]) {
      rig_rotations[j] = hypothesis->rig_from_world[j]->rotation;
    }
  }
  int anchor = 0;
  const rig_init::DeterminedParts parts =
      rig_init::FindTranslationDeterminedParts(
          problem, cam_rotations, rig_rotations, agree,
          kMinAgreeingImagesPerCamera, problem.reference_camera, &anchor);
  for (int j = 0; j < problem.num_framesets; ++j) {
    if (!parts.framesets[j]) hypothesis->rig_from_world[j].reset();
  }
  for (int i = 0; i < problem.num_cameras; ++i) {
    if (!parts.cameras[i]) hypothesis->cam_from_rig[i].reset();
  }
  return parts.images;
}

// Writes the kept rig into the calibration (see the header), warning about
// cameras with localized images that were left out.
void WriteCalibration(const InitProblem& problem, const RigDataset& dataset,
                      const Hypothesis& best, RigCalibration* calibration) {
  calibration->cam_from_rig.assign(problem.num_cameras, Rigid3d());
  calibration->camera_calibrated.assign(problem.num_cameras, false);
  for (int i = 0; i < problem.num_cameras; ++i) {
    if (best.cam_from_rig[i]) {
      calibration->cam_from_rig[i] = *best.cam_from_rig[i];
      calibration->camera_calibrated[i] = true;
    } else if (!problem.images_of_camera[i].empty()) {
      LOG(WARNING) << "InitializeRig: camera " << dataset.cameras[i].name
                   << " is left out of the rig although "
                   << problem.images_of_camera[i].size()
                   << " of its images are localized: fewer than two agree "
                      "with the rig, or they do not determine its position"
                   << (problem.options.radial
                           ? " (a radial camera seen only in framesets of two "
                             "cameras whose axes are (nearly) coplanar with "
                             "its own cannot be placed within that plane; it "
                             "needs framesets with two other cameras)"
                           : "");
    }
  }
  calibration->cam_from_rig[problem.reference_camera] = Rigid3d();
  calibration->rig_from_world = best.rig_from_world;
  if (problem.options.radial) {
    NormalizeRadialRigOrigin(problem.reference_camera, calibration);
  }
}

bool Fail(const std::string& message, RigInitializerSummary* summary) {
  LOG(ERROR) << "InitializeRig: " << message;
  if (summary) summary->message = message;
  return false;
}

// The reference camera could not be placed: by any RANSAC hypothesis, or
// (after_hypothesis) by the images that agree with the best one.
bool FailOnReference(const InitProblem& problem, const RigDataset& dataset,
                     bool after_hypothesis, RigInitializerSummary* summary) {
  const std::string& name = dataset.cameras[problem.reference_camera].name;
  const int num_images =
      problem.images_of_camera[problem.reference_camera].size();
  std::ostringstream message;
  if (!after_hypothesis) {
    message << "the reference camera " << name
            << " could not be placed in the rig (" << num_images
            << " of its images localized); choose another reference camera";
  } else {
    message << "the reference camera " << name
            << " cannot be placed in the rig: fewer than two of its "
            << num_images
            << " localized images agree with the best rig hypothesis, or "
               "they do not determine its position; choose another "
               "reference camera";
  }
  return Fail(message.str(), summary);
}

}  // namespace

bool InitializeRig(const RigInitializerOptions& options,
                   const RigDataset& dataset, RigCalibration* calibration,
                   RigInitializerSummary* summary) {
  if (summary) *summary = RigInitializerSummary();
  if (calibration == nullptr) return Fail("no calibration given", summary);
  InitProblem problem;
  const std::string error =
      rig_init::BuildProblem(options, dataset, *calibration, &problem);
  if (!error.empty()) return Fail(error, summary);
  if (summary) summary->num_images_localized = problem.images.size();

  if (options.radial) {
    std::string explanation;
    // No pair of cameras would determine a frameset: fail with the reason
    // rather than later with an unplaceable reference camera.
    if (PrincipalAxesAreParallel(dataset, *calibration,
                                 kMinDeterminingAxisAngleDeg, &explanation)) {
      return Fail(explanation +
                      "; 1D radial poses cannot determine the rig poses of "
                      "a rig with parallel or anti-parallel principal axes: "
                      "use full per-image poses (the rd_ra method)",
                  summary);
    }
  }

  std::vector<int> seeds;
  for (int j = 0; j < problem.num_framesets; ++j) {
    if (problem.images_of_frameset[j].size() >= 2) seeds.push_back(j);
  }
  if (seeds.empty()) {
    return Fail("no frameset has two localized images", summary);
  }
  std::mt19937 random_engine(options.seed);
  std::shuffle(seeds.begin(), seeds.end(), random_engine);
  RansacResult ransac = RunRansac(problem, seeds);

  if (summary) {
    int num_scored = 0;
    for (const LocalizedImage& image : problem.images) {
      num_scored += image.points2D.size();
    }
    summary->num_trials = ransac.num_trials;
    summary->best_score =
        num_scored > 0 ? std::sqrt(ransac.best_score / num_scored) : 0;
  }

  Hypothesis& best = ransac.best;
  if (!best.cam_from_rig[problem.reference_camera]) {
    return FailOnReference(problem, dataset, false, summary);
  }
  ExpressInReferenceFrame(problem, &best);
  const std::vector<char> used = KeepDeterminedParts(
      problem, AgreeingImages(problem, FitHypothesis(problem, best)), &best);
  if (!best.cam_from_rig[problem.reference_camera]) {
    return FailOnReference(problem, dataset, true, summary);
  }
  rig_init::MinimizePoseDeviation(problem, used, &best);
  WriteCalibration(problem, dataset, best, calibration);

  if (summary) {
    summary->num_cameras_assigned =
        std::count(calibration->camera_calibrated.begin(),
                   calibration->camera_calibrated.end(), true);
    summary->num_framesets_assigned = std::count_if(
        calibration->rig_from_world.begin(), calibration->rig_from_world.end(),
        [](const std::optional<Rigid3d>& pose) { return pose.has_value(); });
    summary->num_images_consistent = std::count(used.begin(), used.end(), 1);
  }
  return true;
}

}  // namespace rig_calibrator
