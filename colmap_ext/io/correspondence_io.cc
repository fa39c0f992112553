#include "colmap_ext/io/correspondence_io.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string_view>
#include <unordered_set>

#include "colmap_ext/io/atomic_output.h"
#include "colmap_ext/io/number_text.h"

namespace rig_calibrator {
namespace {

bool IsSpace(char c) { return c == ' ' || c == '\t'; }

// The shortest row, "0 0 0 0 0" and its line break: a file of B more bytes
// holds at most (B + 1) / kMinRowBytes rows (the last one without a break).
constexpr int64_t kMinRowBytes = 10;

// A field quoted in a message: at most 40 bytes of it.
std::string Quote(std::string_view field) {
  constexpr size_t kMaxQuoted = 40;
  return "'" + std::string(field.substr(0, kMaxQuoted)) +
         (field.size() > kMaxQuoted ? "...'" : "'");
}

std::vector<std::string_view> SplitWhitespace(std::string_view line) {
  std::vector<std::string_view> tokens;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && IsSpace(line[i])) ++i;
    const size_t begin = i;
    while (i < line.size() && !IsSpace(line[i])) ++i;
    if (i > begin) tokens.push_back(line.substr(begin, i - begin));
  }
  return tokens;
}

class LineError {
 public:
  LineError(const std::string& path, int line_number)
      : prefix_("file " + path + " line " + std::to_string(line_number) +
                ": ") {}
  bool operator()(const std::string& message, std::string* error) const {
    *error = prefix_ + message;
    return false;
  }

 private:
  std::string prefix_;
};

// "IMAGE <name> <width> <height> <num_rows>"; the name is everything between
// the keyword and the last three fields, so it may contain spaces.
bool ParseImageLine(std::string_view line, const LineError& fail,
                    ImageCorrespondences* image, int64_t* num_rows,
                    std::string* error) {
  const std::vector<std::string_view> tokens = SplitWhitespace(line);
  if (tokens.size() < 5) {
    return fail("expected IMAGE <image_name> <width> <height> <num_rows>",
                error);
  }
  const size_t n = tokens.size();
  int64_t width = 0;
  int64_t height = 0;
  if (!ParseInt64(tokens[n - 3], &width) ||
      !ParseInt64(tokens[n - 2], &height) ||
      !ParseInt64(tokens[n - 1], num_rows)) {
    return fail(
        "expected integers <width> <height> <num_rows> after the "
        "image name",
        error);
  }
  if (width <= 0 || height <= 0 || width > INT32_MAX || height > INT32_MAX) {
    return fail("the image size must be positive", error);
  }
  if (*num_rows < 0) {
    return fail("num_rows must be >= 0", error);
  }
  const size_t name_begin = tokens[1].data() - line.data();
  const size_t name_end =
      tokens[n - 4].data() + tokens[n - 4].size() - line.data();
  image->image_name =
      std::string(line.substr(name_begin, name_end - name_begin));
  // No file name holds a NUL byte; any other byte (e.g. a name that is not
  // UTF-8) is kept as it is, as COLMAP keeps it.
  if (image->image_name.find('\0') != std::string::npos) {
    return fail(
        "the image name " + Quote(image->image_name) + " contains a NUL byte",
        error);
  }
  image->width = static_cast<int>(width);
  image->height = static_cast<int>(height);
  return true;
}

bool ParseRow(std::string_view line, const LineError& fail,
              Correspondence* correspondence, std::string* error) {
  const std::vector<std::string_view> tokens = SplitWhitespace(line);
  if (tokens.size() != 5 && tokens.size() != 6) {
    return fail("expected 5 or 6 numbers, found " +
                    std::to_string(tokens.size()) + " fields",
                error);
  }
  double values[5];
  for (int i = 0; i < 5; ++i) {
    if (!ParseDouble(tokens[i], &values[i])) {
      return fail("field " + std::to_string(i + 1) + " " + Quote(tokens[i]) +
                      " is not a finite number",
                  error);
    }
  }
  correspondence->point2D = Eigen::Vector2d(values[0], values[1]);
  correspondence->point3D = Eigen::Vector3d(values[2], values[3], values[4]);
  correspondence->point3D_id = -1;
  if (tokens.size() == 6 &&
      (!ParseInt64(tokens[5], &correspondence->point3D_id) ||
       correspondence->point3D_id < -1)) {
    return fail(
        "the point3D_id " + Quote(tokens[5]) + " is not an integer >= -1",
        error);
  }
  return true;
}

}  // namespace

