// What the principal axes of a 1D radial rig determine (paper eq. 3 and
// Limitations). A radial camera observes only the first two rows
// of its pose, so its position along its own principal axis z is unknown:
//  - a rig pose's translation is determined by the radial rows of cameras
//    with axes z_k only if N = sum_k (I - z_k z_k^T) is regular. For two
//    axes at an angle theta, N's eigenvalues are 1 - |cos theta|,
//    1 + |cos theta| and 2: parallel AND anti-parallel axes (a front/back
//    rig) leave the translation along the common axis free;
//  - the rig origin can slide along the reference camera's axis
//    (NormalizeRadialRigOrigin fixes that gauge).
// The angle of two axes from parallel is therefore acos(|z_a . z_b|), in
// [0, 90] degrees, everywhere in the project.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "src/geometry/rigid3d.h"
#include "src/rig/rig_dataset.h"

namespace rig_calibrator {

// Determinedness (per frameset, rig initialization and radial BA): radial
// cameras determine a rig pose's translation only if the smallest eigenvalue
// of N is at least 1 - cos(kMinDeterminingAxisAngleDeg), i.e. (for two
// cameras) their axes are at least this far from parallel and from
// anti-parallel. A numerical floor: closer to parallel, a radial pose error
// of e moves the translation along the weak direction by about
// e / sin(angle) (> 11 e below 5 degrees).
constexpr double kMinDeterminingAxisAngleDeg = 5.0;

// Whole-rig diagnosis (the pipeline's choice of method): a rig on which no
// pair of cameras is farther than this from (anti-)parallel, median over
// the framesets where both are localized, is not calibrated from 1D radial
// poses (1dr) but from full per-image poses (rd_ra). A decision about
// accuracy, not solvability, hence wider than the determinedness floor:
// between 5 and 10 degrees the framesets are determined, but every rig
// translation rests on the small differences of nearly parallel axes. Must
// be at least kMinDeterminingAxisAngleDeg, so that every rig 1dr is tried
// on has determinable framesets.
constexpr double kParallelAxesMaxAngleDeg = 10.0;
static_assert(kParallelAxesMaxAngleDeg >= kMinDeterminingAxisAngleDeg);

// The principal axis of a camera in frame x: the third row of R_cam_from_x.
Eigen::Vector3d PrincipalAxis(const Rigid3d& cam_from_x);

// Angle of two unit axes from parallel, acos(|a . b|), degrees in [0, 90]:
// 0 for parallel and for anti-parallel axes.
double AxisAngleFromParallelDeg(const Eigen::Vector3d& a,
                                const Eigen::Vector3d& b);

// The smallest eigenvalue of N = sum_k (I - z_k z_k^T) over unit axes z_k:
// the normal matrix of a rig pose's translation in eq. 3 with radial poses.
// Zero iff all axes are parallel or anti-parallel.
double SmallestAxisEigenvalue(const std::vector<Eigen::Vector3d>& axes);

// The smallest eigenvalue of N for two axes min_angle_deg from parallel,
// 1 - cos(min_angle_deg): the threshold on SmallestAxisEigenvalue.
double AxisEigenvalueOfAngle(double min_angle_deg);

// Whether radial cameras with these axes determine a rig pose's
// translation: at least two axes and SmallestAxisEigenvalue >=
// AxisEigenvalueOfAngle(min_angle_deg).
bool AxesDetermineTranslation(
    const std::vector<Eigen::Vector3d>& axes,
    double min_angle_deg = kMinDeterminingAxisAngleDeg);

// Parallel-axes diagnosis. From the per-image poses
// calibration.images[i].single_image_cam_from_world: for every pair of
// cameras, the median over the framesets where both are localized of the
// angle of their principal axes from parallel (AxisAngleFromParallelDeg).
// Returns true if every pair's median is at most max_angle_deg, i.e. a
// radial rig cannot be fixed (use full per-image poses, `rd_ra`). Returns
// false if some pair is farther from parallel, and also if no frameset has
// two localized images (nothing to judge); `explanation` (may be null) says
// which.
bool PrincipalAxesAreParallel(const RigDataset& dataset,
                              const RigCalibration& calibration,
                              double max_angle_deg, std::string* explanation);

// Fixes the gauge of a radial rig (rig_initializer.h): moves the rig origin
// along the reference camera's principal axis to the point closest, in least
// squares, to the principal axes of the other calibrated cameras,
//   d = -sum_i g_i . t_i,xy / sum_i |g_i|^2,  g_i = (R_i e_z)_xy,
// then t_i,xy += d g_i, every rig_from_world translation -= d e_z, and tz = 0
// for all cameras. |t_i,xy| is the distance of the rig origin from camera i's
// axis. The radial projections do not change. Does nothing to the
// translations if all calibrated cameras are parallel or anti-parallel to
// the reference (g_i = 0: the slide changes nothing).
void NormalizeRadialRigOrigin(int reference_camera,
                              RigCalibration* calibration);

}  // namespace rig_calibrator
