#include "colmap_ext/io/correspondence_io.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string_view>
#include <unordered_set>

#include "colmap_ext/io/atomic_output.h"
#include "colmap_ext/io/number_text.h"

namespace rig_calibrator {
namespace {

bool IsSpace(char c) { return c == ' ' || c == '\t'; }

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

// The line at `*offset` in `text`, without its line break (and a '\r'
// before it); `*offset` then points past it.
std::string_view NextLine(std::string_view text, size_t* offset) {
  const size_t end = std::min(text.find('\n', *offset), text.size());
  std::string_view line = text.substr(*offset, end - *offset);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  *offset = end + 1;
  return line;
}

enum class LineKind { kSkipped, kImage, kRow };

// Blank lines and comments (first field starting with '#') are skipped; an
// IMAGE line has the first field "IMAGE".
LineKind KindOf(std::string_view line) {
  size_t i = 0;
  while (i < line.size() && IsSpace(line[i])) ++i;
  if (i == line.size() || line[i] == '#') return LineKind::kSkipped;
  constexpr std::string_view kImage = "IMAGE";
  if (line.compare(i, kImage.size(), kImage) == 0 &&
      (i + kImage.size() == line.size() || IsSpace(line[i + kImage.size()]))) {
    return LineKind::kImage;
  }
  return LineKind::kRow;
}

}  // namespace

// In two passes: the structure (IMAGE lines, row counts, names) line by
// line, then the rows of every image on all threads, each into its own
// image. The error reported is the one of the first line that has one, as a
// single pass would find it.
bool ReadCorrespondenceFile(const std::string& path,
                            std::vector<ImageCorrespondences>* images,
                            std::string* error) {
  images->clear();
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    *error = "cannot open the correspondence file " + path;
    return false;
  }
  // The whole file at once (a pipe, without a size, byte by byte).
  std::string content;
  file.seekg(0, std::ios::end);
  const std::streamoff size = file.tellg();
  if (size >= 0) {
    file.seekg(0);
    content.resize(static_cast<size_t>(size));
    file.read(content.data(), size);
  } else {
    file.clear();
    content.assign(std::istreambuf_iterator<char>(file),
                   std::istreambuf_iterator<char>());
  }
  if (file.bad() || (size >= 0 && file.gcount() != size)) {
    *error = "cannot read the correspondence file " + path;
    return false;
  }
  const std::string_view text = content;

  // Pass 1. Per image, where its rows start (the line after its IMAGE line)
  // and how many there are; the first error of the structure, if any, and
  // its line.
  struct ImageRows {
    size_t offset = 0;
    int first_line = 0;
    int64_t num_rows = 0;
  };
  std::vector<ImageRows> rows;
  std::unordered_set<std::string> names;
  int64_t rows_left = 0;
  int line_number = 0;
  int image_line_number = 0;
  std::string structure_error;
  const auto structure_fails = [&](const std::string& message) {
    structure_error = "file " + path + " line " + std::to_string(line_number) +
                      ": " + message;
  };
  for (size_t offset = 0; offset < text.size() && structure_error.empty();) {
    const std::string_view line = NextLine(text, &offset);
    ++line_number;
    const LineKind kind = KindOf(line);
    if (kind == LineKind::kSkipped) continue;
    if (kind == LineKind::kImage) {
      if (rows_left > 0) {
        structure_fails("image " + images->back().image_name + " (line " +
                        std::to_string(image_line_number) + ") declares " +
                        std::to_string(rows.back().num_rows + rows_left) +
                        " rows but has only " +
                        std::to_string(rows.back().num_rows));
        break;
      }
      ImageCorrespondences image;
      std::string image_error;
      if (!ParseImageLine(line, LineError(path, line_number), &image,
                          &rows_left, &image_error)) {
        structure_error = image_error;
        break;
      }
      if (!names.insert(image.image_name).second) {
        structure_fails("the image " + image.image_name + " appears twice");
        break;
      }
      images->push_back(std::move(image));
      rows.push_back({offset, line_number + 1, 0});
      image_line_number = line_number;
      continue;
    }
    if (images->empty()) {
      structure_fails("expected an IMAGE line before the first row");
      break;
    }
    if (rows_left == 0) {
      structure_fails("image " + images->back().image_name + " (line " +
                      std::to_string(image_line_number) + ") declares " +
                      std::to_string(rows.back().num_rows) +
                      " rows, but there are more");
      break;
    }
    ++rows.back().num_rows;
    --rows_left;
  }
  if (structure_error.empty() && rows_left > 0) {
    structure_error =
        "file " + path + " line " + std::to_string(line_number) +
        ": the file ends but image " + images->back().image_name + " (line " +
        std::to_string(image_line_number) + ") declares " +
        std::to_string(rows.back().num_rows + rows_left) + " rows";
  }

  // Pass 2. The rows pass 1 counted, per image; per image the first row
  // that fails, if any.
  const int num_images = static_cast<int>(images->size());
  std::vector<std::string> row_errors(num_images);
  std::vector<int> row_error_lines(num_images, 0);
#pragma omp parallel for schedule(dynamic, 4)
  for (int i = 0; i < num_images; ++i) {
    std::vector<Correspondence>& correspondences =
        (*images)[i].correspondences;
    correspondences.reserve(rows[i].num_rows);
    size_t offset = rows[i].offset;
    for (int number = rows[i].first_line;
         static_cast<int64_t>(correspondences.size()) < rows[i].num_rows;
         ++number) {
      const std::string_view line = NextLine(text, &offset);
      if (KindOf(line) != LineKind::kRow) continue;
      Correspondence correspondence;
      if (!ParseRow(line, LineError(path, number), &correspondence,
                    &row_errors[i])) {
        row_error_lines[i] = number;
        break;
      }
      correspondences.push_back(correspondence);
    }
  }
  // The first failing line: pass 2 read only rows before the structure's
  // error, and the images are in file order.
  for (int i = 0; i < num_images; ++i) {
    if (row_error_lines[i] > 0) {
      *error = row_errors[i];
      images->clear();
      return false;
    }
  }
  if (!structure_error.empty()) {
    *error = structure_error;
    images->clear();
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
  }
  // Each image's text on its own, on all threads, written in image order;
  // the rows are appended number by number (an ostringstream with a
  // string per number took seconds for 10^6 rows).
  const int num_images = static_cast<int>(images.size());
  std::vector<std::string> texts(num_images);
  std::vector<char> finite(num_images, 1);
#pragma omp parallel for schedule(dynamic, 4)
  for (int i = 0; i < num_images; ++i) {
    const ImageCorrespondences& image = images[i];
    std::string& text = texts[i];
    text.reserve(100 * image.correspondences.size() + 64);
    text += "IMAGE " + image.image_name + " " + std::to_string(image.width) +
            " " + std::to_string(image.height) + " " +
            std::to_string(image.correspondences.size()) + "\n";
    for (const Correspondence& c : image.correspondences) {
      if (!c.point2D.allFinite() || !c.point3D.allFinite()) {
        finite[i] = 0;
        break;
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
  for (int i = 0; i < num_images; ++i) {
    if (!finite[i]) {
      *error = "the image " + images[i].image_name +
               " has a non-finite correspondence";
      return false;
    }
  }
  const std::string header_text = header.str();
  std::vector<std::string_view> pieces = {header_text};
  pieces.insert(pieces.end(), texts.begin(), texts.end());
  return WriteFileAtomically(path, pieces, error);
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
