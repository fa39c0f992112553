// `rig_calibrator_lab render`: renders a rig dataset with exact ground truth
// (src/synthetic/rendered_dataset.h, src/synthetic/scene_renderer.h) into a
// folder:
//
//   map_images/map_000000.png ...   the mapping sequence (a PINHOLE camera)
//   rig_images/cam0/000000.png ...  one folder per rig camera, one file name
//                                   per frameset
//   ground_truth/
//     map_camera.txt                "PINHOLE width height fx,fy,cx,cy"
//     map_image_positions.txt       "name X Y Z" per map image (camera
//                                   centers), for colmap model_aligner
//                                   --ref_images_path ... --ref_is_gps 0
//     map_model/                    COLMAP text model of the map images'
//                                   true poses (no points)
//     rig_model/                    COLMAP text model of the rig images' true
//                                   poses (no points)
//     rig_config.json               the true rig (COLMAP >= 3.12
//                                   rig_configurator format)
//     rig_from_world.txt            "FRAMESET QW QX QY QZ TX TY TZ" per
//                                   frameset
//     dataset.txt                   the options used, the counts and
//                                   "camera_models cam0:OPENCV,..." (the
//                                   true models, as
//                                   --RigCalibrator.camera_model takes them)
//
// With a time model (--frameset_rate_hz > 0; the options of `synthetic`,
// synthetic_data_options.h) every rig image is rendered at its own capture
// time, each row of a rolling shutter at its own (rendered_dataset.h), and
// named by its capture time in nanoseconds (rig_images/cam1/1240100000.png);
// rig_from_world.txt names the framesets by cam0's time stamp and the
// rig_model's image poses are those of the images' top rows. Also written:
//     time_model.json               the frameset times, offsets and line
//                                   delays (time_model_json.h)
//     dataset.txt                   also "timestamp_tolerance_ns T": the
//                                   --RigCalibrator.timestamp_tolerance that
//                                   groups the images into framesets
#pragma once

#include <string>

#include "src/synthetic/rendered_dataset.h"
#include "src/synthetic/scene_renderer.h"

namespace rig_calibrator {

// Renders every image of the plan and writes the folder above to
// `output_path` atomically (all or nothing). An existing non-empty folder is
// replaced only with `overwrite`.
bool WriteRenderedDataset(const RenderedDatasetOptions& dataset_options,
                          const RenderedDatasetPlan& plan,
                          const RenderOptions& render_options,
                          const std::string& output_path, bool overwrite,
                          std::string* error);

// rig_calibrator_lab render --output_path DIR [--preset ring5] [--scene room]
//   [--num_map_images 60] [--num_framesets 12] [--seed 0] ...
int RunRender(int argc, char** argv);

}  // namespace rig_calibrator
