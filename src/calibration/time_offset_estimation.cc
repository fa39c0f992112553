#include "src/calibration/time_offset_estimation.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/jet.h>
#include <ceres/loss_function.h>
#include <ceres/problem.h>
#include <ceres/rotation.h>
#include <ceres/solver.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include <colmap/util/math.h>

#include "src/geometry/pose_interpolation.h"

namespace rig_calibrator {
namespace {

// chi^2 quantile, 6 degrees of freedom, 99.9 %: the inlier test of a
// whitened residual block.
constexpr double kInlierChi2 = 22.46;
// Cauchy scale of the whitened refinement residual (a block norm of 4 has
// weight 1/2; an inlier's is about sqrt(6)).
constexpr double kRefinementLossScale = 4.0;
// The coarse offset's own error assumed by the consistency tolerance.
constexpr double kCoarseOffsetMargin_s = 0.005;
// Rounds of the refinement: with the stated noise, then with the residuals'
// scales (twice, so the frameset selection follows the refined offset).
constexpr int kRefinementRounds = 3;

double SpeedQuantile(std::vector<double> values, double q) {
  const size_t k = std::min(values.size() - 1,
                            static_cast<size_t>(q * values.size()));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[k];
}

// The speed of a camera between consecutive framesets (chord speeds), at
// the middle of the interval.
struct ChordSpeed {
  double time_s;
  double angular_rad_s;
  double linear;  // map units per second
};

std::vector<ChordSpeed> ChordSpeeds(
    const std::vector<double>& times,
    const std::vector<std::optional<Rigid3d>>& cam_from_world,
    double max_angular_speed) {
  std::vector<ChordSpeed> speeds;
  for (size_t f = 0; f + 1 < times.size(); ++f) {
    if (!cam_from_world[f] || !cam_from_world[f + 1]) continue;
    const double dt = times[f + 1] - times[f];
    const double angular =
        RotationDifferenceRad(cam_from_world[f]->rotation,
                              cam_from_world[f + 1]->rotation) / dt;
    if (angular > max_angular_speed) continue;
    const double linear =
        (cam_from_world[f + 1]->Center() - cam_from_world[f]->Center())
            .norm() / dt;
    speeds.push_back({0.5 * (times[f] + times[f + 1]), angular, linear});
  }
  return speeds;
}

// The rig's high speeds, bounds of its motion during an offset: per
// interval between consecutive framesets the median over cameras of their
// chord speeds (a wrong localization spoils one camera's), then the 90th
// percentile over intervals, times 1.2.
struct RigSpeeds {
  double angular_rad_s = 0.0;
  double linear = 0.0;
};

RigSpeeds HighRigSpeeds(
    const std::vector<double>& times,
    const std::vector<std::vector<std::optional<Rigid3d>>>& cam_from_world,
    const TimeOffsetOptions& options) {
  std::vector<double> angular, linear;
  for (size_t f = 0; f + 1 < times.size(); ++f) {
    std::vector<double> interval_angular, interval_linear;
    for (const auto& camera : cam_from_world) {
      for (const ChordSpeed& s : ChordSpeeds({times[f], times[f + 1]},
                                             {camera[f], camera[f + 1]},
                                             options.max_angular_speed_rad_s)) {
        interval_angular.push_back(s.angular_rad_s);
        interval_linear.push_back(s.linear);
      }
    }
    if (interval_angular.empty()) continue;
    angular.push_back(colmap::Median(interval_angular));
    linear.push_back(colmap::Median(interval_linear));
  }
  RigSpeeds speeds;
  if (angular.empty()) return speeds;
  speeds.angular_rad_s = 1.2 * SpeedQuantile(angular, 0.9);
  speeds.linear = 1.2 * SpeedQuantile(linear, 0.9);
  return speeds;
}

// The reference's angular speed at time t, interpolated between two
// consecutive chords (no more than max_spacing apart; false if none): a
// cubic Hermite with central-difference slopes where the neighbouring chords
// are present (error O(h^3) instead of linear interpolation's h^2/8 s''),
// else the chord's one-sided slope.
bool InterpolateSpeed(const std::vector<ChordSpeed>& speeds, double t,
                      double max_spacing, double* speed) {
  const auto upper = std::lower_bound(
      speeds.begin(), speeds.end(), t,
      [](const ChordSpeed& s, double time) { return s.time_s < time; });
  if (upper == speeds.end() || upper == speeds.begin()) return false;
  const int after = static_cast<int>(upper - speeds.begin());
  const int before = after - 1;
  const int n = static_cast<int>(speeds.size());
  auto consecutive = [&](int a, int b) {
    return a >= 0 && b < n && speeds[b].time_s - speeds[a].time_s <= max_spacing;
  };
  if (!consecutive(before, after)) return false;
  const double spacing = speeds[after].time_s - speeds[before].time_s;
  const double chord = (speeds[after].angular_rad_s - speeds[before].angular_rad_s) /
                       spacing;
  auto slope = [&](int k) {
    if (!consecutive(k - 1, k) || !consecutive(k, k + 1)) return chord;
    return (speeds[k + 1].angular_rad_s - speeds[k - 1].angular_rad_s) /
           (speeds[k + 1].time_s - speeds[k - 1].time_s);
  };
  const double s = (t - speeds[before].time_s) / spacing;
  const double s2 = s * s, s3 = s2 * s;
  *speed = (2 * s3 - 3 * s2 + 1) * speeds[before].angular_rad_s +
           (s3 - 2 * s2 + s) * spacing * slope(before) +
           (-2 * s3 + 3 * s2) * speeds[after].angular_rad_s +
           (s3 - s2) * spacing * slope(after);
  return true;
}

// Step 2 of the header: the offset minimizing the robust speed mismatch.
// False (offset 0) if the reference's angular speed hardly varies or the
// series do not overlap.
bool CoarseOffset(const std::vector<ChordSpeed>& camera,
                  const std::vector<ChordSpeed>& reference,
                  double frame_interval, const TimeOffsetOptions& options,
                  double* offset) {
  *offset = 0.0;
  if (camera.size() < 3 || reference.size() < 3) return false;
  std::vector<double> reference_speeds;
  for (const ChordSpeed& s : reference) reference_speeds.push_back(s.angular_rad_s);
  const double median_speed = colmap::Median(reference_speeds);
  std::vector<double> deviations;
  for (double s : reference_speeds) deviations.push_back(std::abs(s - median_speed));
  if (1.4826 * colmap::Median(deviations) < 0.5 * options.speed_loss_scale_rad_s) {
    return false;
  }
  const double b2 = options.speed_loss_scale_rad_s * options.speed_loss_scale_rad_s;
  const int min_overlap = std::max<int>(3, camera.size() / 2);
  const int steps =
      static_cast<int>(std::floor(options.search_range_s / options.coarse_step_s));
  std::vector<double> costs;
  for (int k = -steps; k <= steps; ++k) {
    const double delta = k * options.coarse_step_s;
    double sum = 0.0;
    int count = 0;
    for (const ChordSpeed& s : camera) {
      double reference_speed;
      if (!InterpolateSpeed(reference, s.time_s + delta, 1.5 * frame_interval,
                            &reference_speed)) {
        continue;
      }
      const double x = s.angular_rad_s - reference_speed;
      sum += std::log1p(x * x / b2);
      ++count;
    }
    costs.push_back(count >= min_overlap
                        ? sum / count
                        : std::numeric_limits<double>::infinity());
  }
  const int best = static_cast<int>(
      std::min_element(costs.begin(), costs.end()) - costs.begin());
  if (!std::isfinite(costs[best])) return false;
  double refinement = 0.0;
  if (best > 0 && best + 1 < static_cast<int>(costs.size()) &&
      std::isfinite(costs[best - 1]) && std::isfinite(costs[best + 1])) {
    const double curvature = costs[best - 1] - 2 * costs[best] + costs[best + 1];
    if (curvature > 0) {
      refinement = std::clamp(0.5 * (costs[best - 1] - costs[best + 1]) /
                                  curvature, -1.0, 1.0);
    }
  }
  *offset = (best - steps + refinement) * options.coarse_step_s;
  return true;
}

// Step 1's result for one camera.
struct InitialCamera {
  Rigid3d cam_from_rig;
  std::vector<char> consistent;  // per frameset: pair consistent with the reference
};

// Step 1 of the header. rotation_tolerance, position_tolerance_base: the
// rig's motion during the offset plus the noise (the lever arm term is added
// here).
InitialCamera InitializeCamera(
    const std::vector<std::optional<Rigid3d>>& camera,
    const std::vector<std::optional<Rigid3d>>& reference,
    double rotation_tolerance, double position_tolerance_base) {
  const int num_framesets = static_cast<int>(camera.size());
  std::vector<int> framesets;
  std::vector<Eigen::Quaterniond> rotations;  // cam_c from reference camera
  std::vector<Eigen::Vector3d> centers;       // camera c's centre, reference frame
  for (int f = 0; f < num_framesets; ++f) {
    if (!camera[f] || !reference[f]) continue;
    framesets.push_back(f);
    rotations.push_back(camera[f]->rotation * reference[f]->rotation.conjugate());
    centers.push_back(reference[f]->rotation *
                      (camera[f]->Center() - reference[f]->Center()));
  }
  InitialCamera result;
  result.consistent.assign(num_framesets, 0);
  if (framesets.empty()) return result;
  // The rotation agreeing with most others (at most 200 candidates).
  const int n = static_cast<int>(rotations.size());
  const int stride = std::max(1, n / 200);
  int best = 0, best_count = -1;
  for (int i = 0; i < n; i += stride) {
    int count = 0;
    for (int j = 0; j < n; ++j) {
      count += RotationDifferenceRad(rotations[i], rotations[j]) < rotation_tolerance;
    }
    if (count > best_count) best = i, best_count = count;
  }
  // Its neighbours' mean (sign-aligned quaternion sum: the chordal mean for
  // rotations this close).
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  std::vector<Eigen::Vector3d> agreeing_centers;
  for (int j = 0; j < n; ++j) {
    if (RotationDifferenceRad(rotations[best], rotations[j]) >= rotation_tolerance) {
      continue;
    }
    const double sign = rotations[best].coeffs().dot(rotations[j].coeffs()) < 0 ? -1 : 1;
    sum += sign * rotations[j].coeffs();
    agreeing_centers.push_back(centers[j]);
  }
  Eigen::Quaterniond rotation;
  rotation.coeffs() = sum.normalized();
  Eigen::Vector3d center;
  for (int k = 0; k < 3; ++k) {
    std::vector<double> coordinate;
    for (const Eigen::Vector3d& c : agreeing_centers) coordinate.push_back(c(k));
    center(k) = colmap::Median(coordinate);
  }
  result.cam_from_rig = Rigid3d(rotation, -(rotation * center));
  const double position_tolerance =
      position_tolerance_base + center.norm() * rotation_tolerance;
  for (int j = 0; j < n; ++j) {
    result.consistent[framesets[j]] =
        RotationDifferenceRad(rotation, rotations[j]) < rotation_tolerance &&
        (centers[j] - center).norm() < position_tolerance;
  }
  return result;
}

// The rig trajectory as pieces without long gaps.
struct RigTrajectory {
  std::vector<PoseTrajectory> pieces;

