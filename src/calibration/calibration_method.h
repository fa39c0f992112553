// The methods of the pipeline (pipeline.h): the paper's Inf+1DR+RA and its
// baselines (paper §5.1, Tables 1 and 3), and what each one does in each
// stage.
//
//   method        paper       single-image pose    rig initialization
//   1dr           Inf+1DR+RA  1D radial            robust, radial
//   rd_ra         Inf+RD+RA   pose + intrinsics    robust, full poses
//   rd            Inf+RD      pose + intrinsics    best complete frameset
//   known         Inf+K       given intrinsics     best complete frameset
//   known_refine  Inf+K+RI    given intrinsics     best complete frameset
//   known_ra      (none)      given intrinsics     robust, full poses
//
// known and known_refine are Heng et al.'s pipeline as the paper runs it;
// known_ra gives it the robust rig initialization of rd_ra, for comparing
// the initializations with the intrinsics out of the picture. The final
// bundle adjustment refines the intrinsics for every method but known and
// known_ra.
#pragma once

#include <string>

#include "src/calibration/initial_pose_estimation.h"

namespace rig_calibrator {

enum class CalibrationMethod {
  kKnown,
  kKnownRefine,
  kKnownRa,
  kRd,
  kRdRa,
  kRadial1D
};

// "known", "known_refine", "known_ra", "rd", "rd_ra", "1dr".
bool CalibrationMethodFromName(const std::string& name,
                               CalibrationMethod* method);
std::string CalibrationMethodName(CalibrationMethod method);

// The intrinsics are given (known*), not estimated.
bool UsesKnownIntrinsics(CalibrationMethod method);
// The rig comes from the best complete frameset (Heng et al.), not from the
// robust initialization.
bool UsesCompleteFramesetInitialization(CalibrationMethod method);
// The final bundle adjustment refines the intrinsics.
bool RefinesIntrinsics(CalibrationMethod method);
InitialPoseModel InitialPoseModelOf(CalibrationMethod method);

}  // namespace rig_calibrator
