#include "colmap_ext/io/rigs_frames_io.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

#include "colmap_ext/io/atomic_output.h"
#include "colmap_ext/io/binary_bytes.h"
#include "colmap_ext/io/map_reader.h"
#include "colmap_ext/io/name_table.h"
#include "colmap_ext/io/number_text.h"

namespace rig_calibrator {
namespace {

const NameTable<int>& SensorTypeNames() {
  static const NameTable<int> names = {{kSensorCamera, "CAMERA"},
                                       {kSensorImu, "IMU"}};
  return names;
}

std::string SensorTypeName(int type) {
  return NameOfValue(SensorTypeNames(), type, "INVALID");
}

bool SensorTypeFromName(const std::string& name, int* type) {
  return ValueFromName(SensorTypeNames(), name, type);
}

bool SameSensor(const ColmapSensorId& a, const ColmapSensorId& b) {
  return a.type == b.type && a.id == b.id;
}

// Poses as COLMAP writes them: precision 17, qw qx qy qz tx ty tz.
void WritePoseText(const Rigid3d& pose, std::ostream* stream) {
  *stream << pose.rotation.w() << " " << pose.rotation.x() << " "
          << pose.rotation.y() << " " << pose.rotation.z() << " "
          << pose.translation.x() << " " << pose.translation.y() << " "
          << pose.translation.z();
}

void AppendPoseBinary(const Rigid3d& pose, std::string* bytes) {
  for (const double value :
       {pose.rotation.w(), pose.rotation.x(), pose.rotation.y(),
        pose.rotation.z(), pose.translation.x(), pose.translation.y(),
        pose.translation.z()}) {
    AppendBinary<double>(value, bytes);
  }
}

// Sequential reading of a binary file with a sticky failure flag.
class BinaryReader {
 public:
  explicit BinaryReader(const std::string& bytes) : bytes_(bytes) {}
  template <typename T>
  T Read() {
    T value{};
    if (ok_ && offset_ + sizeof(T) <= bytes_.size()) {
      std::memcpy(&value, bytes_.data() + offset_, sizeof(T));
      offset_ += sizeof(T);
    } else {
      ok_ = false;
    }
    return value;
  }
  // The accessors of TokenReader, for ReadFrame.
  template <typename T>
  T NextInteger() {
    return Read<T>();
  }
  ColmapSensorId NextSensor() {
    ColmapSensorId sensor;
    sensor.type = Read<int32_t>();
    sensor.id = Read<uint32_t>();
    return sensor;
  }
  Rigid3d NextPose() {
    double v[7];
    for (double& value : v) value = Read<double>();
    return Rigid3d(Eigen::Quaterniond(v[0], v[1], v[2], v[3]),
                   Eigen::Vector3d(v[4], v[5], v[6]));
  }
  bool ok() const { return ok_; }
  bool AtEnd() const { return offset_ == bytes_.size(); }

 private:
  const std::string& bytes_;
  size_t offset_ = 0;
  bool ok_ = true;
};

bool ReadWholeFile(const std::string& path, std::string* bytes,
                   std::string* error) {
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    *error = "cannot open " + path;
    return false;
  }
  std::ostringstream contents;
  contents << file.rdbuf();
  *bytes = contents.str();
  return true;
}

// Whitespace-separated tokens of one data line, with typed accessors that
// record the first failure.
class TokenReader {
 public:
  explicit TokenReader(const std::string& line) {
    std::istringstream stream(line);
    std::string token;
    while (stream >> token) tokens_.push_back(token);
  }
  std::string Next() {
    if (next_ < tokens_.size()) return tokens_[next_++];
    ok_ = false;
    return "";
  }
  template <typename T>
  T NextInteger() {
    int64_t value = 0;
    if (!ParseInt64(Next(), &value) || value < 0 ||
        static_cast<uint64_t>(value) > std::numeric_limits<T>::max()) {
      ok_ = false;
    }
    return static_cast<T>(value);
  }
  double NextDouble() {
    double value = 0;
    if (!ParseDouble(Next(), &value)) ok_ = false;
    return value;
  }
  ColmapSensorId NextSensor() {
    ColmapSensorId sensor;
    if (!SensorTypeFromName(Next(), &sensor.type)) ok_ = false;
    sensor.id = NextInteger<uint32_t>();
    return sensor;
  }
  Rigid3d NextPose() {
    double v[7];
    for (double& value : v) value = NextDouble();
    return Rigid3d(Eigen::Quaterniond(v[0], v[1], v[2], v[3]),
                   Eigen::Vector3d(v[4], v[5], v[6]));
  }
  bool ok() const { return ok_; }
  bool AtEnd() const { return next_ == tokens_.size(); }

