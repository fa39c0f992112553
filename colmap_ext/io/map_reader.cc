#include "colmap_ext/io/map_reader.h"

#include <colmap/base/camera_models.h>

#include <algorithm>
#include <boost/algorithm/string.hpp>
#include <boost/filesystem.hpp>
#include <cstdint>
#include <fstream>
#include <functional>

#include "colmap_ext/io/model_unique_ids.h"

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
    *error_ = file_.string() +
              " is not a COLMAP binary model file (of COLMAP 3.8): " + message;
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

// Record layouts of COLMAP 3.8's Reconstruction::Write*Binary.
bool CheckCamerasBinary(const fs::path& file, std::string* error) {
  return CheckBinaryRecords(
      file, "the camera count",
      [](BinaryWalker* walker) {
        uint32_t camera_id = 0;
        int32_t model_id = 0;
        if (!walker->Read(&camera_id, "a camera id") ||
            !walker->Read(&model_id, "a camera model id")) {
          return false;
        }
        if (!colmap::ExistsCameraModelWithId(model_id)) {
          return walker->Fail("camera " + std::to_string(camera_id) +
                              " has the model id " + std::to_string(model_id) +
                              ", which COLMAP 3.8 does not know");
        }
        return walker->Skip(2, sizeof(uint64_t), "a camera size") &&
               walker->Skip(colmap::CameraModelNumParams(model_id),
                            sizeof(double), "camera parameters");
      },
      error);
}

bool CheckImagesBinary(const fs::path& file, std::string* error) {
  return CheckBinaryRecords(
      file, "the image count",
      [](BinaryWalker* walker) {
        uint64_t num_points2D = 0;
        // id, qvec, tvec, camera id, name, points2D (x, y, point3D id).
        return walker->Skip(1, 4 + 7 * sizeof(double) + 4, "an image record") &&
               walker->SkipString("an image name") &&
               walker->Read(&num_points2D, "a points2D count") &&
               walker->Skip(num_points2D, 2 * sizeof(double) + sizeof(uint64_t),
                            "an image's points2D");
      },
      error);
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

// COLMAP 3.8's text reader aborts on an unknown model name or a wrong number
// of parameters; everything else it cannot parse throws.
bool CheckCamerasText(const fs::path& file, std::string* error) {
  std::ifstream stream(file.string());
  std::string line;
  for (int line_number = 1; std::getline(stream, line); ++line_number) {
    boost::trim(line);
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> items;
    boost::split(items, line, boost::is_any_of(" "));
    const std::string where =
        file.string() + " line " + std::to_string(line_number) + ": ";
    if (items.size() < 4 || !colmap::ExistsCameraModelWithName(items[1])) {
      *error = where +
               "expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS[] with a COLMAP "
               "3.8 camera model, found '" +
               line.substr(0, 80) + "'";
      return false;
    }
    const size_t num_params =
        colmap::CameraModelNumParams(colmap::CameraModelNameToId(items[1]));
    if (items.size() - 4 != num_params) {
      *error = where + "the model " + items[1] + " has " +
               std::to_string(num_params) + " parameters, the line gives " +
               std::to_string(items.size() - 4);
      return false;
    }
  }
  return true;
}

// References between cameras, images and points that the rest of the
// program follows without checking (COLMAP's accessors throw or abort).
bool CheckReferences(const std::string& path, const colmap::Reconstruction& map,
                     std::string* error) {
  const std::string prefix = "the map in " + path + " is inconsistent: ";
  for (const auto& [image_id, image] : map.Images()) {
    if (!map.ExistsCamera(image.CameraId())) {
      *error = prefix + "image " + image.Name() + " refers to camera " +
               std::to_string(image.CameraId()) + ", which is not in it";
      return false;
    }
    for (const colmap::Point2D& point2D : image.Points2D()) {
      if (point2D.HasPoint3D() && !map.ExistsPoint3D(point2D.Point3DId())) {
        *error = prefix + "image " + image.Name() + " observes point " +
                 std::to_string(point2D.Point3DId()) + ", which is not in it";
        return false;
      }
    }
  }
  for (const auto& [point3D_id, point3D] : map.Points3D()) {
    for (const colmap::TrackElement& element : point3D.Track().Elements()) {
      if (!map.ExistsImage(element.image_id) ||
          element.point2D_idx >= map.Image(element.image_id).NumPoints2D()) {
        *error = prefix + "the track of point " + std::to_string(point3D_id) +
                 " refers to image " + std::to_string(element.image_id) +
                 ", point " + std::to_string(element.point2D_idx) +
                 ", which is not in it";
        return false;
      }
    }
  }
  return true;
}

}  // namespace

bool ReadMap(const std::string& path, colmap::Reconstruction* map,
             std::string* error) {
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
  const bool checked =
      binary ? CheckCamerasBinary(folder / "cameras.bin", error) &&
                   CheckImagesBinary(folder / "images.bin", error) &&
                   CheckPoints3DBinary(folder / "points3D.bin", error)
             : CheckCamerasText(folder / "cameras.txt", error);
  if (!checked) return false;
  try {
    if (binary) {
      map->ReadBinary(path);
    } else {
      map->ReadText(path);
    }
  } catch (const std::exception& exception) {
    *error = "cannot read the map in " + path +
             " (not a COLMAP 3.8 text model?): " + exception.what();
    return false;
  }
  if (!CheckUniqueModelIds(path, binary, *map, error) ||
      !CheckReferences(path, *map, error)) {
    return false;
  }
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
