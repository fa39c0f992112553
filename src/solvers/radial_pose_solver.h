// Minimal solver for the absolute pose of a 1D radial camera (paper §3.2,
// Kukelova et al. ICCV 2013, radial step).
//
// A 1D radial camera observes only the direction of an image point from the
// principal point: focal length and any radially symmetric distortion move a
// projection along that line. For a centered image point x = (u, v) and a
// world point X, x is parallel to the first two rows of the camera-frame point,
// x || (r1.X + t1, r2.X + t2), and the forward translation tz does not enter.
// Five correspondences determine R and (tx, ty), with up to 4 solutions.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "src/geometry/rigid3d.h"

namespace rig_calibrator {

// points2D are relative to the principal point (any scale), points3D in world
// coordinates, exactly 5 each. Appends up to 4 cam_from_world poses with
// translation.z() == 0 (tz is unobservable); each puts all 5 sample points on
// the correct half-line (alpha > 0 below). Degenerate samples (coincident
// points, a 2D point at the principal point, non-finite values) append
// nothing.
//
// Method: each point gives one linear equation in p = (r1, t1, r2, t2),
//   u (r2.X + t2) - v (r1.X + t1) = 0,
// so p lies in the 3-dimensional null space of the 5x8 system; the rotation
// constraints then give a quartic (RadialPosesInSubspace). Conditioning:
// x is normalized to unit length, X centered and scaled to unit RMS radius,
// and the normalization is undone on the solutions.
void SolveRadialPose5(const std::vector<Eigen::Vector2d>& points2D,
                      const std::vector<Eigen::Vector3d>& points3D,
                      std::vector<Rigid3d>* cam_from_world);

// The 1D radial poses in a 3-dimensional subspace of R^8: the vectors
// p = a basis.col(0) + b basis.col(1) + basis.col(2), p = (r1, t1, r2, t2),
// whose rotation rows satisfy r1.r2 = 0 and |r1|^2 - |r2|^2 = 0. Each
// constraint is a quadratic in b with coefficients polynomial in a; the
// Sylvester resultant eliminating b is a quartic in a. Each solution is scaled
// so that r1, r2 are orthonormal (nearest orthonormal pair, by polar
// decomposition, which absorbs rounding). The overall sign is NOT fixed:
// p and -p are both solutions (a 180 degree turn about the optical axis).
// Writes up to 4 solutions and returns their number. Shared by the minimal
// solver and the non-minimal estimator.
int RadialPosesInSubspace(const Eigen::Matrix<double, 8, 3>& basis,
                          Eigen::Matrix<double, 8, 1> solutions[4]);

// Scales p = (r1, t1, r2, t2) so that [r1; r2] becomes the nearest pair of
// orthonormal rows: with [r1; r2] = U S V^T, the rows become U V^T and
// (t1, t2) is divided by the mean singular value. Returns false if [r1; r2]
// has rank < 2 or p is not finite.
bool NormalizeRadialRows(Eigen::Matrix<double, 8, 1>* p);

}  // namespace rig_calibrator