bool ReadCorrespondenceFile(const std::string& path,
                            std::vector<ImageCorrespondences>* images,
                            std::string* error) {
  images->clear();
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    *error = "cannot open the correspondence file " + path;
    return false;
  }
  file.seekg(0, std::ios::end);
  const int64_t file_size = file.tellg();
  file.seekg(0);
  // Bytes read so far, line breaks included.
  int64_t position = 0;
  std::unordered_set<std::string> names;
  int64_t rows_left = 0;
  int line_number = 0;
  int image_line_number = 0;
  std::string line;
  while (std::getline(file, line)) {
    ++line_number;
    position += static_cast<int64_t>(line.size()) + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const LineError fail(path, line_number);
    const std::vector<std::string_view> tokens = SplitWhitespace(line);
    if (tokens.empty() || tokens[0].front() == '#') {
      continue;
    }
    if (tokens[0] == "IMAGE") {
      if (rows_left > 0) {
        return fail("image " + images->back().image_name + " (line " +
                        std::to_string(image_line_number) + ") declares " +
                        std::to_string(images->back().correspondences.size() +
                                       rows_left) +
                        " rows but has only " +
                        std::to_string(images->back().correspondences.size()),
                    error);
      }
      ImageCorrespondences image;
      if (!ParseImageLine(line, fail, &image, &rows_left, error)) {
        return false;
      }
      if (!names.insert(image.image_name).second) {
        return fail("the image " + image.image_name + " appears twice", error);
      }
      // Room for the rows that the rest of the file can hold, not for what
      // the line claims: a count beyond them fails when the file ends.
      const int64_t bytes_left = std::max<int64_t>(file_size - position, 0);
      image.correspondences.reserve(
          std::min(rows_left, (bytes_left + 1) / kMinRowBytes));
      images->push_back(std::move(image));
      image_line_number = line_number;
      continue;
    }
    if (images->empty()) {
      return fail("expected an IMAGE line before the first row", error);
    }
    if (rows_left == 0) {
      return fail("image " + images->back().image_name + " (line " +
                      std::to_string(image_line_number) + ") declares " +
                      std::to_string(images->back().correspondences.size()) +
                      " rows, but there are more",
                  error);
    }
    Correspondence correspondence;
    if (!ParseRow(line, fail, &correspondence, error)) {
      return false;
    }
    images->back().correspondences.push_back(correspondence);
    --rows_left;
  }
  if (file.bad()) {
    *error = "cannot read the correspondence file " + path;
    return false;
  }
  if (rows_left > 0) {
    *error = "file " + path + " line " + std::to_string(line_number) +
             ": the file ends but image " + images->back().image_name +
             " (line " + std::to_string(image_line_number) + ") declares " +
             std::to_string(images->back().correspondences.size() + rows_left) +
             " rows";
    return false;
  }
  return true;
}

bool WriteCorrespondenceFile(const std::string& path,
                             const std::vector<ImageCorrespondences>& images,
                             std::string* error) {
  size_t num_rows = 0;
  for (const ImageCorrespondences& image : images) {
    num_rows += image.correspondences.size();
  }
  std::ostringstream header;
  header << "# rig_calibrator 2D-3D correspondences\n"
         << "# IMAGE <image_name> <width> <height> <num_rows>, then num_rows "
            "lines: <x> <y> <X> <Y> <Z> [<point3D_id>]\n"
         << "# Pixels: COLMAP convention (center of the top-left pixel at "
            "(0.5, 0.5)); 3D points in map coordinates.\n"
         << "# Number of images: " << images.size()
         << ", correspondences: " << num_rows << "\n";
  // The rows are appended number by number (an ostringstream with a string
  // per number took seconds for 10^6 rows).
  std::string text = header.str();
  text.reserve(text.size() + 100 * num_rows);
  std::unordered_set<std::string> names;
  for (const ImageCorrespondences& image : images) {
    const std::string& name = image.image_name;
    if (name.empty() || name.find_first_of("\r\n") != std::string::npos ||
        IsSpace(name.front()) || IsSpace(name.back())) {
      *error = "cannot write the image name '" + name +
               "' in a correspondence file: it is empty, has a line break or "
               "starts or ends with a space";
      return false;
    }
    if (!names.insert(name).second) {
      *error = "the image " + name + " appears twice";
      return false;
    }
    if (image.width <= 0 || image.height <= 0) {
      *error = "the image " + name + " has no size";
      return false;
    }
    text += "IMAGE " + name + " " + std::to_string(image.width) + " " +
            std::to_string(image.height) + " " +
            std::to_string(image.correspondences.size()) + "\n";
    for (const Correspondence& c : image.correspondences) {
      if (!c.point2D.allFinite() || !c.point3D.allFinite()) {
        *error = "the image " + name + " has a non-finite correspondence";
        return false;
      }
      const double values[5] = {c.point2D.x(), c.point2D.y(), c.point3D.x(),
                                c.point3D.y(), c.point3D.z()};
      for (int v = 0; v < 5; ++v) {
        if (v > 0) text += ' ';
        AppendDouble(values[v], &text);
      }
      if (c.point3D_id >= 0) {
        text += ' ';
        AppendInt64(c.point3D_id, &text);
      }
      text += '\n';
    }
  }
  return WriteFileAtomically(path, text, error);
}

std::vector<ImageCorrespondences> DatasetCorrespondences(
    const RigDataset& dataset) {
  std::vector<ImageCorrespondences> images;
  images.reserve(dataset.images.size());
  for (const RigImage& rig_image : dataset.images) {
    ImageCorrespondences image;
    image.image_name = rig_image.name;
    if (rig_image.camera_index >= 0 &&
        rig_image.camera_index < static_cast<int>(dataset.cameras.size())) {
      const colmap::Camera& camera =
          dataset.cameras[rig_image.camera_index].camera;
      image.width = static_cast<int>(camera.Width());
      image.height = static_cast<int>(camera.Height());
    }
    image.correspondences = rig_image.correspondences;
    images.push_back(std::move(image));
  }
  return images;
}

}  // namespace rig_calibrator
