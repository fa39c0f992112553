// The pixel x = pi_theta(u, v) of a COLMAP camera model at the normalized
// point (u, v), with its derivatives by (u, v) and by the model's parameters
// theta: the inner loop of the final bundle adjustment
// (rig_reprojection_cost.h) and of the uncertainty.
//
// Closed form for the models of COLMAP 3.8 that calibrations use most, with
// the parameter order of COLMAP's params_info:
//   SIMPLE_PINHOLE f, cx, cy            RADIAL       f, cx, cy, k1, k2
//   PINHOLE        fx, fy, cx, cy       OPENCV       fx, fy, cx, cy, k1, k2,
//   SIMPLE_RADIAL  f, cx, cy, k                      p1, p2
//   OPENCV_FISHEYE fx, fy, cx, cy, k1..k4
//   FULL_OPENCV    fx, fy, cx, cy, k1, k2, p1, p2, k3..k6
// Every one is x = f (x_d, y_d) + c of a distorted normalized point
// (x_d, y_d) = d(u, v), so dx/d(u,v) = diag(f) dd/d(u,v), dx/df = (x_d, y_d),
// dx/dc = I and dx/dk = diag(f) dd/dk. The other models (FOV, the radial and
// thin-prism fisheyes) are differentiated by forward-mode Jets of COLMAP's
// templated WorldToImage: 2 + kNumParams derivatives through every operation,
// 3-4x the arithmetic of the closed form (500 framesets x 10 OPENCV cameras:
// most of the final bundle adjustment's residual evaluation).
#pragma once

#include <ceres/jet.h>
#include <colmap/base/camera_models.h>

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <type_traits>

