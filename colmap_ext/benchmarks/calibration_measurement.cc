#include "colmap_ext/benchmarks/calibration_measurement.h"

#include <colmap/util/timer.h>

#include "colmap_ext/benchmarks/child_process.h"
#include "src/calibration/pipeline.h"
#include "src/evaluation/evaluation.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {

bool MeasureCalibration(const RuntimeBenchmarkOptions& options,
                        const int num_framesets, const int num_cameras,
                        CalibrationRuntime* runtime, std::string* error) {
  *runtime = CalibrationRuntime();
  runtime->num_framesets = num_framesets;
  runtime->num_cameras = num_cameras;

  SyntheticRigOptions rig_options = options.data;
  rig_options.preset = RigPreset::kRing5;
  rig_options.ring_num_cameras = num_cameras;
  rig_options.num_framesets = num_framesets;
  rig_options.seed = static_cast<unsigned int>(options.seed);
  PipelineOptions pipeline_options;
  pipeline_options.num_threads = options.num_threads;
  pipeline_options.seed = static_cast<unsigned int>(options.seed);
  pipeline_options.print_progress = false;
  pipeline_options.final_bundle_adjustment.refine_points =
      options.refine_points;
  if (!rig_options.Check(error)) return false;
  if (!CalibrationMethodFromName(options.method, &pipeline_options.method)) {
    *error = "unknown method " + options.method;
    return false;
  }

  colmap::Timer timer;
  timer.Start();
  const SyntheticRig rig = GenerateSyntheticRig(rig_options);
  runtime->generation_seconds = timer.ElapsedSeconds();
  runtime->num_images = static_cast<int>(rig.dataset.images.size());
  for (const RigImage& image : rig.dataset.images) {
    runtime->num_correspondences += image.correspondences.size();
  }

  RigCalibration calibration;
  PipelineReport report;
  const double cpu_start = ProcessCpuSeconds();
  timer.Restart();
  runtime->success =
      CalibrateRig(pipeline_options, rig.dataset, &calibration, &report);
  runtime->seconds = timer.ElapsedSeconds();
  runtime->cpu_seconds = ProcessCpuSeconds() - cpu_start;
  runtime->error = report.error;
  runtime->final_rms_px = report.final_rms_px;
  for (const StageTiming& timing : report.timings) {
    runtime->stages.push_back({timing.stage, timing.seconds, timing.cpu_seconds,
                               timing.num_iterations});
  }
  if (runtime->success) {
    const CalibrationError accuracy =
        CompareCalibrations(rig.truth.cameras, rig.truth.cam_from_rig,
                            calibration.cameras, calibration.cam_from_rig,
                            /*align_scale=*/false);
    runtime->max_rotation_error_deg = accuracy.MaxRotationDeg();
    runtime->max_center_error_m = accuracy.MaxCenterError();
  }
  return true;
}

}  // namespace rig_calibrator