 private:
  std::vector<std::string> tokens_;
  size_t next_ = 0;
  bool ok_ = true;
};

// A frame record, the same fields in frames.txt and frames.bin: frame id, rig
// id, rig_from_world, the number of data, then per data its sensor and id.
// Reader: TokenReader or BinaryReader (check ok() after).
template <typename Reader>
ColmapFrame ReadFrame(Reader* reader) {
  ColmapFrame frame;
  frame.frame_id = reader->template NextInteger<uint32_t>();
  frame.rig_id = reader->template NextInteger<uint32_t>();
  frame.rig_from_world = reader->NextPose();
  const uint32_t num_data = reader->template NextInteger<uint32_t>();
  for (uint32_t d = 0; reader->ok() && d < num_data; ++d) {
    ColmapFrameData data;
    data.sensor = reader->NextSensor();
    data.data_id = reader->template NextInteger<uint64_t>();
    frame.data.push_back(data);
  }
  return frame;
}

// Calls `parse_line` for every data line of a text file (not blank, not a
// '#' comment) with its line number.
template <typename ParseLine>
bool ForEachDataLine(const std::string& path, ParseLine parse_line,
                     std::string* error) {
  std::ifstream file(path);
  if (!file) {
    *error = "cannot open " + path;
    return false;
  }
  std::string line;
  int line_number = 0;
  while (std::getline(file, line)) {
    ++line_number;
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    if (!parse_line(line, line_number)) return false;
  }
  return true;
}

bool ReadText(const std::string& folder, ColmapRigsAndFrames* rigs_frames,
              std::string* error) {
  const std::string rigs_path = folder + "/rigs.txt";
  const std::string frames_path = folder + "/frames.txt";
  auto fail = [error](const std::string& path, int line_number) {
    *error = "file " + path + " line " + std::to_string(line_number) +
             ": malformed line";
    return false;
  };
  if (!ForEachDataLine(
          rigs_path,
          [&](const std::string& line, int line_number) {
            TokenReader tokens(line);
            ColmapRig rig;
            rig.rig_id = tokens.NextInteger<uint32_t>();
            const uint32_t num_sensors = tokens.NextInteger<uint32_t>();
            if (num_sensors > 0) rig.ref_sensor = tokens.NextSensor();
            for (uint32_t s = 1; tokens.ok() && s < num_sensors; ++s) {
              ColmapRigSensor sensor;
              sensor.sensor = tokens.NextSensor();
              const std::string has_pose = tokens.Next();
              if (has_pose == "1") {
                sensor.sensor_from_rig = tokens.NextPose();
              } else if (has_pose != "0") {
                return fail(rigs_path, line_number);
              }
              rig.sensors.push_back(sensor);
            }
            if (!tokens.ok() || !tokens.AtEnd() || num_sensors == 0) {
              return fail(rigs_path, line_number);
            }
            rigs_frames->rigs.push_back(std::move(rig));
            return true;
          },
          error)) {
    return false;
  }
  return ForEachDataLine(
      frames_path,
      [&](const std::string& line, int line_number) {
        TokenReader tokens(line);
        ColmapFrame frame = ReadFrame(&tokens);
        if (!tokens.ok() || !tokens.AtEnd()) {
          return fail(frames_path, line_number);
        }
        rigs_frames->frames.push_back(std::move(frame));
        return true;
      },
      error);
}

bool ReadBinary(const std::string& folder, ColmapRigsAndFrames* rigs_frames,
                std::string* error) {
  const std::string rigs_path = folder + "/rigs.bin";
  const std::string frames_path = folder + "/frames.bin";
  std::string rigs_bytes;
  if (!ReadWholeFile(rigs_path, &rigs_bytes, error)) return false;
  BinaryReader rigs(rigs_bytes);
  const uint64_t num_rigs = rigs.Read<uint64_t>();
  for (uint64_t r = 0; rigs.ok() && r < num_rigs; ++r) {
    ColmapRig rig;
    rig.rig_id = rigs.Read<uint32_t>();
    const uint32_t num_sensors = rigs.Read<uint32_t>();
    if (num_sensors > 0) {
      rig.ref_sensor = rigs.NextSensor();
    }
    for (uint32_t s = 1; rigs.ok() && s < num_sensors; ++s) {
      ColmapRigSensor sensor;
      sensor.sensor = rigs.NextSensor();
      if (rigs.Read<uint8_t>() != 0) {
        sensor.sensor_from_rig = rigs.NextPose();
      }
      rig.sensors.push_back(sensor);
    }
    rigs_frames->rigs.push_back(std::move(rig));
  }
  if (!rigs.ok() || !rigs.AtEnd()) {
    *error = rigs_path + " is truncated or has trailing bytes";
    return false;
  }

  std::string frames_bytes;
  if (!ReadWholeFile(frames_path, &frames_bytes, error)) return false;
  BinaryReader frames(frames_bytes);
  const uint64_t num_frames = frames.Read<uint64_t>();
  for (uint64_t f = 0; frames.ok() && f < num_frames; ++f) {
    rigs_frames->frames.push_back(ReadFrame(&frames));
  }
  if (!frames.ok() || !frames.AtEnd()) {
    *error = frames_path + " is truncated or has trailing bytes";
    return false;
  }
  return true;
}

// The rigs: a trivial rig per camera outside the calibrated rig, sorted by id
// as COLMAP writes them, then the calibrated rig.
void AddRigs(const colmap::Reconstruction& model, const ModelRig& rig,
             const std::unordered_map<colmap::camera_t, int>& rig_camera_index,
             uint32_t calibrated_rig_id, ColmapRigsAndFrames* rigs_frames) {
  std::vector<colmap::camera_t> camera_ids;
  for (const auto& [camera_id, camera] : model.Cameras()) {
    if (rig_camera_index.count(camera_id) == 0) camera_ids.push_back(camera_id);
  }
  std::sort(camera_ids.begin(), camera_ids.end());
  for (const colmap::camera_t camera_id : camera_ids) {
    ColmapRig trivial;
    trivial.rig_id = camera_id;
    trivial.ref_sensor = {kSensorCamera, camera_id};
    rigs_frames->rigs.push_back(trivial);
  }
  ColmapRig calibrated;
  calibrated.rig_id = calibrated_rig_id;
  calibrated.ref_sensor = {kSensorCamera, rig.camera_ids[rig.reference_camera]};
  for (int c = 0; c < static_cast<int>(rig.camera_ids.size()); ++c) {
    if (c == rig.reference_camera) continue;
    calibrated.sensors.push_back(
        {{kSensorCamera, rig.camera_ids[c]}, rig.cam_from_rig[c]});
  }
  rigs_frames->rigs.push_back(calibrated);
}

// An image of a rig frame must be a registered image of a calibrated rig
// camera, in no other rig frame, with the stored pose cam_from_rig *
// rig_from_world.
bool CheckRigFrameImage(
    const colmap::Reconstruction& model, const ModelRig& rig,
    const std::unordered_map<colmap::camera_t, int>& rig_camera_index,
    const Rigid3d& rig_from_world, colmap::image_t image_id,
    std::unordered_set<colmap::image_t>* in_rig_frame, std::string* error) {
  if (!model.ExistsImage(image_id) || !model.IsImageRegistered(image_id)) {
    *error = "the rig frame image " + std::to_string(image_id) +
             " is not a registered image of the model";
    return false;
  }
  const colmap::Image& image = model.Image(image_id);
  const auto camera = rig_camera_index.find(image.CameraId());
  if (camera == rig_camera_index.end() || !rig.cam_from_rig[camera->second]) {
    *error = "the image " + image.Name() +
             " of a rig frame is not of a calibrated rig camera";
    return false;
  }
  if (!in_rig_frame->insert(image_id).second) {
    *error = "the image " + image.Name() + " is in two rig frames";
    return false;
  }
  // COLMAP >= 3.12 recomputes the pose from the frame; the model must
  // agree so that COLMAP 3.8 and later show the same poses.
  const Rigid3d expected = *rig.cam_from_rig[camera->second] * rig_from_world;
  const Rigid3d stored = Rigid3d::FromQvecTvec(image.Qvec(), image.Tvec());
  if ((expected.RotationMatrix() - stored.RotationMatrix()).norm() > 1e-9 ||
      (expected.translation - stored.translation).norm() >
          1e-9 * std::max(1.0, expected.translation.norm())) {
    *error = "the pose of the image " + image.Name() +
             " differs from cam_from_rig * rig_from_world";
    return false;
  }
  return true;
}

// The frames of the rig (ids max_image_id + 1, ...), their images sorted by
// camera id; *in_rig_frame gets their images.
bool MakeRigFrames(
    const colmap::Reconstruction& model, const ModelRig& rig,
    const std::unordered_map<colmap::camera_t, int>& rig_camera_index,
    colmap::image_t max_image_id, uint32_t rig_id,
    std::unordered_set<colmap::image_t>* in_rig_frame,
    std::vector<ColmapFrame>* rig_frames, std::string* error) {
  for (size_t f = 0; f < rig.frames.size(); ++f) {
    const ModelRig::Frame& rig_frame = rig.frames[f];
    if (rig_frame.image_ids.empty()) {
      *error = "a rig frame has no images";
      return false;
    }
    ColmapFrame frame;
    frame.frame_id = max_image_id + 1 + static_cast<colmap::image_t>(f);
    frame.rig_id = rig_id;
    frame.rig_from_world = rig_frame.rig_from_world;
    for (const colmap::image_t image_id : rig_frame.image_ids) {
      if (!CheckRigFrameImage(model, rig, rig_camera_index,
                              rig_frame.rig_from_world, image_id, in_rig_frame,
                              error)) {
        return false;
      }
      frame.data.push_back(
          {{kSensorCamera, model.Image(image_id).CameraId()}, image_id});
    }
    std::sort(frame.data.begin(), frame.data.end(),
              [](const ColmapFrameData& a, const ColmapFrameData& b) {
                return a.sensor.id < b.sensor.id;
              });
    rig_frames->push_back(std::move(frame));
  }
  return true;
}

// A trivial frame (id = image id) for every registered image outside the rig
// frames, sorted by id; fails for an image of a rig camera.
bool AddTrivialFrames(
    const colmap::Reconstruction& model,
    const std::unordered_map<colmap::camera_t, int>& rig_camera_index,
    const std::unordered_set<colmap::image_t>& in_rig_frame,
    ColmapRigsAndFrames* rigs_frames, std::string* error) {
  std::vector<colmap::image_t> image_ids = model.RegImageIds();
  std::sort(image_ids.begin(), image_ids.end());
  for (const colmap::image_t image_id : image_ids) {
    if (in_rig_frame.count(image_id) > 0) continue;
    const colmap::Image& image = model.Image(image_id);
    if (rig_camera_index.count(image.CameraId()) > 0) {
      *error = "the registered image " + image.Name() +
               " is of a rig camera but in no rig frame";
      return false;
    }
    ColmapFrame trivial;
    trivial.frame_id = image_id;
    trivial.rig_id = image.CameraId();
    trivial.rig_from_world = Rigid3d::FromQvecTvec(image.Qvec(), image.Tvec());
    trivial.data.push_back({{kSensorCamera, image.CameraId()}, image_id});
    rigs_frames->frames.push_back(std::move(trivial));
  }
  return true;
}

bool WriteRigsAndFramesBinary(const std::string& folder,
                              const ColmapRigsAndFrames& rigs_frames,
                              std::string* error) {
  std::string rigs;
  AppendBinary<uint64_t>(rigs_frames.rigs.size(), &rigs);
  for (const ColmapRig& rig : rigs_frames.rigs) {
    AppendBinary<uint32_t>(rig.rig_id, &rigs);
    AppendBinary<uint32_t>(static_cast<uint32_t>(rig.sensors.size() + 1),
                           &rigs);
    AppendBinary<int32_t>(rig.ref_sensor.type, &rigs);
    AppendBinary<uint32_t>(rig.ref_sensor.id, &rigs);
    for (const ColmapRigSensor& sensor : rig.sensors) {
      AppendBinary<int32_t>(sensor.sensor.type, &rigs);
      AppendBinary<uint32_t>(sensor.sensor.id, &rigs);
      AppendBinary<uint8_t>(sensor.sensor_from_rig ? 1 : 0, &rigs);
      if (sensor.sensor_from_rig) {
        AppendPoseBinary(*sensor.sensor_from_rig, &rigs);
      }
    }
  }
  std::string frames;
  AppendBinary<uint64_t>(rigs_frames.frames.size(), &frames);
  for (const ColmapFrame& frame : rigs_frames.frames) {
    AppendBinary<uint32_t>(frame.frame_id, &frames);
    AppendBinary<uint32_t>(frame.rig_id, &frames);
    AppendPoseBinary(frame.rig_from_world, &frames);
    AppendBinary<uint32_t>(static_cast<uint32_t>(frame.data.size()), &frames);
    for (const ColmapFrameData& data : frame.data) {
      AppendBinary<int32_t>(data.sensor.type, &frames);
      AppendBinary<uint32_t>(data.sensor.id, &frames);
      AppendBinary<uint64_t>(data.data_id, &frames);
    }
  }
  return WriteFileAtomically(folder + "/rigs.bin", rigs, error) &&
         WriteFileAtomically(folder + "/frames.bin", frames, error);
}

bool WriteRigsAndFramesText(const std::string& folder,
                            const ColmapRigsAndFrames& rigs_frames,
                            std::string* error) {
  std::ostringstream rigs;
  rigs.precision(17);
  rigs << "# Rig calib list with one line of data per calib:\n"
       << "#   RIG_ID, NUM_SENSORS, REF_SENSOR_TYPE, REF_SENSOR_ID, SENSORS[] "
          "as (SENSOR_TYPE, SENSOR_ID, HAS_POSE, [QW, QX, QY, QZ, TX, TY, "
          "TZ])\n"
       << "# Number of rigs: " << rigs_frames.rigs.size() << "\n";
  for (const ColmapRig& rig : rigs_frames.rigs) {
    rigs << rig.rig_id << " " << rig.sensors.size() + 1 << " "
         << SensorTypeName(rig.ref_sensor.type) << " " << rig.ref_sensor.id;
    for (const ColmapRigSensor& sensor : rig.sensors) {
      rigs << " " << SensorTypeName(sensor.sensor.type) << " "
           << sensor.sensor.id;
      if (sensor.sensor_from_rig) {
        rigs << " 1 ";
        WritePoseText(*sensor.sensor_from_rig, &rigs);
      } else {
        rigs << " 0";
      }
    }
    rigs << "\n";
  }
  std::ostringstream frames;
  frames.precision(17);
  frames << "# Frame list with one line of data per frame:\n"
         << "#   FRAME_ID, RIG_ID, RIG_FROM_WORLD[QW, QX, QY, QZ, TX, TY, TZ], "
            "NUM_DATA_IDS, DATA_IDS[] as (SENSOR_TYPE, SENSOR_ID, DATA_ID)\n"
         << "# Number of frames: " << rigs_frames.frames.size() << "\n";
  for (const ColmapFrame& frame : rigs_frames.frames) {
    frames << frame.frame_id << " " << frame.rig_id << " ";
    WritePoseText(frame.rig_from_world, &frames);
    frames << " " << frame.data.size();
    for (const ColmapFrameData& data : frame.data) {
      frames << " " << SensorTypeName(data.sensor.type) << " " << data.sensor.id
             << " " << data.data_id;
    }
    frames << "\n";
  }
  return WriteFileAtomically(folder + "/rigs.txt", rigs.str(), error) &&
         WriteFileAtomically(folder + "/frames.txt", frames.str(), error);
}

}  // namespace

