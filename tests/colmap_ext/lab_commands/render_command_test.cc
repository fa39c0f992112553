#include "colmap_ext/lab_commands/render_command.h"

#include <colmap/base/reconstruction.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <boost/filesystem.hpp>
#include <cmath>
#include <fstream>
#include <memory>
#include <sstream>

#include "colmap_ext/io/rig_config_io.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace render_command_test {

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

// The small dataset written into a temporary folder (ctest runs every test
// in its own process, so a suite-wide setup would not render it less often).
class RenderCommandOutput : public ::testing::Test {
 protected:
  void SetUp() override {
    out_ = temp_.File("dataset");
    truth_ = out_ + "/ground_truth/";
    ASSERT_TRUE(WriteRenderedDataset(dataset_->options, dataset_->plan,
                                     dataset_->render, out_, false, &error_))
        << error_;
  }

  const std::unique_ptr<const SmallDataset> dataset_ =
      std::make_unique<const SmallDataset>();
  testing::ScopedTempDir temp_;
  std::string out_;
  std::string truth_;
  std::string error_;
};

// Images: named as planned, of the cameras' sizes, equal to a fresh
// rendering with the same noise seed as the writer's (seed << 32 + index).
TEST_F(RenderCommandOutput, WritesTheRenderedImages) {
  for (const std::string& name : dataset_->plan.map_image_names) {
    EXPECT_TRUE(fs::is_regular_file(out_ + "/map_images/" + name)) << name;
  }
  colmap::Bitmap written;
  ASSERT_TRUE(written.Read(out_ + "/map_images/map_000001.png", true));
  const colmap::Bitmap expected = RenderImage(
      dataset_->plan.scene, dataset_->plan.map_camera,
      dataset_->plan.map_cam_from_world[1], dataset_->render, (4ull << 32) + 1);
  EXPECT_EQ(written.ConvertToRowMajorArray(),
            expected.ConvertToRowMajorArray());
  for (int c = 0; c < 2; ++c) {
    for (int f = 0; f < 2; ++f) {
      colmap::Bitmap image;
      ASSERT_TRUE(image.Read(
          out_ + "/rig_images/" + dataset_->plan.RigImageName(c, f), true));
      EXPECT_EQ(image.Width(), dataset_->plan.rig.cameras[c].Width());
      EXPECT_EQ(image.Height(), dataset_->plan.rig.cameras[c].Height());
    }
  }
}

// Map camera and positions (the format of colmap model_aligner).
TEST_F(RenderCommandOutput, WritesTheMapGroundTruth) {
  const std::vector<std::string> camera_lines =
      Lines(truth_ + "map_camera.txt");
  ASSERT_EQ(camera_lines.size(), 2u);
  EXPECT_EQ(camera_lines[1], "PINHOLE 640 480 400,400,320,240");
  const std::vector<std::string> positions =
      Lines(truth_ + "map_image_positions.txt");
  ASSERT_EQ(positions.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    std::istringstream line(positions[i]);
    std::string name;
    Eigen::Vector3d center;
    line >> name >> center.x() >> center.y() >> center.z();
    EXPECT_EQ(name, dataset_->plan.map_image_names[i]);
    EXPECT_EQ(center, dataset_->plan.map_cam_from_world[i].Center());
  }
}

// The true rig, read back exactly.
TEST_F(RenderCommandOutput, WritesTheTrueRig) {
  std::vector<RigDescription> rigs;
  ASSERT_TRUE(ReadRigConfigJson(truth_ + "rig_config.json", &rigs, &error_))
      << error_;
  ASSERT_EQ(rigs.size(), 1u);
  ASSERT_EQ(rigs[0].cameras.size(), 2u);
  EXPECT_EQ(rigs[0].reference_camera, 0);
  for (int c = 0; c < 2; ++c) {
    const RigDescriptionCamera& camera = rigs[0].cameras[c];
    EXPECT_EQ(camera.image_prefix, "cam" + std::to_string(c) + "/");
    ASSERT_TRUE(camera.camera.has_value());
    EXPECT_EQ(camera.camera->ModelName(),
              dataset_->plan.rig.cameras[c].ModelName());
    EXPECT_EQ(camera.camera->Params(), dataset_->plan.rig.cameras[c].Params());
  }
  ASSERT_TRUE(rigs[0].cameras[1].cam_from_rig.has_value());
  EXPECT_EQ(rigs[0].cameras[1].cam_from_rig->translation,
            dataset_->plan.rig.cam_from_rig[1].translation);
  EXPECT_NEAR(
      RotationDifferenceDeg(rigs[0].cameras[1].cam_from_rig->rotation,
                            dataset_->plan.rig.cam_from_rig[1].rotation),
      0, 1e-9);
  // Without a time model there is no time_model.json.
  EXPECT_FALSE(fs::exists(truth_ + "time_model.json"));
}

