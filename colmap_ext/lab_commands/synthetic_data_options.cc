#include "colmap_ext/lab_commands/synthetic_data_options.h"

#include <sstream>
#include <vector>

#include "colmap_ext/commands/command_options.h"

namespace rig_calibrator {
namespace {

// "1,-2.5,3e-2" -> {1, -2.5, 0.03}, each scaled by `scale`; false for
// anything that is not a non-empty comma-separated list of numbers.
bool ParseNumberList(const std::string& text, double scale,
                     std::vector<double>* values) {
  values->clear();
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    try {
      size_t used = 0;
      const double value = std::stod(item, &used);
      if (used != item.size()) return false;
      values->push_back(scale * value);
    } catch (const std::exception&) {
      return false;
    }
  }
  return !values->empty();
}

}  // namespace

void AddSyntheticDataOptions(
    boost::program_options::options_description* description,
    SyntheticRigOptions* options) {
  AddOption(description, "points_per_image", &options->points_per_image,
            "correspondences per image");
  AddOption(description, "noise_px", &options->noise_px,
            "pixel noise (standard deviation)");
  AddOption(description, "outlier_ratio", &options->outlier_ratio,
            "share of wrong 2D-3D matches");
  AddOption(description, "missing_image_ratio", &options->missing_image_ratio,
            "share of images dropped");
}

void AddTimeModelOptions(
    boost::program_options::options_description* description,
    SyntheticRigOptions* options, TimeModelArguments* arguments) {
  AddOption(description, "frameset_rate_hz", &options->frameset_rate_hz,
            "time model: framesets per second on a continuous trajectory "
            "(0: every frameset at one instant, global shutters)");
  AddOption(description, "speed_m_s", &options->speed_m_s,
            "time model: the rig's ground speed (metres per second)");
  AddOption(description, "max_turn_rate_deg_s", &options->max_turn_rate_deg_s,
            "time model: the rig's peak heading rate (degrees per second)");
  AddOption(description, "bob_hz", &options->bob_hz,
            "time model: the body bobs up and down at this frequency (Hz) "
            "with the preset's amplitude (0: the preset's bob)");
  AddOption(description, "max_time_offset_ms",
            &arguments->max_time_offset_ms,
            "time model: capture-time offsets of cam1, cam2, ... drawn in "
            "+-this (milliseconds; cam0's is 0)");
  AddOption(description, "camera_time_offsets_ms",
            &arguments->camera_time_offsets_ms,
            "time model: given offsets, one per camera, cam0's 0 "
            "(milliseconds, e.g. 0,12.5,-30,8,-41)");
  AddOption(description, "line_delay_us", &arguments->line_delay_us,
            "time model: rolling-shutter line delay of every camera, MIN,MAX "
            "(drawn per camera) or one value (microseconds per row; 0: "
            "global shutter)");
  AddOption(description, "camera_line_delays_us",
            &arguments->camera_line_delays_us,
            "time model: given line delays, one per camera (microseconds per "
            "row)");
}

bool ApplyTimeModelArguments(const TimeModelArguments& arguments,
                             SyntheticRigOptions* options,
                             std::string* error) {
  options->max_time_offset_s = 1e-3 * arguments.max_time_offset_ms;
  std::vector<double> line_delay;
  if (!ParseNumberList(arguments.line_delay_us, 1e-6, &line_delay) ||
      line_delay.size() > 2) {
    *error = "--line_delay_us must be MIN,MAX or one value (microseconds), "
             "got '" + arguments.line_delay_us + "'";
    return false;
  }
  options->min_line_delay_s = line_delay.front();
  options->max_line_delay_s = line_delay.back();
  if (!arguments.camera_time_offsets_ms.empty() &&
      !ParseNumberList(arguments.camera_time_offsets_ms, 1e-3,
                       &options->time_offsets_s)) {
    *error = "--camera_time_offsets_ms must be a comma-separated list of "
             "numbers (milliseconds), got '" +
             arguments.camera_time_offsets_ms + "'";
    return false;
  }
  if (!arguments.camera_line_delays_us.empty() &&
      !ParseNumberList(arguments.camera_line_delays_us, 1e-6,
                       &options->line_delays_s)) {
    *error = "--camera_line_delays_us must be a comma-separated list of "
             "numbers (microseconds), got '" +
             arguments.camera_line_delays_us + "'";
    return false;
  }
  return true;
}

}  // namespace rig_calibrator
