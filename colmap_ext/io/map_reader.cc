#include "colmap_ext/io/map_reader.h"

#include <colmap/base/camera_models.h>

#include <algorithm>
#include <boost/algorithm/string.hpp>
#include <boost/filesystem.hpp>
#include <cstdint>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <unordered_map>
#include <vector>

#include "colmap_ext/io/colmap_camera_models.h"
#include "colmap_ext/io/map_consistency.h"
#include "colmap_ext/io/model_unique_ids.h"
#include "colmap_ext/io/rigs_frames_io.h"

namespace rig_calibrator {
namespace {

namespace fs = boost::filesystem;

// Reads a binary model file record by record, with bounds: COLMAP 3.8's
// reader trusts every count and length in the file, so a file that is not a
// COLMAP model makes it abort (an unknown camera model id), allocate without
// bound (a huge point count) or loop forever (an image name without its
// terminating zero at the end of the file).
class BinaryWalker {
 public:
  BinaryWalker(const fs::path& file, std::string* error)
      : file_(file), error_(error) {
    size_ = fs::file_size(file);
    stream_.open(file.string(), std::ios::binary);
  }

  template <typename T>
  bool Read(T* value, const char* what) {
    if (!Has(sizeof(T), what)) return false;
    stream_.read(reinterpret_cast<char*>(value), sizeof(T));
    position_ += sizeof(T);
    return static_cast<bool>(stream_) ||
           Fail(std::string("cannot read ") + what);
  }

  // Skips `count` items of `item_size` bytes.
  bool Skip(uint64_t count, uint64_t item_size, const char* what) {
    if (item_size > 0 && count > (size_ - position_) / item_size) {
      return Fail(std::string(what) + " claims " + std::to_string(count) +
                  " entries, more than the " +
                  std::to_string(size_ - position_) + " bytes left can hold");
    }
    position_ += count * item_size;
    // ignore() reads through the stream's buffer; seekg() would drop it and
    // read it again for every record.
    stream_.ignore(static_cast<std::streamsize>(count * item_size));
    return static_cast<bool>(stream_) ||
           Fail(std::string("cannot read ") + what);
  }

  // Skips a zero-terminated string.
  bool SkipString(const char* what) {
    char c = 0;
    do {
      if (!Has(1, what)) return false;
      stream_.get(c);
      ++position_;
    } while (c != '\0');
    return true;
  }

  bool CheckEnd() {
    return position_ == size_ || Fail(std::to_string(size_ - position_) +
                                      " bytes follow the last record");
  }

  bool Fail(const std::string& message) {
    *error_ = file_.string() + " is not a COLMAP binary model file: " + message;
    return false;
  }

 private:
  bool Has(uint64_t num_bytes, const char* what) {
    return num_bytes <= size_ - position_ ||
           Fail(std::string("it ends inside ") + what);
  }

