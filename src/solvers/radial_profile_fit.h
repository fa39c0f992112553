// Linear fit of the focal length and radial distortion of a radial profile
// for a fixed tz (paper §3.5; the formula is under Method below): the inner problem
// of the least-squares upgrade (radial_intrinsics_least_squares.h). Notation:
// radial_intrinsics.h.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "src/solvers/radial_intrinsics.h"

namespace rig_calibrator {

// Problem: for model->tz fixed, f and the first model->num_radial_terms
// (0..2) distortion terms of model->profile from num_radial_terms + 1 or more
// correspondences; with `known_focal` (the user holds f), only the
// distortion terms, from num_radial_terms or more.
// Method: the profile is linear in y = [f, f k1, f k2]:
//   rho_i = f phi_i + f k1 phi_i^3 + f k2 phi_i^5,
// phi_i = ProfileAngle(profile, s_i, c_i + tz); with f known the unknowns are
// y = [f k1, f k2] and the target rho_i - f phi_i. Normal equations of at
// most 3 unknowns, equilibrated to a unit diagonal, solved by Cholesky.
// Solutions: one (least squares). Fills focal (= *known_focal if given) and k
// of `model`; `squared_error` gets the sum of squared radial residuals in
// pixels^2. Returns false if a point has c + tz <= 0, the system is
// rank-deficient or f <= 0.
bool FitRadialProfile(const std::vector<Eigen::Vector2d>& x,
                      const std::vector<Eigen::Vector3d>& points_cam,
                      const std::optional<double>& known_focal,
                      RadialIntrinsics* model, double* squared_error);

// Polishes tz together with f and the distortion terms: Gauss-Newton on the
// radial residuals r_i = f (phi_i + k1 phi_i^3 + k2 phi_i^5) - rho_i over
// (tz, f, f k1, f k2), or (tz, f k1, f k2) with `known_focal`, with
// d phi / d tz = -s / depth^2 (polynomial) or -s / (s^2 + depth^2)
// (equidistant); each step by column-pivoted QR of the column-equilibrated
// Jacobian. Quadratic convergence where the residuals vanish (exact data,
// minimal samples). Stops after max_num_iterations, when a step no longer
// lowers the error, or when tz stops changing. Returns false (model
// unchanged) if FitRadialProfile fails at model->tz; otherwise model and
// squared_error hold the best iterate (focal = *known_focal if given).
bool RefineRadialProfileAndTz(const std::vector<Eigen::Vector2d>& x,
                              const std::vector<Eigen::Vector3d>& points_cam,
                              const std::optional<double>& known_focal,
                              int max_num_iterations, RadialIntrinsics* model,
                              double* squared_error);

}  // namespace rig_calibrator
