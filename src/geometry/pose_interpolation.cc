#include "src/geometry/pose_interpolation.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace rig_calibrator {
namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d skew;
  skew << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return skew;
}

// Weights of the derivative at nodes[at] of the Lagrange polynomial through
// (nodes[j], y_j): p'(nodes[at]) = sum_j weights[j] y_j, with
//   L_j'(x_a) = prod_{k != a, j} (x_a - x_k) / prod_{k != j} (x_j - x_k)
//   (j != a),   L_a'(x_a) = sum_{k != a} 1 / (x_a - x_k).
std::vector<double> LagrangeDerivativeWeights(const std::vector<double>& nodes,
                                              int at) {
  const int n = static_cast<int>(nodes.size());
  std::vector<double> weights(n, 0.0);
  const double x = nodes[at];
  for (int j = 0; j < n; ++j) {
    if (j == at) {
      for (int k = 0; k < n; ++k) {
        if (k != at) weights[j] += 1.0 / (x - nodes[k]);
      }
      continue;
    }
    double numerator = 1.0, denominator = 1.0;
    for (int k = 0; k < n; ++k) {
      if (k != j) denominator *= nodes[j] - nodes[k];
      if (k != j && k != at) numerator *= x - nodes[k];
    }
    weights[j] = numerator / denominator;
  }
  return weights;
}

bool IsFinite(const Rigid3d& pose) {
  return pose.rotation.coeffs().allFinite() &&
         pose.rotation.coeffs().norm() > 0.0 && pose.translation.allFinite();
}

}  // namespace

Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& rotation_vector) {
  const double angle = rotation_vector.norm();
  if (angle < 1e-8) {
    // Second order: the error, O(angle^3), is below rounding.
    const Eigen::Matrix3d skew = Skew(rotation_vector);
    return Eigen::Matrix3d::Identity() + skew + 0.5 * skew * skew;
  }
  return Eigen::AngleAxisd(angle, rotation_vector / angle).toRotationMatrix();
}

Eigen::Vector3d LogSO3(const Eigen::Matrix3d& rotation) {
  // Through the quaternion (w, v): angle 2 atan2(|v|, w) keeps full
  // precision at small angles, where acos((trace - 1) / 2) does not.
  Eigen::Quaterniond q(rotation);
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const double vector_norm = q.vec().norm();
  if (vector_norm < 1e-12) return 2.0 * q.vec() / q.w();
  return 2.0 * std::atan2(vector_norm, q.w()) / vector_norm * q.vec();
}

Eigen::Matrix3d RightJacobianSO3(const Eigen::Vector3d& rotation_vector) {
  const double angle = rotation_vector.norm();
  const Eigen::Matrix3d skew = Skew(rotation_vector);
  double a, b;  // (1 - cos)/angle^2, (angle - sin)/angle^3
  if (angle < 1e-4) {
    // Taylor series; the next terms are O(angle^4) relative.
    const double angle2 = angle * angle;
    a = 0.5 - angle2 / 24.0;
    b = 1.0 / 6.0 - angle2 / 120.0;
  } else {
    a = (1.0 - std::cos(angle)) / (angle * angle);
    b = (angle - std::sin(angle)) / (angle * angle * angle);
  }
  return Eigen::Matrix3d::Identity() - a * skew + b * skew * skew;
}

bool PoseTrajectory::Create(const std::vector<double>& times,
                            const std::vector<Rigid3d>& world_from_body,
                            PoseTrajectory* trajectory, std::string* error) {
  if (times.size() != world_from_body.size()) {
    *error = "pose trajectory: " + std::to_string(times.size()) +
             " times but " + std::to_string(world_from_body.size()) + " poses";
    return false;
  }
  if (times.size() < 2) {
    *error = "pose trajectory: needs at least two poses, got " +
             std::to_string(times.size());
    return false;
  }
  for (size_t i = 0; i < times.size(); ++i) {
    if (!std::isfinite(times[i]) || (i > 0 && !(times[i] > times[i - 1]))) {
      *error = "pose trajectory: times must be finite and strictly "
               "increasing (time " + std::to_string(i) + ")";
      return false;
    }
    if (!IsFinite(world_from_body[i])) {
      *error = "pose trajectory: pose " + std::to_string(i) +
               " is not finite or has a zero quaternion";
      return false;
    }
  }
  const int n = static_cast<int>(times.size());
  PoseTrajectory result;
  result.times_ = times;
  for (const Rigid3d& pose : world_from_body) {
    result.rotations_.push_back(pose.RotationMatrix());
    result.positions_.push_back(pose.translation);
  }
  // Knot derivatives from the five nearest knots (the window shifted inward
  // at the ends).
  const int stencil = std::min(n, 5);
  for (int i = 0; i < n; ++i) {
    const int first = std::clamp(i - stencil / 2, 0, n - stencil);
    std::vector<double> nodes(times.begin() + first,
                              times.begin() + first + stencil);
    const std::vector<double> weights =
        LagrangeDerivativeWeights(nodes, i - first);
    Eigen::Vector3d angular_rate = Eigen::Vector3d::Zero();
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    for (int j = 0; j < stencil; ++j) {
      const int knot = first + j;
      velocity += weights[j] * result.positions_[knot];
      if (knot != i) {
        angular_rate += weights[j] * LogSO3(result.rotations_[i].transpose() *
                                            result.rotations_[knot]);
      }
    }
    result.body_angular_rates_.push_back(angular_rate);
    result.velocities_.push_back(velocity);
  }
  *trajectory = std::move(result);
  return true;
}