  fs::path file_;
  std::string* error_;
  std::ifstream stream_;
  uint64_t size_ = 0;
  uint64_t position_ = 0;
};

// A COLMAP binary file: a uint64 record count, the records, nothing after.
bool CheckBinaryRecords(const fs::path& file, const char* count_what,
                        const std::function<bool(BinaryWalker*)>& check_record,
                        std::string* error) {
  BinaryWalker walker(file, error);
  uint64_t count = 0;
  if (!walker.Read(&count, count_what)) return false;
  for (uint64_t i = 0; i < count; ++i) {
    if (!check_record(&walker)) return false;
  }
  return walker.CheckEnd();
}

// COLMAP 3.8 aborts (CHECK in Image::SetCameraId) on an image whose camera
// id is kInvalidCameraId, 2^32 - 1 (also what "-1" becomes in images.txt).
bool InvalidCameraIdError(const fs::path& file, std::string* error) {
  *error = file.string() + ": an image has the camera id " +
           std::to_string(colmap::kInvalidCameraId) +
           ", COLMAP's invalid id: give every image the id of a camera in "
           "cameras of the model";
  return false;
}

// Record layouts of COLMAP's Reconstruction::Write*Binary (3.8 to 4.1).
bool CheckImagesBinary(const fs::path& file, std::string* error) {
  return CheckBinaryRecords(
      file, "the image count",
      [&](BinaryWalker* walker) {
        uint64_t num_points2D = 0;
        uint32_t camera_id = 0;
        // id, qvec, tvec, camera id, name, points2D (x, y, point3D id).
        return walker->Skip(1, 4 + 7 * sizeof(double), "an image record") &&
               walker->Read(&camera_id, "an image's camera id") &&
               (camera_id != colmap::kInvalidCameraId ||
                InvalidCameraIdError(file, error)) &&
               walker->SkipString("an image name") &&
               walker->Read(&num_points2D, "a points2D count") &&
               walker->Skip(num_points2D, 2 * sizeof(double) + sizeof(uint64_t),
                            "an image's points2D");
      },
      error);
}

// images.txt read as COLMAP 3.8 does (a record line, then its points2D
// line; fields split at single spaces by std::getline): the CAMERA_ID that
// COLMAP parses with std::stoul and narrows to 32 bits must not be
// kInvalidCameraId. It is the 9th field, or for a shorter line the last one
// (std::getline on an exhausted stream leaves the previous field in place).
// Other malformed fields make COLMAP's parser throw, which ReadWithColmap
// reports.
bool CheckImagesText(const fs::path& file, std::string* error) {
  std::ifstream stream(file.string());
  std::string line;
  while (std::getline(stream, line)) {
    boost::trim(line);
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> fields;
    boost::split(fields, line, boost::is_any_of(" "));
    const std::string& camera_id =
        fields.size() > 8 ? fields[8] : fields.back();
    try {
      if (static_cast<uint32_t>(std::stoul(camera_id)) ==
          colmap::kInvalidCameraId) {
        return InvalidCameraIdError(file, error);
      }
    } catch (const std::exception&) {
      // Not a number: COLMAP's parser throws on it too.
    }
    std::getline(stream, line);
  }
  return true;
}

bool CheckPoints3DBinary(const fs::path& file, std::string* error) {
  return CheckBinaryRecords(
      file, "the point count",
      [](BinaryWalker* walker) {
        uint64_t track_length = 0;
        // id, xyz, rgb, error, track (image id, point2D index).
        return walker->Skip(1, 8 + 3 * sizeof(double) + 3 + sizeof(double),
                            "a point record") &&
               walker->Read(&track_length, "a track length") &&
               walker->Skip(track_length, 2 * sizeof(uint32_t),
                            "a point's track");
      },
      error);
}

// A folder under the system's temporary folder, removed with its contents
// when the object goes out of scope.
class TemporaryFolder {
 public:
  TemporaryFolder() {
    boost::system::error_code fs_error;
    path_ = fs::temp_directory_path(fs_error) /
            fs::unique_path("rig_calibrator_map_%%%%-%%%%-%%%%");
    created_ = fs::create_directories(path_, fs_error);
  }
  ~TemporaryFolder() {
    boost::system::error_code ignored;
    if (created_) fs::remove_all(path_, ignored);
  }
  TemporaryFolder(const TemporaryFolder&) = delete;
  TemporaryFolder& operator=(const TemporaryFolder&) = delete;
  bool created() const { return created_; }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
  bool created_ = false;
};

// The placeholder of a camera of a model COLMAP 3.8 does not know.
CameraRecord PlaceholderCamera(const CameraRecord& camera) {
  CameraRecord placeholder = camera;
  placeholder.model_id = colmap::PinholeCameraModel::model_id;
  const double focal =
      1.2 * static_cast<double>(std::max(camera.width, camera.height));
  placeholder.params = {focal, focal, 0.5 * camera.width, 0.5 * camera.height};
  return placeholder;
}

// Reads the model with COLMAP 3.8's reader, from a temporary folder with
// placeholder cameras (and links to the other files) if some cameras have
// models it does not know.
bool ReadWithColmap(const fs::path& folder, const bool binary,
                    const std::vector<CameraRecord>& cameras,
                    colmap::Reconstruction* map, MapReadInfo* info,
                    std::string* error) {
  std::vector<CameraRecord> readable = cameras;
  for (CameraRecord& camera : readable) {
    if (!colmap::ExistsCameraModelWithId(camera.model_id)) {
      info->newer_model_cameras.push_back(camera);
      camera = PlaceholderCamera(camera);
    }
  }
  const std::string extension = binary ? ".bin" : ".txt";
  std::optional<TemporaryFolder> temporary;
  fs::path read_folder = folder;
  if (!info->newer_model_cameras.empty()) {
    boost::system::error_code fs_error;
    temporary.emplace();
    if (!temporary->created()) {
      *error = "cannot create a temporary folder to read the map in " +
               folder.string();
      return false;
    }
    for (const std::string name : {"images", "points3D"}) {
      fs::create_symlink(fs::absolute(folder / (name + extension)),
                         temporary->path() / (name + extension), fs_error);
      if (fs_error) {
        *error = "cannot link " + (folder / (name + extension)).string() +
                 " into a temporary folder: " + fs_error.message();
        return false;
      }
    }
    if (!WriteCameraRecords(
            (temporary->path() / ("cameras" + extension)).string(), binary,
            readable, error)) {
      return false;
    }
    read_folder = temporary->path();
    std::string list;
    for (const CameraRecord& camera : info->newer_model_cameras) {
      list += (list.empty() ? "" : ", ") + std::to_string(camera.camera_id) +
              " " + DescribeColmapCameraModel(camera.model_id);
    }
    info->notes.push_back(
        "map camera(s) of models COLMAP 3.8 does not know: " + list +
        "; held as placeholders (localization does not use the map's "
        "intrinsics) and written back unchanged into the output model");
  }
  try {
    if (binary) {
      map->ReadBinary(read_folder.string());
    } else {
      map->ReadText(read_folder.string());
    }
  } catch (const std::exception& exception) {
    *error = "cannot read the map in " + folder.string() +
             " (not a COLMAP text model?): " + exception.what();
    return false;
  }
  return true;
}

// Checks the rigs and frames against the images (see map_reader.h) and
// summarizes them in `info`.
bool CheckRigsAndFrames(const std::string& path,
                        const colmap::Reconstruction& map,
                        const ColmapRigsAndFrames& rigs_frames,
                        MapReadInfo* info, std::string* error) {
  const std::string prefix = "the map in " + path + ": ";
  // sensor_from_rig of every camera sensor, by rig; the reference camera's
  // is the identity.
  std::map<uint32_t, std::unordered_map<uint32_t, std::optional<Rigid3d>>>
      camera_from_rig;
  for (const ColmapRig& rig : rigs_frames.rigs) {
    auto& cameras = camera_from_rig[rig.rig_id];
    int num_cameras = 0;
    if (rig.ref_sensor.type == kSensorCamera) {
      cameras[rig.ref_sensor.id] = Rigid3d();
      ++num_cameras;
    }
    for (const ColmapRigSensor& sensor : rig.sensors) {
      if (sensor.sensor.type != kSensorCamera) continue;
      cameras[sensor.sensor.id] = sensor.sensor_from_rig;
      ++num_cameras;
    }
    info->num_multi_camera_rigs += num_cameras > 1 ? 1 : 0;
  }
  std::unordered_map<colmap::image_t, int> num_frames_of_image;
  for (const ColmapFrame& frame : rigs_frames.frames) {
    const auto rig = camera_from_rig.find(frame.rig_id);
    if (rig == camera_from_rig.end()) {
      *error = prefix + "frame " + std::to_string(frame.frame_id) +
               " refers to rig " + std::to_string(frame.rig_id) +
               ", which is not in the rigs file";
      return false;
    }
    for (const ColmapFrameData& data : frame.data) {
      if (data.sensor.type != kSensorCamera) continue;
      const colmap::image_t image_id =
          static_cast<colmap::image_t>(data.data_id);
      ++num_frames_of_image[image_id];
      const auto sensor = rig->second.find(data.sensor.id);
      if (!map.ExistsImage(image_id) || sensor == rig->second.end() ||
          map.Image(image_id).CameraId() != data.sensor.id) {
        *error = prefix + "frame " + std::to_string(frame.frame_id) +
                 " holds image " + std::to_string(image_id) + " of camera " +
                 std::to_string(data.sensor.id) +
                 ", which is not an image of that camera of the model or not "
                 "a camera of rig " +
                 std::to_string(frame.rig_id);
        return false;
      }
      if (!sensor->second) continue;
      const colmap::Image& image = map.Image(image_id);
      const Rigid3d expected = *sensor->second * frame.rig_from_world;
      const Rigid3d stored = Rigid3d::FromQvecTvec(image.Qvec(), image.Tvec());
      if ((expected.RotationMatrix() - stored.RotationMatrix()).norm() > 1e-6 ||
          (expected.translation - stored.translation).norm() >
              1e-6 * std::max(1.0, expected.translation.norm())) {
        *error = prefix + "the pose of image " + image.Name() +
                 " differs from sensor_from_rig * rig_from_world of frame " +
                 std::to_string(frame.frame_id) +
                 ": the rigs/frames files do not belong to this model";
        return false;
      }
    }
  }
  for (const colmap::image_t image_id : map.RegImageIds()) {
    const auto count = num_frames_of_image.find(image_id);
    if (count == num_frames_of_image.end() || count->second != 1) {
      *error = prefix + "the image " + map.Image(image_id).Name() + " is in " +
               std::to_string(
                   count == num_frames_of_image.end() ? 0 : count->second) +
               " frames; COLMAP >= 3.12 needs every registered image in one "
               "frame";
      return false;
    }
  }
  info->has_rigs_frames = true;
  info->num_rigs = static_cast<int>(rigs_frames.rigs.size());
  info->num_frames = static_cast<int>(rigs_frames.frames.size());
  info->notes.push_back(
      "rigs and frames (COLMAP >= 3.12): " + std::to_string(info->num_rigs) +
      " rig(s), " + std::to_string(info->num_multi_camera_rigs) +
      " with several cameras, " + std::to_string(info->num_frames) +
      " frame(s); every image's pose equals sensor_from_rig * rig_from_world "
      "of its frame, so the image poses are used as they are");
  return true;
}

// The rigs and frames files of the model's type: both or none.
bool ReadMapRigsAndFrames(const std::string& path, const bool binary,
                          const colmap::Reconstruction& map, MapReadInfo* info,
                          std::string* error) {
  const fs::path folder(path);
  const std::string extension = binary ? ".bin" : ".txt";
  const bool has_rigs = fs::exists(folder / ("rigs" + extension));
  const bool has_frames = fs::exists(folder / ("frames" + extension));
  if (!has_rigs && !has_frames) return true;
  if (has_rigs != has_frames) {
    *error = "the map folder " + path + " has " +
             (has_rigs ? "rigs" : "frames") + extension + " but no " +
             (has_rigs ? "frames" : "rigs") + extension +
             " (COLMAP >= 3.12 writes both)";
    return false;
  }
  ColmapRigsAndFrames rigs_frames;
  std::string read_error;
  // ReadRigsAndFrames reads the .bin files if both are there, else the .txt
  // ones, as COLMAP does.
  if (!ReadRigsAndFrames(path, &rigs_frames, &read_error)) {
    *error = "cannot read the rigs and frames of the map in " + path + ": " +
             read_error;
    return false;
  }
  return CheckRigsAndFrames(path, map, rigs_frames, info, error);
}

}  // namespace

bool ReadMap(const std::string& path, colmap::Reconstruction* map,
             std::string* error) {
  MapReadInfo info;
  return ReadMap(path, map, &info, error);
}

bool ReadModel(const std::string& path, colmap::Reconstruction* map,
               MapReadInfo* info, std::string* error) {
  *info = MapReadInfo();
  const fs::path folder(path);
  if (!fs::is_directory(folder)) {
    *error = "the map folder " + path +
             " does not exist or is not a folder (--input_path must be a "
             "COLMAP sparse model folder, e.g. sparse/0)";
    return false;
  }
  // COLMAP reads the binary files if cameras.bin exists, else the text ones;
  // all three must then be there.
  const bool binary = fs::exists(folder / "cameras.bin");
  for (const std::string name : {"cameras", "images", "points3D"}) {
    const fs::path file = folder / (name + (binary ? ".bin" : ".txt"));
    if (!fs::is_regular_file(file)) {
      *error = "the map folder " + path + " has no " + name +
               (binary ? ".bin" : ".txt") +
               ": it is not a complete COLMAP sparse model";
      return false;
    }
    std::ifstream readable(file.string());
    if (!readable) {
      *error = "cannot read " + file.string();
      return false;
    }
  }
  std::vector<CameraRecord> cameras;
  if (!ReadCameraRecords(
          (folder / (binary ? "cameras.bin" : "cameras.txt")).string(), binary,
          &cameras, error)) {
    return false;
  }
  if (binary ? !CheckImagesBinary(folder / "images.bin", error) ||
                   !CheckPoints3DBinary(folder / "points3D.bin", error)
             : !CheckImagesText(folder / "images.txt", error)) {
    return false;
  }
  MapRepairs repairs;
  if (!ReadWithColmap(folder, binary, cameras, map, info, error) ||
      !CheckUniqueModelIds(path, binary, *map, error) ||
      !CheckMapConsistency(path, binary, map, &repairs, error) ||
      !ReadMapRigsAndFrames(path, binary, *map, info, error)) {
    return false;
  }
  if (repairs.Any()) info->warnings.push_back(repairs.Describe(path));
  return true;
}

bool ReadMap(const std::string& path, colmap::Reconstruction* map,
             MapReadInfo* info, std::string* error) {
  if (!ReadModel(path, map, info, error)) return false;
  if (map->NumRegImages() == 0) {
    *error = "the map in " + path + " has no registered image";
    return false;
  }
  if (map->NumPoints3D() == 0) {
    *error = "the map in " + path +
             " has no 3D points: rig images can only be localized against "
             "a map with points (run colmap mapper or point_triangulator)";
    return false;
  }
  return true;
}

bool RestoreNewerModelCameras(const std::string& folder, const bool binary,
                              const std::vector<CameraRecord>& cameras,
                              std::string* error) {
  if (cameras.empty()) return true;
  const std::string path = folder + (binary ? "/cameras.bin" : "/cameras.txt");
  std::vector<CameraRecord> written;
  if (!ReadCameraRecords(path, binary, &written, error)) return false;
  for (CameraRecord& record : written) {
    for (const CameraRecord& camera : cameras) {
      if (camera.camera_id == record.camera_id) record = camera;
    }
  }
  return WriteCameraRecords(path, binary, written, error);
}

colmap::camera_t MaxCameraId(const colmap::Reconstruction& model) {
  colmap::camera_t max_camera_id = 0;
  for (const auto& [camera_id, camera] : model.Cameras()) {
    max_camera_id = std::max(max_camera_id, camera_id);
  }
  return max_camera_id;
}

colmap::image_t MaxImageId(const colmap::Reconstruction& model) {
  colmap::image_t max_image_id = 0;
  for (const auto& [image_id, image] : model.Images()) {
    max_image_id = std::max(max_image_id, image_id);
  }
  return max_image_id;
}

}  // namespace rig_calibrator
