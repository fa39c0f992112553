// The 2D-3D correspondence file: the correspondences a run used (so it can be
// repeated without matching) or correspondences from another matcher.
//
//   # rig_calibrator 2D-3D correspondences
//   # IMAGE <image_name> <width> <height> <num_rows>, then num_rows lines:
//   #   <x> <y> <X> <Y> <Z> [<point3D_id>]
//   IMAGE cam0/frame_0000.png 640 480 2
//   312.41 220.13 1.234 -0.55 4.21 1234
//   100.5 20.25 0.5 0.25 3.5
//
// Pixels follow COLMAP (the center of the top-left pixel is (0.5, 0.5)); 3D
// points are in map coordinates; point3D_id is the map point's id, absent
// when unknown. Lines starting with '#' and blank lines are ignored. Numbers
// are written as the shortest text that reads back bit for bit. An image name
// may contain spaces (the last three fields of an IMAGE line are numbers),
// but not line breaks or leading/trailing spaces.
#pragma once

#include <string>
#include <vector>

#include "src/rig/rig_dataset.h"

namespace rig_calibrator {

struct ImageCorrespondences {
  std::string image_name;
  int width = 0;
  int height = 0;
  std::vector<Correspondence> correspondences;
};

// Reads the whole file strictly: errors name the file and line, e.g.
// "file F line N: expected 5 or 6 numbers, found 4".
bool ReadCorrespondenceFile(const std::string& path,
                            std::vector<ImageCorrespondences>* images,
                            std::string* error);

// Writes atomically (temporary file, then rename).
bool WriteCorrespondenceFile(const std::string& path,
                             const std::vector<ImageCorrespondences>& images,
                             std::string* error);

// The dataset's correspondences, one entry per image, with the image size of
// its camera.
std::vector<ImageCorrespondences> DatasetCorrespondences(
    const RigDataset& dataset);

}  // namespace rig_calibrator
