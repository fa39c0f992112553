#include "colmap_ext/io/model_unique_ids.h"

#include <boost/algorithm/string.hpp>
#include <cstdint>
#include <fstream>
#include <unordered_set>

namespace rig_calibrator {
namespace {

// The record count at the start of a binary model file (checked against the
// file's size by the map reader before).
uint64_t BinaryRecordCount(const std::string& file) {
  uint64_t count = 0;
  std::ifstream(file, std::ios::binary)
      .read(reinterpret_cast<char*>(&count), sizeof(count));
  return count;
}

// Reads the ids of a text model file's records as COLMAP 3.8 does: a record
// is a line that is neither empty nor a comment, its id the first field; in
// images.txt the line after a record (its points2D) is part of it. Returns
// the number of records, and the first id seen twice in *repeated ("" if
// none).
uint64_t TextRecordIds(const std::string& file, bool two_line_records,
                       std::string* repeated) {
  std::ifstream stream(file);
  std::unordered_set<std::string> ids;
  uint64_t count = 0;
  std::string line;
  while (std::getline(stream, line)) {
    boost::trim(line);
    if (line.empty() || line[0] == '#') continue;
    ++count;
    const std::string id = line.substr(0, line.find(' '));
    if (!ids.insert(id).second && repeated->empty()) *repeated = id;
    if (two_line_records) std::getline(stream, line);
  }
  return count;
}

}  // namespace

bool CheckUniqueModelIds(const std::string& folder, bool binary,
                         const colmap::Reconstruction& model,
                         std::string* error) {
  struct File {
    std::string name;
    const char* what;
    size_t num_read;
  };
  const File files[] = {{"cameras", "camera", model.NumCameras()},
                        {"images", "image", model.NumImages()},
                        {"points3D", "point", model.NumPoints3D()}};
  for (const File& file : files) {
    const std::string path =
        folder + "/" + file.name + (binary ? ".bin" : ".txt");
    std::string repeated;
    const uint64_t num_records =
        binary ? BinaryRecordCount(path)
               : TextRecordIds(path, file.name == "images", &repeated);
    if (num_records != file.num_read || !repeated.empty()) {
      *error = path + " has " + std::to_string(num_records) + " " + file.what +
               " records but " + std::to_string(file.num_read) + " distinct " +
               file.what + " ids" +
               (repeated.empty() ? "" : " (" + repeated + " appears twice)") +
               ": every " + file.what +
               " id must be unique (COLMAP would keep only the first record)";
      return false;
    }
  }
  // images.txt registers an image once per record.
  if (model.NumRegImages() > model.NumImages()) {
    *error = folder + ": " + std::to_string(model.NumRegImages()) +
             " registered images but " + std::to_string(model.NumImages()) +
             " images: an image id appears twice";
    return false;
  }
  return true;
}

}  // namespace rig_calibrator