  // The piece whose range holds t, or null.
  const PoseTrajectory* PieceAt(double t) const {
    for (const PoseTrajectory& piece : pieces) {
      if (t >= piece.StartTime() && t <= piece.EndTime()) return &piece;
    }
    return nullptr;
  }
};

RigTrajectory BuildRigTrajectory(
    const std::vector<double>& times,
    const std::vector<std::optional<Rigid3d>>& reference,
    const std::vector<char>& is_knot, double max_gap) {
  std::vector<double> knot_times;
  std::vector<Rigid3d> knots;
  for (size_t f = 0; f < times.size(); ++f) {
    if (!is_knot[f]) continue;
    knot_times.push_back(times[f]);
    knots.push_back(reference[f]->Inverse());  // world_from_rig
  }
  RigTrajectory trajectory;
  trajectory.pieces = PiecewisePoseTrajectories(knot_times, knots, max_gap);
  return trajectory;
}

double ScalarValue(double x) { return x; }
template <int N>
double ScalarValue(const ceres::Jet<double, N>& x) {
  return x.a;
}

// The residual r_{c,f} of the header's step 4. Parameters: the rotation
// vector w of cam_from_rig's rotation, R_cr = Exp(w) R_cr0; p_c, the camera
// centre in the rig frame; delta_c.
//
// The trajectory is evaluated in double at t0 = t_f + delta (the value) and
// extended to first order in dt = delta - t0 + t_f, which is exactly what a
// Jet carries:  R_wr(t0 + dt) = Exp(w_world dt) R_wr(t0),
// c_rig(t0 + dt) = c_rig(t0) + v dt.
class OffsetResidual {
 public:
  OffsetResidual(const Rigid3d& observed_cam_from_world,
                 const Eigen::Matrix3d& initial_cam_from_rig_rotation,
                 const PoseTrajectory* trajectory, double frameset_time,
                 double rotation_sigma, double position_sigma)
      : observed_rotation_(observed_cam_from_world.RotationMatrix()),
        observed_center_(observed_cam_from_world.Center()),
        initial_rig_from_cam_rotation_(initial_cam_from_rig_rotation.transpose()),
        trajectory_(trajectory),
        frameset_time_(frameset_time),
        rotation_sigma_(rotation_sigma),
        position_sigma_(position_sigma) {}