PoseTrajectory::State PoseTrajectory::EvaluateSegment(int segment,
                                                      double t) const {
  const int i = segment;
  const double delta = times_[i + 1] - times_[i];
  const double s = (t - times_[i]) / delta;
  const double s2 = s * s, s3 = s2 * s;
  const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s;
  const double h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
  // Derivatives with respect to t (d/ds divided by delta).
  const double d00 = (6 * s2 - 6 * s) / delta, d10 = (3 * s2 - 4 * s + 1) / delta;
  const double d01 = (-6 * s2 + 6 * s) / delta, d11 = (3 * s2 - 2 * s) / delta;

  State state;
  const Eigen::Vector3d position =
      h00 * positions_[i] + h10 * delta * velocities_[i] +
      h01 * positions_[i + 1] + h11 * delta * velocities_[i + 1];
  state.velocity = d00 * positions_[i] + d10 * delta * velocities_[i] +
                   d01 * positions_[i + 1] + d11 * delta * velocities_[i + 1];

  const Eigen::Vector3d phi =
      LogSO3(rotations_[i].transpose() * rotations_[i + 1]);
  // The end tangent of u: w_{i+1} = Jr(phi) u'(t_{i+1}).
  const Eigen::Vector3d end_tangent =
      RightJacobianSO3(phi).inverse() * body_angular_rates_[i + 1];
  const Eigen::Vector3d u = h10 * delta * body_angular_rates_[i] + h01 * phi +
                            h11 * delta * end_tangent;
  const Eigen::Vector3d u_dot = d10 * delta * body_angular_rates_[i] +
                                d01 * phi + d11 * delta * end_tangent;
  const Eigen::Matrix3d rotation = rotations_[i] * ExpSO3(u);
  state.angular_velocity_world = rotation * (RightJacobianSO3(u) * u_dot);
  state.world_from_body = Rigid3d(rotation, position);
  return state;
}

PoseTrajectory::State PoseTrajectory::Evaluate(double t) const {
  const int last = NumKnots() - 1;
  if (t < times_.front() || t > times_.back()) {
    // Constant body angular velocity and linear velocity from the nearer end.
    const int end = t < times_.front() ? 0 : last;
    const double dt = t - times_[end];
    const Eigen::Matrix3d rotation =
        rotations_[end] * ExpSO3(body_angular_rates_[end] * dt);
    State state;
    state.world_from_body =
        Rigid3d(rotation, positions_[end] + velocities_[end] * dt);
    state.angular_velocity_world = rotation * body_angular_rates_[end];
    state.velocity = velocities_[end];
    return state;
  }
  // The segment [t_i, t_{i+1}] holding t (the last one for t = t_n).
  const int segment = std::clamp(
      static_cast<int>(std::upper_bound(times_.begin(), times_.end(), t) -
                       times_.begin()) - 1,
      0, last - 1);
  return EvaluateSegment(segment, t);
}

std::vector<PoseTrajectory> PiecewisePoseTrajectories(
    const std::vector<double>& times_s, const std::vector<Rigid3d>& poses,
    double max_gap_s) {
  std::vector<PoseTrajectory> pieces;
  size_t first = 0;
  for (size_t k = 1; k <= times_s.size(); ++k) {
    if (k < times_s.size() && times_s[k] - times_s[k - 1] <= max_gap_s) {
      continue;
    }
    // Knots [first, k) are one piece.
    PoseTrajectory piece;
    std::string unused;
    if (k - first >= 2 &&
        PoseTrajectory::Create(
            std::vector<double>(times_s.begin() + first, times_s.begin() + k),
            std::vector<Rigid3d>(poses.begin() + first, poses.begin() + k),
            &piece, &unused)) {
      pieces.push_back(std::move(piece));
    }
    first = k;
  }
  return pieces;
}

}  // namespace rig_calibrator
