// The map reader on maps of COLMAP 3.12 - 4.1: the real COLMAP 4.1.1 map of
// tests/data/colmap_4_1_1 (binary and text, with rigs and frames), cameras
// of models COLMAP 3.8 does not know, and rigs/frames that disagree with the
// images.
#include "colmap_ext/io/map_reader.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "colmap_ext/io/colmap_camera_models.h"
#include "colmap_ext/io/rigs_frames_io.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace map_reader_test {

namespace fs = std::filesystem;

std::string Colmap411Map(const std::string& folder) {
  return testing::SourceDir() + "/tests/data/colmap_4_1_1/map/" + folder;
}

class Colmap411MapTest : public ::testing::TestWithParam<std::string> {};

TEST_P(Colmap411MapTest, ReadsTheMapWithItsRigsAndFrames) {
  colmap::Reconstruction map;
  MapReadInfo info;
  std::string error;
  ASSERT_TRUE(ReadMap(Colmap411Map(GetParam()), &map, &info, &error)) << error;
  EXPECT_EQ(map.NumRegImages(), 30u);
  EXPECT_EQ(map.NumPoints3D(), 3840u);
  EXPECT_EQ(map.Camera(1).ModelName(), "PINHOLE");
  EXPECT_TRUE(info.has_rigs_frames);
  EXPECT_EQ(info.num_rigs, 1);
  EXPECT_EQ(info.num_multi_camera_rigs, 0);
  EXPECT_EQ(info.num_frames, 30);
  EXPECT_TRUE(info.newer_model_cameras.empty());
}

INSTANTIATE_TEST_SUITE_P(BinaryAndText, Colmap411MapTest,
                         ::testing::Values("sparse/0", "sparse_txt"),
                         [](const auto& info) {
                           return info.param == "sparse/0" ? "Binary" : "Text";
                         });

class MapCopyTest : public ::testing::Test {
 protected:
  // A copy of the COLMAP 4.1.1 map, binary or text.
  std::string CopyMap(const std::string& folder) {
    const std::string copy = temp_.File(fs::path(folder).filename().string());
    fs::copy(Colmap411Map(folder), copy);
    return copy;
  }

  testing::ScopedTempDir temp_;
};

TEST_F(MapCopyTest, HoldsCamerasOfNewerModelsAsPlaceholders) {
  for (const bool binary : {true, false}) {
    const std::string map_path = CopyMap(binary ? "sparse/0" : "sparse_txt");
    const std::string cameras_path =
        map_path + (binary ? "/cameras.bin" : "/cameras.txt");
    // The map camera as FISHEYE (COLMAP 4.0, fx, fy, cx, cy).
    CameraRecord fisheye;
    fisheye.camera_id = 1;
    fisheye.model_id = ColmapCameraModelIdFromName("FISHEYE");
    fisheye.width = 640;
    fisheye.height = 480;
    fisheye.params = {400, 401, 320, 240};
    std::string error;
    ASSERT_TRUE(WriteCameraRecords(cameras_path, binary, {fisheye}, &error))
        << error;

    colmap::Reconstruction map;
    MapReadInfo info;
    ASSERT_TRUE(ReadMap(map_path, &map, &info, &error)) << error;
    EXPECT_EQ(map.NumRegImages(), 30u);
    EXPECT_EQ(map.Camera(1).ModelName(), "PINHOLE");
    EXPECT_EQ(map.Camera(1).Width(), 640u);
    ASSERT_EQ(info.newer_model_cameras.size(), 1u);
    EXPECT_EQ(info.newer_model_cameras[0].params, fisheye.params);
    ASSERT_FALSE(info.notes.empty());
    EXPECT_NE(info.notes[0].find("1 FISHEYE (model id 15, COLMAP >= 4.0)"),
              std::string::npos)
        << info.notes[0];
    // No temporary folder is left behind and the map is unchanged.
    EXPECT_EQ(testing::ListFolder(map_path).size(), 5u);

    // Written back: COLMAP 3.8 writes the placeholder, RestoreNewerModel-
    // Cameras the real camera.
    const std::string written = temp_.File(binary ? "written" : "written_txt");
    fs::create_directories(written);
    if (binary) {
      map.WriteBinary(written);
    } else {
      map.WriteText(written);
    }
    ASSERT_TRUE(RestoreNewerModelCameras(written, binary,
                                         info.newer_model_cameras, &error))
        << error;
    std::vector<CameraRecord> cameras;
    ASSERT_TRUE(
        ReadCameraRecords(written + (binary ? "/cameras.bin" : "/cameras.txt"),
                          binary, &cameras, &error))
        << error;
    ASSERT_EQ(cameras.size(), 1u);
    EXPECT_EQ(cameras[0].model_id, 15);
    EXPECT_EQ(cameras[0].params, fisheye.params);
    if (binary) {
      EXPECT_EQ(testing::ReadBytes(written + "/cameras.bin"),
                testing::ReadBytes(cameras_path));
    }
  }
}

TEST_F(MapCopyTest, RejectsRigsAndFramesThatDisagreeWithTheImages) {
  const std::string map_path = CopyMap("sparse_txt");
  ColmapRigsAndFrames rigs_frames;
  std::string error;
  ASSERT_TRUE(ReadRigsAndFrames(map_path, &rigs_frames, &error)) << error;

  // A frame whose pose is not the image's.
  ColmapRigsAndFrames moved = rigs_frames;
  moved.frames[4].rig_from_world.translation.x() += 0.01;
  ASSERT_TRUE(WriteRigsAndFrames(map_path, moved, false, &error)) << error;
  colmap::Reconstruction map;
  EXPECT_FALSE(ReadMap(map_path, &map, &error));
  EXPECT_NE(error.find("the pose of image map_000004.png differs from "
                       "sensor_from_rig * rig_from_world of frame 5"),
            std::string::npos)
      << error;

  // An image in no frame.
  ColmapRigsAndFrames missing = rigs_frames;
  missing.frames.pop_back();
  ASSERT_TRUE(WriteRigsAndFrames(map_path, missing, false, &error)) << error;
  colmap::Reconstruction map2;
  EXPECT_FALSE(ReadMap(map_path, &map2, &error));
  EXPECT_NE(error.find("the image map_000029.png is in 0 frames"),
            std::string::npos)
      << error;

  // rigs.txt without frames.txt.
  fs::remove(map_path + "/frames.txt");
  colmap::Reconstruction map3;
  EXPECT_FALSE(ReadMap(map_path, &map3, &error));
  EXPECT_NE(error.find("has rigs.txt but no frames.txt"), std::string::npos)
      << error;

  // Without both files it is a COLMAP 3.8 model.
  fs::remove(map_path + "/rigs.txt");
  colmap::Reconstruction map4;
  MapReadInfo info;
  ASSERT_TRUE(ReadMap(map_path, &map4, &info, &error)) << error;
  EXPECT_FALSE(info.has_rigs_frames);
}

}  // namespace map_reader_test
}  // namespace rig_calibrator