// rig_from_world per frameset and the true poses as COLMAP models.
TEST_F(RenderCommandOutput, WritesTheTruePoses) {
  const RenderedDatasetPlan& plan = dataset_->plan;
  // A header line, then "<frameset> qw qx qy qz tx ty tz" per frameset, each
  // number read back bit for bit.
  const std::vector<std::string> rig_poses =
      Lines(truth_ + "rig_from_world.txt");
  ASSERT_EQ(rig_poses.size(), 1 + plan.frameset_names.size());
  for (size_t f = 0; f < plan.frameset_names.size(); ++f) {
    std::istringstream line(rig_poses[1 + f]);
    std::string name;
    Eigen::Vector4d qvec;
    Eigen::Vector3d tvec;
    line >> name >> qvec(0) >> qvec(1) >> qvec(2) >> qvec(3) >> tvec(0) >>
        tvec(1) >> tvec(2);
    ASSERT_FALSE(line.fail()) << rig_poses[1 + f];
    EXPECT_EQ(name, plan.frameset_names[f]);
    EXPECT_EQ(qvec, plan.rig.rig_from_world[f].Qvec());
    EXPECT_EQ(tvec, plan.rig.rig_from_world[f].translation);
  }
  // Every rig image at cam_from_rig * rig_from_world, with its camera.
  colmap::Reconstruction rig_model;
  rig_model.ReadText(truth_ + "rig_model");
  ASSERT_EQ(rig_model.NumRegImages(), 4u);
  for (int c = 0; c < 2; ++c) {
    for (int f = 0; f < 2; ++f) {
      const colmap::Image* image =
          rig_model.FindImageWithName(plan.RigImageName(c, f));
      ASSERT_NE(image, nullptr) << plan.RigImageName(c, f);
      const Rigid3d expected =
          plan.rig.cam_from_rig[c] * plan.rig.rig_from_world[f];
      const Rigid3d actual =
          Rigid3d::FromQvecTvec(image->Qvec(), image->Tvec());
      EXPECT_LT((actual.ToMatrix() - expected.ToMatrix()).norm(), 1e-12);
      const colmap::Camera& camera = rig_model.Camera(image->CameraId());
      EXPECT_EQ(camera.ModelName(), plan.rig.cameras[c].ModelName());
      for (size_t k = 0; k < camera.NumParams(); ++k) {
        EXPECT_NEAR(camera.Params(k), plan.rig.cameras[c].Params(k),
                    1e-12 * std::max(1.0, std::abs(camera.Params(k))));
      }
    }
  }
  colmap::Reconstruction map_model;
  map_model.ReadText(truth_ + "map_model");
  ASSERT_EQ(map_model.NumRegImages(), 3u);
  for (size_t i = 0; i < plan.map_image_names.size(); ++i) {
    const colmap::Image* image =
        map_model.FindImageWithName(plan.map_image_names[i]);
    ASSERT_NE(image, nullptr) << plan.map_image_names[i];
    const Rigid3d actual = Rigid3d::FromQvecTvec(image->Qvec(), image->Tvec());
    EXPECT_LT(
        (actual.ToMatrix() - plan.map_cam_from_world[i].ToMatrix()).norm(),
        1e-12);
  }

  bool found_models = false;
  for (const std::string& line : Lines(truth_ + "dataset.txt")) {
    found_models |= line == "camera_models cam0:OPENCV,cam1:OPENCV";
  }
  EXPECT_TRUE(found_models);
}

