// The map's consistency check (map_consistency.h): one test per violation
// class, on a small model made consistent by COLMAP's own API and then broken
// the way an edited or merged model is.
#include "colmap_ext/io/map_consistency.h"

#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <string>

#include "tests/testing.h"

namespace rig_calibrator {
namespace map_consistency_test {

constexpr int kNumPoints = 4;

// One camera, three images with kNumPoints + 1 points2D each; point p
// (id p + 1) is points2D p of every image; the last points2D has no point.
colmap::Reconstruction ConsistentMap() {
  colmap::Reconstruction map;
  colmap::Camera camera;
  camera.InitializeWithName("SIMPLE_RADIAL", 500, 640, 480);
  camera.SetCameraId(1);
  map.AddCamera(camera);
  for (colmap::image_t image_id = 1; image_id <= 3; ++image_id) {
    colmap::Image image;
    image.SetImageId(image_id);
    image.SetName("map/" + std::to_string(image_id) + ".png");
    image.SetCameraId(1);
    image.SetQvec(Eigen::Vector4d(1, 0, 0, 0));
    image.SetTvec(Eigen::Vector3d(0.1 * image_id, 0, 0));
    image.SetPoints2D(std::vector<Eigen::Vector2d>(
        kNumPoints + 1, Eigen::Vector2d(320.5, 240.5)));
    map.AddImage(image);
    map.RegisterImage(image_id);
  }
  for (colmap::point2D_t p = 0; p < kNumPoints; ++p) {
    colmap::Track track;
    for (colmap::image_t image_id = 1; image_id <= 3; ++image_id) {
      track.AddElement(image_id, p);
    }
    map.AddPoint3D(Eigen::Vector3d(p, 0, 5), track);
  }
  return map;
}

// Every observation and track element confirms the other (what every later
// stage assumes).
void ExpectConsistent(const colmap::Reconstruction& map) {
  for (const auto& [point3D_id, point3D] : map.Points3D()) {
    EXPECT_GT(point3D.Track().Length(), 0u);
    for (const colmap::TrackElement& element : point3D.Track().Elements()) {
      ASSERT_TRUE(map.ExistsImage(element.image_id));
      ASSERT_LT(element.point2D_idx,
                map.Image(element.image_id).NumPoints2D());
      EXPECT_EQ(map.Image(element.image_id)
                    .Point2D(element.point2D_idx)
                    .Point3DId(),
                point3D_id);
    }
  }
  for (const auto& [image_id, image] : map.Images()) {
    for (const colmap::Point2D& point2D : image.Points2D()) {
      if (!point2D.HasPoint3D()) continue;
      ASSERT_TRUE(map.ExistsPoint3D(point2D.Point3DId()));
    }
  }
}

// Runs the check, which must repair (not refuse); returns the repairs.
MapRepairs Repair(colmap::Reconstruction* map) {
  MapRepairs repairs;
  std::string error;
  EXPECT_TRUE(CheckMapConsistency("MAP", false, map, &repairs, &error))
      << error;
  ExpectConsistent(*map);
  std::cout << "warning: " << repairs.Describe("MAP") << "\n";
  return repairs;
}

std::string Refused(colmap::Reconstruction* map) {
  MapRepairs repairs;
  std::string error;
  EXPECT_FALSE(CheckMapConsistency("MAP", false, map, &repairs, &error));
  std::cout << "ERROR: " << error << "\n";
  return error;
}

TEST(MapConsistency, ConsistentMapIsUnchanged) {
  colmap::Reconstruction map = ConsistentMap();
  const MapRepairs repairs = Repair(&map);
  EXPECT_FALSE(repairs.Any());
  EXPECT_EQ(map.NumPoints3D(), static_cast<size_t>(kNumPoints));
  EXPECT_EQ(map.Image(1).NumPoints3D(), static_cast<size_t>(kNumPoints));
}

// images.txt with a POINT3D_ID changed to another point: the new point's
// track does not list the observation (dropped), and the old point's track
// lists an observation that no longer points at it (dropped).
TEST(MapConsistency, ObservationOfAPointWhoseTrackDoesNotListIt) {
  colmap::Reconstruction map = ConsistentMap();
  map.Image(2).SetPoint3DForPoint2D(0, 3);
  const MapRepairs repairs = Repair(&map);
  EXPECT_EQ(repairs.num_dropped_observations, 1);
  EXPECT_EQ(repairs.num_dropped_track_elements, 1);
  EXPECT_EQ(repairs.num_dropped_points, 0);
  EXPECT_FALSE(map.Image(2).Point2D(0).HasPoint3D());
  EXPECT_EQ(map.Point3D(1).Track().Length(), 2u);
  EXPECT_EQ(map.Point3D(3).Track().Length(), 3u);
  const std::string warning = repairs.Describe("MAP");
  EXPECT_NE(warning.find("image map/2.png, point2D 0 -> point 3, whose track "
                         "does not list it"),
            std::string::npos)
      << warning;
  EXPECT_NE(warning.find("point 1 lists image id 2, point2D 0"),
            std::string::npos)
      << warning;
}

// images.txt with a POINT3D_ID changed to -1 (no point): the track still
// lists the observation; what made the output writer throw
// std::out_of_range (issue 31).
TEST(MapConsistency, TrackElementWhoseObservationHasNoPoint) {
  colmap::Reconstruction map = ConsistentMap();
  map.Image(3).ResetPoint3DForPoint2D(2);
  const MapRepairs repairs = Repair(&map);
  EXPECT_EQ(repairs.num_dropped_track_elements, 1);
  EXPECT_EQ(repairs.num_dropped_observations, 0);
  EXPECT_EQ(map.Point3D(3).Track().Length(), 2u);
}

// images.txt with a POINT3D_ID changed to an id no point has.
TEST(MapConsistency, ObservationOfAMissingPoint) {
  colmap::Reconstruction map = ConsistentMap();
  map.Image(1).SetPoint3DForPoint2D(kNumPoints, 999);
  const MapRepairs repairs = Repair(&map);
  EXPECT_EQ(repairs.num_dropped_observations, 1);
  EXPECT_EQ(repairs.num_dropped_track_elements, 0);
  EXPECT_NE(repairs.Describe("MAP").find("-> point 999, which is not in the "
                                         "map"),
            std::string::npos);
}

// points3D.txt with track elements naming a missing image, a points2D index
// beyond the image's, and one element twice; a point whose track then is
// empty is dropped.
TEST(MapConsistency, TrackElementsThatNoImageConfirms) {
  colmap::Reconstruction map = ConsistentMap();
  map.Point3D(1).Track().AddElement(77, 0);
  map.Point3D(2).Track().AddElement(1, 1000);
  map.Point3D(2).Track().AddElement(1, 1);
  colmap::Track orphan;
  orphan.AddElement(2, 0);  // points2D 0 of image 2 is point 1's
  const colmap::point3D_t orphan_id =
      map.AddPoint3D(Eigen::Vector3d(0, 0, 5), colmap::Track());
  map.Point3D(orphan_id).SetTrack(orphan);
  const MapRepairs repairs = Repair(&map);
  EXPECT_EQ(repairs.num_dropped_track_elements, 4);
  EXPECT_EQ(repairs.num_dropped_observations, 0);
  EXPECT_EQ(repairs.num_dropped_points, 1);
  EXPECT_FALSE(map.ExistsPoint3D(orphan_id));
  EXPECT_EQ(map.Point3D(1).Track().Length(), 3u);
  EXPECT_EQ(map.Point3D(2).Track().Length(), 3u);
}

// points3D.txt with a point of id -1, which COLMAP reads as
// kInvalidPoint3DId, the id of "no point" of a points2D: the points2D it
// lists have no point, so it is dropped.
TEST(MapConsistency, PointWithTheInvalidIdIsDropped) {
  colmap::Reconstruction map;
  std::string error;
  colmap::Reconstruction consistent = ConsistentMap();
  testing::ScopedTempDir temp;
  consistent.WriteText(temp.path());
  std::ofstream(temp.path() + "/points3D.txt", std::ios::app)
      << "-1 0 0 5 0 0 0 0.5 1 " << kNumPoints << " 2 " << kNumPoints
      << "\n";
  map.ReadText(temp.path());
  ASSERT_TRUE(map.ExistsPoint3D(colmap::kInvalidPoint3DId));
  const MapRepairs repairs = Repair(&map);
  EXPECT_EQ(repairs.num_dropped_track_elements, 2);
  EXPECT_EQ(repairs.num_dropped_points, 1);
  EXPECT_FALSE(map.ExistsPoint3D(colmap::kInvalidPoint3DId));
}

TEST(MapConsistency, PointAtNoFinitePositionIsDroppedWithItsObservations) {
  colmap::Reconstruction map = ConsistentMap();
  map.Point3D(4).SetXYZ(
      Eigen::Vector3d(std::numeric_limits<double>::quiet_NaN(), 0, 5));
  const MapRepairs repairs = Repair(&map);
  EXPECT_EQ(repairs.num_dropped_points, 1);
  EXPECT_FALSE(map.ExistsPoint3D(4));
  EXPECT_FALSE(map.Image(1).Point2D(3).HasPoint3D());
  EXPECT_EQ(map.Image(1).NumPoints3D(), static_cast<size_t>(kNumPoints - 1));
}

TEST(MapConsistency, ObservationAtNoFinitePixelIsDropped) {
  colmap::Reconstruction map = ConsistentMap();
  map.Image(1).Point2D(0).SetXY(
      Eigen::Vector2d(std::numeric_limits<double>::infinity(), 1));
  const MapRepairs repairs = Repair(&map);
  EXPECT_EQ(repairs.num_dropped_track_elements, 1);
  EXPECT_EQ(repairs.num_dropped_observations, 1);
  EXPECT_FALSE(map.Image(1).Point2D(0).HasPoint3D());
}

TEST(MapConsistency, InvalidCamerasAreRefusedByName) {
  colmap::Reconstruction map = ConsistentMap();
  map.Camera(1).Params()[0] = -500;
  EXPECT_NE(Refused(&map).find("MAP/cameras.txt: camera 1 has the focal "
                               "length -500"),
            std::string::npos);
  map = ConsistentMap();
  map.Camera(1).Params()[3] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(Refused(&map).find("camera 1 has a parameter that is not a "
                               "finite number"),
            std::string::npos);
  map = ConsistentMap();
  map.Camera(1).Params().pop_back();
  EXPECT_NE(Refused(&map).find("camera 1 has 3 parameters, but its model "
                               "SIMPLE_RADIAL has 4"),
            std::string::npos);
  map = ConsistentMap();
  map.Camera(1).SetWidth(0);
  EXPECT_NE(Refused(&map).find("camera 1 has the image size 0x480"),
            std::string::npos);
}

TEST(MapConsistency, ImagesWithoutCameraOrPoseAreRefusedByName) {
  colmap::Reconstruction map = ConsistentMap();
  map.Image(2).SetCameraId(5);
  EXPECT_NE(Refused(&map).find("MAP/images.txt: image map/2.png (id 2) refers "
                               "to camera 5"),
            std::string::npos);
  map = ConsistentMap();
  map.Image(3).Tvec(1) = std::numeric_limits<double>::infinity();
  EXPECT_NE(Refused(&map).find("image map/3.png (id 3) has a pose that is not "
                               "finite"),
            std::string::npos);
}

}  // namespace map_consistency_test
}  // namespace rig_calibrator
