// Rigs and frames in the files of COLMAP >= 3.12 (rigs.txt/bin,
// frames.txt/bin), written next to a COLMAP 3.8 model so that current COLMAP
// opens it as a rig; COLMAP 3.8 ignores them.
//
// A rig has a reference sensor (its sensor_from_rig is the identity and is
// not stored) and other sensors with an optional sensor_from_rig. A frame is
// one instance of a rig: rig_from_world and the data (for cameras: image ids)
// taken then. COLMAP derives an image's pose as
// cam_from_world = sensor_from_rig * rig_from_world and ignores the pose in
// images.*, and it fails to read a model in which a registered image is in no
// frame.
//
// rigs.txt, one line per rig (single spaces, 17 significant digits):
//   RIG_ID NUM_SENSORS REF_TYPE REF_ID (TYPE ID HAS_POSE [QW QX QY QZ TX TY
//   TZ])*
// frames.txt, one line per frame:
//   FRAME_ID RIG_ID QW QX QY QZ TX TY TZ NUM_DATA (TYPE SENSOR_ID DATA_ID)*
// rigs.bin (little endian): u64 num_rigs, per rig u32 rig_id, u32 num_sensors,
//   [i32 ref_type, u32 ref_id], per other sensor i32 type, u32 id, u8 has_pose,
//   [f64 x 7].
// frames.bin: u64 num_frames, per frame u32 frame_id, u32 rig_id, f64 x 7,
//   u32 num_data, per data i32 type, u32 sensor_id, u64 data_id.
// Sensor types: CAMERA = 0, IMU = 1.
#pragma once

#include <colmap/base/reconstruction.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "src/geometry/rigid3d.h"

namespace rig_calibrator {

constexpr int kSensorCamera = 0;
constexpr int kSensorImu = 1;

struct ColmapSensorId {
  int type = kSensorCamera;
  uint32_t id = 0;  // for cameras, the camera id
};

struct ColmapRigSensor {
  ColmapSensorId sensor;
  std::optional<Rigid3d> sensor_from_rig;
};

struct ColmapRig {
  uint32_t rig_id = 0;
  ColmapSensorId ref_sensor;
  std::vector<ColmapRigSensor> sensors;  // without the reference sensor
};

struct ColmapFrameData {
  ColmapSensorId sensor;
  uint64_t data_id = 0;  // for cameras, the image id
};

struct ColmapFrame {
  uint32_t frame_id = 0;
  uint32_t rig_id = 0;
  Rigid3d rig_from_world;
  std::vector<ColmapFrameData> data;
};

struct ColmapRigsAndFrames {
  std::vector<ColmapRig> rigs;
  std::vector<ColmapFrame> frames;
};

// A calibrated rig inside a COLMAP 3.8 model.
struct ModelRig {
  std::vector<colmap::camera_t> camera_ids;  // per rig camera
  int reference_camera = 0;
  // Per rig camera, relative to the reference camera; unknown for cameras
  // that were not calibrated.
  std::vector<std::optional<Rigid3d>> cam_from_rig;
  struct Frame {
    Rigid3d rig_from_world;
    std::vector<colmap::image_t> image_ids;  // registered images of the frame
  };
  std::vector<Frame> frames;
};

// The rigs and frames of `model` with `rig`: one trivial rig per camera
// outside the rig (rig id = camera id) and one trivial frame per registered
// image outside the rig's frames (frame id = image id, COLMAP's legacy
// convention), one rig for the rig's cameras (id after every camera id) and
// one frame per rig frame (ids after every image id, so they never collide
// with the trivial frames). Fails if a rig frame holds an image that is not
// registered, of a camera outside the rig or of a camera without
// cam_from_rig, or that is already in another frame, or an image's pose in
// `model` differs from cam_from_rig * rig_from_world by more than 1e-9.
bool BuildRigsAndFrames(const colmap::Reconstruction& model,
                        const ModelRig& rig, ColmapRigsAndFrames* rigs_frames,
                        std::string* error);

// Writes rigs.txt and frames.txt, or rigs.bin and frames.bin, into `folder`.
bool WriteRigsAndFrames(const std::string& folder,
                        const ColmapRigsAndFrames& rigs_frames, bool binary,
                        std::string* error);

// Reads rigs.bin and frames.bin from `folder` if both exist, else rigs.txt
// and frames.txt.
bool ReadRigsAndFrames(const std::string& folder,
                       ColmapRigsAndFrames* rigs_frames, std::string* error);

}  // namespace rig_calibrator
