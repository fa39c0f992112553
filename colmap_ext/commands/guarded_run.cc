#include "colmap_ext/commands/guarded_run.h"

#include <exception>
#include <string>

#include "colmap_ext/io/error_output.h"

namespace rig_calibrator {
namespace {

int PrintInternalError(const std::string& what) {
  return PrintError("internal error: " + what +
                    " (a defect of rig_calibrator, not of the input alone: "
                    "please report it with the command line and the input)");
}

}  // namespace

int RunGuarded(const std::function<int()>& command) {
  try {
    return command();
  } catch (const std::exception& exception) {
    return PrintInternalError(exception.what());
  } catch (...) {
    return PrintInternalError("an exception of unknown type");
  }
}

}  // namespace rig_calibrator
