#include "colmap_ext/io/correspondence_io.h"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <random>

#include "tests/testing.h"

namespace rig_calibrator {
namespace correspondence_io_test {

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream file(path, std::ios::binary);
  file << text;
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, 8) == 0; }

std::string ReadError(const std::string& path, const std::string& text) {
  WriteText(path, text);
  std::vector<ImageCorrespondences> images;
  std::string error;
  EXPECT_FALSE(ReadCorrespondenceFile(path, &images, &error)) << text;
  return error;
}

TEST(CorrespondenceIo, RoundTripIsBitExact) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> pixel(0, 640);
  std::uniform_real_distribution<double> world(-1e3, 1e3);
  std::vector<ImageCorrespondences> images(3);
  images[0].image_name = "cam0/frame 0000.png";  // a space in the name
  images[1].image_name = "cam1/frame_0000.png";
  images[2].image_name = "cam1/empty.png";
  for (ImageCorrespondences& image : images) {
    image.width = 640;
    image.height = 480;
  }
  for (int i = 0; i < 2; ++i) {
    for (int k = 0; k < 200; ++k) {
      Correspondence c;
      c.point2D = Eigen::Vector2d(pixel(random), pixel(random));
      c.point3D = Eigen::Vector3d(world(random), world(random), 1e-7 * k);
      c.point3D_id = k % 3 == 0 ? -1 : 1000000000000LL + k;
      images[i].correspondences.push_back(c);
    }
  }
  images[0].correspondences[1].point3D = Eigen::Vector3d(-0.0, 1e300, 5e-324);

  testing::ScopedTempDir dir;
  const std::string path = dir.File("correspondences.txt");
  std::string error;
  ASSERT_TRUE(WriteCorrespondenceFile(path, images, &error)) << error;
  std::vector<ImageCorrespondences> read;
  ASSERT_TRUE(ReadCorrespondenceFile(path, &read, &error)) << error;
  ASSERT_EQ(read.size(), images.size());
  for (size_t i = 0; i < images.size(); ++i) {
    EXPECT_EQ(read[i].image_name, images[i].image_name);
    EXPECT_EQ(read[i].width, 640);
    EXPECT_EQ(read[i].height, 480);
    ASSERT_EQ(read[i].correspondences.size(), images[i].correspondences.size());
    for (size_t k = 0; k < images[i].correspondences.size(); ++k) {
      const Correspondence& a = images[i].correspondences[k];
      const Correspondence& b = read[i].correspondences[k];
      for (int d = 0; d < 2; ++d) {
        EXPECT_TRUE(SameBits(a.point2D(d), b.point2D(d)));
      }
      for (int d = 0; d < 3; ++d) {
        EXPECT_TRUE(SameBits(a.point3D(d), b.point3D(d)))
            << a.point3D(d) << " " << b.point3D(d);
      }
      EXPECT_EQ(a.point3D_id, b.point3D_id);
    }
  }
}

TEST(CorrespondenceIo, ReadsTheDesignExample) {
  testing::ScopedTempDir dir;
  const std::string path = dir.File("c.txt");
  WriteText(path,
            "# rig_calibrator 2D-3D correspondences\r\n"
            "# IMAGE <image_name> <width> <height> <num_rows>, then ...\n"
            "IMAGE cam0/frame_0000.png 640 480 2\n"
            "312.41 220.13 1.2340 -0.5500 4.2100 1234\n"
            "\n"
            "# a comment between rows\n"
            "\t1 2 3 4 5\n");
  std::vector<ImageCorrespondences> images;
  std::string error;
  ASSERT_TRUE(ReadCorrespondenceFile(path, &images, &error)) << error;
  ASSERT_EQ(images.size(), 1u);
  ASSERT_EQ(images[0].correspondences.size(), 2u);
  EXPECT_EQ(images[0].correspondences[0].point2D,
            Eigen::Vector2d(312.41, 220.13));
  EXPECT_EQ(images[0].correspondences[0].point3D,
            Eigen::Vector3d(1.234, -0.55, 4.21));
  EXPECT_EQ(images[0].correspondences[0].point3D_id, 1234);
  EXPECT_EQ(images[0].correspondences[1].point3D_id, -1);
}