TEST_F(RenderCommandOutput, ASecondRunIntoTheFolderNeedsOverwrite) {
  EXPECT_FALSE(WriteRenderedDataset(dataset_->options, dataset_->plan,
                                    dataset_->render, out_, false, &error_));
  EXPECT_NE(error_.find("not empty"), std::string::npos) << error_;
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

// With a time model (offsets only: the stereo pair's cam1 30 ms late): the
// images are named by their capture times, cam1's image is the
// global-shutter image at t_f + 30 ms, and the ground truth holds the times
// and the tolerance that groups the framesets.
TEST(RenderCommand, TimeModelRendersEachImageAtItsCaptureTime) {
  SmallDataset dataset;
  dataset.options.time_model.frameset_rate_hz = 5;
  // Slow enough for the room's small loop (rendered_dataset.h).
  dataset.options.time_model.speed_m_s = 0.5;
  dataset.options.time_model.time_offsets_s = {0, 0.03};
  std::string error;
  ASSERT_TRUE(PlanRenderedDataset(dataset.options, &dataset.plan, &error))
      << error;
  testing::ScopedTempDir temp;
  const std::string out = temp.File("dataset");
  ASSERT_TRUE(WriteRenderedDataset(dataset.options, dataset.plan,
                                   dataset.render, out, false, &error))
      << error;
  const RenderedDatasetPlan& plan = dataset.plan;
  EXPECT_EQ(plan.RigImageName(1, 1), "cam1/430000000.png");
  colmap::Bitmap written;
  ASSERT_TRUE(written.Read(out + "/rig_images/cam1/430000000.png", true));
  const Rigid3d at_capture_time =
      plan.RigImageCapture(1, 1).CamFromWorldAt(0.4 + 0.03);
  const uint64_t noise_seed = (4ull << 32) + 0x80000000ull + 1 * 2 + 1;
  EXPECT_EQ(written.ConvertToRowMajorArray(),
            RenderImage(plan.scene, plan.rig.cameras[1], at_capture_time,
                        dataset.render, noise_seed)
                .ConvertToRowMajorArray());
  EXPECT_TRUE(fs::is_regular_file(out + "/rig_images/cam0/400000000.png"));

  const std::vector<std::string> summary =
      Lines(out + "/ground_truth/dataset.txt");
  EXPECT_NE(std::find(summary.begin(), summary.end(),
                      "timestamp_tolerance_ns 100000000"),
            summary.end());
  std::ifstream json_file(out + "/ground_truth/time_model.json");
  std::stringstream json;
  json << json_file.rdbuf();
  EXPECT_NE(json.str().find("\"time_offset_s\": 0.03"), std::string::npos)
      << json.str();
  EXPECT_NE(json.str().find("\"name\": \"400000000\""), std::string::npos);
  // The rig model's image pose is the image's (its top row's).
  colmap::Reconstruction rig_model;
  rig_model.ReadText(out + "/ground_truth/rig_model");
  const colmap::Image* image = rig_model.FindImageWithName(
      "cam1/430000000.png");
  ASSERT_NE(image, nullptr);
  EXPECT_LT((image->Tvec() - at_capture_time.translation).norm(), 1e-9);
}

TEST(RenderCommand, TimeModelOptionErrorsNameTheOption) {
  testing::ScopedTempDir temp;
  const std::string out = temp.File("dataset");
  auto run = [&](std::vector<std::string> args) {
    args.insert(args.begin(), {"rig_calibrator", "--output_path", out,
                               "--preset", "stereo_pair",
                               "--num_map_images", "3", "--num_framesets",
                               "1"});
    std::vector<char*> argv;
    for (std::string& arg : args) argv.push_back(arg.data());
    return RunRender(static_cast<int>(argv.size()), argv.data());
  };
  EXPECT_EQ(run({"--frameset_rate_hz", "5", "--line_delay_us", "20,x"}),
            EXIT_FAILURE);
  EXPECT_EQ(run({"--line_delay_us", "20"}), EXIT_FAILURE);  // no rate
  EXPECT_EQ(run({"--frameset_rate_hz", "10", "--max_time_offset_ms", "50"}),
            EXIT_FAILURE);
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace render_command_test
}  // namespace rig_calibrator
