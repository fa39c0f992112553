// Radial bundle adjustment of the rig (paper §3.4):
//   min_{P_i, Q_j, c_i} sum_{i,j,p} rho(|pi_r(P_i Q_j X_p, x_ijp - c_i)
//                                       - (x_ijp - c_i)|^2),
// pi_r(u, v) = (u^T v / u^T u) u, the projection of v onto the line spanned
// by the first two camera-frame coordinates u of the point: the residual is
// the distance of the observation from its predicted radial line, which
// does not depend on focal length, distortion or tz. rho is a Cauchy loss.
//
// Gauge (see "Gauge of radial rigs" in rig_initializer.h): the reference camera's
// cam_from_rig stays the identity, every camera's tz stays 0, and the slide
// of the rig origin along the reference camera's axis is fixed by
// NormalizeRadialRigOrigin after the solve.
#pragma once

#include <string>

#include "src/rig/rig_dataset.h"
#include "src/solvers/bundle_solver.h"

namespace rig_calibrator {

struct RadialBundleAdjustmentOptions {
  double loss_scale_px = 1.0;  // Cauchy scale, pixels
  int max_num_iterations = 100;
  bool refine_principal_points = true;
  // After a first solve, correspondences with a larger radial error (pixels)
  // are dropped, and images with fewer than half of theirs within it are
  // dropped whole; the rest is solved again. The Cauchy loss bounds each
  // wrong correspondence's pull, but those of a mis-localized image agree
  // with one another and add up along the weakly constrained
  // principal point / pan-tilt direction. 0: keep all.
  double max_radial_error_px = 8.0;
  // The adjustment is only the initialization of the camera upgrade and the
  // final bundle adjustment, and a rig pose has 6 unknowns, a camera 7: at
  // most this many of an image's correspondences take part (evenly spaced
  // over the image's inliers, so the selection is fixed for given data).
  // Issue 14's scenario, 100 framesets x 10 cameras: radial BA CPU time
  // 4.6 -> 2.2 s, the same number of iterations and the same final errors
  // against the truth. 0: all.
  int max_correspondences_per_image = 100;
  int num_threads = -1;
  bool print_progress = false;  // per-iteration progress on stdout
  // Each solve stops when a step changes the cost by at most this share of
  // it (Ceres' default), or on the parameter tolerance (1e-10).
  double function_tolerance = 1e-6;
  // The solver's backend (bundle_solver.h): the own one, or Ceres' to
  // compare with.
  BundleSolverBackend bundle_solver = BundleSolverBackend::kOwn;
};

struct RadialBundleAdjustmentSummary {
  // Radial reprojection RMS (no robust loss), pixels: before, over all
  // selected correspondences; after, over those kept (num_residuals).
  double initial_rms_px = 0;
  double final_rms_px = 0;
  int num_residuals = 0;   // correspondences (2 residual components each)
  int num_outliers = 0;    // correspondences dropped (max_radial_error_px)
  int num_iterations = 0;  // of both solves
  double seconds = 0;
  // Framesets with a rig pose that their images do not determine
  // (AxesDetermineTranslation, principal_axes.h) in the final solve; their rig
  // pose is left as it was (or as the first solve left it).
  int num_framesets_skipped = 0;
  std::string message;  // why AdjustRadialRig failed; empty on success
};

// Adjusts calibration->cam_from_rig (rotation, tx, ty of the calibrated
// cameras; tz stays 0; the reference camera stays the identity),
// calibration->rig_from_world (framesets with a pose) and, with
// refine_principal_points, each camera's principal point, stored in
// calibration->cameras[i] (colmap::Camera::SetPrincipalPointX/Y). The
// correspondences are those selected by calibration->images[k].inlier_mask
// of images of calibrated cameras whose frameset has a rig pose; the
// observed points are centered on calibration->cameras[i]'s principal point.
// The solver (bundle_solver.h, options.bundle_solver) runs on num_threads
// threads; the own backend's result is the same on any count.
// Correspondences with a radial error above max_radial_error_px after a
// first solve, and mostly-outlier images, are dropped for a second one.
// Returns false, with calibration unchanged and the reason in
// summary->message and the log, on inconsistent input, if the reference
// camera has no correspondences, or if the solver fails. summary may be
// null.
bool AdjustRadialRig(const RadialBundleAdjustmentOptions& options,
                     const RigDataset& dataset, RigCalibration* calibration,
                     RadialBundleAdjustmentSummary* summary);

}  // namespace rig_calibrator
