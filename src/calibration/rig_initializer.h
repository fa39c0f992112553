// Robust initialization of the rig (paper §3.3): the camera-from-rig poses
// P_i and the rig-from-world poses Q_j from the per-image poses T_ij, which
// should satisfy T_ij = P_i Q_j for every localized image (camera i,
// frameset j).
//
// With 1D radial poses only the first two rows of T_ij are known, so only the
// first two rows of P_i are sought (paper eq. 3-4). A RANSAC over seed
// framesets makes hypotheses by greedy back-and-forth assignment; the one
// with the lowest robust radial reprojection error over all images wins and
// is refined by minimizing eq. 4,
//   min_{P_i, Q_j} sum_{(i,j)} rho(d(T_ij, P_i Q_j)),
// with a Cauchy loss rho.
//
// Gauge of radial rigs. A radial camera's position along its own
// principal axis is unobservable, and that includes the reference camera:
// the rig origin can slide by d along the reference camera's axis, which
// changes no radial projection but changes every other camera's (tx, ty) by
// d (R_i e_z)_xy. The radial stages therefore store tz = 0 for every camera
// and fix d with NormalizeRadialRigOrigin (principal_axes.h); the reference
// camera's cam_from_rig is the identity in that sense (its tz is unknown). Once
// the forward translations are estimated (camera_upgrader.h), including the
// reference camera's, re-expressing everything in the reference camera's
// frame (Q_j <- P_ref Q_j, P_i <- P_i P_ref^-1) makes the rig metric.
#pragma once

#include <string>

#include "src/calibration/principal_axes.h"
#include "src/rig/rig_dataset.h"

namespace rig_calibrator {

struct RigInitializerOptions {
  // True: only the first two rows of each per-image pose are known (1D radial
  // poses, tz unknown; the `1dr` method). False: full 6-DoF poses (`rd_ra`,
  // `known*` methods).
  bool radial = true;
  // RANSAC over seed framesets. A seed frameset determines its hypothesis, so
  // at most one trial per seed frameset is made; trials also stop once the
  // share of seeds consistent with the best hypothesis makes another seed
  // unlikely to do better (at `confidence`).
  int max_num_trials = 500;
  double confidence = 0.999;
  // Truncation of the robust radial reprojection score, pixels.
  double max_radial_error_px = 8.0;
  // In the greedy assignment, a per-image rotation within this angle of
  // R_P R_Q supports the hypothesis (wrong per-image poses are random; the
  // radial score judges what remains).
  double max_rotation_deviation_deg = 5.0;
  // Cauchy scale of the local optimization of eq. 4, in the units of
  // d(T, P Q): |(rotation difference in radians, translation_weight times
  // translation difference in map units)|. The translation difference is
  // that of the camera-frame positions of the image's scene center
  // (centroid of its scored map points) under T and P Q (first two rows
  // when radial): unlike t_T - t_PQ it does not grow with the distance from
  // the map's origin.
  double loss_scale = 1.0;
  // Radians per map unit: weight of the translation difference against the
  // rotation difference in d(T, P Q).
  double translation_weight = 1.0;
  int num_threads = -1;
  unsigned int seed = 0;
};

struct RigInitializerSummary {
  int num_trials = 0;
  // Truncated radial RMS of the best hypothesis, pixels: the square root of
  // the mean of min(e, max_radial_error_px)^2 over the scored inlier
  // correspondences of all localized images (images of unassigned cameras or
  // framesets count max_radial_error_px).
  double best_score = 0;
  int num_cameras_assigned = 0;
  int num_framesets_assigned = 0;
  // Localized images whose pose and correspondences agree with the rig; the
  // observations of eq. 4.
  int num_images_consistent = 0;
  // Localized images whose own pose puts at least 5 of their scored inliers
  // within max_radial_error_px; the others are ignored.
  int num_images_localized = 0;
  // Why InitializeRig failed; empty on success.
  std::string message;
};

// Input: dataset (cameras with the principal point in camera.params, images
// with correspondences) and, per dataset image, calibration->images[i]:
// single_image_cam_from_world (unset = not localized; with `radial`, its
// translation.z() is ignored) and inlier_mask (that image's RANSAC inliers,
// one entry per correspondence; empty = no inliers).
// Output: calibration->cam_from_rig (one per camera; the reference camera's
// is the identity; with `radial`, tz = 0 for all cameras and the rig origin
// is fixed by NormalizeRadialRigOrigin), calibration->rig_from_world (per
// frameset; nullopt where it could not be determined from consistent
// images) and calibration->camera_calibrated (false for cameras that could
// not be placed; their cam_from_rig is the identity).
//
// Per trial (the greedy back-and-forth assignment):
//  1. Rotations. A random seed frameset with >= 2 localized images gives the
//     rotations of its cameras relative to one of them; then, alternately,
//     framesets seen by cameras with a rotation get R_Q and cameras seen in
//     framesets with a rotation get R_P, each as the chordal mean of the
//     candidates (R_P^T R_T, resp. R_T R_Q^T) that agree with the
//     best-supported one; estimates supported by two images go first, and
//     two sweeps re-estimate everything at the end. A radial pose's rotation
//     is complete, so one shared camera links a frameset: partial framesets
//     of 2-3 cameras still connect the rig.
//  2. Translations. Eq. 3's observable rows are linear once the rotations
//     are known, A_i (R_Q X + t_Q) + t_P,i = rows of T_ij X, compared at
//     the image's scene center X. They are solved jointly by least squares
//     over all images whose rotation agrees with the rig (each frameset's
//     t_Q eliminated by Schur complement; radial rigs need two cameras with
//     axes neither parallel nor anti-parallel per frameset,
//     kMinDeterminingAxisAngleDeg in principal_axes.h), iteratively reweighted
//     (Cauchy), and once more over those whose correspondences agree with the
//     result. Cameras whose translation the images leave (nearly) undetermined
//     are dropped: e.g. a radial camera seen only in framesets of two cameras
//     can slide along its partner's axis, and within the plane of the axes
//     if they are (nearly) coplanar, as in a ring.
// An image agrees with a pose if both its own pose and that pose put >= 5 of
// its scored inliers within max_radial_error_px and neither explains less
// than half of what the other does. The hypothesis with the best truncated
// radial score keeps its agreeing images, the framesets they determine and
// the cameras with two of them and a determined translation; eq. 4 is
// minimized over those.
//
// Returns false (message in summary->message and the log) on inconsistent
// input, on radial rigs whose principal axes are all within
// kMinDeterminingAxisAngleDeg of parallel or anti-parallel (no pair of
// cameras determines a frameset; PrincipalAxesAreParallel), or if the reference
// camera cannot be placed. Deterministic for a given seed. summary may be
// null.
bool InitializeRig(const RigInitializerOptions& options,
                   const RigDataset& dataset, RigCalibration* calibration,
                   RigInitializerSummary* summary);

}  // namespace rig_calibrator
