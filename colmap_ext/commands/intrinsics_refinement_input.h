// COLMAP's refinement switches on the command line:
// --RigCalibrator.refine_focal_length, refine_principal_point and
// refine_extra_params, each "1" / "0" for every camera or per camera
// ("cam0:0,cam1:1"; a bare value is the default of the cameras not named,
// which are otherwise refined), and the given values of the parameters they
// hold (src/rig/intrinsics_refinement.h).
//
// Where a held parameter's value comes from:
//  - the known* methods: the given intrinsics they run with
//    (--RigCalibrator.intrinsics_path or the database cameras); known and
//    known_ra hold every parameter anyway, known_refine refines the others
//    in its final adjustment;
//  - the other methods: the camera of the same name in
//    --RigCalibrator.intrinsics_path when it is given, else the database
//    camera of the camera's first rig image when it has a prior focal length
//    (feature_extractor --ImageReader.camera_params), else COLMAP's initial
//    camera: the principal point at the image centre (the value COLMAP's
//    bundle_adjuster holds by default), the distortion 0; a held focal length
//    then has no value and is refused, naming the camera and what to give.
#pragma once

#include <map>
#include <string>

#include "colmap_ext/commands/calibrate_options.h"
#include "colmap_ext/io/database_reader.h"
#include "src/rig/rig_dataset.h"

namespace rig_calibrator {

// Sets every dataset camera's refinement from the three options and the
// held parameters' given values (above). `database_cameras`: the database
// camera of every rig image by name (empty without a database). False with
// *error naming the option or the camera.
bool SetIntrinsicsRefinement(
    const CalibrateOptions& options,
    const std::map<std::string, DatabaseCamera>& database_cameras,
    RigDataset* dataset, std::string* error);

}  // namespace rig_calibrator
