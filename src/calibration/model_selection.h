// Automatic choice of a camera's COLMAP model (--RigCalibrator.camera_model
// auto): every candidate model is fitted by the camera upgrade
// (camera_upgrader.h) to the same correspondences, candidates that are not
// valid over the whole image (model_validity.h) are dropped, and the others
// are compared by their held-out reprojection error.
//
// Held-out error: the framesets are split into K folds (frameset index mod
// K). For fold k, tz and the model's parameters are refined from the
// candidate's full fit on its inliers outside fold k (Levenberg-Marquardt,
// the upgrade's Cauchy loss, the poses held), and every evaluation row in
// fold k is predicted. The evaluation rows are the union of the valid
// candidates' inliers, the same for all candidates, so that a model cannot
// look good by rejecting what it cannot fit; a row's squared error is
// truncated at the upgrade's inlier threshold T, e^2 = min(|r|^2, T^2), so
// that the few wrong correspondences that some candidate accepted do not
// dominate. heldout_rms = sqrt(mean e^2).
//
// Choice (the "one standard error" rule of cross-validation): with b the
// candidate of least held-out error and, per row, d_i = e_m,i^2 - e_b,i^2,
// a candidate m is as good as b when mean(d) <= z SE(d) + kMinMseDifference
// (SE = standard deviation / sqrt(n), z = `significance`); of those, the one
// with the fewest parameters wins (ties: the earlier in the candidates'
// order, pinhole-type before fisheye). More parameters must earn their place
// by predicting unseen framesets better.
//
// This first choice is made at the camera upgrade, on the upgrade's poses,
// so that the final adjustment has a model to start from; the final choice
// is made again on the adjusted rig (model_choice_after_adjustment.h).
//
// Candidates (ModelSelectionOptions::candidate_models), why these:
// SIMPLE_RADIAL, RADIAL, OPENCV cover pinhole-type lenses with no, radial
// or radial-tangential distortion; SIMPLE_RADIAL_FISHEYE, RADIAL_FISHEYE and
// OPENCV_FISHEYE the same for angle-based (fisheye) lenses, which are the
// only ones that can represent fields of view near or beyond 120 degrees.
// Not by default: SIMPLE_PINHOLE / PINHOLE (a real lens has some
// distortion, SIMPLE_RADIAL costs one parameter more), FULL_OPENCV (its
// rational terms fit the data region and fold outside it easily),
// THIN_PRISM_FISHEYE (12 parameters for decentred lenses: give it by hand).
#pragma once

#include <colmap/base/camera.h>

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "src/calibration/camera_upgrader.h"
#include "src/calibration/model_validity.h"

