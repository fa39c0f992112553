// The calibrate command on text maps whose observations and tracks do not
// confirm each other (issue 31): a map written from a synthetic rig, with
// images.txt's POINT3D_IDs or points3D.txt's tracks edited. Before the
// map's consistency check (map_consistency.h), the -1 case ended the process
// after the calibration (std::out_of_range from the output writer, exit
// -6). Each case must now calibrate with one warning naming the map and the
// repair (exit 0, complete output), or be refused with a message naming the
// file and the camera (exit 1, no output); the inputs stay unchanged.
#include <colmap/base/reconstruction.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "colmap_ext/benchmarks/synthetic_map_model.h"
#include "colmap_ext/commands/commands.h"
#include "tests/colmap_ext/colmap_testing.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace map_consistency_command_test {

namespace fs = std::filesystem;

std::vector<std::string> Lines(const std::string& path) {
  std::ifstream file(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(file, line);) lines.push_back(line);
  return lines;
}

void WriteLines(const std::string& path, const std::vector<std::string>& lines) {
  std::ofstream file(path, std::ios::trunc);
  for (const std::string& line : lines) file << line << "\n";
}

struct RunResult {
  int exit_code = 0;
  std::string messages;  // stderr
};

// <temp>/inputs: correspondences.txt and sparse/ (text) of a 3-camera ring
// with a map of 8 images; <temp>/out the output.
class MapConsistencyCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    SyntheticRigOptions options;
    options.ring_num_cameras = 3;
    options.num_framesets = 8;
    options.points_per_image = 60;
    options.outlier_ratio = 0.1;
    options.missing_image_ratio = 0;
    options.num_map_images = 8;
    options.seed = 7;
    SyntheticRig rig = GenerateSyntheticRig(options);
    KeepCorrespondencesWithMapTracks(&rig);
    model_ = MakeSyntheticMapModel(rig);
    inputs_ = temp_.File("inputs");
    output_ = temp_.File("out");
    std::string error;
    ASSERT_TRUE(WriteSyntheticMapModel(model_, inputs_, false, &error))
        << error;
  }

  // Edits the POINT3D_ID of points2D `point2D_idx` of map image `image_id`
  // in images.txt.
  void SetPoint3DIdInImagesTxt(const colmap::image_t image_id,
                               const size_t point2D_idx,
                               const std::string& point3D_id) {
    const std::string path = inputs_ + "/sparse/images.txt";
    std::vector<std::string> lines = Lines(path);
    for (size_t i = 0; i + 1 < lines.size(); ++i) {
      if (lines[i].empty() || lines[i][0] == '#') continue;
      if (std::stoul(lines[i]) != image_id) {
        ++i;  // its POINTS2D line
        continue;
      }
      std::istringstream fields(lines[i + 1]);
      std::vector<std::string> values;
      for (std::string value; fields >> value;) values.push_back(value);
      ASSERT_LT(3 * point2D_idx + 2, values.size());
      values[3 * point2D_idx + 2] = point3D_id;
      std::string edited;
      for (const std::string& value : values) {
        edited += (edited.empty() ? "" : " ") + value;
      }
      lines[i + 1] = edited;
      WriteLines(path, lines);
      return;
    }
    FAIL() << "no image " << image_id << " in " << path;
  }

  RunResult Calibrate() {
    const std::map<std::string, std::string> inputs_before =
        testing::SnapshotFolder(inputs_);
    ::testing::internal::CaptureStderr();
    ::testing::internal::CaptureStdout();
    RunResult result;
    result.exit_code = testing::RunCommand(
        &RunCalibrate,
        {"--correspondences_path", inputs_ + "/correspondences.txt",
         "--input_path", inputs_ + "/sparse", "--output_path", output_,
         "--RigCalibrator.camera_model", "OPENCV"});
    ::testing::internal::GetCapturedStdout();
    result.messages = ::testing::internal::GetCapturedStderr();
    std::cout << result.messages << std::flush;  // for the test log
    EXPECT_TRUE(testing::SnapshotFolder(inputs_) == inputs_before);
    return result;
  }

  // A repaired run: exit 0, the warning with `expected`, a complete output.
  void ExpectRepaired(const std::vector<std::string>& expected) {
    const RunResult result = Calibrate();
    EXPECT_EQ(result.exit_code, EXIT_SUCCESS) << result.messages;
    EXPECT_NE(result.messages.find("warning: the map in " + inputs_ +
                                   "/sparse is inconsistent and was "
                                   "repaired in memory"),
              std::string::npos)
        << result.messages;
    for (const std::string& text : expected) {
      EXPECT_NE(result.messages.find(text), std::string::npos)
          << "expected '" << text << "' in:\n"
          << result.messages;
    }
    EXPECT_TRUE(fs::exists(output_ + "/points3D.bin"));
    EXPECT_TRUE(fs::exists(output_ + "/calibration_summary.json"));
  }

  testing::ScopedTempDir temp_;
  SyntheticMapModel model_;
  std::string inputs_;
  std::string output_;
};

