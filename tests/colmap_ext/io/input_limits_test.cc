// The readers' limits (README, "Bad input"): counts and lengths that a file
// cannot hold fail fast with a message, before anything is allocated for
// them; NUL bytes, non-UTF-8 and spaces in names, very long lines and
// non-finite numbers are refused or kept exactly. The inputs that the fuzz
// targets (tests/fuzz) found crashing are among them.
#include <colmap/base/database.h>
#include <colmap/base/reconstruction.h>
#include <gtest/gtest.h>

#include <boost/algorithm/string.hpp>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <utility>
#include <vector>

#include "colmap_ext/io/correspondence_io.h"
#include "colmap_ext/io/database_reader.h"
#include "colmap_ext/io/map_reader.h"
#include "tests/colmap_ext/colmap_testing.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace input_limits_test {

void WriteBytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

template <typename T>
std::string Binary(T value) {
  std::string bytes(sizeof(T), '\0');
  std::memcpy(bytes.data(), &value, sizeof(T));
  return bytes;
}

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
      .count();
}

// --- correspondence file ---------------------------------------------------

std::string CorrespondenceError(const std::string& path,
                                const std::string& text) {
  WriteBytes(path, text);
  std::vector<ImageCorrespondences> images;
  std::string error;
  EXPECT_FALSE(ReadCorrespondenceFile(path, &images, &error));
  return error;
}

std::vector<ImageCorrespondences> ReadCorrespondences(const std::string& path,
                                                      const std::string& text) {
  WriteBytes(path, text);
  std::vector<ImageCorrespondences> images;
  std::string error;
  EXPECT_TRUE(ReadCorrespondenceFile(path, &images, &error)) << error;
  return images;
}

// Found by correspondence_fuzzer: the reader reserved the declared number of
// rows, so a short file claiming 10^12 rows ended the process (length_error).
TEST(InputLimits, CorrespondenceRowCountBeyondTheFileFailsFast) {
  testing::ScopedTempDir dir;
  const std::string path = dir.File("c.txt");
  std::string text = "IMAGE cam0/a.png 640 480 1000000000000\n";
  while (text.size() < 100) text += "1 2 3 4 5\n";
  const auto start = std::chrono::steady_clock::now();
  const std::string error = CorrespondenceError(path, text);
  EXPECT_LT(SecondsSince(start), 1.0);
  EXPECT_NE(error.find("file " + path + " line "), std::string::npos) << error;
  EXPECT_NE(error.find("the file ends but image cam0/a.png (line 1) declares "
                       "1000000000000 rows"),
            std::string::npos)
      << error;
}

TEST(InputLimits, CorrespondenceNamesKeepSpacesAndBytesButNoNul) {
  testing::ScopedTempDir dir;
  const std::string path = dir.File("c.txt");
  // Spaces inside a name and bytes that are not UTF-8 (Latin-1 "\xe9") are
  // part of the name, as in COLMAP; the outputs' JSON replaces such bytes.
  const std::string latin1 = "cam0/caf\xe9 1.png";
  const auto images =
      ReadCorrespondences(path, "IMAGE cam0/my  image.png 640 480 0\nIMAGE " +
                                    latin1 + " 640 480 1\n1 2 3 4 5\n");
  ASSERT_EQ(images.size(), 2u);
  EXPECT_EQ(images[0].image_name, "cam0/my  image.png");
  EXPECT_EQ(images[1].image_name, latin1);
  const std::string rewritten = dir.File("rewritten.txt");
  std::string error;
  ASSERT_TRUE(WriteCorrespondenceFile(rewritten, images, &error)) << error;
  std::vector<ImageCorrespondences> again;
  ASSERT_TRUE(ReadCorrespondenceFile(rewritten, &again, &error)) << error;
  EXPECT_EQ(again[1].image_name, latin1);

  EXPECT_EQ(CorrespondenceError(
                path, std::string("IMAGE cam0/a\0b.png 640 480 0\n", 29)),
            "file " + path + " line 1: the image name 'cam0/a" +
                std::string(1, '\0') + "b.png' contains a NUL byte");
  // A NUL byte in a row is a field that is not a number.
  EXPECT_EQ(CorrespondenceError(
                path, std::string("IMAGE a.png 640 480 1\n1 2\0 3 4 5\n", 33)),
            "file " + path + " line 2: field 2 '2" + std::string(1, '\0') +
                "' is not a finite number");
}

