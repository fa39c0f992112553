// `rig_calibrator report`: rebuilds report.html in a calibration output
// folder from the files there (colmap_ext/report/report_page.h), e.g. after
// the report's format changed or for a folder written before it existed.
#include <iostream>

#include "colmap_ext/commands/command_options.h"
#include "colmap_ext/commands/commands.h"
#include "colmap_ext/report/report_page.h"

namespace rig_calibrator {

int RunReport(int argc, char** argv) {
  std::string calibration_path;
  boost::program_options::options_description description =
      CommandOptions("rig_calibrator report options");
  AddRequiredOption(&description, "calibration_path", &calibration_path,
                    "output folder of a calibration (its --output_path): "
                    "report.html is written there, nothing else changes");
  if (const std::optional<int> exit_code = ParseCommandLine(
          argc, argv, description,
          "rig_calibrator report: rebuild report.html in a calibration "
          "output folder")) {
    return *exit_code;
  }
  std::string error;
  if (!WriteReportHtml(calibration_path, &error)) {
    return PrintError("no report written: " + error);
  }
  std::cout << "Report: " << calibration_path << "/" << kReportFile
            << std::endl;
  return EXIT_SUCCESS;
}

}  // namespace rig_calibrator