  static ceres::CostFunction* Create(
      const Rigid3d& observed_cam_from_world,
      const Eigen::Matrix3d& initial_cam_from_rig_rotation,
      const PoseTrajectory* trajectory, double frameset_time,
      double rotation_sigma, double position_sigma) {
    return new ceres::AutoDiffCostFunction<OffsetResidual, 6, 3, 3, 1>(
        new OffsetResidual(observed_cam_from_world,
                           initial_cam_from_rig_rotation, trajectory,
                           frameset_time, rotation_sigma, position_sigma));
  }

  template <typename T>
  bool operator()(const T* rotation_update, const T* center_in_rig,
                  const T* offset, T* residuals) const {
    using Matrix3T = Eigen::Matrix<T, 3, 3>;
    using Vector3T = Eigen::Matrix<T, 3, 1>;
    const double t0 = frameset_time_ + ScalarValue(offset[0]);
    const PoseTrajectory::State state = trajectory_->Evaluate(t0);
    const T dt = offset[0] - T(ScalarValue(offset[0]));
    const Vector3T motion = state.angular_velocity_world.cast<T>() * dt;
    Matrix3T motion_rotation;
    ceres::AngleAxisToRotationMatrix(motion.data(), motion_rotation.data());
    const Matrix3T world_from_rig =
        motion_rotation * state.world_from_body.RotationMatrix().cast<T>();
    // R_obs R_pred^T = R_obs R_wr(t) R_cr0^T Exp(-w).
    const Vector3T inverse_update(-rotation_update[0], -rotation_update[1],
                                  -rotation_update[2]);
    Matrix3T update_inverse;
    ceres::AngleAxisToRotationMatrix(inverse_update.data(), update_inverse.data());
    const Matrix3T difference = observed_rotation_.cast<T>() * world_from_rig *
                                initial_rig_from_cam_rotation_.cast<T>() *
                                update_inverse;
    T rotation_residual[3];
    ceres::RotationMatrixToAngleAxis(difference.data(), rotation_residual);
    const Vector3T center(center_in_rig[0], center_in_rig[1], center_in_rig[2]);
    const Vector3T predicted_center =
        state.world_from_body.translation.cast<T>() +
        state.velocity.cast<T>() * dt + world_from_rig * center;
    for (int k = 0; k < 3; ++k) {
      residuals[k] = rotation_residual[k] / rotation_sigma_;
      residuals[3 + k] =
          (observed_center_(k) - predicted_center(k)) / position_sigma_;
    }
    return true;
  }

