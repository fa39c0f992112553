#include "src/calibration/time_offsets_from_rotations.h"

#include <algorithm>
#include <cmath>

#include <colmap/util/math.h>

#include "src/geometry/pose_interpolation.h"
#include "src/geometry/rigid3d.h"

namespace rig_calibrator {
namespace {

// Iterations of the reweighted rotation mean (step 2): from the medoid the
// weights settle in a few; 20 leave the profile smooth to well below the
// golden-section tolerance.
constexpr int kMeanIterations = 20;
// The medoid counts the samples within this many loss scales.
constexpr double kMedoidScales = 10.0;
// The data's own Cauchy scale (step 5): 3 times the median residual angle
// at the best offset (for Gaussian noise of sigma per axis the angle's
// median is 1.54 sigma, so about 4.6 sigma: inliers stay in the loss's
// quadratic part).
constexpr double kDataScaleFactor = 3.0;
// 1 / golden ratio.
constexpr double kInverseGolden = 0.6180339887498949;

// The reference orientation as pieces of PoseTrajectory (step 1), each with
// the range of times it interpolates.
struct OrientationPieces {
  std::vector<PoseTrajectory> pieces;

  // The piece whose knot range holds t, or -1.
  int PieceAt(double t) const {
    for (size_t k = 0; k < pieces.size(); ++k) {
      if (t >= pieces[k].StartTime() && t <= pieces[k].EndTime()) {
        return static_cast<int>(k);
      }
    }
    return -1;
  }

