// Solvers for the forward translation tz, the focal length and the radial
// distortion of a camera whose 1D radial pose (R, tx, ty) is known (paper
// §3.5, MATH.md §3). They initialize the camera upgrade; the final values come
// from the LM in camera_upgrader.h.
//
// Notation: x = (u, v) is a pixel relative to the principal point, rho = |x|.
// (a, b, c) = R X + (tx, ty, 0) is the camera-frame point without tz, so the
// full camera-frame point is (a, b, c + tz). s = x.(a, b) / rho is the signed
// radial coordinate of the 3D point along the image point's direction; s > 0
// for a point on the correct half-line of the radial pose.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace rig_calibrator {

// How the distance of an image point from the principal point depends on the
// incoming ray's angle theta to the optical axis.
enum class RadialProfile {
  // r_d = f q (1 + k1 q^2 + k2 q^4), q = tan(theta): the radial part of
  // SIMPLE_RADIAL, RADIAL, OPENCV and FULL_OPENCV (k3.. and tangential = 0).
  kPolynomial,
  // r_d = f theta (1 + k1 theta^2 + k2 theta^4): the OpenCV fisheye family
  // (SIMPLE_RADIAL_FISHEYE, RADIAL_FISHEYE, OPENCV_FISHEYE, k3.. = 0).
  kEquidistant,
};

// tz, focal length and the first `num_radial_terms` (0..2) distortion terms
// of a radial profile.
struct RadialIntrinsics {
  RadialProfile profile = RadialProfile::kPolynomial;
  int num_radial_terms = 0;
  double tz = 0;
  double focal = 0;
  double k[2] = {0, 0};

  // Radial distance r_d of the image of a ray with tan(theta) = q >= 0.
  double DistortedRadius(double q) const;

  // Image of the camera-frame point (a, b, c + tz) relative to the principal
  // point; false when c + tz <= 0 (behind the camera, or on its plane).
  bool Project(const Eigen::Vector3d& point_cam, Eigen::Vector2d* x) const;
};

// Division ("undistortion") model with distortion in pixel units (Kukelova et
// al. ICCV'13, second step):
//   x / (1 + kappa1 rho^2 + kappa2 rho^4) = f (a, b) / (c + tz).
struct DivisionIntrinsics {
  int num_kappa = 0;
  double tz = 0;
  double focal = 0;
  double kappa[2] = {0, 0};
};

// Fully linear estimate of a division model with `num_kappa` (0..2) terms.
// Projecting the model onto the direction of x and multiplying by c + tz gives
// one equation per point, linear in y = [f, f kappa1, f kappa2, tz]:
//   [s, s rho^2, s rho^4, -rho] . y = rho c.
// Exact for num_kappa + 2 points (the minimal case), least squares for more.
// Pixels are scaled by their RMS radius and the columns are equilibrated
// before the solve. Returns false for a rank-deficient system or f <= 0 (the
// points would be on the wrong half-line of the radial pose).
bool SolveDivisionIntrinsics(const std::vector<Eigen::Vector2d>& x,
                             const std::vector<Eigen::Vector3d>& points_cam,
                             int num_kappa, DivisionIntrinsics* model);

// For a fixed tz the radial profile is linear in [f, f k1, f k2]:
//   rho_i = f phi(q_i) + f k1 phi(q_i)^3 + f k2 phi(q_i)^5,
// with phi(q) = q = s / (c + tz) (polynomial) or phi = atan2(s, c + tz)
// (equidistant). Solves that least-squares problem for model->tz and fills
// focal and k of `model` (its profile and num_radial_terms are inputs).
// `squared_error` gets the sum of squared radial residuals in pixels^2.
// Returns false if a point has c + tz <= 0, the system is rank-deficient or
// f <= 0.
bool FitRadialProfile(const std::vector<Eigen::Vector2d>& x,
                      const std::vector<Eigen::Vector3d>& points_cam,
                      RadialIntrinsics* model, double* squared_error);

// Variable projection over tz (radial_solvers.md §3.4): minimizes
// E(tz) = FitRadialProfile's squared error over tz. tz is bracketed by a
// log-spaced grid over the depth of the nearest point, tz + min(c), from 1/30
// to 30 times its value under SolveDivisionIntrinsics (num_kappa =
// num_radial_terms, or the spread median(c) - min(c) when that fails); the 5
// lowest local minima of the grid are refined by Brent's method. Solutions
// whose r_d does not grow with the ray angle over the points are dropped.
// Returns up to 3 solutions, best first. With num_radial_terms + 2 points E
// vanishes at every solution of the minimal problem, hence several
// candidates; with more points the first is the estimate.
std::vector<RadialIntrinsics> EstimateRadialIntrinsics(
    const std::vector<Eigen::Vector2d>& x,
    const std::vector<Eigen::Vector3d>& points_cam, RadialProfile profile,
    int num_radial_terms);

// The solver above in COLMAP's estimator concept (<colmap/optim/ransac.h>),
// for RANSAC and as the local estimator of LORANSAC. The residual is the
// squared full reprojection error in pixels^2 (infinite for c + tz <= 0).
template <int kNumRadialTerms>
class RadialIntrinsicsEstimator {
 public:
  typedef Eigen::Vector2d X_t;  // pixel relative to the principal point
  typedef Eigen::Vector3d Y_t;  // camera-frame point without tz
  typedef RadialIntrinsics M_t;

  static_assert(kNumRadialTerms >= 0 && kNumRadialTerms <= 2,
                "0 to 2 radial terms");
  // f, the radial terms and tz.
  static constexpr int kMinNumSamples = kNumRadialTerms + 2;

  RadialProfile profile = RadialProfile::kPolynomial;

  std::vector<M_t> Estimate(const std::vector<X_t>& x,
                            const std::vector<Y_t>& points_cam) const {
    return EstimateRadialIntrinsics(x, points_cam, profile, kNumRadialTerms);
  }

  void Residuals(const std::vector<X_t>& x, const std::vector<Y_t>& points_cam,
                 const M_t& model, std::vector<double>* residuals) const;
};

// Squared full reprojection errors of `model` (infinite for c + tz <= 0).
void RadialIntrinsicsResiduals(const std::vector<Eigen::Vector2d>& x,
                               const std::vector<Eigen::Vector3d>& points_cam,
                               const RadialIntrinsics& model,
                               std::vector<double>* residuals);

template <int kNumRadialTerms>
void RadialIntrinsicsEstimator<kNumRadialTerms>::Residuals(
    const std::vector<X_t>& x, const std::vector<Y_t>& points_cam,
    const M_t& model, std::vector<double>* residuals) const {
  RadialIntrinsicsResiduals(x, points_cam, model, residuals);
}

}  // namespace rig_calibrator
