#include "colmap_ext/commands/render_command.h"

#include <colmap/base/reconstruction.h>
#include <gtest/gtest.h>

#include <boost/filesystem.hpp>
#include <fstream>
#include <sstream>

#include "colmap_ext/io/rig_config_io.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace {

namespace fs = boost::filesystem;

std::vector<std::string> Lines(const std::string& path) {
  std::ifstream file(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(file, line);) lines.push_back(line);
  return lines;
}

// A small dataset: the stereo pair, 3 map images, 2 framesets, one sample per
// pixel.
struct SmallDataset {
  RenderedDatasetOptions options;
  RenderedDatasetPlan plan;
  RenderOptions render;
  SmallDataset() {
    options.preset = RigPreset::kStereoPair;
    options.num_map_images = 3;
    options.num_framesets = 2;
    options.seed = 4;
    render.supersampling = 1;
    std::string error;
    EXPECT_TRUE(PlanRenderedDataset(options, &plan, &error)) << error;
  }
};

TEST(RenderCommand, WritesImagesAndExactGroundTruth) {
  const SmallDataset dataset;
  testing::ScopedTempDir temp;
  const std::string out = temp.File("dataset");
  std::string error;
  ASSERT_TRUE(WriteRenderedDataset(dataset.options, dataset.plan,
                                   dataset.render, out, false, &error))
      << error;

  // Images: named as planned, of the cameras' sizes, equal to a fresh
  // rendering with the same noise seed as the writer's (seed << 32 + index).
  for (const std::string& name : dataset.plan.map_image_names) {
    EXPECT_TRUE(fs::is_regular_file(out + "/map_images/" + name)) << name;
  }
  colmap::Bitmap written;
  ASSERT_TRUE(written.Read(out + "/map_images/map_000001.png", true));
  const colmap::Bitmap expected = RenderImage(
      dataset.plan.scene, dataset.plan.map_camera,
      dataset.plan.map_cam_from_world[1], dataset.render, (4ull << 32) + 1);
  EXPECT_EQ(written.ConvertToRowMajorArray(),
            expected.ConvertToRowMajorArray());
  for (int c = 0; c < 2; ++c) {
    for (int f = 0; f < 2; ++f) {
      colmap::Bitmap image;
      ASSERT_TRUE(image.Read(
          out + "/rig_images/" + dataset.plan.RigImageName(c, f), true));
      EXPECT_EQ(image.Width(), dataset.plan.rig.cameras[c].Width());
      EXPECT_EQ(image.Height(), dataset.plan.rig.cameras[c].Height());
    }
  }

  // Map camera and positions (the format of colmap model_aligner).
  const std::string truth = out + "/ground_truth/";
  const std::vector<std::string> camera_lines = Lines(truth + "map_camera.txt");
  ASSERT_EQ(camera_lines.size(), 2u);
  EXPECT_EQ(camera_lines[1], "PINHOLE 640 480 400,400,320,240");
  const std::vector<std::string> positions =
      Lines(truth + "map_image_positions.txt");
  ASSERT_EQ(positions.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    std::istringstream line(positions[i]);
    std::string name;
    Eigen::Vector3d center;
    line >> name >> center.x() >> center.y() >> center.z();
    EXPECT_EQ(name, dataset.plan.map_image_names[i]);
    EXPECT_EQ(center, dataset.plan.map_cam_from_world[i].Center());
  }

  // The true rig, read back exactly.
  std::vector<RigDescription> rigs;
  ASSERT_TRUE(ReadRigConfigJson(truth + "rig_config.json", &rigs, &error))
      << error;
  ASSERT_EQ(rigs.size(), 1u);
  ASSERT_EQ(rigs[0].cameras.size(), 2u);
  EXPECT_EQ(rigs[0].reference_camera, 0);
  for (int c = 0; c < 2; ++c) {
    const RigDescriptionCamera& camera = rigs[0].cameras[c];
    EXPECT_EQ(camera.image_prefix, "cam" + std::to_string(c) + "/");
    ASSERT_TRUE(camera.camera.has_value());
    EXPECT_EQ(camera.camera->ModelName(),
              dataset.plan.rig.cameras[c].ModelName());
    EXPECT_EQ(camera.camera->Params(), dataset.plan.rig.cameras[c].Params());
  }
  ASSERT_TRUE(rigs[0].cameras[1].cam_from_rig.has_value());
  EXPECT_EQ(rigs[0].cameras[1].cam_from_rig->translation,
            dataset.plan.rig.cam_from_rig[1].translation);
  EXPECT_NEAR(RotationDifferenceDeg(rigs[0].cameras[1].cam_from_rig->rotation,
                                    dataset.plan.rig.cam_from_rig[1].rotation),
              0, 1e-9);

  // rig_from_world per frameset and the true poses as COLMAP models.
  const std::vector<std::string> rig_poses =
      Lines(truth + "rig_from_world.txt");
  ASSERT_EQ(rig_poses.size(), 3u);
  EXPECT_EQ(rig_poses[2].substr(0, 7), "000001 ");
  colmap::Reconstruction rig_model;
  rig_model.ReadText(truth + "rig_model");
  ASSERT_EQ(rig_model.NumRegImages(), 4u);
  const colmap::Image* image = rig_model.FindImageWithName("cam1/000001.png");
  ASSERT_NE(image, nullptr);
  const Rigid3d cam_from_world =
      dataset.plan.rig.cam_from_rig[1] * dataset.plan.rig.rig_from_world[1];
  EXPECT_NEAR((image->Tvec() - cam_from_world.translation).norm(), 0, 1e-12);
  EXPECT_NEAR(rig_model.Camera(image->CameraId()).Params(0),
              dataset.plan.rig.cameras[1].Params(0), 1e-12);
  colmap::Reconstruction map_model;
  map_model.ReadText(truth + "map_model");
  EXPECT_EQ(map_model.NumRegImages(), 3u);

  bool found_models = false;
  for (const std::string& line : Lines(truth + "dataset.txt")) {
    found_models |= line == "camera_models cam0:OPENCV,cam1:OPENCV";
  }
  EXPECT_TRUE(found_models);

  // A second run into the same folder needs overwrite.
  EXPECT_FALSE(WriteRenderedDataset(dataset.options, dataset.plan,
                                    dataset.render, out, false, &error));
  EXPECT_NE(error.find("not empty"), std::string::npos) << error;
}

TEST(RenderCommand, CommandLineErrorsFailCleanly) {
  testing::ScopedTempDir temp;
  const std::string out = temp.File("dataset");
  auto run = [](std::vector<std::string> args) {
    args.insert(args.begin(), "rig_calibrator");
    std::vector<char*> argv;
    for (std::string& arg : args) argv.push_back(arg.data());
    return RunRender(static_cast<int>(argv.size()), argv.data());
  };
  EXPECT_EQ(run({"--output_path", out, "--preset", "ring6"}), EXIT_FAILURE);
  EXPECT_EQ(run({"--output_path", out, "--scene", "garden"}), EXIT_FAILURE);
  EXPECT_EQ(run({"--output_path", out, "--num_map_images", "1"}), EXIT_FAILURE);
  EXPECT_EQ(run({"--output_path", out, "--supersampling", "0"}), EXIT_FAILURE);
  EXPECT_EQ(run({"--preset", "ring5"}), EXIT_FAILURE);  // no output path
  EXPECT_EQ(run({"--help"}), EXIT_SUCCESS);
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace rig_calibrator