TEST_F(MapConsistencyCommand, ConsistentMapGivesNoWarning) {
  const RunResult result = Calibrate();
  EXPECT_EQ(result.exit_code, EXIT_SUCCESS) << result.messages;
  EXPECT_EQ(result.messages.find("inconsistent"), std::string::npos)
      << result.messages;
}

// The case of the issue that ended the process: a POINT3D_ID set to -1 (no
// point) while the point's track still lists the observation.
TEST_F(MapConsistencyCommand, ObservationWithoutPointButListedInTrack) {
  const colmap::point3D_t point3D_id =
      model_.map.Image(2).Point2D(0).Point3DId();
  SetPoint3DIdInImagesTxt(2, 0, "-1");
  ExpectRepaired({"dropped 1 track element(s) whose image does not observe "
                  "the point (e.g. point " +
                  std::to_string(point3D_id) + " lists image id 2, point2D 0)"});
}

// A POINT3D_ID set to another point, whose track does not list it.
TEST_F(MapConsistencyCommand, ObservationOfAPointWhoseTrackDoesNotListIt) {
  colmap::point3D_t other = colmap::kInvalidPoint3DId;
  for (const auto& [point3D_id, point3D] : model_.map.Points3D()) {
    if (!model_.map.Image(3).HasPoint3D(point3D_id)) {
      other = point3D_id;
      break;
    }
  }
  ASSERT_NE(other, colmap::kInvalidPoint3DId);
  SetPoint3DIdInImagesTxt(3, 0, std::to_string(other));
  ExpectRepaired(
      {"dropped 1 observation(s) whose point does not exist or does not list "
       "them (e.g. image " +
           model_.map.Image(3).Name() + ", point2D 0 -> point " +
           std::to_string(other) + ", whose track does not list it)",
       "dropped 1 track element(s)"});
}

// A POINT3D_ID set to an id that no point has (refused before this check,
// now repaired like the others).
TEST_F(MapConsistencyCommand, ObservationOfAMissingPoint) {
  SetPoint3DIdInImagesTxt(1, 1, "987654");
  ExpectRepaired({"-> point 987654, which is not in the map",
                  "dropped 1 track element(s)"});
}

// A track element naming an image the map does not have.
TEST_F(MapConsistencyCommand, TrackElementOfAMissingImage) {
  std::vector<std::string> lines = Lines(inputs_ + "/sparse/points3D.txt");
  for (std::string& line : lines) {
    if (line.empty() || line[0] == '#') continue;
    line += " 77 0";
    break;
  }
  WriteLines(inputs_ + "/sparse/points3D.txt", lines);
  ExpectRepaired({"lists image id 77, point2D 0"});
}

// A camera that cannot be projected with is refused, naming the file.
TEST_F(MapConsistencyCommand, CameraWithNegativeFocalLengthIsRefused) {
  std::vector<std::string> lines = Lines(inputs_ + "/sparse/cameras.txt");
  for (std::string& line : lines) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string id, model, width, height, focal, rest;
    fields >> id >> model >> width >> height >> focal;
    std::getline(fields, rest);
    line = id + " " + model + " " + width + " " + height + " -" + focal + rest;
  }
  WriteLines(inputs_ + "/sparse/cameras.txt", lines);
  const RunResult result = Calibrate();
  EXPECT_EQ(result.exit_code, EXIT_FAILURE);
  EXPECT_NE(result.messages.find("ERROR: " + inputs_ +
                                 "/sparse/cameras.txt: camera 1 has the "
                                 "focal length -"),
            std::string::npos)
      << result.messages;
  EXPECT_FALSE(fs::exists(output_));
}

}  // namespace map_consistency_command_test
}  // namespace rig_calibrator
