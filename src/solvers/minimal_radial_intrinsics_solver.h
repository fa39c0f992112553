// Minimal solver for tz, the focal length and radial distortion of a camera
// whose 1D radial pose (R, tx, ty) is known (paper §3.5; the
// polynomial case is Larsson et al. ICCV'19's D(n, 0) with the pose known).
// The minimal estimator of the upgrade's LO-RANSAC
// (radial_intrinsics_estimator.h). Notation: radial_intrinsics.h.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "src/solvers/radial_intrinsics.h"

namespace rig_calibrator {

// Problem: tz, f and the first n = num_radial_terms (0..2) distortion terms
// of `profile` from exactly n + 2 correspondences (n + 2 unknowns); with
// `known_focal` (the user holds f), tz and the n distortion terms from
// exactly n + 1 correspondences.
//
// Method: for a fixed tz the profile is linear in y = [f, f k1, .., f kn],
//   rho_i = sum_j y_j phi_i^(2j+1),   phi_i = ProfileAngle(s_i, c_i + tz),
// so the (n+2)x(n+2) matrix M(tz) with rows [phi_i, phi_i^3, ..,
// phi_i^(2n+1), -rho_i] has the null vector [y; 1]: det M(tz) = 0 at every
// solution. With f known, rho_i - f phi_i = f sum_{j>=1} k_j phi_i^(2j+1):
// the (n+1)x(n+1) matrix M(tz) with rows [phi_i^3, .., phi_i^(2n+1),
// f phi_i - rho_i] (M's first column times f added to its last, then
// dropped; the factor f of the other columns does not change the roots) has
// the null vector [f k; 1].
//  - Polynomial profile, phi_i = s_i / d_i with d_i = c_i + tz: row i times
//    d_i^(2n+1) is [s_i d_i^(2n), s_i^3 d_i^(2n-2), .., s_i^(2n+1),
//    -rho_i d_i^(2n+1)], polynomial in tz, so det is a polynomial of degree
//    sum_j (2n - 2j) + 2n + 1 = n^2 + 3n + 1, i.e. 1, 5 or 11; with f known
//    the last entry is f s_i d_i^(2n) - rho_i d_i^(2n+1) and the column
//    s_i d_i^(2n) is gone: degree sum_{j>=1} (2n - 2j) + 2n + 1 =
//    n^2 + n + 1, i.e. 1, 3 or 7 (n = 0 is the closed form
//    tz = f s / rho - c of the single point). The coefficients are expanded
//    exactly (cofactor expansion on coefficient vectors) in the variable
//    v = (tz + mean(c)) / L, with L the RMS of (s_i, c_i - mean(c)) and rho
//    (and a known f) scaled to unit RMS of rho, so that they are of order 1;
//    its real roots come from the companion matrix
//    (colmap::FindPolynomialRootsCompanionMatrix).
//  - Equidistant profile, phi_i = atan2(s_i, d_i): det M(tz) is not
//    algebraic in tz, so there is no closed form. It is a smooth function
//    that changes sign at each (simple) solution, unlike the variable
//    projection's E(tz) >= 0 that only touches zero there, so the solutions
//    are bracketed by a scan of its sign over the depth of the nearest point
//    D = tz + min(c), log-spaced from 1e-4 L to 1e4 L
//    (kNumEquidistantScanSteps in the .cc), and each bracket is
//    solved by TOMS 748 (Boost). Where |det| has a local minimum between
//    samples of equal sign, a pair of close roots is looked for by Brent's
//    minimization of |det| there.
// Every root is then made a solution: y by least squares at that tz
// (FitRadialProfile), tz and y polished together by Newton
// (RefineRadialProfileAndTz, quadratic on these square systems; f held when
// known), kept if the residuals vanish (1e-6 of the RMS radius), every
// c_i + tz > 0, f > 0 and r_d grows with the ray angle over the points
// (RadiusGrowsOverPoints).
//
// Solutions: polynomial at most 1, 5, 11 for n = 0, 1, 2 (1, 3, 7 with f
// known; the degree); equidistant at most one per scan step, in practice as
// many as the polynomial case. Order: increasing tz. With f known every
// solution has focal == *known_focal exactly. Degenerate samples
// (rank-deficient M, points on the principal point, non-finite values, a
// known f that is not finite and positive) give none.
std::vector<RadialIntrinsics> SolveMinimalRadialIntrinsics(
    const std::vector<Eigen::Vector2d>& x,
    const std::vector<Eigen::Vector3d>& points_cam, RadialProfile profile,
    int num_radial_terms, const std::optional<double>& known_focal);

}  // namespace rig_calibrator
