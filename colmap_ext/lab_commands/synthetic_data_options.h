// The option declarations of the synthetic data, which more than one lab
// sub-command has.
#pragma once

#include <boost/program_options.hpp>
#include <string>

#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {

// The synthetic data of `rig_calibrator_lab synthetic`, `benchmark_runtime`
// and `benchmark_colmap_rig_ba`: --points_per_image, --noise_px,
// --outlier_ratio, --missing_image_ratio.
void AddSyntheticDataOptions(
    boost::program_options::options_description* description,
    SyntheticRigOptions* options);

// The time model's options as the command line gives them: offsets in
// milliseconds and line delays in microseconds, lists as comma-separated
// text (SyntheticRigOptions holds seconds).
struct TimeModelArguments {
  double max_time_offset_ms = 0;
  std::string camera_time_offsets_ms;  // "0,12.5,-30,...": one per camera
  std::string line_delay_us = "0";     // "MIN,MAX" or one value for all
  std::string camera_line_delays_us;   // "0,25,30,...": one per camera
};

// The time model of `rig_calibrator_lab synthetic` and `render`:
// --frameset_rate_hz, --speed_m_s, --max_turn_rate_deg_s, --bob_hz (bound to
// *options), and
// --max_time_offset_ms, --camera_time_offsets_ms, --line_delay_us,
// --camera_line_delays_us (bound to *arguments; ApplyTimeModelArguments
// converts them after parsing).
void AddTimeModelOptions(
    boost::program_options::options_description* description,
    SyntheticRigOptions* options, TimeModelArguments* arguments);

// Sets the offsets and line delays of *options, in seconds, from the parsed
// arguments. False with a message naming the option for text that is not a
// list of numbers (line_delay_us: one or two); the ranges are
// SyntheticRigOptions::Check's.
bool ApplyTimeModelArguments(const TimeModelArguments& arguments,
                             SyntheticRigOptions* options, std::string* error);

}  // namespace rig_calibrator
