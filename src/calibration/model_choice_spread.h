// The model choice's share of the intrinsics' uncertainty: when the data
// cannot tell two camera models apart, the focal length and principal point
// that the calibration reports depend on which one was chosen.
//
// The choice on the adjusted rig (model_choice_after_adjustment.h) keeps the
// candidate with the fewest parameters among those whose held-out error is
// as good as the best's (the one-standard-error rule). That is the model
// that predicts unseen framesets as well with the fewest terms, not
// necessarily the lens's: for an OPENCV_FISHEYE lens whose third and fourth
// coefficients are small it can be RADIAL_FISHEYE, whose k1, k2 then absorb
// what k3, k4 did and move the focal length. The covariance of the final
// adjustment (calibration_uncertainty.h) is that of the chosen model's
// parameters given the model, so it does not see this: on synthetic rigs
// (scripts/benchmark_time_model_seeds.sh, 16 seeds per preset) the cameras
// given a model other than their lens's had focal lengths 6.0-9.4 times
// their sigma off (RMS), those with the lens's model 1.0-1.2 times.
//
// Spread. The data allow each candidate as good as the best; if candidate
// a_k is the lens's model, the chosen value q(c) of a shared quantity q
// (the focal length along x and along y, the principal point's x and y) is
// off from the truth by d_k = q(c) - q(a_k) plus a_k's own error, whose
// standard deviation sigma_k the candidate's fits without each of the K
// folds give (the grouped jackknife over framesets: sigma_k^2 = (K - 1) / K
// sum_j (q(a_k,-j) - mean_j q(a_k,-j))^2). So, per quantity,
//
//   s_q = max_k sqrt(d_k^2 + sigma_k^2),
//
// over the candidates as good as the best other than the chosen one (each
// fitted to the same rows with the rig held and its cam_from_rig free). A
// model with one focal length takes f for both axes, and the chosen model's
// single focal length is compared with each candidate's mean focal length
// (what the single f estimates, and what the evaluation compares). The
// distortion parameters have no counterpart across models: 0. Why the
// jackknife and not d_k alone: the flexible candidate's focal length trades
// with its extra distortion terms, and d_k alone was 0.003-0.69 px for a
// bias of 0.26-0.47 px (the synthetic helmet's cam0, 47 seeds).
//
// The reported sigma is the larger of the adjustment's (the chosen model
// being the lens's) and s_q:
//
//   sigma_q' = max(sigma_q, s_q)
//
// (parameters held, sigma 0, and undetermined ones, NaN, stay as they are).
// When the chosen model is the lens's and a more flexible one is as good,
// sigma' is about the flexible model's sigma: what the data can tell when
// they cannot tell the models apart.
//
// Not in the rotation's sigma nor in the projection grid: the projections
// of the candidates as good as the best agree to within the noise (that is
// what "as good held out" means), and the principal point's spread comes
// with a turn of the camera that the pose's sigma already holds (on the
// same seeds the rotation errors of those cameras were 0.6-0.9 sigma).
#pragma once

#include <colmap/base/camera.h>

#include <vector>

#include "src/calibration/calibration_uncertainty.h"

namespace rig_calibrator {

// A candidate as good as the best: its fit to every row, and its fits
// without each fold (fewer than two: sigma_k 0).
struct AlternativeModelFit {
  colmap::Camera camera;
  std::vector<colmap::Camera> folds;
};

// s above, one entry per parameter of `chosen` (COLMAP order); all zeros
// when `others` is empty.
std::vector<double> SharedParameterSpread(
    const colmap::Camera& chosen,
    const std::vector<AlternativeModelFit>& others);

// sigma' above for every parameter of `uncertainty` (its params_stddev,
// one per parameter of the camera `spread` was computed for), and
// uncertainty->model_choice_stddev the spread where it is the larger (0
// elsewhere; empty when it is nowhere). Nothing when `spread` is empty or
// its size differs (another model than the one chosen).
void AddModelChoiceSpread(const std::vector<double>& spread,
                          CameraUncertainty* uncertainty);

}  // namespace rig_calibrator