  // cam_from_world rotation of the reference at t on piece k.
  Eigen::Quaterniond At(int k, double t) const {
    return pieces[k].Evaluate(t).world_from_body.rotation.conjugate();
  }
};

// The reference orientations that the other cameras agree with (step 1).
// For camera c the samples Y_f = R_{c,f} R_{ref,f}^T are Q_c up to the rig's
// rotation during delta_c, at most w_hi * search_range_s (w_hi: 1.2 times
// the 90th percentile of the reference's chord speeds below the rate gate);
// within that tolerance of the sample agreeing with most others a frameset
// agrees. A reference orientation is kept unless most of the cameras that
// have an orientation in its frameset disagree there (then it, or most of
// them, is a wrong localization; with the reference alone all are kept).
std::vector<char> AgreedReferenceOrientations(
    const RotationTimeOffsetProblem& problem,
    const RotationTimeOffsetOptions& options) {
  const auto& times = problem.frameset_times_s;
  const auto& reference = problem.cam_from_world[problem.reference_camera];
  const int num_framesets = static_cast<int>(times.size());
  std::vector<double> chord_speeds;
  for (int f = 0; f + 1 < num_framesets; ++f) {
    if (!reference[f] || !reference[f + 1]) continue;
    const double speed = RotationDifferenceRad(*reference[f], *reference[f + 1]) /
                         (times[f + 1] - times[f]);
    if (speed <= options.max_angular_speed_rad_s) chord_speeds.push_back(speed);
  }
  double high_speed = options.max_angular_speed_rad_s;
  if (!chord_speeds.empty()) {
    std::sort(chord_speeds.begin(), chord_speeds.end());
    high_speed = 1.2 * chord_speeds[std::min(
        chord_speeds.size() - 1,
        static_cast<size_t>(0.9 * chord_speeds.size()))];
  }
  const double tolerance =
      high_speed * options.search_range_s + kMedoidScales * options.loss_scale_rad;
  std::vector<int> agree(num_framesets, 0), disagree(num_framesets, 0);
  for (size_t c = 0; c < problem.cam_from_world.size(); ++c) {
    if (static_cast<int>(c) == problem.reference_camera) continue;
    std::vector<int> framesets;
    std::vector<Eigen::Quaterniond> samples;
    for (int f = 0; f < num_framesets; ++f) {
      if (!reference[f] || !problem.cam_from_world[c][f]) continue;
      framesets.push_back(f);
      samples.push_back(*problem.cam_from_world[c][f] * reference[f]->conjugate());
    }
    const int n = static_cast<int>(samples.size());
    int best = 0, best_count = -1;
    for (int i = 0; i < n; ++i) {
      int count = 0;
      for (int j = 0; j < n; ++j) {
        count += RotationDifferenceRad(samples[i], samples[j]) < tolerance;
      }
      if (count > best_count) best = i, best_count = count;
    }
    for (int j = 0; j < n; ++j) {
      (RotationDifferenceRad(samples[best], samples[j]) < tolerance
           ? agree : disagree)[framesets[j]]++;
    }
  }
  std::vector<char> kept(num_framesets, 0);
  for (int f = 0; f < num_framesets; ++f) {
    kept[f] = reference[f].has_value() && disagree[f] <= agree[f];
  }
  return kept;
}

OrientationPieces BuildOrientationPieces(
    const std::vector<double>& times,
    const std::vector<std::optional<Eigen::Quaterniond>>& reference,
    const std::vector<char>& kept, double max_gap) {
  std::vector<double> knot_times;
  std::vector<Rigid3d> knots;
  for (size_t f = 0; f < times.size(); ++f) {
    if (!kept[f]) continue;
    knot_times.push_back(times[f]);
    // world_from_reference, at the origin: only the rotation is used.
    knots.emplace_back(reference[f]->conjugate(), Eigen::Vector3d::Zero());
  }
  OrientationPieces result;
  result.pieces = PiecewisePoseTrajectories(knot_times, knots, max_gap);
  return result;
}

// One camera's samples: its orientation and the piece of its frameset time.
struct CameraSamples {
  std::vector<double> times;
  std::vector<int> pieces;
  std::vector<Eigen::Quaterniond> rotations;
};

// The profile of step 2 at delta; `mean` and `angles` receive Q and the
// angles of X_f Q^T.
double Profile(const CameraSamples& samples, const OrientationPieces& reference,
               double delta, double loss_scale, Eigen::Quaterniond* mean,
               std::vector<double>* angles) {
  const int n = static_cast<int>(samples.times.size());
  std::vector<Eigen::Quaterniond> x(n);
  for (int i = 0; i < n; ++i) {
    x[i] = samples.rotations[i] *
           reference.At(samples.pieces[i], samples.times[i] + delta).conjugate();
  }
  const double b2 = loss_scale * loss_scale;
  int best = 0, best_count = -1;
  for (int i = 0; i < n; ++i) {
    int count = 0;
    for (int j = 0; j < n; ++j) {
      count += RotationDifferenceRad(x[i], x[j]) < kMedoidScales * loss_scale;
    }
    if (count > best_count) best = i, best_count = count;
  }
  Eigen::Quaterniond q = x[best];
  angles->assign(n, 0.0);
  for (int iteration = 0; iteration <= kMeanIterations; ++iteration) {
    Eigen::Vector4d sum = Eigen::Vector4d::Zero();
    for (int i = 0; i < n; ++i) {
      const double a = RotationDifferenceRad(q, x[i]);
      (*angles)[i] = a;
      const double sign = q.coeffs().dot(x[i].coeffs()) < 0 ? -1.0 : 1.0;
      sum += sign / (1.0 + a * a / b2) * x[i].coeffs();
    }
    if (iteration == kMeanIterations) break;
    q.coeffs() = sum.normalized();
  }
  double cost = 0.0;
  for (double a : *angles) cost += std::log1p(a * a / b2);
  *mean = q;
  return cost / n;
}

bool ValidateRotationProblem(const RotationTimeOffsetProblem& problem,
                             const RotationTimeOffsetOptions& options,
                             std::string* error) {
  const auto& times = problem.frameset_times_s;
  const int num_cameras = static_cast<int>(problem.cam_from_world.size());
  if (problem.reference_camera < 0 || problem.reference_camera >= num_cameras) {
    *error = "time offsets from rotations: reference camera " +
             std::to_string(problem.reference_camera) + " is not one of the " +
             std::to_string(num_cameras) + " cameras";
    return false;
  }
  if (times.size() < 2) {
    *error = "time offsets from rotations: fewer than two framesets";
    return false;
  }
  for (size_t f = 0; f < times.size(); ++f) {
    if (!std::isfinite(times[f]) || (f > 0 && !(times[f] > times[f - 1]))) {
      *error = "time offsets from rotations: frameset times must be finite "
               "and strictly increasing (frameset " + std::to_string(f) + ")";
      return false;
    }
  }
  for (int c = 0; c < num_cameras; ++c) {
    if (problem.cam_from_world[c].size() != times.size()) {
      *error = "time offsets from rotations: camera " + std::to_string(c) +
               " has " + std::to_string(problem.cam_from_world[c].size()) +
               " framesets, the times " + std::to_string(times.size());
      return false;
    }
    for (const auto& rotation : problem.cam_from_world[c]) {
      if (rotation && !(rotation->coeffs().allFinite() &&
                        rotation->coeffs().norm() > 0)) {
        *error = "time offsets from rotations: a rotation of camera " +
                 std::to_string(c) + " is not finite";
        return false;
      }
    }
  }
  if (!(options.search_range_s > 0) || !(options.coarse_step_s > 0) ||
      !(options.coarse_step_s < options.search_range_s) ||
      !(options.tolerance_s > 0) || !(options.loss_scale_rad > 0) ||
      !(options.max_angular_speed_rad_s > 0) ||
      !(options.max_gap_intervals >= 1) || options.min_framesets < 3) {
    *error = "time offsets from rotations: options must be positive (the "
             "step below the search range), max_gap_intervals >= 1 and "
             "min_framesets >= 3";
    return false;
  }
  return true;
}

}  // namespace

bool EstimateTimeOffsetsFromRotations(
    const RotationTimeOffsetProblem& problem,
    const RotationTimeOffsetOptions& options,
    std::vector<RotationTimeOffset>* offsets, std::string* error) {
  if (!ValidateRotationProblem(problem, options, error)) return false;
  const auto& times = problem.frameset_times_s;
  const int num_cameras = static_cast<int>(problem.cam_from_world.size());
  const int ref = problem.reference_camera;
  std::vector<double> intervals;
  for (size_t f = 0; f + 1 < times.size(); ++f) {
    intervals.push_back(times[f + 1] - times[f]);
  }
  const OrientationPieces reference = BuildOrientationPieces(
      times, problem.cam_from_world[ref],
      AgreedReferenceOrientations(problem, options),
      options.max_gap_intervals * colmap::Median(intervals));

  offsets->assign(num_cameras, RotationTimeOffset());
  (*offsets)[ref].found = true;
  for (int c = 0; c < num_cameras; ++c) {
    if (c == ref) continue;
    RotationTimeOffset& result = (*offsets)[c];
    CameraSamples samples;
    for (size_t f = 0; f < times.size(); ++f) {
      const auto& rotation = problem.cam_from_world[c][f];
      // Within a piece at every offset searched: the profile then uses the
      // same framesets at every offset and never extrapolates.
      const int piece = reference.PieceAt(times[f] - options.search_range_s);
      if (!rotation || piece < 0 ||
          reference.PieceAt(times[f] + options.search_range_s) != piece) {
        continue;
      }
      samples.times.push_back(times[f]);
      samples.pieces.push_back(piece);
      samples.rotations.push_back(*rotation);
    }
    result.num_framesets = static_cast<int>(samples.times.size());
    if (result.num_framesets < options.min_framesets) {
      result.diagnosis = std::to_string(result.num_framesets) +
                         " framesets with an orientation on the reference's "
                         "trajectory, " + std::to_string(options.min_framesets) +
                         " needed";
      continue;
    }
    Eigen::Quaterniond mean;
    std::vector<double> angles;
    double loss_scale = options.loss_scale_rad;
    auto profile = [&](double delta) {
      return Profile(samples, reference, delta, loss_scale, &mean, &angles);
    };
    const int steps = static_cast<int>(
        std::floor(options.search_range_s / options.coarse_step_s));
    std::vector<double> costs;
    int best = 0;
    double minimum = 0.0;
    // Step 5: the search with the given scale, then again with the data's
    // own when their residuals are larger.
    for (int pass = 0; pass < 2; ++pass) {
      costs.clear();
      for (int k = -steps; k <= steps; ++k) {
        costs.push_back(profile(k * options.coarse_step_s));
      }
      best = static_cast<int>(
          std::min_element(costs.begin(), costs.end()) - costs.begin());
      // Golden-section search on [best - 1, best + 1] steps.
      double lo = (best - steps - 1) * options.coarse_step_s;
      double hi = (best - steps + 1) * options.coarse_step_s;
      double x1 = hi - kInverseGolden * (hi - lo);
      double x2 = lo + kInverseGolden * (hi - lo);
      double f1 = profile(x1), f2 = profile(x2);
      while (hi - lo > options.tolerance_s) {
        if (f1 < f2) {
          hi = x2, x2 = x1, f2 = f1;
          x1 = hi - kInverseGolden * (hi - lo);
          f1 = profile(x1);
        } else {
          lo = x1, x1 = x2, f1 = f2;
          x2 = lo + kInverseGolden * (hi - lo);
          f2 = profile(x2);
        }
      }
      result.offset_s = 0.5 * (lo + hi);
      minimum = profile(result.offset_s);
      result.cam_from_rig = mean;
      result.median_residual_rad = colmap::Median(angles);
      if (result.median_residual_rad <= loss_scale) break;
      loss_scale = kDataScaleFactor * result.median_residual_rad;
    }
    const double bound_cost = std::min(costs.front(), costs.back());
    if (best <= 1 || best + 2 >= static_cast<int>(costs.size())) {
      result.diagnosis = "the best offset is at the search range's bound";
    } else if (!(minimum <= 0.5 * bound_cost)) {
      result.diagnosis =
          "the orientations fit about as well at every offset (the rig does "
          "not turn, or turns at a constant rate)";
    } else {
      result.found = true;
    }
  }
  return true;
}

}  // namespace rig_calibrator
