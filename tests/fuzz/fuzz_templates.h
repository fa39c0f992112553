// Small valid inputs of every reader: the seed corpus (fuzz_seed_corpus) is
// written from them, and the targets that fuzz one file of several (a model,
// rigs and frames) or one blob of a database keep the others valid with them.
#pragma once

#include <colmap/base/reconstruction.h>

#include <string>

#include "colmap_ext/io/correspondence_io.h"
#include "colmap_ext/io/rig_description.h"
#include "colmap_ext/io/rigs_frames_io.h"

namespace rig_calibrator {
namespace fuzz {

// Two cameras, two registered images with three points2D each, two points.
colmap::Reconstruction TemplateModel();

// One rig of two cameras (one with a pose) and two frames.
ColmapRigsAndFrames TemplateRigsAndFrames();

// Two calibrated cameras, "cam0/" and "cam1/".
RigDescription TemplateRig();

// Two images with two correspondences each.
std::vector<ImageCorrespondences> TemplateCorrespondences();

// A COLMAP 3.8 database written by colmap::Database: cameras 1 and 2, images
// 1 "map/a.png", 2 "cam0/0001.png" and 3 "cam1/0001.png", keypoints and
// descriptors of each, verified matches between 1 and 2.
void WriteTemplateDatabase(const std::string& path);

}  // namespace fuzz
}  // namespace rig_calibrator