namespace rig_calibrator {

// The --RigCalibrator.camera_model value that asks for the choice.
inline constexpr char kAutoCameraModel[] = "auto";

// With fewer framesets than ModelSelectionOptions::min_num_framesets the
// held-out error of 5 folds is mostly noise (a fold holds one frameset or
// none): these are tried in order and the first valid over the image that
// follows the lens where there are data (model_validity.h, all three
// checks) wins.
inline constexpr const char* kFewFramesetsModels[] = {"OPENCV",
                                                      "OPENCV_FISHEYE"};

// Differences of mean squared held-out error below this (px^2, i.e. 0.01 px
// of RMS on exact data) carry no information.
constexpr double kMinMseDifference = 1e-4;

struct ModelSelectionOptions {
  std::vector<std::string> candidate_models = {
      "SIMPLE_RADIAL",         "RADIAL",         "OPENCV",
      "SIMPLE_RADIAL_FISHEYE", "RADIAL_FISHEYE", "OPENCV_FISHEYE"};
  int num_folds = 5;
  // Framesets (distinct groups) needed for the held-out comparison; fewer:
  // kFewFramesetsModels.
  int min_num_framesets = 10;
  double significance = 2.0;  // z of the choice rule
  // The held-out evaluation uses at most this many rows (a fixed random
  // subset): its statistics need a few thousand, not 1e5.
  int max_num_rows = 10000;
  // The candidates are fitted to at most this many rows (a fixed random
  // subset: what tells the models apart is the same in 10^4 rows as in
  // 10^5) and the chosen model then to all of them, so the choice costs
  // about six upgrades of 10^4 rows whatever the data's size.
  int max_num_fit_rows = 10000;
  int max_num_fold_iterations = 50;
  ModelValidityOptions validity;
};

struct ModelCandidate {
  std::string model;
  int num_params = 0;
  bool fitted = false;  // the upgrade found a consistent model
  bool valid = false;   // fitted and valid over the whole image
  int num_inliers = 0;
  double train_rms_px = 0;    // over its inliers, the full fit
  // 0 unless valid; NaN when valid but not compared held out.
  double heldout_rms_px = 0;
  bool chosen = false;
  // Compared held out and within the rule's standard errors of the best
  // (the best included).
  bool as_good_as_best = false;
  std::string note;  // why dropped, or how it compares with the best
};

struct ModelChoice {
  std::string chosen;  // empty when no candidate could be used
  std::string reason;
  // The chosen model failed a check that a sure choice passes (the reason
  // says which): the pipeline warns (diagnostic "uncertain_model_choice").
  bool uncertain = false;
  std::vector<ModelCandidate> candidates;
  // The choice on the adjusted rig only (model_choice_after_adjustment.h):
  // per parameter of the chosen model, how far its focal lengths and
  // principal point lie from those of the other candidates that the rule
  // found as good as the best (model_choice_spread.h; 0 for the other
  // parameters); empty when no other candidate was. spread_models: those
  // candidates.
  std::vector<double> parameter_spread;
  std::vector<std::string> spread_models;
};

// points2D, points_cam: as for UpgradeCamera; groups: the frameset of every
// row (the cross-validation folds). camera: in: width, height, principal
// point; out: the chosen model and its parameters. result: the chosen
// model's upgrade. Returns false (camera unchanged) when no candidate is
// valid, with result->error_message and choice->reason saying why.
bool SelectCameraModel(const ModelSelectionOptions& options,
                       const CameraUpgradeOptions& upgrade_options,
                       const std::vector<Eigen::Vector2d>& points2D,
                       const std::vector<Eigen::Vector3d>& points_cam,
                       const std::vector<int>& groups, colmap::Camera* camera,
                       CameraUpgradeResult* result, ModelChoice* choice);

// The choice rule above over the candidates of `choice` whose
// squared_errors (per evaluation row, the held-out squared error) are not
// empty; clusters: per evaluation row the group whose rows are not
// independent (the standard error of mean(d) is clustered by it:
// sqrt(G / (G - 1) sum_g (S_g - n_g mean(d))^2) / n, S_g the sum of d over
// group g). Sets the candidates' heldout_rms_px, notes and chosen flag,
// choice->chosen and choice->reason (`evaluation` says over what the
// held-out errors were taken). Returns the chosen candidate's index, -1
// when no candidate was compared.
int ChooseByHeldOutError(double significance,
                         const std::vector<std::vector<double>>& squared_errors,
                         const std::vector<int>& clusters,
                         const std::string& evaluation, ModelChoice* choice);

// Whether errors `a` are as good as `b` by the choice rule above (per
// evaluation row, squared; d = a - b, the standard error clustered as
// ChooseByHeldOutError's): mean(d) <= significance SE(d) +
// kMinMseDifference. `comparison` (optional): "mean squared error +X px^2,
// standard error Y".
bool AsGoodAs(double significance, const std::vector<double>& a,
              const std::vector<double>& b, const std::vector<int>& clusters,
              std::string* comparison = nullptr);

// The held-out squared errors (per evaluation row, as ChooseByHeldOutError
// takes them) of the candidates that can still be as good as the best, the
// others' left empty: held_out(m) computes candidate m's (its folds: most of
// a choice's cost). training_errors[m]: per evaluation row, candidate m's
// squared error under its fit to every row (empty: not valid). Candidates are
// taken by increasing mean training error; one whose training error alone is
// worse than the best held-out error so far by the choice rule (mean(d) >
// significance SE(d) + kMinMseDifference, d = training - best held-out, SE
// clustered as ChooseByHeldOutError's) is not held out: a held-out error is
// on average no smaller than the training error of the same model (the full
// fit minimized its error on the rows a fold's fit never saw), so the rule
// would find it worse than the best but by chance (on the real ring,
// scripts/real_data_check.sh, all 25 cameras got the model they got before
// this rule). Its note and heldout_rms_px (NaN) say so.
std::vector<std::vector<double>> HeldOutErrorsOfContenders(
    double significance, const std::vector<std::vector<double>>& training_errors,
    const std::vector<int>& clusters,
    const std::function<std::vector<double>(size_t)>& held_out,
    ModelChoice* choice);

// The candidates' table (one line each) and the reason, for the terminal.
std::string FormatModelChoice(const ModelChoice& choice,
                              const std::string& indent);

}  // namespace rig_calibrator
