// Least-squares upgrade of a camera from many correspondences: tz, the focal
// length and radial distortion given its 1D radial pose (paper §3.5,
// the method is stated below). The local estimator of the upgrade's LO-RANSAC
// (radial_intrinsics_estimator.h). Notation: radial_intrinsics.h.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "src/solvers/radial_intrinsics.h"

namespace rig_calibrator {

// Problem: tz, f and the first num_radial_terms (0..2) distortion terms of
// `profile` minimizing the squared radial error over num_radial_terms + 3 or
// more correspondences; with `known_focal` (the user holds f), tz and the
// distortion terms over num_radial_terms + 2 or more.
// Method: variable projection over tz. E(tz) = FitRadialProfile's squared
// error (f and k, or k alone for a known f, eliminated linearly for each tz)
// is sampled on a log-spaced
// grid of the depth of the nearest point, tz + min(c), from 1/30 to 30 times
// its value under SolveDivisionIntrinsics (num_kappa = num_radial_terms; the
// spread median(c) - min(c) when that fails); E is not convex in tz, so its
// 5 lowest local minima on the grid are refined by Brent's method (Boost)
// within their neighbouring grid points and polished by
// RefineRadialProfileAndTz (f held when known). Solutions whose r_d does not
// grow with the ray angle over the points are dropped.
// Solutions: up to 3 local minima of E, lowest first; the first is the
// estimate. With f known every solution has focal == *known_focal exactly.
std::vector<RadialIntrinsics> SolveRadialIntrinsicsLeastSquares(
    const std::vector<Eigen::Vector2d>& x,
    const std::vector<Eigen::Vector3d>& points_cam, RadialProfile profile,
    int num_radial_terms, const std::optional<double>& known_focal);

}  // namespace rig_calibrator
