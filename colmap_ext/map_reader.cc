#include "colmap_ext/map_reader.h"

#include <boost/filesystem.hpp>
#include <cstdint>
#include <fstream>

namespace rig_calibrator {
namespace {

namespace fs = boost::filesystem;

// The smallest size of one record of each binary file: cameras (id, model,
// width, height: 4 + 4 + 8 + 8 bytes), images (id, qvec, tvec, camera id,
// name terminator, point count: 4 + 32 + 24 + 4 + 1 + 8), points3D (id, xyz,
// rgb, error, track length: 8 + 24 + 3 + 8 + 8).
uintmax_t MinRecordSize(const std::string& name) {
  if (name == "cameras") return 24;
  if (name == "images") return 73;
  return 51;
}

// A binary file starts with its record count (uint64, little endian); a file
// that is not a COLMAP binary model gives a count its size cannot hold, and
// COLMAP would read past its end.
bool CheckBinaryFile(const fs::path& file, const std::string& name,
                     std::string* error) {
  const uintmax_t size = fs::file_size(file);
  std::ifstream stream(file.string(), std::ios::binary);
  uint64_t count = 0;
  if (size < sizeof(count) ||
      !stream.read(reinterpret_cast<char*>(&count), sizeof(count))) {
    *error = file.string() + " is too short to be a COLMAP binary model file";
    return false;
  }
  if (count > (size - sizeof(count)) / MinRecordSize(name)) {
    *error = file.string() + " is not a COLMAP binary model file: it claims " +
             std::to_string(count) + " records in " + std::to_string(size) +
             " bytes";
    return false;
  }
  return true;
}

}  // namespace

bool ReadMap(const std::string& path, colmap::Reconstruction* map,
             std::string* error) {
  const fs::path folder(path);
  if (!fs::is_directory(folder)) {
    *error = "the map folder " + path +
             " does not exist (--input_path must be a COLMAP sparse model "
             "folder, e.g. sparse/0)";
    return false;
  }
  // COLMAP reads the binary files if cameras.bin exists, else the text ones;
  // all three must then be there.
  const bool binary = fs::exists(folder / "cameras.bin");
  for (const std::string name : {"cameras", "images", "points3D"}) {
    const fs::path bin = folder / (name + ".bin");
    const fs::path txt = folder / (name + ".txt");
    if (binary && fs::exists(bin)) {
      if (!CheckBinaryFile(bin, name, error)) return false;
    } else if (!binary && fs::exists(txt)) {
      continue;
    } else {
      *error = "the map folder " + path + " has no " + name +
               (binary ? ".bin" : ".txt") +
               ": it is not a complete COLMAP sparse model";
      return false;
    }
  }
  try {
    if (binary) {
      map->ReadBinary(path);
    } else {
      map->ReadText(path);
    }
  } catch (const std::exception& exception) {
    *error = "cannot read the map in " + path + ": " + exception.what();
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

}  // namespace rig_calibrator
