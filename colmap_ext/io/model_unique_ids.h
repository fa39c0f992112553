// Unique ids in a COLMAP model's files. COLMAP 3.8's readers keep the first
// camera, image or point of an id and silently drop the others (and, in
// images.txt, register the id once per record, so that the model counts more
// registered images than it holds): a model with a repeated id is not what its
// files say, so it is refused.
#pragma once

#include <colmap/base/reconstruction.h>

#include <string>

namespace rig_calibrator {

// Compares the records of each file of the model in `folder` (cameras,
// images, points3D; .bin or .txt) with what `model`, read from it, holds, and
// fails with a message that names the file (and, for text files, the
// repeated id) when a file has more records than distinct ids.
bool CheckUniqueModelIds(const std::string& folder, bool binary,
                         const colmap::Reconstruction& model,
                         std::string* error);

}  // namespace rig_calibrator
