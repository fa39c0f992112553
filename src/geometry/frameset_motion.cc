#include "src/geometry/frameset_motion.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>

#include "src/geometry/pose_interpolation.h"

namespace rig_calibrator {
namespace {

// Weights w_k[j] such that the k-th derivative at time `at` of the
// interpolating polynomial through (nodes[j], y_j) is sum_j w_k[j] y_j,
// k = 1..3 (zero rows above the polynomial's degree). From the Vandermonde
// system in s = (t - at) / scale, scale the nodes' span, so that it stays
// well conditioned.
Eigen::Matrix<double, 3, Eigen::Dynamic> DerivativeWeights(
    const std::vector<double>& nodes, double at) {
  const int n = static_cast<int>(nodes.size());
  const double scale = nodes.back() - nodes.front();
  Eigen::MatrixXd vandermonde(n, n);
  for (int j = 0; j < n; ++j) {
    const double s = (nodes[j] - at) / scale;
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

// The posed framesets (indices into the frameset list).
std::vector<int> PosedFramesets(
    const std::vector<std::optional<Rigid3d>>& rig_from_world) {
  std::vector<int> posed;
  for (size_t f = 0; f < rig_from_world.size(); ++f) {
    if (rig_from_world[f]) posed.push_back(static_cast<int>(f));
  }
  return posed;
}

constexpr int kStencil = 5;

// The knots of posed frameset posed[i]'s polynomial (see the header): the
// window of the kStencil nearest posed framesets, without posed[i] itself
// when `without_own_pose` and at least two others remain.
std::vector<int> Knots(const std::vector<int>& posed, int i,
                       bool without_own_pose) {
  const int n = static_cast<int>(posed.size());
  const int stencil = std::min(n, kStencil);
  const int first = std::clamp(i - stencil / 2, 0, n - stencil);
  std::vector<int> knots;
  for (int j = first; j < first + stencil; ++j) {
    if (j != i || !without_own_pose || stencil < 3) knots.push_back(posed[j]);
  }
  return knots;
}

// S^-1/2 = U diag(lambda)^-1/2 U^T for S = U diag(lambda) U^T, each
// eigenvalue at least `min_variance`.
Eigen::Matrix3d InverseSquareRoot(const Eigen::Matrix3d& covariance,
                                  double min_variance) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
  const Eigen::Vector3d inverse_deviation =
      eigen.eigenvalues().cwiseMax(min_variance).cwiseSqrt().cwiseInverse();
  return eigen.eigenvectors() * inverse_deviation.asDiagonal() *
         eigen.eigenvectors().transpose();
}

}  // namespace

bool ComputeFramesetMotions(
    const std::vector<double>& times_s,
    const std::vector<std::optional<Rigid3d>>& rig_from_world,
    std::vector<FramesetMotion>* motions, std::string* error,
    const std::vector<char>& without_own_pose,
    std::vector<TranslationStencil>* stencils) {
  if (times_s.size() != rig_from_world.size()) {
    *error = "frameset motion: " + std::to_string(times_s.size()) +
             " frameset times for " + std::to_string(rig_from_world.size()) +
             " framesets";
    return false;
  }
  if (!without_own_pose.empty() &&
      without_own_pose.size() != rig_from_world.size()) {
    *error = "frameset motion: " + std::to_string(without_own_pose.size()) +
             " own-pose flags for " + std::to_string(rig_from_world.size()) +
             " framesets";
    return false;
  }
  const std::vector<int> posed = PosedFramesets(rig_from_world);
  if (posed.size() < 2) {
    *error = "frameset motion: fewer than two framesets have a rig pose";
    return false;
  }
  motions->assign(times_s.size(), FramesetMotion{});
  if (stencils != nullptr) {
    stencils->resize(times_s.size());
    for (TranslationStencil& stencil : *stencils) {
      stencil.window.clear();
      stencil.own_slot = -1;
    }
  }
  for (size_t i = 0; i < posed.size(); ++i) {
    const int frameset = posed[i];
    const bool own_left_out =
        !without_own_pose.empty() && without_own_pose[frameset];
    const std::vector<int> knots =
        Knots(posed, static_cast<int>(i), own_left_out);
    const Rigid3d world_from_rig = rig_from_world[frameset]->Inverse();
    const Eigen::Matrix3d rotation_t =
        world_from_rig.RotationMatrix().transpose();
    std::vector<double> nodes;
    for (const int knot : knots) nodes.push_back(times_s[knot]);
    const Eigen::Matrix<double, 3, Eigen::Dynamic> weights =
        DerivativeWeights(nodes, times_s[frameset]);
    if (stencils != nullptr) {
      TranslationStencil& stencil = (*stencils)[frameset];
      stencil.window = Knots(posed, static_cast<int>(i), false);
      stencil.own_slot = static_cast<int>(
          std::find(stencil.window.begin(), stencil.window.end(), frameset) -
          stencil.window.begin());
      stencil.weights.setZero(2, static_cast<int>(stencil.window.size()));
      for (size_t j = 0; j < knots.size(); ++j) {
        const int slot = static_cast<int>(
            std::find(stencil.window.begin(), stencil.window.end(),
                      knots[j]) -
            stencil.window.begin());
        stencil.weights.col(slot) = weights.col(j).head<2>();
      }
    }
    FramesetMotion& motion = (*motions)[frameset];
    for (size_t j = 0; j < knots.size(); ++j) {
      const Rigid3d knot = rig_from_world[knots[j]]->Inverse();
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

std::vector<char> FramesetsWithoutOwnPose(
    const std::vector<double>& times_s,
    const std::vector<std::optional<Rigid3d>>& rig_from_world,
    const std::vector<std::vector<double>>& capture_offsets_s) {
  std::vector<char> without(rig_from_world.size(), 0);
  const std::vector<int> posed = PosedFramesets(rig_from_world);
  if (times_s.size() != rig_from_world.size() ||
      capture_offsets_s.size() != rig_from_world.size() || posed.size() < 3) {
    return without;
  }
  // The alternating pattern's gain, 8/3 mean (tau / Delta)^2 over every
  // image (Delta the median interval between posed framesets).
  std::vector<double> intervals;
  for (size_t i = 1; i < posed.size(); ++i) {
    intervals.push_back(times_s[posed[i]] - times_s[posed[i - 1]]);
  }
  std::nth_element(intervals.begin(),
                   intervals.begin() + intervals.size() / 2, intervals.end());
  const double interval = intervals[intervals.size() / 2];
  double sum_squares = 0;
  int count = 0;
  for (const int frameset : posed) {
    for (const double tau : capture_offsets_s[frameset]) {
      sum_squares += (tau / interval) * (tau / interval);
      ++count;
    }
  }
  const bool alternating_unstable =
      count > 0 && interval > 0 &&
      8.0 / 3.0 * sum_squares / count > kMaxOwnPoseGain;
  for (size_t i = 0; i < posed.size(); ++i) {
    const int frameset = posed[i];
    const std::vector<double>& offsets = capture_offsets_s[frameset];
    const std::vector<int> knots = Knots(posed, static_cast<int>(i), false);
    // The alternating pattern's gain above is that of a window centred on
    // the frameset; the ends keep their own pose unless its own gain says.
    if (alternating_unstable && knots[knots.size() / 2] == frameset) {
      without[frameset] = 1;
      continue;
    }
    if (offsets.empty()) continue;
    std::vector<double> nodes;
    int own = 0;
    for (size_t j = 0; j < knots.size(); ++j) {
      nodes.push_back(times_s[knots[j]]);
      if (knots[j] == frameset) own = static_cast<int>(j);
    }
    const Eigen::Vector3d w =
        DerivativeWeights(nodes, times_s[frameset]).col(own);
    double gain = 0;
    for (const double tau : offsets) {
      gain += w(0) * tau + w(1) * tau * tau / 2 + w(2) * tau * tau * tau / 6;
    }
    without[frameset] = std::abs(gain / offsets.size()) > kMaxOwnPoseGain;
  }
  return without;
}

void UseTranslationDerivatives(
    const std::vector<TranslationDerivatives>& estimates,
    std::vector<FramesetMotion>* motions) {
  if (estimates.size() != motions->size()) return;
  for (size_t f = 0; f < motions->size(); ++f) {
    for (int k = 0; k < 6; ++k) (*motions)[f][9 + k] = estimates[f](k);
  }
}

TranslationPrior EstimateTranslationPrior(
    const std::vector<FramesetMotion>& motions,
    const std::vector<TranslationDerivatives>& estimates,
    const std::vector<std::optional<Rigid3d>>& rig_from_world) {
  const size_t num_framesets = std::min(motions.size(), rig_from_world.size());
  const bool estimated = estimates.size() == motions.size();
  std::vector<TranslationDerivatives> deviations(num_framesets,
                                                 TranslationDerivatives::Zero());
  std::array<double, 2> sum_squared = {0, 0};
  int count = 0;
  for (size_t f = 0; f < num_framesets; ++f) {
    if (!rig_from_world[f]) continue;
    const Eigen::Map<const TranslationDerivatives> polynomial(&motions[f][9]);
    for (int k = 0; k < 2; ++k) {
      sum_squared[k] += polynomial.segment<3>(3 * k).squaredNorm();
    }
    if (estimated) deviations[f] = estimates[f] - polynomial;
    ++count;
  }
  TranslationPrior prior;
  for (int k = 0; k < 2; ++k) {
    const double rms = count > 0 ? std::sqrt(sum_squared[k] / count) : 0.0;
    if (!(rms > 0)) continue;
    const double min_variance = 0.01 * rms * 0.01 * rms;
    if (!estimated) {
      prior.whitening.block<3, 3>(3 * k, 3 * k) =
          Eigen::Matrix3d::Identity() / rms;
      prior.innovation_whitening.block<3, 3>(3 * k, 3 * k) =
          Eigen::Matrix3d::Identity() / rms;
      continue;
    }
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (size_t f = 0; f < num_framesets; ++f) {
      if (!rig_from_world[f]) continue;
      const Eigen::Vector3d d = deviations[f].segment<3>(3 * k);
      covariance += d * d.transpose();
    }
    covariance /= count;
    const Eigen::Matrix3d whitening =
        InverseSquareRoot(covariance, min_variance);
    prior.whitening.block<3, 3>(3 * k, 3 * k) = whitening;
    prior.innovation_whitening.block<3, 3>(3 * k, 3 * k) = whitening;
    // Phi = U diag(phi) U^T, phi_j along S_d's principal axis u_j: the
    // regression of u_j^T d_f on u_j^T d_(f-1) over the consecutive pairs.
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> axes(covariance);
    const Eigen::Matrix3d& to_axes = axes.eigenvectors();
    Eigen::Array3d lagged = Eigen::Array3d::Zero();
    Eigen::Array3d previous = Eigen::Array3d::Zero();
    int num_pairs = 0;
    for (size_t f = 1; f < num_framesets; ++f) {
      if (!rig_from_world[f] || !rig_from_world[f - 1]) continue;
      const Eigen::Array3d w =
          (to_axes.transpose() * deviations[f].segment<3>(3 * k)).array();
      const Eigen::Array3d w_previous =
          (to_axes.transpose() * deviations[f - 1].segment<3>(3 * k)).array();
      lagged += w * w_previous;
      previous += w_previous.square();
      ++num_pairs;
    }
    if (num_pairs < kMinTranslationPriorPairs) continue;
    // Negative only (see the header): a positive correlation is what the
    // prior's own smoothing of the estimates creates.
    const Eigen::Vector3d correlation =
        (lagged / (previous + num_pairs * min_variance))
            .cwiseMax(-kMaxTranslationPriorCorrelation)
            .cwiseMin(0.0)
            .matrix();
    const Eigen::Matrix3d gain =
        to_axes * correlation.asDiagonal() * to_axes.transpose();
    Eigen::Matrix3d innovations = Eigen::Matrix3d::Zero();
    for (size_t f = 1; f < num_framesets; ++f) {
      if (!rig_from_world[f] || !rig_from_world[f - 1]) continue;
      const Eigen::Vector3d innovation =
          deviations[f].segment<3>(3 * k) -
          gain * deviations[f - 1].segment<3>(3 * k);
      innovations += innovation * innovation.transpose();
    }
    prior.predecessor_gain.block<3, 3>(3 * k, 3 * k) = gain;
    prior.innovation_whitening.block<3, 3>(3 * k, 3 * k) =
        InverseSquareRoot(innovations / num_pairs, min_variance);
  }
  return prior;
}

}  // namespace rig_calibrator
