// report.html: the page that shows a calibration, built from its output
// folder only (report_inputs.h), self-contained (inline CSS and SVG, one
// small inline script that counts the drawn figures; no network, no external
// file), deterministic (the same folder gives the same bytes: the wall times
// of timings.json are left out).
//
// Sections (element ids): overview, parameters (intrinsics-table,
// poses-table), model-choice, diagnostics (diagnostics-list,
// validity-table), cameras (per camera i: camera-i with the figures
// residuals-i, coverage-i, uncertainty-i, distortion-i), rig (rig-above,
// rig-side), framesets (frameset-errors, worst-framesets, worst-images),
// camchain. A figure whose data the summary lacks is a "not computed" note in
// place of its <svg>.
#pragma once

#include <string>

#include "colmap_ext/report/report_inputs.h"

namespace rig_calibrator {

// Cells across each camera image in the residual figure (rows in
// proportion): aggregates, so the page's size does not grow with the number
// of observations.
inline constexpr int kResidualGridCols = 16;

// The page. Fails only if the summary holds values of unexpected types
// (message naming calibration_summary.json).
bool BuildReportHtml(const ReportInputs& inputs, std::string* html,
                     std::string* error);

// Reads `folder` (ReadReportInputs) and writes `folder`/report.html through a
// temporary file and a rename; nothing else in the folder changes.
bool WriteReportHtml(const std::string& folder, std::string* error);

}  // namespace rig_calibrator
