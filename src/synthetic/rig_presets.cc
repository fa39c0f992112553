#include "src/synthetic/rig_presets.h"

#include <colmap/util/math.h>

#include <cmath>
#include <string>
#include <vector>

#include "src/synthetic/enum_names.h"

namespace rig_calibrator {
namespace {

constexpr EnumNameTable<RigPreset, 4> kRigPresetNames = {
    {{RigPreset::kRing5, "ring5"},
     {RigPreset::kFisheyeHelmet5, "fisheye_helmet5"},
     {RigPreset::kCarSurround4, "car_surround4"},
     {RigPreset::kStereoPair, "stereo_pair"}}};

// A camera of the given model, size and parameters at the body origin,
// looking forward.
CameraSpec MakeSpec(const std::string& model_name, int width, int height,
                    const std::vector<double>& params) {
  CameraSpec spec;
  spec.model_name = model_name;
  spec.width = width;
  spec.height = height;
  spec.params = params;
  return spec;
}

// Cameras evenly spaced on a horizontal ring, looking outwards.
void PlaceOnRing(double radius, std::vector<CameraSpec>* cameras) {
  const int num_cameras = cameras->size();
  for (int i = 0; i < num_cameras; ++i) {
    const double yaw_deg = 360.0 * i / num_cameras;
    CameraSpec& spec = (*cameras)[i];
    spec.yaw_deg = yaw_deg;
    spec.position.x() = radius * std::cos(colmap::DegToRad(yaw_deg));
    spec.position.y() = radius * std::sin(colmap::DegToRad(yaw_deg));
  }
}

// ring5, or its layout with num_cameras cameras (ring_num_cameras): camera i
// takes the parameters of ring5's camera i mod 5, its focal lengths scaled by
// 1 + 0.03 * (i / 5) so that no two cameras are alike.
PresetDefinition Ring(int num_cameras) {
  PresetDefinition preset;
  // fx, fy, cx, cy, k1, k2, p1, p2; principal points off the center
  // (320, 240) by up to 20 px in varied directions.
  const std::vector<std::vector<double>> params = {
      {420, 421, 332, 232, -0.30, 0.080, 4e-4, -3e-4},
      {445, 444, 302, 245, -0.32, 0.070, -5e-4, 2e-4},
      {405, 406, 324, 255, -0.28, 0.090, 2e-4, 5e-4},
      {432, 433, 313, 221, -0.31, 0.085, -3e-4, -4e-4},
      {412, 411, 339, 250, -0.29, 0.075, 5e-4, 1e-4}};
  const double pitch_deg[] = {2, -3, 1, -2, 3};
  const double roll_deg[] = {0, 1, -1, 0.5, -0.5};
  const double height_m[] = {0, 0.01, -0.005, 0.008, -0.01};
  for (int i = 0; i < num_cameras; ++i) {
    CameraSpec spec = MakeSpec("OPENCV", 640, 480, params[i % 5]);
    spec.params[0] *= 1 + 0.03 * (i / 5);
    spec.params[1] *= 1 + 0.03 * (i / 5);
    spec.pitch_deg = pitch_deg[i % 5];
    spec.roll_deg = roll_deg[i % 5];
    spec.position.z() = height_m[i % 5];
    preset.cameras.push_back(spec);
  }
  PlaceOnRing(0.15, &preset.cameras);
  preset.motion.height_m = 1.5;
  return preset;
}

// OPENCV_FISHEYE focal length that maps the given diagonal field of view
// onto the image diagonal: half_diagonal = f * theta_d(half_fov).
double FisheyeFocalForDiagonalFov(int width, int height, double fov_deg,
                                  const double* k) {
  const double theta = colmap::DegToRad(0.5 * fov_deg);
  const double theta2 = theta * theta;
  const double theta_d =
      theta *
      (1 + theta2 * (k[0] + theta2 * (k[1] + theta2 * (k[2] + theta2 * k[3]))));
  return 0.5 * std::hypot(width, height) / theta_d;
}

CameraSpec FisheyeCamera(int width, int height, double fov_deg,
                         const std::vector<double>& k, double fy_ratio,
                         double cx_offset, double cy_offset) {
  const double f = FisheyeFocalForDiagonalFov(width, height, fov_deg, k.data());
  return MakeSpec("OPENCV_FISHEYE", width, height,
                  {f, f * fy_ratio, 0.5 * width + cx_offset,
                   0.5 * height + cy_offset, k[0], k[1], k[2], k[3]});
}

PresetDefinition FisheyeHelmet5() {
  PresetDefinition preset;
  const double fov_deg[] = {150, 145, 155, 148, 152};
  const std::vector<std::vector<double>> k = {{0.020, -0.010, 0.003, -0.0005},
                                              {0.030, -0.012, 0.002, -0.0004},
                                              {0.015, -0.008, 0.004, -0.0006},
                                              {0.025, -0.011, 0.001, -0.0003},
                                              {0.018, -0.009, 0.003, -0.0005}};
  const double fy_ratio[] = {1.0, 1.001, 0.999, 1.0005, 0.9995};
  const double cx_offset[] = {6, -8, 3, -4, 9};
  const double cy_offset[] = {-5, 4, 8, -9, 2};
  const double pitch_deg[] = {15, -10, 12, -15, 10};
  for (int i = 0; i < 5; ++i) {
    CameraSpec spec = FisheyeCamera(640, 480, fov_deg[i], k[i], fy_ratio[i],
                                    cx_offset[i], cy_offset[i]);
    spec.pitch_deg = pitch_deg[i];
    spec.roll_deg = (i % 2 == 0 ? 1.5 : -1.0);
    spec.position.z() = 0.02 * std::sin(i);
    preset.cameras.push_back(spec);
  }
  PlaceOnRing(0.12, &preset.cameras);
  preset.motion.height_m = 1.7;
  return preset;
}

PresetDefinition CarSurround4() {
  PresetDefinition preset;
  // The body origin is on the ground below the car's center; the car is
  // 4.5 m long and 1.8 m wide.
  CameraSpec front = MakeSpec("OPENCV", 960, 600,
                              {420, 420.5, 488, 293, -0.25, 0.06, 3e-4, -2e-4});
  front.position = Eigen::Vector3d(2.25, 0.0, 0.6);
  front.pitch_deg = -12;

  const std::vector<double> k_left = {0.030, -0.010, 0.002, -0.0004};
  CameraSpec left = FisheyeCamera(800, 600, 160, k_left, 1.0, -7, 5);
  left.position = Eigen::Vector3d(0.9, 0.9, 1.0);
  left.yaw_deg = 90;
  left.pitch_deg = -30;

  CameraSpec back = MakeSpec("RADIAL", 640, 480, {380, 326, 236, -0.20, 0.04});
  back.position = Eigen::Vector3d(-2.25, 0.0, 1.1);
  back.yaw_deg = 180;
  back.pitch_deg = -20;

  const std::vector<double> k_right = {0.020, -0.008, 0.003, -0.0005};
  CameraSpec right = FisheyeCamera(800, 600, 160, k_right, 1.0005, 9, -6);
  right.position = Eigen::Vector3d(0.9, -0.9, 1.0);
  right.yaw_deg = -90;
  right.pitch_deg = -28;

  preset.cameras = {front, left, back, right};
  preset.motion.step_m = 1.5;
  preset.motion.height_m = 0;
  preset.motion.bob_m = 0.01;
  // The body bounces on its suspension at about 1.25 Hz (cars: 1-1.5 Hz),
  // 0.6 m/s^2 at its peak. One bob every 2 profile steps, as a walker's
  // gait, would shake it at 4.8 Hz and 9 m/s^2 when the profile is played
  // at 60 deg/s (0.1 s per step).
  preset.motion.bob_period_s = 0.8;
  preset.motion.yaw_amplitude_deg = 30;
  preset.motion.yaw_period = 40;
  preset.motion.yaw_rate_deg = 1.5;
  preset.motion.pitch_amplitude_deg = 2;
  preset.motion.roll_amplitude_deg = 2;
  return preset;
}

PresetDefinition StereoPair() {
  PresetDefinition preset;
  // EuRoC MAV cam0/cam1 intrinsics (OPENCV = pinhole + radtan).
  CameraSpec left = MakeSpec("OPENCV", 752, 480,
                             {458.654, 457.296, 367.215, 248.375, -0.28340811,
                              0.07395907, 0.00019359, 1.76187114e-05});
  CameraSpec right = left;
  right.params = {457.587,     456.134,    379.999,     255.238,
                  -0.28368365, 0.07451284, -0.00010473, -3.55590700e-05};
  // 0.11 m to the right (-y in the body frame), nearly parallel axes.
  right.position = Eigen::Vector3d(0.0005, -0.11, 0.0008);
  right.yaw_deg = 0.1;
  right.pitch_deg = -0.15;
  right.roll_deg = 0.05;
  preset.cameras = {left, right};
  preset.motion.height_m = 1.2;
  return preset;
}

PresetDefinition FixedPresetDefinition(RigPreset preset) {
  switch (preset) {
    case RigPreset::kRing5:
      return Ring(5);
    case RigPreset::kFisheyeHelmet5:
      return FisheyeHelmet5();
    case RigPreset::kCarSurround4:
      return CarSurround4();
    case RigPreset::kStereoPair:
      return StereoPair();
  }
  return Ring(5);
}

colmap::Camera MakeCamera(const std::string& model_name, int width, int height,
                          const std::vector<double>& params, int camera_id) {
  colmap::Camera camera;
  camera.SetCameraId(camera_id);
  camera.SetModelIdFromName(model_name);
  camera.SetWidth(width);
  camera.SetHeight(height);
  camera.SetParams(params);
  return camera;
}

}  // namespace

PresetDefinition MakePresetDefinition(RigPreset preset, int ring_num_cameras) {
  if (preset == RigPreset::kRing5 && ring_num_cameras > 0) {
    return Ring(ring_num_cameras);
  }
  return FixedPresetDefinition(preset);
}

Rigid3d BodyFromCamera(const CameraSpec& spec) {
  const double yaw = colmap::DegToRad(spec.yaw_deg);
  const double pitch = colmap::DegToRad(spec.pitch_deg);
  const double roll = colmap::DegToRad(spec.roll_deg);
  const Eigen::Vector3d forward(std::cos(pitch) * std::cos(yaw),
                                std::cos(pitch) * std::sin(yaw),
                                std::sin(pitch));
  const Eigen::Vector3d right0 =
      forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d down0 = forward.cross(right0);
  Eigen::Matrix3d body_from_cam_rotation;
  body_from_cam_rotation.col(0) =
      std::cos(roll) * right0 + std::sin(roll) * down0;
  body_from_cam_rotation.col(1) =
      -std::sin(roll) * right0 + std::cos(roll) * down0;
  body_from_cam_rotation.col(2) = forward;
  return Rigid3d(body_from_cam_rotation, spec.position);
}

void ReplicateStereoPair(int num_pairs, bool alternate_facing,
                         PresetDefinition* definition) {
  const std::vector<CameraSpec> pair = definition->cameras;
  definition->cameras.clear();
  for (int k = 0; k < num_pairs; ++k) {
    for (CameraSpec spec : pair) {
      spec.position.z() += 0.25 * k;
      if (alternate_facing && k % 2 == 1) {
        // Turned by 180 degrees about the vertical: left and right swap.
        spec.yaw_deg += 180;
        spec.position.x() = -0.3 - spec.position.x();
        spec.position.y() = -spec.position.y();
      }
      definition->cameras.push_back(spec);
    }
  }
}

RigGroundTruth TruthOfDefinition(const PresetDefinition& definition) {
  RigGroundTruth truth;
  const Rigid3d body_from_rig = BodyFromCamera(definition.cameras[0]);
  for (size_t i = 0; i < definition.cameras.size(); ++i) {
    const CameraSpec& spec = definition.cameras[i];
    truth.cameras.push_back(MakeCamera(spec.model_name, spec.width, spec.height,
                                       spec.params, i + 1));
    truth.cam_from_rig.push_back(
        i == 0 ? Rigid3d() : BodyFromCamera(spec).Inverse() * body_from_rig);
    truth.camera_names.push_back("cam" + std::to_string(i));
  }
  return truth;
}

bool RigPresetFromName(const std::string& name, RigPreset* preset) {
  return EnumFromName(kRigPresetNames, name, preset);
}

std::string RigPresetName(RigPreset preset) {
  return EnumName(kRigPresetNames, preset);
}

std::vector<RigPreset> AllRigPresets() { return EnumValues(kRigPresetNames); }

RigGroundTruth MakeRigPreset(RigPreset preset) {
  return TruthOfDefinition(MakePresetDefinition(preset, 0));
}

}  // namespace rig_calibrator
