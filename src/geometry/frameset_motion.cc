#include "src/geometry/frameset_motion.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "src/geometry/pose_interpolation.h"

namespace rig_calibrator {
namespace {

// Weights w_k[j] such that the k-th derivative at nodes[center] of the
// interpolating polynomial through (nodes[j], y_j) is sum_j w_k[j] y_j,
// k = 1..3 (zero rows above the polynomial's degree). From the Vandermonde
// system in s = (t - nodes[center]) / scale, scale the nodes' span, so that
// it stays well conditioned.
Eigen::Matrix<double, 3, Eigen::Dynamic> DerivativeWeights(
    const std::vector<double>& nodes, int center) {
  const int n = static_cast<int>(nodes.size());
  const double scale = nodes.back() - nodes.front();
  Eigen::MatrixXd vandermonde(n, n);
  for (int j = 0; j < n; ++j) {
    const double s = (nodes[j] - nodes[center]) / scale;
    for (int m = 0; m < n; ++m) vandermonde(j, m) = std::pow(s, m);
  }
  // Row m of V^-1 maps the values to the coefficient of s^m; the k-th
  // derivative in t at s = 0 is k! c_k / scale^k.
  const Eigen::MatrixXd inverse = vandermonde.inverse();
  Eigen::Matrix<double, 3, Eigen::Dynamic> weights =
      Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, n);
  double factorial = 1;
  for (int k = 1; k <= 3 && k < n; ++k) {
    factorial *= k;
    weights.row(k - 1) = inverse.row(k) * factorial / std::pow(scale, k);
  }
  return weights;
}

}  // namespace

bool ComputeFramesetMotions(
    const std::vector<double>& times_s,
    const std::vector<std::optional<Rigid3d>>& rig_from_world,
    std::vector<FramesetMotion>* motions, std::string* error) {
  if (times_s.size() != rig_from_world.size()) {
    *error = "frameset motion: " + std::to_string(times_s.size()) +
             " frameset times for " + std::to_string(rig_from_world.size()) +
             " framesets";
    return false;
  }
  std::vector<int> posed;
  for (size_t f = 0; f < rig_from_world.size(); ++f) {
    if (rig_from_world[f]) posed.push_back(static_cast<int>(f));
  }
  if (posed.size() < 2) {
    *error = "frameset motion: fewer than two framesets have a rig pose";
    return false;
  }
  const int n = static_cast<int>(posed.size());
  const int stencil = std::min(n, 5);
  motions->assign(times_s.size(), FramesetMotion{});
  for (int i = 0; i < n; ++i) {
    const int first = std::clamp(i - stencil / 2, 0, n - stencil);
    const Rigid3d world_from_rig = rig_from_world[posed[i]]->Inverse();
    const Eigen::Matrix3d rotation_t =
        world_from_rig.RotationMatrix().transpose();
    std::vector<double> nodes;
    for (int j = first; j < first + stencil; ++j) {
      nodes.push_back(times_s[posed[j]]);
    }
    const Eigen::Matrix<double, 3, Eigen::Dynamic> weights =
        DerivativeWeights(nodes, i - first);
    FramesetMotion& motion = (*motions)[posed[i]];
    for (int j = 0; j < stencil; ++j) {
      const Rigid3d knot = rig_from_world[posed[first + j]]->Inverse();
      const Eigen::Vector3d u =
          LogSO3(rotation_t * knot.RotationMatrix());
      const Eigen::Vector3d p =
          rotation_t * (knot.translation - world_from_rig.translation);
      for (int k = 0; k < 3; ++k) {
        for (int axis = 0; axis < 3; ++axis) {
          motion[3 * k + axis] += weights(k, j) * u(axis);
          motion[9 + 3 * k + axis] += weights(k, j) * p(axis);
        }
      }
    }
  }
  return true;
}

void UseFramesetVelocities(const std::vector<Eigen::Vector3d>& velocities,
                           std::vector<FramesetMotion>* motions) {
  if (velocities.size() != motions->size()) return;
  for (size_t f = 0; f < motions->size(); ++f) {
    for (int k = 0; k < 3; ++k) (*motions)[f][9 + k] = velocities[f](k);
  }
}

double FramesetVelocityPriorSigma(
    const std::vector<FramesetMotion>& motions,
    const std::vector<Eigen::Vector3d>& velocities,
    const std::vector<std::optional<Rigid3d>>& rig_from_world) {
  double sum_speed = 0, sum_deviation = 0;
  int count = 0;
  for (size_t f = 0; f < motions.size() && f < rig_from_world.size(); ++f) {
    if (!rig_from_world[f]) continue;
    const Eigen::Map<const Eigen::Vector3d> p1(&motions[f][9]);
    sum_speed += p1.squaredNorm();
    if (velocities.size() == motions.size()) {
      sum_deviation += (velocities[f] - p1).squaredNorm();
    }
    ++count;
  }
  const double speed = count > 0 ? std::sqrt(sum_speed / count) : 0.0;
  if (!(speed > 0)) return 1.0;
  if (velocities.size() != motions.size()) return speed;
  return std::max(std::sqrt(sum_deviation / (3.0 * count)), 0.01 * speed);
}

}  // namespace rig_calibrator