TEST(InputLimits, CorrespondenceLongLinesAreReadAndQuotedShort) {
  testing::ScopedTempDir dir;
  const std::string path = dir.File("c.txt");
  const std::string long_name = "cam0/" + std::string(1 << 20, 'x') + ".png";
  const auto images =
      ReadCorrespondences(path, "IMAGE " + long_name + " 640 480 0\n");
  ASSERT_EQ(images.size(), 1u);
  EXPECT_EQ(images[0].image_name, long_name);
  // A 1 MiB field is quoted by its first 40 bytes.
  const std::string error =
      CorrespondenceError(path, "IMAGE a.png 640 480 1\n1 2 3 4 " +
                                    std::string(1 << 20, '7') + "x\n");
  EXPECT_EQ(error, "file " + path + " line 2: field 5 '" +
                       std::string(40, '7') + "...' is not a finite number");
}

TEST(InputLimits, CorrespondenceNonFiniteNumbersAreRefused) {
  testing::ScopedTempDir dir;
  const std::string path = dir.File("c.txt");
  for (const std::string value :
       {"nan", "-nan", "inf", "-inf", "infinity", "1e999", "NaN"}) {
    EXPECT_EQ(CorrespondenceError(
                  path, "IMAGE a.png 640 480 1\n1 " + value + " 3 4 5\n"),
              "file " + path + " line 2: field 2 '" + value +
                  "' is not a finite number");
  }
  EXPECT_EQ(CorrespondenceError(path, "IMAGE a.png inf 480 0\n"),
            "file " + path +
                " line 1: expected integers <width> <height> <num_rows> "
                "after the image name");
  EXPECT_EQ(CorrespondenceError(path,
                                "IMAGE a.png 640 480 0\nIMAGE b.png 640 480 0\n"
                                "IMAGE a.png 640 480 0\n"),
            "file " + path + " line 3: the image a.png appears twice");
}

// --- binary model files -----------------------------------------------------

// A model with one camera, one registered image with one point2D, one point.
colmap::Reconstruction TestModel() {
  colmap::Reconstruction model;
  colmap::Camera camera;
  camera.InitializeWithName("SIMPLE_RADIAL", 500, 640, 480);
  camera.SetCameraId(1);
  model.AddCamera(camera);
  colmap::Image image;
  image.SetImageId(1);
  image.SetCameraId(1);
  image.SetName("map/a.png");
  image.SetQvec(Eigen::Vector4d(1, 0, 0, 0));
  image.SetTvec(Eigen::Vector3d::Zero());
  image.SetPoints2D({Eigen::Vector2d(100, 200)});
  model.AddImage(image);
  model.RegisterImage(1);
  colmap::Track track;
  track.AddElement(1, 0);
  model.AddPoint3D(Eigen::Vector3d(0, 0, 4), track);
  return model;
}

void WriteModel(const std::string& folder) { TestModel().WriteBinary(folder); }

// A 100-byte file: `head`, then zeros.
std::string HundredBytes(const std::string& head) {
  return head + std::string(100 - head.size(), '\0');
}

std::string MapError(const std::string& folder) {
  colmap::Reconstruction map;
  std::string error;
  const auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(ReadMap(folder, &map, &error));
  EXPECT_LT(SecondsSince(start), 1.0);
  return error;
}

TEST(InputLimits, BinaryModelCountsBeyondTheFileFailFast) {
  testing::ScopedTempDir dir;
  const std::string folder = dir.path();
  WriteModel(folder);
  const uint64_t huge = 1000000000000;
  const std::string prefix = folder + "/";

  // 10^12 points in 100 bytes: the records run out.
  WriteBytes(prefix + "points3D.bin", HundredBytes(Binary(huge)));
  EXPECT_EQ(MapError(folder),
            prefix +
                "points3D.bin is not a COLMAP binary model file: "
                "a point record claims 1 entries, more "
                "than the 41 bytes left can hold");
  // One point whose track claims 10^12 elements.
  WriteBytes(prefix + "points3D.bin",
             HundredBytes(Binary<uint64_t>(1) +
                          std::string(8 + 24 + 3 + 8, '\0') + Binary(huge)));
  EXPECT_EQ(MapError(folder),
            prefix +
                "points3D.bin is not a COLMAP binary model file: "
                "a point's track claims 1000000000000 "
                "entries, more than the 41 bytes left can hold");
  WriteModel(folder);

  // One image claiming 10^12 points2D.
  WriteBytes(prefix + "images.bin",
             HundredBytes(Binary<uint64_t>(1) + std::string(4 + 56 + 4, '\0') +
                          "a.png" + std::string(1, '\0') + Binary(huge)));
  EXPECT_EQ(MapError(folder),
            prefix +
                "images.bin is not a COLMAP binary model file: "
                "an image's points2D claims 1000000000000 "
                "entries, more than the 14 bytes left can hold");
  WriteModel(folder);

  // 10^12 cameras: the second record (zeros: a camera of model 0,
  // SIMPLE_PINHOLE) does not fit.
  WriteBytes(
      prefix + "cameras.bin",
      HundredBytes(Binary(huge) + Binary<uint32_t>(1) + Binary<int32_t>(2)));
  EXPECT_EQ(MapError(folder),
            prefix +
                "cameras.bin is not a COLMAP binary model file: it ends inside "
                "the parameters of camera 0");
}