bool BuildRigsAndFrames(const colmap::Reconstruction& model,
                        const ModelRig& rig, ColmapRigsAndFrames* rigs_frames,
                        std::string* error) {
  *rigs_frames = ColmapRigsAndFrames();
  const int num_rig_cameras = static_cast<int>(rig.camera_ids.size());
  if (num_rig_cameras == 0 || rig.reference_camera < 0 ||
      rig.reference_camera >= num_rig_cameras ||
      static_cast<int>(rig.cam_from_rig.size()) != num_rig_cameras) {
    *error =
        "the rig has no cameras, or its reference camera or poses do "
        "not match its cameras";
    return false;
  }
  std::unordered_map<colmap::camera_t, int> rig_camera_index;
  for (int c = 0; c < num_rig_cameras; ++c) {
    if (!model.ExistsCamera(rig.camera_ids[c]) ||
        !rig_camera_index.emplace(rig.camera_ids[c], c).second) {
      *error = "the rig camera id " + std::to_string(rig.camera_ids[c]) +
               " is not in the model or appears twice";
      return false;
    }
  }

  const colmap::camera_t max_camera_id = MaxCameraId(model);
  const colmap::image_t max_image_id = MaxImageId(model);
  if (static_cast<uint64_t>(max_camera_id) + 1 >=
          std::numeric_limits<uint32_t>::max() ||
      static_cast<uint64_t>(max_image_id) + rig.frames.size() >=
          std::numeric_limits<uint32_t>::max()) {
    *error = "the model's ids leave no room for the rig's rig and frame ids";
    return false;
  }
  const uint32_t calibrated_rig_id = max_camera_id + 1;
  AddRigs(model, rig, rig_camera_index, calibrated_rig_id, rigs_frames);
  // Rig frames first, to know which images they hold; they are listed after
  // the trivial frames.
  std::unordered_set<colmap::image_t> in_rig_frame;
  std::vector<ColmapFrame> rig_frames;
  if (!MakeRigFrames(model, rig, rig_camera_index, max_image_id,
                     calibrated_rig_id, &in_rig_frame, &rig_frames, error) ||
      !AddTrivialFrames(model, rig_camera_index, in_rig_frame, rigs_frames,
                        error)) {
    return false;
  }
  for (ColmapFrame& frame : rig_frames) {
    rigs_frames->frames.push_back(std::move(frame));
  }
  return true;
}

bool WriteRigsAndFrames(const std::string& folder,
                        const ColmapRigsAndFrames& rigs_frames, bool binary,
                        std::string* error) {
  for (const ColmapRig& rig : rigs_frames.rigs) {
    for (const ColmapRigSensor& sensor : rig.sensors) {
      if (SameSensor(sensor.sensor, rig.ref_sensor)) {
        *error = "the rig " + std::to_string(rig.rig_id) +
                 " lists its reference sensor twice";
        return false;
      }
    }
  }
  return binary ? WriteRigsAndFramesBinary(folder, rigs_frames, error)
                : WriteRigsAndFramesText(folder, rigs_frames, error);
}

bool ReadRigsAndFrames(const std::string& folder,
                       ColmapRigsAndFrames* rigs_frames, std::string* error) {
  *rigs_frames = ColmapRigsAndFrames();
  std::error_code ignored;
  if (std::filesystem::exists(folder + "/rigs.bin", ignored) &&
      std::filesystem::exists(folder + "/frames.bin", ignored)) {
    return ReadBinary(folder, rigs_frames, error);
  }
  return ReadText(folder, rigs_frames, error);
}

}  // namespace rig_calibrator
