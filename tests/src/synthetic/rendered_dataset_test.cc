#include "src/synthetic/rendered_dataset.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

namespace rig_calibrator {
namespace rendered_dataset_test {

RenderedDatasetOptions Options(RigPreset preset, SceneType scene) {
  RenderedDatasetOptions options;
  options.preset = preset;
  options.scene = scene;
  options.seed = 11;
  return options;
}

// Fraction of a camera's view (a coarse grid of pixel rays) that hits the
// scene rather than the sky.
double SurfaceFraction(const TexturedScene& scene, const colmap::Camera& camera,
                       const Rigid3d& cam_from_world) {
  int num_hits = 0;
  int num_rays = 0;
  for (double y = 0.5; y < camera.Height(); y += camera.Height() / 12.0) {
    for (double x = 0.5; x < camera.Width(); x += camera.Width() / 16.0) {
      const Eigen::Vector3d ray =
          cam_from_world.rotation.conjugate() *
          camera.ImageToWorld(Eigen::Vector2d(x, y)).homogeneous().normalized();
      SceneHit hit;
      num_hits += scene.Intersect(cam_from_world.Center(), ray, &hit);
      ++num_rays;
    }
  }
  return static_cast<double>(num_hits) / num_rays;
}

TEST(RenderedDataset, EveryRigFitsEveryScene) {
  for (const SceneType scene : AllSceneTypes()) {
    for (const RigPreset preset : AllRigPresets()) {
      RenderedDatasetPlan plan;
      std::string error;
      ASSERT_TRUE(PlanRenderedDataset(Options(preset, scene), &plan, &error))
          << SceneTypeName(scene) << " " << RigPresetName(preset) << ": "
          << error;
      ASSERT_EQ(plan.map_image_names.size(), 60u);
      ASSERT_EQ(plan.map_cam_from_world.size(), 60u);
      ASSERT_EQ(plan.rig.rig_from_world.size(), 12u);
      ASSERT_EQ(plan.frameset_names.size(), 12u);
      EXPECT_EQ(plan.RigImageName(1, 3), "cam1/000003.png");
      EXPECT_EQ(plan.map_image_names[7], "map_000007.png");
      // The rig frame is the reference camera's.
      EXPECT_NEAR(plan.rig.cam_from_rig[0].translation.norm(), 0, 1e-12);
      for (const Rigid3d& rig_from_world : plan.rig.rig_from_world) {
        for (size_t c = 0; c < plan.rig.cameras.size(); ++c) {
          const Rigid3d cam_from_world =
              plan.rig.cam_from_rig[c] * rig_from_world;
          EXPECT_TRUE(plan.scene.IsFree(cam_from_world.Center(), 0.25));
          // Outdoors some cameras look up at the sky, but most of each view
          // is textured.
          EXPECT_GT(
              SurfaceFraction(plan.scene, plan.rig.cameras[c], cam_from_world),
              0.5);
        }
      }
    }
  }
}

// Consecutive map images differ by bounded steps (sequential matching needs
// overlap), the loop closes, and the views cover every heading.
TEST(RenderedDataset, MapSequenceOverlapsAndCoversTheScene) {
  for (const SceneType scene : AllSceneTypes()) {
    RenderedDatasetPlan plan;
    std::string error;
    ASSERT_TRUE(
        PlanRenderedDataset(Options(RigPreset::kRing5, scene), &plan, &error))
        << error;
    const int n = static_cast<int>(plan.map_cam_from_world.size());
    std::set<int> heading_sectors;
    for (int i = 0; i < n; ++i) {
      const Rigid3d& pose = plan.map_cam_from_world[i];
      const Rigid3d& next = plan.map_cam_from_world[(i + 1) % n];
      EXPECT_LT((pose.Center() - next.Center()).norm(),
                scene == SceneType::kRoom ? 0.4 : 2.0)
          << SceneTypeName(scene) << " image " << i;
      EXPECT_LT(RotationDifferenceDeg(pose.rotation, next.rotation), 20.0)
          << SceneTypeName(scene) << " image " << i;
      EXPECT_TRUE(plan.scene.IsFree(pose.Center(), 0.25));
      EXPECT_GT(SurfaceFraction(plan.scene, plan.map_camera, pose), 0.7);
      const Eigen::Vector3d view =
          pose.rotation.conjugate() * Eigen::Vector3d::UnitZ();
      heading_sectors.insert(static_cast<int>(
          std::floor((std::atan2(view.y(), view.x()) + M_PI) / (M_PI / 4))));
    }
    EXPECT_EQ(heading_sectors.size(), 8u) << SceneTypeName(scene);
  }
}

TEST(RenderedDataset, DeterministicForASeed) {
  RenderedDatasetPlan first, second, other;
  std::string error;
  RenderedDatasetOptions options =
      Options(RigPreset::kFisheyeHelmet5, SceneType::kCourtyard);
  ASSERT_TRUE(PlanRenderedDataset(options, &first, &error));
  ASSERT_TRUE(PlanRenderedDataset(options, &second, &error));
  options.seed = 12;
  ASSERT_TRUE(PlanRenderedDataset(options, &other, &error));
  for (size_t j = 0; j < first.rig.rig_from_world.size(); ++j) {
    EXPECT_EQ(first.rig.rig_from_world[j].Qvec(),
              second.rig.rig_from_world[j].Qvec());
    EXPECT_EQ(first.rig.rig_from_world[j].translation,
              second.rig.rig_from_world[j].translation);
  }
  EXPECT_NE(first.rig.rig_from_world[0].translation,
            other.rig.rig_from_world[0].translation);
}

TEST(RenderedDataset, RejectsInvalidOptions) {
  RenderedDatasetPlan plan;
  std::string error;
  RenderedDatasetOptions options;
  options.num_map_images = 2;
  EXPECT_FALSE(PlanRenderedDataset(options, &plan, &error));
  EXPECT_NE(error.find("num_map_images"), std::string::npos);
  options = RenderedDatasetOptions();
  options.map_focal_length = -1;
  EXPECT_FALSE(PlanRenderedDataset(options, &plan, &error));
  EXPECT_NE(error.find("map_focal_length"), std::string::npos);
  options = RenderedDatasetOptions();
  options.rig_height = 2.95;  // cameras in the room's ceiling
  EXPECT_FALSE(PlanRenderedDataset(options, &plan, &error));
  EXPECT_NE(error.find("would stand in a wall"), std::string::npos) << error;
}

// The helmet with a time model at 5 Hz: offsets in +-50 ms, 20-30 us per row.
RenderedDatasetOptions TimeModelOptions() {
  RenderedDatasetOptions options =
      Options(RigPreset::kFisheyeHelmet5, SceneType::kCourtyard);
  options.num_framesets = 4;
  options.time_model.frameset_rate_hz = 5;
  options.time_model.max_time_offset_s = 0.05;
  options.time_model.min_line_delay_s = 20e-6;
  options.time_model.max_line_delay_s = 30e-6;
  return options;
}

// The rig moves on one continuous trajectory: at t_f it is at
// rig_from_world[f], it walks the courtyard's loop (0.65 times the walk
// ellipse) at 1.5 m/s between framesets, its heading never turns faster than
// 60 deg/s, and images are named by their capture times. In the room the
// loop alone turns too fast for 1.5 m/s and 60 deg/s: refused, naming the
// courtyard.
TEST(RenderedDataset, TimeModelFollowsOneTrajectoryThroughTheFramesets) {
  RenderedDatasetPlan plan;
  std::string error;
  RenderedDatasetOptions options = TimeModelOptions();
  options.num_framesets = 20;
  ASSERT_TRUE(PlanRenderedDataset(options, &plan, &error)) << error;
  ASSERT_TRUE(plan.HasTimeModel());
  const RigGroundTruth& rig = plan.rig;
  ASSERT_EQ(rig.time_offsets_s.size(), 5u);
  EXPECT_EQ(rig.time_offsets_s[0], 0);
  for (int c = 0; c < 5; ++c) {
    EXPECT_LE(std::abs(rig.time_offsets_s[c]), 0.05);
    EXPECT_GE(rig.line_delays_s[c], 20e-6);
    EXPECT_LE(rig.line_delays_s[c], 30e-6);
  }
  EXPECT_NE(rig.time_offsets_s[1], 0);
  EXPECT_EQ(plan.TimestampTolerance(), 1e8);  // half of 200 ms, in ns
  const SceneWalk& walk = plan.scene.walk();
  const Rigid3d rig_from_body = rig.body_from_rig.Inverse();
  for (int f = 0; f < options.num_framesets; ++f) {
    const double time_s = (f + 1) / 5.0;
    EXPECT_DOUBLE_EQ(rig.frameset_times_s[f], time_s);
    EXPECT_EQ(plan.frameset_names[f], Timestamp(time_s));
    for (int c = 0; c < 5; ++c) {
      EXPECT_EQ(plan.RigImageName(c, f),
                "cam" + std::to_string(c) + "/" +
                    Timestamp(time_s + rig.time_offsets_s[c]) + ".png");
      const Rigid3d planned = rig.cam_from_rig[c] * rig.rig_from_world[f];
      const Rigid3d at_frameset_time =
          plan.RigImageCapture(c, f).CamFromWorldAt(time_s);
      EXPECT_LT(RotationDifferenceRad(at_frameset_time.rotation,
                                      planned.rotation),
                1e-12);
      EXPECT_LT((at_frameset_time.translation - planned.translation).norm(),
                1e-12);
    }
    // The body (the cameras' mean centre) on the loop.
    const Rigid3d world_from_body =
        rig.rig_from_world[f].Inverse() * rig_from_body;
    const Eigen::Vector2d on_unit_circle =
        (world_from_body.translation.head<2>() - walk.center)
            .cwiseQuotient(0.65 * walk.radii);
    EXPECT_NEAR(on_unit_circle.norm(), 1, 1e-9);
    if (f == 0) continue;
    // A frameset period apart: 0.3 m of walk (a chord of it), and the
    // heading turned by at most 60 deg/s * 0.2 s.
    const Rigid3d previous =
        rig.rig_from_world[f - 1].Inverse() * rig_from_body;
    const double step_m =
        (world_from_body.translation - previous.translation).head<2>().norm();
    EXPECT_LT(step_m, 0.3 + 1e-9);
    EXPECT_GT(step_m, 0.29);
    const Eigen::Vector3d forward = world_from_body.rotation * Eigen::Vector3d::UnitX();
    const Eigen::Vector3d previous_forward =
        previous.rotation * Eigen::Vector3d::UnitX();
    const double heading_step_deg =
        std::abs(std::remainder(std::atan2(forward.y(), forward.x()) -
                                    std::atan2(previous_forward.y(),
                                               previous_forward.x()),
                                2 * M_PI)) *
        180 / M_PI;
    EXPECT_LT(heading_step_deg, 12 + 1e-9) << f;
  }
  options.scene = SceneType::kRoom;
  EXPECT_FALSE(PlanRenderedDataset(options, &plan, &error));
  EXPECT_NE(error.find("courtyard"), std::string::npos) << error;
  options.time_model.speed_m_s = 0.5;  // 31.5 deg/s of the room's loop
  EXPECT_TRUE(PlanRenderedDataset(options, &plan, &error)) << error;
  EXPECT_EQ(Timestamp(1.2), "1200000000");
  // Without a time model: no times, the frameset names of earlier versions.
  ASSERT_TRUE(PlanRenderedDataset(
      Options(RigPreset::kFisheyeHelmet5, SceneType::kRoom), &plan, &error));
  EXPECT_FALSE(plan.HasTimeModel());
  EXPECT_EQ(plan.frameset_names[0], "000000");
  EXPECT_EQ(plan.RigImageName(1, 0), "cam1/000000.png");
}

TEST(RenderedDataset, RejectsInvalidTimeModels) {
  RenderedDatasetPlan plan;
  std::string error;
  RenderedDatasetOptions options = TimeModelOptions();
  options.time_model.frameset_rate_hz = 10;  // +-50 ms > 100 ms / 4
  EXPECT_FALSE(PlanRenderedDataset(options, &plan, &error));
  EXPECT_NE(error.find("quarter of the frameset period"), std::string::npos)
      << error;
  options = TimeModelOptions();
  options.time_model.frameset_rate_hz = 0;  // line delays without times
  EXPECT_FALSE(PlanRenderedDataset(options, &plan, &error));
  EXPECT_NE(error.find("frameset_rate_hz > 0"), std::string::npos) << error;
  options = TimeModelOptions();
  options.time_model.max_time_offset_s = 0;
  options.time_model.time_offsets_s = {0, 0.01};  // 2 of 5 cameras
  EXPECT_FALSE(PlanRenderedDataset(options, &plan, &error));
  EXPECT_NE(error.find("time_offsets_s"), std::string::npos) << error;
}

}  // namespace rendered_dataset_test
}  // namespace rig_calibrator