TEST(CorrespondenceIo, MalformedFilesGiveLineNumbers) {
  testing::ScopedTempDir dir;
  const std::string path = dir.File("bad.txt");
  const std::string header = "# header\nIMAGE a.png 640 480 2\n";
  EXPECT_EQ(
      ReadError(path, header + "1 2 3 4\n5 6 7 8 9\n"),
      "file " + path + " line 3: expected 5 or 6 numbers, found 4 fields");
  EXPECT_EQ(ReadError(path, header + "1 2 3 4 5\n1 2 x 4 5\n"),
            "file " + path + " line 4: field 3 'x' is not a finite number");
  EXPECT_EQ(ReadError(path, header + "1 2 3 4 5\n1 2 nan 4 5\n"),
            "file " + path + " line 4: field 3 'nan' is not a finite number");
  EXPECT_EQ(ReadError(path, header + "1 2 3 4 5 6.5\n"),
            "file " + path +
                " line 3: the point3D_id '6.5' is not an integer "
                ">= -1");
  EXPECT_EQ(ReadError(path, header + "1 2 3 4 5\n"),
            "file " + path +
                " line 3: the file ends but image a.png (line 2) "
                "declares 2 rows");
  EXPECT_EQ(ReadError(path, header + "1 2 3 4 5\nIMAGE b.png 1 1 0\n"),
            "file " + path +
                " line 4: image a.png (line 2) declares 2 rows "
                "but has only 1");
  EXPECT_EQ(ReadError(path, header + "1 2 3 4 5\n1 2 3 4 5\n1 2 3 4 5\n"),
            "file " + path +
                " line 5: image a.png (line 2) declares 2 rows, "
                "but there are more");
  EXPECT_EQ(ReadError(path, "1 2 3 4 5\n"),
            "file " + path +
                " line 1: expected an IMAGE line before the "
                "first row");
  EXPECT_EQ(ReadError(path, "IMAGE a.png 640 0 0\n"),
            "file " + path + " line 1: the image size must be positive");
  EXPECT_EQ(ReadError(path, "IMAGE a.png 640 480\n"),
            "file " + path +
                " line 1: expected IMAGE <image_name> <width> "
                "<height> <num_rows>");
  EXPECT_EQ(ReadError(path, "IMAGE a.png 640 480 0\nIMAGE a.png 640 480 0\n"),
            "file " + path + " line 2: the image a.png appears twice");
  std::vector<ImageCorrespondences> images;
  std::string error;
  EXPECT_FALSE(
      ReadCorrespondenceFile(dir.File("missing.txt"), &images, &error));
}

TEST(CorrespondenceIo, RefusesUnwritableNamesAndKeepsOldFile) {
  testing::ScopedTempDir dir;
  const std::string path = dir.File("c.txt");
  WriteText(path, "old");
  std::vector<ImageCorrespondences> images(1);
  images[0].image_name = "bad\nname.png";
  images[0].width = 10;
  images[0].height = 10;
  std::string error;
  EXPECT_FALSE(WriteCorrespondenceFile(path, images, &error));
  images[0].image_name = " leading.png";
  EXPECT_FALSE(WriteCorrespondenceFile(path, images, &error));
  std::ifstream file(path);
  std::string contents((std::istreambuf_iterator<char>(file)),
                       std::istreambuf_iterator<char>());
  EXPECT_EQ(contents, "old");
}

TEST(CorrespondenceIo, DatasetCorrespondencesTakeTheCameraSize) {
  RigDataset dataset;
  dataset.cameras.resize(2);
  dataset.cameras[1].camera.InitializeWithName("PINHOLE", 500, 752, 480);
  RigImage image;
  image.name = "cam1/1.png";
  image.camera_index = 1;
  image.correspondences.resize(3);
  dataset.images.push_back(image);
  const std::vector<ImageCorrespondences> images =
      DatasetCorrespondences(dataset);
  ASSERT_EQ(images.size(), 1u);
  EXPECT_EQ(images[0].image_name, "cam1/1.png");
  EXPECT_EQ(images[0].width, 752);
  EXPECT_EQ(images[0].height, 480);
  EXPECT_EQ(images[0].correspondences.size(), 3u);
}

}  // namespace correspondence_io_test
}  // namespace rig_calibrator
