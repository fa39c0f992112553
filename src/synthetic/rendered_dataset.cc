#include "src/synthetic/rendered_dataset.h"

#include <colmap/base/camera_models.h>
#include <colmap/util/math.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "src/synthetic/ground_loop.h"
#include "src/synthetic/rig_presets.h"
#include "src/synthetic/rig_trajectory.h"

namespace rig_calibrator {
namespace {

// Closest a camera center may come to a surface.
constexpr double kMinClearance = 0.25;
// The rig walks an ellipse this much smaller than the map camera's.
constexpr double kRigWalkScale = 0.65;

Eigen::Vector3d PointOnWalk(const SceneWalk& walk, double scale, double phi,
                            double height) {
  return Eigen::Vector3d(
      walk.center.x() + scale * walk.radii.x() * std::cos(phi),
      walk.center.y() + scale * walk.radii.y() * std::sin(phi), height);
}

// `count` ellipse parameters phi in [0, 2 pi), spaced evenly in the cost
// sqrt(ds^2 + (12 m * dphi)^2): the heading follows phi, so on a long, thin
// ellipse (the street) views are spaced by distance along the sides and by
// turning angle at the ends, instead of turning 60 degrees between two views.
std::vector<double> EvenlySpacedAngles(const SceneWalk& walk, double scale,
                                       int count, double offset) {
  constexpr int kSteps = 20000;
  constexpr double kTurnWeightMeters = 12.0;
  std::vector<double> cumulative(kSteps + 1, 0.0);
  for (int k = 0; k < kSteps; ++k) {
    const double phi = (k + 0.5) * 2.0 * M_PI / kSteps;
    const double speed = scale * std::hypot(walk.radii.x() * std::sin(phi),
                                            walk.radii.y() * std::cos(phi));
    cumulative[k + 1] = cumulative[k] + std::hypot(speed, kTurnWeightMeters) *
                                            2.0 * M_PI / kSteps;
  }
  std::vector<double> angles;
  for (int i = 0; i < count; ++i) {
    const double target = (i + offset) / count * cumulative.back();
    const int k = static_cast<int>(
        std::upper_bound(cumulative.begin(), cumulative.end(), target) -
        cumulative.begin() - 1);
    const int step = std::min(std::max(k, 0), kSteps - 1);
    const double fraction =
        (target - cumulative[step]) / (cumulative[step + 1] - cumulative[step]);
    angles.push_back((step + fraction) * 2.0 * M_PI / kSteps);
  }
  return angles;
}

// world_from_body for the body frame (x forward, y left, z up) at `position`
// with heading (yaw about z), pitch (nose up positive) and roll (about x).
Rigid3d WorldFromBody(const Eigen::Vector3d& position, double yaw, double pitch,
                      double roll) {
  // Body y is left, so nose up is a negative rotation about y.
  const Eigen::Quaterniond rotation =
      Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
      Eigen::AngleAxisd(-pitch, Eigen::Vector3d::UnitY()) *
      Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
  return Rigid3d(rotation, position);
}

// body_from_cam of a camera looking along body x, image x to the right (body
// -y) and image y down (body -z).
Rigid3d BodyFromForwardCamera() {
  Eigen::Matrix3d rotation;
  rotation.col(0) = -Eigen::Vector3d::UnitY();
  rotation.col(1) = -Eigen::Vector3d::UnitZ();
  rotation.col(2) = Eigen::Vector3d::UnitX();
  return Rigid3d(rotation, Eigen::Vector3d::Zero());
}

// A body frame for a rig known only by its cam_from_rig poses: up is against
// the mean of the cameras' image-down axes (every preset's cameras are
// roughly upright), forward is the reference camera's viewing direction made
// horizontal, and the origin is the mean camera center.
Rigid3d BodyFromRig(const std::vector<Rigid3d>& cam_from_rig) {
  Eigen::Vector3d down_sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d center_sum = Eigen::Vector3d::Zero();
  for (const Rigid3d& pose : cam_from_rig) {
    down_sum += pose.rotation.conjugate() * Eigen::Vector3d::UnitY();
    center_sum += pose.Center();
  }
  const Eigen::Vector3d up = -down_sum.normalized();
  const Eigen::Vector3d view =
      cam_from_rig[0].rotation.conjugate() * Eigen::Vector3d::UnitZ();
  Eigen::Vector3d forward = view - view.dot(up) * up;
  if (forward.norm() < 1e-6) forward = up.unitOrthogonal();
  forward.normalize();
  const Eigen::Vector3d left = up.cross(forward);
  Eigen::Matrix3d body_from_rig_rotation;
  body_from_rig_rotation.row(0) = forward;
  body_from_rig_rotation.row(1) = left;
  body_from_rig_rotation.row(2) = up;
  const Eigen::Vector3d mean_center = center_sum / cam_from_rig.size();
  return Rigid3d(body_from_rig_rotation,
                 -(body_from_rig_rotation * mean_center));
}

// The map camera and its poses (plan->scene is set), drawing 4 phases.
bool PlanMapSequence(const RenderedDatasetOptions& options,
                     std::mt19937* random, RenderedDatasetPlan* plan,
                     std::string* error) {
  const SceneWalk& walk = plan->scene.walk();
  const bool indoors = options.scene == SceneType::kRoom;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto phase = [&]() { return 2.0 * M_PI * unit(*random); };

  plan->map_camera.SetCameraId(1);
  plan->map_camera.SetModelIdFromName("PINHOLE");
  plan->map_camera.SetWidth(options.map_width);
  plan->map_camera.SetHeight(options.map_height);
  plan->map_camera.SetParams({options.map_focal_length,
                              options.map_focal_length, 0.5 * options.map_width,
                              0.5 * options.map_height});

  // The map camera: heading outward (phi) plus a slow swing, pitch and roll
  // oscillations, indoors pitched more to cover floor and ceiling.
  const double yaw_phase = phase();
  const double pitch_phase = phase();
  const double roll_phase = phase();
  const double height_phase = phase();
  const double mean_pitch =
      indoors ? -colmap::DegToRad(3.0) : colmap::DegToRad(3.0);
  const double pitch_swing =
      indoors ? colmap::DegToRad(15.0) : colmap::DegToRad(8.0);
  const Rigid3d body_from_map_camera = BodyFromForwardCamera();
  const std::vector<double> map_angles =
      EvenlySpacedAngles(walk, 1.0, options.num_map_images, 0.0);
  for (int i = 0; i < options.num_map_images; ++i) {
    const double phi = map_angles[i];
    const Eigen::Vector3d position =
        PointOnWalk(walk, 1.0, phi,
                    walk.eye_height + 0.1 * std::sin(4.0 * phi + height_phase));
    if (!plan->scene.IsFree(position, kMinClearance)) {
      *error = "map camera " + std::to_string(i) + " would stand in a wall";
      return false;
    }
    const Rigid3d world_from_body = WorldFromBody(
        position,
        phi + colmap::DegToRad(30.0) * std::sin(2.0 * phi + yaw_phase),
        mean_pitch + pitch_swing * std::sin(5.0 * phi + pitch_phase),
        colmap::DegToRad(4.0) * std::sin(7.0 * phi + roll_phase));
    plan->map_image_names.push_back("map_" + FramesetName(i) + ".png");
    plan->map_cam_from_world.push_back(
        (world_from_body * body_from_map_camera).Inverse());
  }

  return true;
}

// Without a time model, the rig: the same loop as the map camera's, smaller,
// half a step out of phase, with random heading swings up to 45 degrees and
// tilts up to 8 degrees; 4 draws per frameset. Each frameset at one instant,
// its poses seconds apart.
bool PlanRigSequence(const RenderedDatasetOptions& options,
                     std::mt19937* random, RenderedDatasetPlan* plan,
                     std::string* error) {
  const SceneWalk& walk = plan->scene.walk();
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  plan->rig = MakeRigPreset(options.preset);
  const Rigid3d body_from_rig = BodyFromRig(plan->rig.cam_from_rig);
  const double rig_height =
      options.rig_height > 0 ? options.rig_height : walk.eye_height;
  const std::vector<double> rig_angles =
      EvenlySpacedAngles(walk, kRigWalkScale, options.num_framesets, 0.5);
  for (int j = 0; j < options.num_framesets; ++j) {
    const double phi = rig_angles[j];
    const double yaw =
        phi + colmap::DegToRad(45.0) * (2.0 * unit(*random) - 1.0);
    const double pitch = colmap::DegToRad(8.0) * (2.0 * unit(*random) - 1.0);
    const double roll = colmap::DegToRad(6.0) * (2.0 * unit(*random) - 1.0);
    const double height = rig_height + 0.1 * (2.0 * unit(*random) - 1.0);
    const Rigid3d world_from_body = WorldFromBody(
        PointOnWalk(walk, kRigWalkScale, phi, height), yaw, pitch, roll);
    const Rigid3d rig_from_world = (world_from_body * body_from_rig).Inverse();
    for (size_t c = 0; c < plan->rig.cam_from_rig.size(); ++c) {
      const Eigen::Vector3d center =
          (plan->rig.cam_from_rig[c] * rig_from_world).Center();
      if (!plan->scene.IsFree(center, kMinClearance)) {
        *error = "rig camera " + plan->rig.camera_names[c] + " of frameset " +
                 std::to_string(j) + " would stand in a wall: the " +
                 RigPresetName(options.preset) + " rig does not fit the " +
                 SceneTypeName(options.scene) + " scene";
        return false;
      }
    }
    plan->rig.rig_from_world.push_back(rig_from_world);
    plan->frameset_names.push_back(FramesetName(j));
  }
  return true;
}

// With a time model (options.time_model.frameset_rate_hz > 0; see the
// header): the rig walks the scene's walk loop, kRigWalkScale as large, on
// one continuous trajectory from a random point of it (1 draw, then the
// trajectory's 4 phases), with the offsets and line delays of
// DrawCaptureTimes (the dataset's seed). Fails when the loop alone turns
// faster than three quarters of the turn rate (the rest is the rig's
// look-around swing), or when a rig camera would stand in a wall when its
// top or bottom row is taken.
bool PlanRigWalk(const RenderedDatasetOptions& options, std::mt19937* random,
                 RenderedDatasetPlan* plan, std::string* error) {
  const SyntheticRigOptions& time_model = options.time_model;
  const SceneWalk& walk = plan->scene.walk();
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const GroundLoop loop(walk.center, kRigWalkScale * walk.radii,
                        2 * M_PI * unit(*random));
  const double loop_turn_rate_deg_s =
      RigTrajectory::LoopTurnRateDegS(loop, time_model.speed_m_s);
  if (loop_turn_rate_deg_s > 0.75 * time_model.max_turn_rate_deg_s) {
    *error = "walking the " + SceneTypeName(options.scene) +
             " scene's loop at " + std::to_string(time_model.speed_m_s) +
             " m/s turns at up to " + std::to_string(loop_turn_rate_deg_s) +
             " deg/s, more than three quarters of max_turn_rate_deg_s: use a "
             "larger scene (courtyard), a lower speed_m_s or a higher "
             "max_turn_rate_deg_s";
    return false;
  }
  RigGroundTruth& rig = plan->rig;
  rig = MakeRigPreset(options.preset);
  rig.body_from_rig = BodyFromRig(rig.cam_from_rig);
  MotionProfile motion = TimeModelMotion(
      time_model, MakePresetDefinition(options.preset, 0).motion);
  motion.height_m =
      options.rig_height > 0 ? options.rig_height : walk.eye_height;
  rig.trajectory.emplace(motion, time_model.speed_m_s,
                         time_model.max_turn_rate_deg_s, loop, random);
  SyntheticRigOptions draws = time_model;
  draws.seed = options.seed;
  DrawCaptureTimes(draws, &rig);
  for (int f = 0; f < options.num_framesets; ++f) {
    const double time_s = (f + 1) / time_model.frameset_rate_hz;
    rig.frameset_times_s.push_back(time_s);
    rig.rig_from_world.push_back(RigFromWorldAtTime(rig, time_s));
    plan->frameset_names.push_back(Timestamp(time_s));
  }
  for (int f = 0; f < options.num_framesets; ++f) {
    for (size_t c = 0; c < rig.cameras.size(); ++c) {
      const ImageCapture capture = CaptureOfImage(rig, static_cast<int>(c), f);
      const double bottom_row_y = rig.cameras[c].Height() - 0.5;
      for (const double y : {0.5, bottom_row_y}) {
        const Eigen::Vector3d center =
            capture.CamFromWorldAt(capture.RowTime(y)).Center();
        if (!plan->scene.IsFree(center, kMinClearance)) {
          *error = "rig camera " + rig.camera_names[c] + " of frameset " +
                   std::to_string(f) +
                   " would stand in a wall during its capture: the " +
                   RigPresetName(options.preset) + " rig does not fit the " +
                   SceneTypeName(options.scene) + " scene's loop";
          return false;
        }
      }
    }
  }
  return true;
}

}  // namespace

std::string Timestamp(double time_s) {
  return std::to_string(std::llround(time_s * 1e9));
}

bool RenderedDatasetOptions::Check(std::string* error) const {
  if (num_map_images < 3 || num_map_images > 100000) {
    *error = "num_map_images must be in [3, 100000]";
    return false;
  }
  if (num_framesets < 1 || num_framesets > 100000) {
    *error = "num_framesets must be in [1, 100000]";
    return false;
  }
  if (map_width < 16 || map_height < 16 || map_width > 20000 ||
      map_height > 20000) {
    *error = "the map image size must be in [16, 20000] pixels";
    return false;
  }
  if (!(map_focal_length > 1 && map_focal_length < 1e6)) {
    *error = "map_focal_length must be in (1, 1e6) pixels";
    return false;
  }
  if (!(rig_height >= 0 && rig_height < 100)) {
    *error = "rig_height must be in [0, 100) meters (0: the scene's)";
    return false;
  }
  // The time model's own checks, for this preset and number of framesets.
  SyntheticRigOptions time_options = time_model;
  time_options.preset = preset;
  time_options.num_framesets = num_framesets;
  if (!time_options.Check(error)) return false;
  const double quarter_period = 0.25 / time_model.frameset_rate_hz;
  bool offsets_fit = time_model.max_time_offset_s <= quarter_period;
  for (const double offset : time_model.time_offsets_s) {
    offsets_fit &= std::abs(offset) <= quarter_period;
  }
  if (time_model.frameset_rate_hz > 0 && !offsets_fit) {
    *error = "the time offsets (max_time_offset_s, time_offsets_s) must be "
             "within a quarter of the frameset period, " +
             std::to_string(quarter_period) +
             " s, for the framesets to be told apart by their time stamps";
    return false;
  }
  return true;
}

std::string RenderedDatasetPlan::RigImageName(int camera_index,
                                              int frameset_index) const {
  if (HasTimeModel()) {
    return rig.camera_names[camera_index] + "/" +
           Timestamp(rig.frameset_times_s[frameset_index] +
                     rig.time_offsets_s[camera_index]) +
           ".png";
  }
  return rig.camera_names[camera_index] + "/" + frameset_names[frameset_index] +
         ".png";
}

ImageCapture RenderedDatasetPlan::RigImageCapture(int camera_index,
                                                  int frameset_index) const {
  return CaptureOfImage(rig, camera_index, frameset_index);
}

double RenderedDatasetPlan::TimestampTolerance() const {
  // t_0 = 1 / frameset_rate_hz is the period.
  return 0.5e9 * rig.frameset_times_s[0];
}

bool PlanRenderedDataset(const RenderedDatasetOptions& options,
                         RenderedDatasetPlan* plan, std::string* error) {
  if (!options.Check(error)) return false;
  *plan = RenderedDatasetPlan();
  plan->scene = TexturedScene::Make(options.scene, options.seed);
  // One random stream: the map sequence's draws, then the rig's.
  std::mt19937 random(options.seed);
  if (!PlanMapSequence(options, &random, plan, error)) return false;
  return options.time_model.frameset_rate_hz > 0
             ? PlanRigWalk(options, &random, plan, error)
             : PlanRigSequence(options, &random, plan, error);
}

}  // namespace rig_calibrator
