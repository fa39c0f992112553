#include "src/synthetic/rig_motion.h"

#include <colmap/util/math.h>

#include <Eigen/Geometry>
#include <cmath>

namespace rig_calibrator {

std::vector<Rigid3d> MakeTrajectory(const MotionProfile& motion,
                                    int num_framesets, std::mt19937* rng) {
  std::uniform_real_distribution<double> phase_distribution(0, 2 * M_PI);
  const double yaw_phase = phase_distribution(*rng);
  const double pitch_phase = phase_distribution(*rng);
  const double roll_phase = phase_distribution(*rng);
  const double bob_phase = phase_distribution(*rng);
  std::vector<Rigid3d> world_from_body;
  Eigen::Vector3d position(0, 0, motion.height_m);
  for (int j = 0; j < num_framesets; ++j) {
    const double yaw = colmap::DegToRad(
        motion.yaw_amplitude_deg *
            std::sin(2 * M_PI * j / motion.yaw_period + yaw_phase) +
        motion.yaw_rate_deg * j);
    const double pitch = colmap::DegToRad(
        motion.pitch_amplitude_deg *
        std::sin(2 * M_PI * j / motion.pitch_period + pitch_phase));
    const double roll = colmap::DegToRad(
        motion.roll_amplitude_deg *
        std::sin(2 * M_PI * j / motion.roll_period + roll_phase));
    if (j > 0) {
      position.x() += motion.step_m * std::cos(yaw);
      position.y() += motion.step_m * std::sin(yaw);
    }
    position.z() = motion.height_m +
                   motion.bob_m * std::sin(2 * M_PI * j / 2.0 + bob_phase);
    // Body y is left and z up, so a positive pitch (nose up) is a negative
    // rotation about y.
    const Eigen::Matrix3d rotation =
        (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(-pitch, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
            .toRotationMatrix();
    world_from_body.emplace_back(rotation, position);
  }
  return world_from_body;
}

}  // namespace rig_calibrator