// COLMAP 3.8 keeps the first record of an id and drops the others (and
// registers a repeated images.txt record twice): the model is refused.
TEST(InputLimits, RepeatedModelIdsAreRefused) {
  testing::ScopedTempDir dir;
  const std::string folder = dir.path();
  const std::string prefix = folder + "/";
  TestModel().WriteText(folder);
  const std::string images = testing::ReadBytes(prefix + "images.txt");
  const size_t record = images.find("\n1 ") + 1;
  WriteBytes(prefix + "images.txt", images + images.substr(record));
  EXPECT_EQ(MapError(folder),
            prefix +
                "images.txt has 2 image records but 1 distinct image "
                "ids (1 appears twice): every image id must be unique "
                "(COLMAP would keep only the first record)");

  TestModel().WriteText(folder);
  const std::string points = testing::ReadBytes(prefix + "points3D.txt");
  const std::string point_line = points.substr(points.find("\n1 ") + 1);
  WriteBytes(prefix + "points3D.txt", points + point_line);
  EXPECT_EQ(MapError(folder),
            prefix +
                "points3D.txt has 2 point records but 1 distinct point "
                "ids (1 appears twice): every point id must be unique "
                "(COLMAP would keep only the first record)");
}

// Found by fuzzing the model reader (CI run of 2026-12-02): an image whose
// camera id is 2^32 - 1, COLMAP's kInvalidCameraId (also what "-1" becomes
// through std::stoul in images.txt), made COLMAP 3.8 abort in
// Image::SetCameraId. Refused before COLMAP reads it, text and binary.
TEST(InputLimits, InvalidCameraIdOfAnImageIsRefused) {
  testing::ScopedTempDir dir;
  const std::string folder = dir.path();
  const std::string prefix = folder + "/";
  const std::string expected =
      ": an image has the camera id 4294967295, COLMAP's invalid id: give "
      "every image the id of a camera in cameras of the model";
  for (const std::string camera_id : {"-1", "4294967295", "8589934591"}) {
    SCOPED_TRACE(camera_id);
    TestModel().WriteText(folder);
    const std::string images = testing::ReadBytes(prefix + "images.txt");
    const size_t record = images.find("\n1 ") + 1;
    const size_t end = images.find('\n', record);
    std::vector<std::string> fields;
    const std::string line = images.substr(record, end - record);
    boost::split(fields, line, boost::is_any_of(" "));
    ASSERT_GT(fields.size(), 9u);
    fields[8] = camera_id;
    WriteBytes(prefix + "images.txt", images.substr(0, record) +
                                          boost::join(fields, " ") +
                                          images.substr(end));
    EXPECT_EQ(MapError(folder), prefix + "images.txt" + expected);
  }
  // The fuzzer's input (tests/fuzz/corpus/model/images_txt_invalid_camera_id):
  // a record of 8 fields, whose last, TZ = -1, COLMAP reads again as the
  // camera id.
  TestModel().WriteText(folder);
  WriteBytes(prefix + "images.txt", "2 0. 5.052 4 0 0 0 -1\n\n");
  EXPECT_EQ(MapError(folder), prefix + "images.txt" + expected);
  std::filesystem::remove(prefix + "cameras.txt");
  std::filesystem::remove(prefix + "images.txt");
  std::filesystem::remove(prefix + "points3D.txt");
  WriteModel(folder);
  std::string images = testing::ReadBytes(prefix + "images.bin");
  // count (8), id (4), qvec and tvec (56), then the camera id.
  const uint32_t invalid = 0xFFFFFFFFu;
  images.replace(8 + 4 + 56, 4, Binary(invalid));
  WriteBytes(prefix + "images.bin", images);
  EXPECT_EQ(MapError(folder), prefix + "images.bin" + expected);
}

TEST(InputLimits, RepeatedBinaryModelIdsAreRefused) {
  testing::ScopedTempDir dir;
  const std::string folder = dir.path();
  const std::string prefix = folder + "/";
  WriteModel(folder);
  const std::string points = testing::ReadBytes(prefix + "points3D.bin");
  WriteBytes(prefix + "points3D.bin",
             Binary<uint64_t>(2) + points.substr(8) + points.substr(8));
  EXPECT_EQ(MapError(folder),
            prefix +
                "points3D.bin has 2 point records but 1 distinct point "
                "ids: every point id must be unique (COLMAP would keep "
                "only the first record)");
}

// --- database blobs ---------------------------------------------------------

