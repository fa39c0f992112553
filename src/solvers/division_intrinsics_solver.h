// Linear solver for tz, the focal length and a division ("undistortion")
// model of radial distortion, given a camera's 1D radial pose (Kukelova et al.
// ICCV'13, second step; the model is stated below). It brackets the search of
// the least-squares upgrade (radial_intrinsics_least_squares.h). Notation:
// radial_intrinsics.h.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace rig_calibrator {

// Division model with distortion in pixel units:
//   x / (1 + kappa1 rho^2 + kappa2 rho^4) = f (a, b) / (c + tz).
struct DivisionIntrinsics {
  int num_kappa = 0;
  double tz = 0;
  double focal = 0;
  double kappa[2] = {0, 0};
};

// Problem: tz, f and `num_kappa` (0..2) distortion terms from num_kappa + 2
// or more correspondences.
// Method: projecting the model onto the direction of x and multiplying by
// c + tz gives one equation per point, linear in y = [f, f kappa1, f kappa2,
// tz]:
//   [s, s rho^2, s rho^4, -rho] . y = rho c.
// Pixels are scaled by their RMS radius and the columns equilibrated before a
// column-pivoted QR solve.
// Solutions: one; exact for num_kappa + 2 points (the minimal case), least
// squares for more. Returns false for a rank-deficient system or f <= 0 (the
// points would be on the wrong half-line of the radial pose).
bool SolveDivisionIntrinsics(const std::vector<Eigen::Vector2d>& x,
                             const std::vector<Eigen::Vector3d>& points_cam,
                             int num_kappa, DivisionIntrinsics* model);

}  // namespace rig_calibrator