namespace rig_calibrator {
namespace camera_model_jacobians {

// (x_d, y_d) = d(u, v), its 2 x 2 Jacobian by (u, v) and its Jacobian by the
// kNumExtra distortion parameters (row-major 2 x kNumExtra).
template <int kNumExtra>
struct Distorted {
  double x = 0, y = 0;
  Eigen::Matrix2d d_uv = Eigen::Matrix2d::Identity();
  double d_extra[2 * kNumExtra + 1] = {};  // + 1: no zero-size array
};

// r2 = u^2 + v^2 and, for radial(r2) with radial' = d radial / d r2,
//   x_d = u (1 + radial) + tangential_x,  dx_d/du = 1 + radial + 2 u^2
//   radial' + ..., dx_d/dv = 2 u v radial' + ...
// (the tangential terms are added by the caller).
template <int kNumExtra>
void AddRadialTerm(double u, double v, double radial, double radial_derivative,
                   Distorted<kNumExtra>* d) {
  d->x = u * (1 + radial);
  d->y = v * (1 + radial);
  const double cross = 2 * u * v * radial_derivative;
  d->d_uv << 1 + radial + 2 * u * u * radial_derivative, cross, cross,
      1 + radial + 2 * v * v * radial_derivative;
}

// OpenCV's tangential terms, tangential = (2 p1 u v + p2 (r2 + 2 u^2),
// 2 p2 u v + p1 (r2 + 2 v^2)), into x_d and its (u, v) Jacobian; their
// p1, p2 derivatives go to columns p1_column and p1_column + 1.
template <int kNumExtra>
void AddTangentialTerm(double u, double v, double p1, double p2, int p1_column,
                       Distorted<kNumExtra>* d) {
  const double r2 = u * u + v * v;
  d->x += 2 * p1 * u * v + p2 * (r2 + 2 * u * u);
  d->y += 2 * p2 * u * v + p1 * (r2 + 2 * v * v);
  d->d_uv(0, 0) += 2 * p1 * v + 6 * p2 * u;
  d->d_uv(0, 1) += 2 * p1 * u + 2 * p2 * v;
  d->d_uv(1, 0) += 2 * p2 * v + 2 * p1 * u;
  d->d_uv(1, 1) += 2 * p2 * u + 6 * p1 * v;
  d->d_extra[p1_column] = 2 * u * v;
  d->d_extra[p1_column + 1] = r2 + 2 * u * u;
  d->d_extra[kNumExtra + p1_column] = r2 + 2 * v * v;
  d->d_extra[kNumExtra + p1_column + 1] = 2 * u * v;
}

// The pinhole models: (x_d, y_d) = (u, v).
inline Distorted<0> Undistorted(double u, double v) {
  Distorted<0> d;
  d.x = u;
  d.y = v;
  return d;
}

// SIMPLE_RADIAL: radial = k r2.
inline Distorted<1> SimpleRadial(const double* k, double u, double v) {
  Distorted<1> d;
  const double r2 = u * u + v * v;
  AddRadialTerm(u, v, k[0] * r2, k[0], &d);
  d.d_extra[0] = u * r2;
  d.d_extra[1] = v * r2;
  return d;
}

// radial = k1 r2 + k2 r2^2 (RADIAL, OPENCV), k1 and k2 the first two
// distortion parameters.
template <int kNumExtra>
Distorted<kNumExtra> TwoTermRadial(const double* k, double u, double v) {
  Distorted<kNumExtra> d;
  const double r2 = u * u + v * v;
  AddRadialTerm(u, v, k[0] * r2 + k[1] * r2 * r2, k[0] + 2 * k[1] * r2, &d);
  d.d_extra[0] = u * r2;
  d.d_extra[1] = u * r2 * r2;
  d.d_extra[kNumExtra] = v * r2;
  d.d_extra[kNumExtra + 1] = v * r2 * r2;
  return d;
}

// RADIAL (k1, k2).
inline Distorted<2> Radial(const double* k, double u, double v) {
  return TwoTermRadial<2>(k, u, v);
}

// OPENCV (k1, k2, p1, p2): the two radial terms plus the tangential ones.
inline Distorted<4> OpenCV(const double* k, double u, double v) {
  Distorted<4> d = TwoTermRadial<4>(k, u, v);
  AddTangentialTerm(u, v, k[2], k[3], 2, &d);
  return d;
}

// FULL_OPENCV (k1, k2, p1, p2, k3, k4, k5, k6): 1 + radial = N / M,
// N = 1 + k1 r2 + k2 r2^2 + k3 r2^3, M = 1 + k4 r2 + k5 r2^2 + k6 r2^3,
// radial' = (N' M - N M') / M^2, dN/dk_i = r2^i, dM/dk_(3+i) = r2^i.
inline Distorted<8> FullOpenCV(const double* k, double u, double v) {
  Distorted<8> d;
  const double r2 = u * u + v * v;
  const double r4 = r2 * r2;
  const double r6 = r4 * r2;
  const double numerator = 1 + k[0] * r2 + k[1] * r4 + k[4] * r6;
  const double denominator = 1 + k[5] * r2 + k[6] * r4 + k[7] * r6;
  const double numerator_derivative = k[0] + 2 * k[1] * r2 + 3 * k[4] * r4;
  const double denominator_derivative = k[5] + 2 * k[6] * r2 + 3 * k[7] * r4;
  const double factor = numerator / denominator;
  AddRadialTerm(
      u, v, factor - 1,
      (numerator_derivative - factor * denominator_derivative) / denominator,
      &d);
  AddTangentialTerm(u, v, k[2], k[3], 2, &d);
  const double powers[3] = {r2, r4, r6};
  const int numerator_columns[3] = {0, 1, 4};
  for (int i = 0; i < 3; ++i) {
    const double d_numerator = powers[i] / denominator;
    const double d_denominator = -factor * powers[i] / denominator;
    d.d_extra[numerator_columns[i]] = u * d_numerator;
    d.d_extra[8 + numerator_columns[i]] = v * d_numerator;
    d.d_extra[5 + i] = u * d_denominator;
    d.d_extra[8 + 5 + i] = v * d_denominator;
  }
  return d;
}

// OPENCV_FISHEYE (k1..k4): with r = |(u, v)|, theta = atan(r),
// theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8),
// (x_d, y_d) = s (u, v), s = theta_d / r, so
//   d(x_d, y_d)/d(u, v) = s I + c (u, v)(u, v)^T,
//   c = (ds/dr) / r = (theta_d'(theta) / (1 + r^2) - s) / r^2,
// and dx_d/dk_i = u theta^(2i+1) / r. c stays finite as r -> 0 (the
// numerator is O(r^2)); its rounding error, ~1e-16 / r^2, is multiplied by
// u^2 + v^2 = r^2. At r <= machine epsilon COLMAP leaves the point
// undistorted (x_d = u), so does this.
inline Distorted<4> OpenCVFisheye(const double* k, double u, double v) {
  Distorted<4> d;
  d.x = u;
  d.y = v;
  const double r = std::sqrt(u * u + v * v);
  if (!(r > std::numeric_limits<double>::epsilon())) {
    return d;
  }
  const double theta = std::atan(r);
  const double theta2 = theta * theta;
  double theta_power = theta;  // theta^(2i+1)
  double polynomial = 1, polynomial_derivative = 1;
  for (int i = 0; i < 4; ++i) {
    theta_power *= theta2;
    polynomial += k[i] * theta_power / theta;
    polynomial_derivative += (2 * i + 3) * k[i] * theta_power / theta;
    d.d_extra[i] = u * theta_power / r;
    d.d_extra[4 + i] = v * theta_power / r;
  }
  const double s = theta * polynomial / r;
  const double c = (polynomial_derivative / (1 + r * r) - s) / (r * r);
  d.x = s * u;
  d.y = s * v;
  d.d_uv << s + c * u * u, c * u * v, c * u * v, s + c * v * v;
  return d;
}

// x = f (x_d, y_d) + c with one focal length (f, cx, cy, extra...) or two
// (fx, fy, cx, cy, extra...); d_pixel_d_params row-major 2 x kNumParams.
template <int kNumFocals, int kNumExtra>
void Project(const double* params, const Distorted<kNumExtra>& d, double* pixel,
             Eigen::Matrix2d* d_pixel_d_uv, double* d_pixel_d_params) {
  constexpr int kNumParams = 2 + kNumFocals + kNumExtra;
  const double fx = params[0];
  const double fy = params[kNumFocals - 1];
  const double* principal_point = params + kNumFocals;
  pixel[0] = fx * d.x + principal_point[0];
  pixel[1] = fy * d.y + principal_point[1];
  d_pixel_d_uv->row(0) = fx * d.d_uv.row(0);
  d_pixel_d_uv->row(1) = fy * d.d_uv.row(1);
  if (d_pixel_d_params == nullptr) {
    return;
  }
  double* row_x = d_pixel_d_params;
  double* row_y = d_pixel_d_params + kNumParams;
  for (int k = 0; k < kNumFocals + 2; ++k) {
    row_x[k] = 0;
    row_y[k] = 0;
  }
  row_x[0] = d.x;
  row_y[kNumFocals - 1] = d.y;
  row_x[kNumFocals] = 1;
  row_y[kNumFocals + 1] = 1;
  for (int k = 0; k < kNumExtra; ++k) {
    row_x[2 + kNumFocals + k] = fx * d.d_extra[k];
    row_y[2 + kNumFocals + k] = fy * d.d_extra[kNumExtra + k];
  }
}

// Forward-mode Jets of CameraModel::WorldToImage: kNumDerivatives = 2
// (u, v) or 2 + kNumParams (and theta).
template <typename CameraModel, int kNumDerivatives>
void ProjectWithJets(const double* params, double u, double v, double* pixel,
                     Eigen::Matrix2d* d_pixel_d_uv, double* d_pixel_d_params) {
  using Jet = ceres::Jet<double, kNumDerivatives>;
  constexpr int kNumParams = static_cast<int>(CameraModel::kNumParams);
  Jet jet_params[kNumParams];
  for (int k = 0; k < kNumParams; ++k) {
    jet_params[k] =
        kNumDerivatives > 2 ? Jet(params[k], 2 + k) : Jet(params[k]);
  }
  Jet x, y;
  CameraModel::WorldToImage(jet_params, Jet(u, 0), Jet(v, 1), &x, &y);
  pixel[0] = x.a;
  pixel[1] = y.a;
  *d_pixel_d_uv << x.v[0], x.v[1], y.v[0], y.v[1];
  if (d_pixel_d_params != nullptr) {
    for (int k = 0; k < kNumParams; ++k) {
      d_pixel_d_params[k] = x.v[2 + k];
      d_pixel_d_params[kNumParams + k] = y.v[2 + k];
    }
  }
}

}  // namespace camera_model_jacobians

// Whether ProjectWithJacobians has the closed form for CameraModel.
template <typename CameraModel>
constexpr bool HasClosedFormJacobians() {
  return std::is_same_v<CameraModel, colmap::SimplePinholeCameraModel> ||
         std::is_same_v<CameraModel, colmap::PinholeCameraModel> ||
         std::is_same_v<CameraModel, colmap::SimpleRadialCameraModel> ||
         std::is_same_v<CameraModel, colmap::RadialCameraModel> ||
         std::is_same_v<CameraModel, colmap::OpenCVCameraModel> ||
         std::is_same_v<CameraModel, colmap::FullOpenCVCameraModel> ||
         std::is_same_v<CameraModel, colmap::OpenCVFisheyeCameraModel>;
}

// pixel = pi_theta(u, v), d_pixel_d_uv = dpi/d(u, v) and, when
// `d_pixel_d_params` is given, dpi/dtheta (row-major 2 x kNumParams).
template <typename CameraModel>
void ProjectWithJacobians(const double* params, double u, double v,
                          double* pixel, Eigen::Matrix2d* d_pixel_d_uv,
                          double* d_pixel_d_params) {
  namespace j = camera_model_jacobians;
  if constexpr (std::is_same_v<CameraModel, colmap::SimplePinholeCameraModel>) {
    j::Project<1>(params, j::Undistorted(u, v), pixel, d_pixel_d_uv,
                  d_pixel_d_params);
  } else if constexpr (std::is_same_v<CameraModel,
                                      colmap::PinholeCameraModel>) {
    j::Project<2>(params, j::Undistorted(u, v), pixel, d_pixel_d_uv,
                  d_pixel_d_params);
  } else if constexpr (std::is_same_v<CameraModel,
                                      colmap::SimpleRadialCameraModel>) {
    j::Project<1>(params, j::SimpleRadial(params + 3, u, v), pixel,
                  d_pixel_d_uv, d_pixel_d_params);
  } else if constexpr (std::is_same_v<CameraModel, colmap::RadialCameraModel>) {
    j::Project<1>(params, j::Radial(params + 3, u, v), pixel, d_pixel_d_uv,
                  d_pixel_d_params);
  } else if constexpr (std::is_same_v<CameraModel, colmap::OpenCVCameraModel>) {
    j::Project<2>(params, j::OpenCV(params + 4, u, v), pixel, d_pixel_d_uv,
                  d_pixel_d_params);
  } else if constexpr (std::is_same_v<CameraModel,
                                      colmap::FullOpenCVCameraModel>) {
    j::Project<2>(params, j::FullOpenCV(params + 4, u, v), pixel, d_pixel_d_uv,
                  d_pixel_d_params);
  } else if constexpr (std::is_same_v<CameraModel,
                                      colmap::OpenCVFisheyeCameraModel>) {
    j::Project<2>(params, j::OpenCVFisheye(params + 4, u, v), pixel,
                  d_pixel_d_uv, d_pixel_d_params);
  } else {
    constexpr int kNumParams = static_cast<int>(CameraModel::kNumParams);
    if (d_pixel_d_params != nullptr) {
      j::ProjectWithJets<CameraModel, 2 + kNumParams>(
          params, u, v, pixel, d_pixel_d_uv, d_pixel_d_params);
    } else {
      j::ProjectWithJets<CameraModel, 2>(params, u, v, pixel, d_pixel_d_uv,
                                         nullptr);
    }
  }
}

// The reprojection residual r = pi_theta(p_x / p_z, p_y / p_z) - observed of
// a point p in the camera frame, and, with `d_pixel_d_cam` given, its
// Jacobian over p,
//   dr/dp = dpi/d(u,v) [1/z, 0, -u/z; 0, 1/z, -v/z],
// and over theta into `d_pixel_d_params` (when given). False, nothing
// written, for a point not in front of the camera (p_z <= 0): an invalid
// evaluation for the solvers, not a NaN. The rig costs' shared last step
// (rig_reprojection_cost.h, timed_rig_reprojection_cost.h).
template <typename CameraModel>
bool ProjectCameraPoint(const double* params, const Eigen::Vector3d& point_in_cam,
                        const Eigen::Vector2d& observed, double* residuals,
                        Eigen::Matrix<double, 2, 3>* d_pixel_d_cam,
                        double* d_pixel_d_params) {
  const double z = point_in_cam.z();
  if (!(z > 0)) return false;
  const double u = point_in_cam.x() / z;
  const double v = point_in_cam.y() / z;
  if (d_pixel_d_cam == nullptr) {
    CameraModel::WorldToImage(params, u, v, &residuals[0], &residuals[1]);
  } else {
    Eigen::Matrix2d d_pixel_d_uv;
    ProjectWithJacobians<CameraModel>(params, u, v, residuals, &d_pixel_d_uv,
                                      d_pixel_d_params);
    d_pixel_d_cam->col(0) = d_pixel_d_uv.col(0) / z;
    d_pixel_d_cam->col(1) = d_pixel_d_uv.col(1) / z;
    d_pixel_d_cam->col(2) =
        -(u * d_pixel_d_uv.col(0) + v * d_pixel_d_uv.col(1)) / z;
  }
  residuals[0] -= observed.x();
  residuals[1] -= observed.y();
  return true;
}

}  // namespace rig_calibrator
