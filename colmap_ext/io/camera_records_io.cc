#include "colmap_ext/io/camera_records_io.h"

#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>

#include "colmap_ext/io/atomic_output.h"
#include "colmap_ext/io/binary_bytes.h"
#include "colmap_ext/io/colmap_camera_models.h"
#include "colmap_ext/io/number_text.h"

namespace rig_calibrator {
namespace {

bool ReadBinaryRecords(const std::string& path,
                       std::vector<CameraRecord>* cameras, std::string* error) {
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    *error = "cannot open " + path;
    return false;
  }
  std::ostringstream contents;
  contents << file.rdbuf();
  const std::string bytes = contents.str();
  size_t offset = 0;
  auto read = [&](void* value, size_t size) {
    if (offset + size > bytes.size()) return false;
    std::memcpy(value, bytes.data() + offset, size);
    offset += size;
    return true;
  };
  const std::string prefix = path + " is not a COLMAP binary model file: ";
  uint64_t count = 0;
  if (!read(&count, sizeof(count))) {
    *error = prefix + "it ends inside the camera count";
    return false;
  }
  for (uint64_t i = 0; i < count; ++i) {
    CameraRecord camera;
    uint32_t camera_id = 0;
    int32_t model_id = 0;
    if (!read(&camera_id, 4) || !read(&model_id, 4) ||
        !read(&camera.width, 8) || !read(&camera.height, 8)) {
      *error = prefix + "it ends inside camera record " + std::to_string(i);
      return false;
    }
    camera.camera_id = camera_id;
    camera.model_id = model_id;
    const int num_params = ColmapCameraModelNumParams(model_id);
    if (num_params < 0) {
      *error = prefix + "camera " + std::to_string(camera_id) +
               " has the model id " + std::to_string(model_id) +
               ", which no COLMAP up to 4.1 knows";
      return false;
    }
    camera.params.resize(num_params);
    if (!read(camera.params.data(), num_params * sizeof(double))) {
      *error = prefix + "it ends inside the parameters of camera " +
               std::to_string(camera_id);
      return false;
    }
    cameras->push_back(std::move(camera));
  }
  if (offset != bytes.size()) {
    *error = prefix + std::to_string(bytes.size() - offset) +
             " bytes follow the last record";
    return false;
  }
  return true;
}

bool ReadTextRecords(const std::string& path,
                     std::vector<CameraRecord>* cameras, std::string* error) {
  std::ifstream file(path);
  if (!file) {
    *error = "cannot open " + path;
    return false;
  }
  std::string line;
  for (int line_number = 1; std::getline(file, line); ++line_number) {
    std::istringstream stream(line);
    std::vector<std::string> items;
    for (std::string item; stream >> item;) items.push_back(item);
    if (items.empty() || items[0][0] == '#') continue;
    const std::string where =
        path + " line " + std::to_string(line_number) + ": ";
    CameraRecord camera;
    int64_t camera_id = 0;
    int64_t width = 0;
    int64_t height = 0;
    camera.model_id =
        items.size() >= 2 ? ColmapCameraModelIdFromName(items[1]) : -1;
    if (items.size() < 4 || !ParseInt64(items[0], &camera_id) ||
        camera_id < 0 || camera_id >= std::numeric_limits<uint32_t>::max() ||
        camera.model_id < 0 || !ParseInt64(items[2], &width) || width < 0 ||
        !ParseInt64(items[3], &height) || height < 0) {
      *error = where +
               "expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS[] with a camera "
               "model of COLMAP 3.8 to 4.1, found '" +
               line.substr(0, 80) + "'";
      return false;
    }
    const size_t num_params =
        static_cast<size_t>(ColmapCameraModelNumParams(camera.model_id));
    if (items.size() - 4 != num_params) {
      *error = where + "the model " + items[1] + " has " +
               std::to_string(num_params) + " parameters, the line gives " +
               std::to_string(items.size() - 4);
      return false;
    }
    camera.camera_id = static_cast<colmap::camera_t>(camera_id);
    camera.width = static_cast<uint64_t>(width);
    camera.height = static_cast<uint64_t>(height);
    for (size_t p = 4; p < items.size(); ++p) {
      double value = 0;
      if (!ParseDouble(items[p], &value)) {
        *error = where + "the parameter '" + items[p] + "' is not a number";
        return false;
      }
      camera.params.push_back(value);
    }
    cameras->push_back(std::move(camera));
  }
  return true;
}

}  // namespace

bool ReadCameraRecords(const std::string& path, const bool binary,
                       std::vector<CameraRecord>* cameras, std::string* error) {
  cameras->clear();
  return binary ? ReadBinaryRecords(path, cameras, error)
                : ReadTextRecords(path, cameras, error);
}

bool WriteCameraRecords(const std::string& path, const bool binary,
                        const std::vector<CameraRecord>& cameras,
                        std::string* error) {
  std::string contents;
  if (binary) {
    AppendBinary<uint64_t>(cameras.size(), &contents);
    for (const CameraRecord& camera : cameras) {
      AppendBinary<uint32_t>(camera.camera_id, &contents);
      AppendBinary<int32_t>(camera.model_id, &contents);
      AppendBinary<uint64_t>(camera.width, &contents);
      AppendBinary<uint64_t>(camera.height, &contents);
      for (const double param : camera.params) {
        AppendBinary<double>(param, &contents);
      }
    }
  } else {
    std::ostringstream text;
    text.precision(17);
    text << "# Camera list with one line of data per camera:\n"
         << "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
         << "# Number of cameras: " << cameras.size() << "\n";
    for (const CameraRecord& camera : cameras) {
      text << camera.camera_id << " " << ColmapCameraModelName(camera.model_id)
           << " " << camera.width << " " << camera.height;
      for (const double param : camera.params) text << " " << param;
      text << "\n";
    }
    contents = text.str();
  }
  return WriteFileAtomically(path, contents, error);
}

}  // namespace rig_calibrator