// Found while fuzzing the blob readers: rows * cols * sizeof(element) could
// overflow int64 and wrap to the blob's size (0 for an empty blob), so the
// reader took 2^62 rows as valid and ended the process allocating them.
TEST(InputLimits, DatabaseBlobShapesBeyondTheBlobAreRefused) {
  testing::ScopedTempDir dir;
  const std::string path = dir.File("database.db");
  {
    colmap::Database database(path);
    colmap::Camera camera;
    camera.InitializeWithName("SIMPLE_RADIAL", 300, 64, 48);
    const colmap::camera_t camera_id = database.WriteCamera(camera);
    for (const char* name : {"map/a.png", "cam0/0001.png"}) {
      colmap::Image image;
      image.SetName(name);
      image.SetCameraId(camera_id);
      const colmap::image_t image_id = database.WriteImage(image);
      database.WriteKeypoints(image_id, colmap::FeatureKeypoints(2));
      database.WriteDescriptors(image_id, colmap::FeatureDescriptors(2, 128));
    }
    colmap::TwoViewGeometry geometry;
    geometry.config = colmap::TwoViewGeometry::CALIBRATED;
    geometry.inlier_matches = {{0, 1}};
    database.WriteTwoViewGeometry(1, 2, geometry);
  }
  // 2^62 * 4 * 4, 2^57 * 128 and 2^61 * 2 * 4 are 2^64: 0 in int64.
  testing::ExecuteSql(
      path,
      "UPDATE keypoints SET rows = 4611686018427387904, cols = 4, data = X'' "
      "WHERE image_id = 1;"
      "UPDATE descriptors SET rows = 144115188075855872, data = X'' "
      "WHERE image_id = 1;"
      "UPDATE two_view_geometries SET rows = 2305843009213693952, data = X'';");
  DatabaseReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(path, &error)) << error;
  colmap::FeatureKeypoints keypoints;
  EXPECT_FALSE(reader.ReadKeypoints(1, &keypoints, &error));
  EXPECT_NE(error.find("keypoints of image map/a.png (id 1) are malformed "
                       "(4611686018427387904x4, 0 bytes)"),
            std::string::npos)
      << error;
  colmap::FeatureDescriptors descriptors;
  EXPECT_FALSE(reader.ReadDescriptors(1, &descriptors, &error));
  EXPECT_NE(error.find("are malformed (144115188075855872x128, 0 bytes)"),
            std::string::npos)
      << error;
  colmap::FeatureMatches matches;
  EXPECT_FALSE(reader.ReadInlierMatches(1, 2, &matches, &error));
  EXPECT_NE(error.find("inlier matches of image map/a.png (id 1) and image "
                       "cam0/0001.png (id 2)"),
            std::string::npos)
      << error;
}

// Found by database_blob_fuzzer: a keypoint of 4 floats with a negative
// scale made COLMAP's FeatureKeypoint end the process (CHECK_GE(scale, 0));
// NaN or infinite keypoints would reach the calibration.
TEST(InputLimits, DatabaseKeypointsWithNegativeScaleOrNanAreRefused) {
  testing::ScopedTempDir dir;
  const std::string path = dir.File("database.db");
  {
    colmap::Database database(path);
    colmap::Camera camera;
    camera.InitializeWithName("SIMPLE_RADIAL", 300, 64, 48);
    colmap::Image image;
    image.SetName("cam0/0001.png");
    image.SetCameraId(database.WriteCamera(camera));
    database.WriteKeypoints(database.WriteImage(image),
                            colmap::FeatureKeypoints(2));
  }
  // Two keypoints (x, y, scale, orientation); the second's scale is -7.
  const float negative_scale[8] = {1, 2, 1.5f, 0, 3, 4, -7, 0};
  const float nan_x[4] = {std::numeric_limits<float>::quiet_NaN(), 2, 1.5f, 0};
  for (const auto& [values, num_rows] :
       {std::pair<const float*, int>(negative_scale, 2), {nan_x, 1}}) {
    std::string hex;
    const auto* bytes = reinterpret_cast<const unsigned char*>(values);
    for (int i = 0; i < num_rows * 16; ++i) {
      char digits[3];
      std::snprintf(digits, sizeof(digits), "%02X", bytes[i]);
      hex += digits;
    }
    testing::ExecuteSql(
        path, "UPDATE keypoints SET rows = " + std::to_string(num_rows) +
                  ", cols = 4, data = X'" + hex + "';");
    DatabaseReader reader;
    std::string error;
    ASSERT_TRUE(reader.Open(path, &error)) << error;
    colmap::FeatureKeypoints keypoints;
    EXPECT_FALSE(reader.ReadKeypoints(1, &keypoints, &error));
    EXPECT_NE(error.find("keypoints of image cam0/0001.png (id 1) are "
                         "malformed: keypoint " +
                         std::to_string(num_rows - 1) +
                         " has a non-finite value or a negative scale"),
              std::string::npos)
        << error;
  }
}

}  // namespace input_limits_test
}  // namespace rig_calibrator