 private:
  const Eigen::Matrix3d observed_rotation_;
  const Eigen::Vector3d observed_center_;
  const Eigen::Matrix3d initial_rig_from_cam_rotation_;
  const PoseTrajectory* trajectory_;
  const double frameset_time_;
  const double rotation_sigma_;
  const double position_sigma_;
};

// Parameters of one camera's refinement.
struct CameraParameters {
  Eigen::Matrix3d initial_rotation;  // R_cr0
  double rotation_update[3] = {0, 0, 0};
  double center_in_rig[3] = {0, 0, 0};
  double offset = 0;

  Rigid3d CamFromRig() const {
    const Eigen::Matrix3d rotation =
        ExpSO3(Eigen::Vector3d(rotation_update[0], rotation_update[1],
                               rotation_update[2])) * initial_rotation;
    return Rigid3d(rotation,
                   -(rotation * Eigen::Vector3d(center_in_rig[0],
                                                center_in_rig[1],
                                                center_in_rig[2])));
  }
};

// The framesets of a camera whose time t_f + offset is on the trajectory,
// with their cost functions.
struct SelectedResiduals {
  std::vector<int> framesets;
  std::vector<std::unique_ptr<ceres::CostFunction>> costs;
};

SelectedResiduals SelectResiduals(
    const std::vector<double>& times,
    const std::vector<std::optional<Rigid3d>>& camera,
    const RigTrajectory& trajectory, const CameraParameters& parameters,
    double rotation_sigma, double position_sigma) {
  SelectedResiduals selected;
  for (size_t f = 0; f < times.size(); ++f) {
    if (!camera[f]) continue;
    const PoseTrajectory* piece = trajectory.PieceAt(times[f] + parameters.offset);
    if (piece == nullptr) continue;
    selected.framesets.push_back(static_cast<int>(f));
    selected.costs.emplace_back(OffsetResidual::Create(
        *camera[f], parameters.initial_rotation, piece, times[f],
        rotation_sigma, position_sigma));
  }
  return selected;
}

// Residual blocks at the current parameters (6 values per block).
std::vector<Eigen::Matrix<double, 6, 1>> EvaluateResiduals(
    const SelectedResiduals& selected, const CameraParameters& parameters) {
  const double* blocks[3] = {parameters.rotation_update,
                             parameters.center_in_rig, &parameters.offset};
  std::vector<Eigen::Matrix<double, 6, 1>> residuals(selected.costs.size());
  for (size_t i = 0; i < selected.costs.size(); ++i) {
    selected.costs[i]->Evaluate(blocks, residuals[i].data(), nullptr);
  }
  return residuals;
}

bool SolveCamera(const SelectedResiduals& selected, double search_range,
                 CameraParameters* parameters) {
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::CauchyLoss loss(kRefinementLossScale);
  for (const auto& cost : selected.costs) {
    problem.AddResidualBlock(cost.get(), &loss, parameters->rotation_update,
                             parameters->center_in_rig, &parameters->offset);
  }
  problem.SetParameterLowerBound(&parameters->offset, 0, -search_range);
  problem.SetParameterUpperBound(&parameters->offset, 0, search_range);
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = 100;
  solver_options.function_tolerance = 1e-15;
  solver_options.parameter_tolerance = 1e-14;
  solver_options.gradient_tolerance = 1e-16;
  solver_options.logging_type = ceres::SILENT;
  solver_options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  return summary.IsSolutionUsable();
}

// Robust per-component scale, 1.4826 MAD (about 0), of the rotation (first)
// or position (second) halves of the blocks, in the units the blocks were
// whitened by `sigma`.
double RobustScale(const std::vector<Eigen::Matrix<double, 6, 1>>& residuals,
                   int half, double sigma) {
  std::vector<double> values;
  for (const auto& r : residuals) {
    for (int k = 0; k < 3; ++k) values.push_back(std::abs(r(3 * half + k)));
  }
  return 1.4826 * colmap::Median(values) * sigma;
}

// Steps 4 and 5 of the header for one (non-reference) camera.
void RefineCamera(const std::vector<double>& times,
                  const std::vector<std::optional<Rigid3d>>& camera,
                  const RigTrajectory& trajectory,
                  const TimeOffsetOptions& options, CameraParameters* parameters,
                  CameraTimeOffset* result) {
  double rotation_sigma = options.rotation_noise_rad;
  double position_sigma = options.position_noise;
  // Scales are kept above a millionth of the stated noise, so exact data
  // whiten to finite residuals.
  const double min_rotation_sigma = 1e-6 * options.rotation_noise_rad;
  const double min_position_sigma = 1e-6 * options.position_noise;
  SelectedResiduals selected;
  for (int round = 0; round < kRefinementRounds; ++round) {
    selected = SelectResiduals(times, camera, trajectory, *parameters,
                               rotation_sigma, position_sigma);
    if (static_cast<int>(selected.costs.size()) < options.min_framesets) {
      result->diagnosis = "only " + std::to_string(selected.costs.size()) +
                          " localized framesets on the rig trajectory (" +
                          std::to_string(options.min_framesets) + " needed)";
      return;
    }
    if (!SolveCamera(selected, options.search_range_s, parameters)) {
      result->diagnosis = "the refinement failed";
      return;
    }
    const auto residuals = EvaluateResiduals(selected, *parameters);
    rotation_sigma =
        std::max(RobustScale(residuals, 0, rotation_sigma), min_rotation_sigma);
    position_sigma =
        std::max(RobustScale(residuals, 1, position_sigma), min_position_sigma);
  }
  result->offset_s = parameters->offset;
  result->cam_from_rig = parameters->CamFromRig();

  // Inliers and their scales.
  selected = SelectResiduals(times, camera, trajectory, *parameters,
                             rotation_sigma, position_sigma);
  const auto residuals = EvaluateResiduals(selected, *parameters);
  std::vector<char> inlier(residuals.size(), 0);
  int num_inliers = 0;
  double rotation_sum = 0, position_sum = 0;
  for (size_t i = 0; i < residuals.size(); ++i) {
    if (residuals[i].squaredNorm() >= kInlierChi2) continue;
    inlier[i] = 1;
    ++num_inliers;
    rotation_sum += residuals[i].head<3>().squaredNorm() * rotation_sigma * rotation_sigma;
    position_sum += residuals[i].tail<3>().squaredNorm() * position_sigma * position_sigma;
  }
  result->num_framesets_used = num_inliers;
  if (num_inliers < options.min_framesets) {
    result->diagnosis = "only " + std::to_string(num_inliers) +
                        " framesets agree with the trajectory (" +
                        std::to_string(options.min_framesets) + " needed)";
    return;
  }
  const double dof_correction = 6.0 * num_inliers / (6.0 * num_inliers - 7.0);
  rotation_sigma = std::max(
      std::sqrt(rotation_sum / (3.0 * num_inliers) * dof_correction),
      min_rotation_sigma);
  position_sigma = std::max(
      std::sqrt(position_sum / (3.0 * num_inliers) * dof_correction),
      min_position_sigma);
  result->rotation_residual_rad = rotation_sigma;
  result->position_residual = position_sigma;

  // Normal equations of the whitened inlier residuals.
  selected = SelectResiduals(times, camera, trajectory, *parameters,
                             rotation_sigma, position_sigma);
  Eigen::Matrix<double, 7, 7> normal = Eigen::Matrix<double, 7, 7>::Zero();
  const double* blocks[3] = {parameters->rotation_update,
                             parameters->center_in_rig, &parameters->offset};
  for (size_t i = 0; i < selected.costs.size(); ++i) {
    if (!inlier[i]) continue;
    Eigen::Matrix<double, 6, 1> residual;
    Eigen::Matrix<double, 6, 3, Eigen::RowMajor> rotation_jacobian, center_jacobian;
    Eigen::Matrix<double, 6, 1> offset_jacobian;
    double* jacobians[3] = {rotation_jacobian.data(), center_jacobian.data(),
                            offset_jacobian.data()};
    selected.costs[i]->Evaluate(blocks, residual.data(), jacobians);
    Eigen::Matrix<double, 6, 7> jacobian;
    jacobian << rotation_jacobian, center_jacobian, offset_jacobian;
    normal += jacobian.transpose() * jacobian;
  }
  // Var(delta) = 1 / (the Schur complement of the camera's pose block).
  const Eigen::Matrix<double, 6, 6> pose_block = normal.topLeftCorner<6, 6>();
  const Eigen::Matrix<double, 6, 1> coupling = normal.block<6, 1>(0, 6);
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> pose_ldlt(pose_block);
  const double offset_information =
      normal(6, 6) - coupling.dot(pose_ldlt.solve(coupling));
  const bool well_conditioned =
      pose_ldlt.info() == Eigen::Success && std::isfinite(offset_information) &&
      offset_information > 1e-9 * normal(6, 6) && normal(6, 6) > 0;
  result->offset_sigma_s = well_conditioned
                               ? 1.0 / std::sqrt(offset_information)
                               : std::numeric_limits<double>::infinity();
  const bool at_bound =
      std::abs(result->offset_s) > options.search_range_s * (1 - 1e-6);
  if (!well_conditioned) {
    result->diagnosis =
        "the offset is not determined: the rig's motion does not change "
        "with time (no rotation or translation, or a constant screw)";
  } else if (at_bound) {
    result->diagnosis = "the offset reached the search range's bound";
  } else if (result->offset_sigma_s > options.max_observable_sigma_s) {
    result->diagnosis =
        "the offset's uncertainty exceeds max_observable_sigma_s: too little "
        "change in the rig's motion";
  } else {
    result->observable = true;
  }
}

bool ValidateProblem(const TimeOffsetProblem& problem,
                     const TimeOffsetOptions& options, std::string* error) {
  const auto& times = problem.frameset_times_s;
  const int num_cameras = static_cast<int>(problem.cam_from_world.size());
  if (num_cameras == 0) {
    *error = "time offsets: no cameras";
    return false;
  }
  if (problem.reference_camera < 0 || problem.reference_camera >= num_cameras) {
    *error = "time offsets: reference camera " +
             std::to_string(problem.reference_camera) + " is not one of the " +
             std::to_string(num_cameras) + " cameras";
    return false;
  }
  for (size_t f = 0; f < times.size(); ++f) {
    if (!std::isfinite(times[f]) || (f > 0 && !(times[f] > times[f - 1]))) {
      *error = "time offsets: frameset times must be finite and strictly "
               "increasing (frameset " + std::to_string(f) + ")";
      return false;
    }
  }
  for (int c = 0; c < num_cameras; ++c) {
    if (problem.cam_from_world[c].size() != times.size()) {
      *error = "time offsets: camera " + std::to_string(c) + " has " +
               std::to_string(problem.cam_from_world[c].size()) +
               " framesets, the times " + std::to_string(times.size());
      return false;
    }
    for (size_t f = 0; f < times.size(); ++f) {
      const auto& pose = problem.cam_from_world[c][f];
      if (pose && !(pose->rotation.coeffs().allFinite() &&
                    pose->rotation.coeffs().norm() > 0 &&
                    pose->translation.allFinite())) {
        *error = "time offsets: the pose of camera " + std::to_string(c) +
                 " in frameset " + std::to_string(f) + " is not finite";
        return false;
      }
    }
  }
  if (!(options.search_range_s > 0) || !(options.coarse_step_s > 0) ||
      !(options.max_angular_speed_rad_s > 0) ||
      !(options.speed_loss_scale_rad_s > 0) ||
      !(options.rotation_noise_rad > 0) || !(options.position_noise > 0) ||
      !(options.max_gap_intervals >= 1) || options.min_framesets < 3 ||
      !(options.max_observable_sigma_s > 0)) {
    *error = "time offsets: options must be positive (search range, step, "
             "speeds, noise, max_observable_sigma_s), max_gap_intervals >= 1 "
             "and min_framesets >= 3";
    return false;
  }
  int num_reference_poses = 0;
  for (const auto& pose : problem.cam_from_world[problem.reference_camera]) {
    num_reference_poses += pose.has_value();
  }
  if (num_reference_poses < options.min_framesets) {
    *error = "time offsets: only " + std::to_string(num_reference_poses) +
             " framesets have a localized reference camera, " +
             std::to_string(options.min_framesets) + " needed";
    return false;
  }
  return true;
}

}  // namespace

bool EstimateTimeOffsets(const TimeOffsetProblem& problem,
                         const TimeOffsetOptions& options,
                         std::vector<CameraTimeOffset>* offsets,
                         std::string* error) {
  if (!ValidateProblem(problem, options, error)) return false;
  const auto& times = problem.frameset_times_s;
  const int num_cameras = static_cast<int>(problem.cam_from_world.size());
  const int num_framesets = static_cast<int>(times.size());
  const int ref = problem.reference_camera;
  const auto& reference = problem.cam_from_world[ref];

  std::vector<double> intervals;
  for (int f = 0; f + 1 < num_framesets; ++f) intervals.push_back(times[f + 1] - times[f]);
  const double frame_interval = colmap::Median(intervals);

  // Step 1, first pass, before any offset is known (|delta_c| <= the search
  // range): the poses consistent with another camera's in their frameset.
  const RigSpeeds rig_speeds =
      HighRigSpeeds(times, problem.cam_from_world, options);
  auto initialize = [&](int c, double offset_bound) {
    const double noise_tolerance = 6 * std::sqrt(2.0);
    return InitializeCamera(
        problem.cam_from_world[c], reference,
        rig_speeds.angular_rad_s * offset_bound +
            noise_tolerance * options.rotation_noise_rad,
        rig_speeds.linear * offset_bound +
            noise_tolerance * options.position_noise);
  };
  std::vector<std::vector<std::optional<Rigid3d>>> trusted(
      num_cameras, std::vector<std::optional<Rigid3d>>(num_framesets));
  for (int c = 0; c < num_cameras; ++c) {
    if (c == ref) continue;
    const InitialCamera loose = initialize(c, options.search_range_s);
    for (int f = 0; f < num_framesets; ++f) {
      if (!loose.consistent[f]) continue;
      trusted[c][f] = problem.cam_from_world[c][f];
      trusted[ref][f] = reference[f];
    }
  }
  if (num_cameras == 1) trusted[ref] = reference;

  // Step 2 on the trusted poses, then step 1's second pass with the coarse
  // offsets: cam_from_rig and the reference knots.
  const std::vector<ChordSpeed> reference_speeds =
      ChordSpeeds(times, trusted[ref], options.max_angular_speed_rad_s);
  offsets->assign(num_cameras, CameraTimeOffset());
  std::vector<InitialCamera> initial(num_cameras);
  std::vector<char> is_knot(num_framesets, 0);
  for (int c = 0; c < num_cameras; ++c) {
    if (c == ref) continue;
    CameraTimeOffset& result = (*offsets)[c];
    const bool coarse_found = CoarseOffset(
        ChordSpeeds(times, trusted[c], options.max_angular_speed_rad_s),
        reference_speeds, frame_interval, options, &result.coarse_offset_s);
    initial[c] = initialize(c, coarse_found ? std::abs(result.coarse_offset_s) +
                                                  kCoarseOffsetMargin_s
                                            : options.search_range_s);
    for (int f = 0; f < num_framesets; ++f) {
      if (initial[c].consistent[f]) is_knot[f] = 1;
    }
  }
  if (num_cameras == 1) {
    for (int f = 0; f < num_framesets; ++f) is_knot[f] = reference[f].has_value();
  }
  const RigTrajectory trajectory = BuildRigTrajectory(
      times, reference, is_knot, options.max_gap_intervals * frame_interval);

  CameraTimeOffset& reference_result = (*offsets)[ref];
  reference_result.observable = true;
  for (const PoseTrajectory& piece : trajectory.pieces) {
    reference_result.num_framesets_used += piece.NumKnots();
  }
  for (int c = 0; c < num_cameras; ++c) {
    if (c == ref) continue;
    CameraTimeOffset& result = (*offsets)[c];
    CameraParameters parameters;
    parameters.initial_rotation = initial[c].cam_from_rig.RotationMatrix();
    const Eigen::Vector3d center = initial[c].cam_from_rig.Center();
    std::copy(center.data(), center.data() + 3, parameters.center_in_rig);
    parameters.offset = result.coarse_offset_s;
    result.cam_from_rig = initial[c].cam_from_rig;
    result.offset_s = result.coarse_offset_s;
    result.offset_sigma_s = std::numeric_limits<double>::infinity();
    RefineCamera(times, problem.cam_from_world[c], trajectory, options,
                 &parameters, &result);
  }
  return true;
}

}  // namespace rig_calibrator
