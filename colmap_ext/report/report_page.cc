#include "colmap_ext/report/report_page.h"

#include <colmap/base/camera_models.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <vector>

#include "colmap_ext/io/atomic_output.h"
#include "colmap_ext/io/model_writer.h"
#include "colmap_ext/report/capture_timing_figure.h"
#include "colmap_ext/report/distortion_profile_figure.h"
#include "colmap_ext/report/frameset_errors_figure.h"
#include "colmap_ext/report/heat_map_figure.h"
#include "colmap_ext/report/model_residuals.h"
#include "colmap_ext/report/report_json.h"
#include "colmap_ext/report/report_tables.h"
#include "colmap_ext/report/residual_field_figure.h"
#include "colmap_ext/report/rig_view_figure.h"
#include "colmap_ext/report/svg_plot.h"

namespace rig_calibrator {
namespace {

// Framesets whose RMS is above this factor times the median are flagged.
constexpr double kOutlyingFramesetFactor = 2;
constexpr size_t kNumWorstRows = 10;

const char kStyle[] = R"(
body { font-family: sans-serif; margin: 1.5em; color: #222; max-width: 1500px; }
h1 { font-size: 1.6em; } h2 { border-bottom: 1px solid #ccc; margin-top: 1.6em; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 3px 7px; text-align: left; vertical-align: top; }
th { background: #f2f2f2; }
.figures { display: flex; flex-wrap: wrap; gap: 12px; }
figure { margin: 0; border: 1px solid #ddd; padding: 6px; background: #fff; }
figcaption { font-size: 0.8em; color: #444; max-width: 560px; }
.not-computed { color: #8a6d00; font-weight: bold; }
.why { color: #666; font-size: 0.9em; }
.error { color: #b00020; } .warning { color: #8a5a00; } .info, .note { color: #333; }
tr.bad td, .bad { background: #fde0e0; }
.chosen { background: #e3f4e3; }
pre { background: #f7f7f7; padding: 0.6em; overflow-x: auto; font-size: 0.8em; }
nav a { margin-right: 1em; }
)";

// Counts the figures that the browser drew (an <svg> with a size and
// content) into the body's data-rendered-figures, for the report's browser
// test; the page needs no script otherwise. Written without &, < and
// CDATA, so that the page is also well-formed XML.
const char kSelfCheckScript[] = R"(
(function () {
  var drawn = 0;
  var figures = document.querySelectorAll("figure svg");
  for (var k = 0; figures.length > k; ++k) {
    var box = figures[k].getBoundingClientRect();
    if (box.width > 0) { if (box.height > 0) { if (figures[k].childElementCount > 0) { ++drawn; } } }
  }
  document.body.setAttribute("data-rendered-figures", String(drawn));
})();
)";

struct Page {
  std::ostringstream html;
  int num_figures = 0;  // <svg> figures

  void Figure(const std::string& id, const std::string& svg,
              const std::string& caption) {
    html << "<figure id=\"fig-" << id << "\">" << svg << "<figcaption>"
         << caption << "</figcaption></figure>\n";
    ++num_figures;
  }
  void MissingFigure(const std::string& id, const std::string& title,
                     const std::string& reason) {
    html << "<figure id=\"fig-" << id << "\" class=\"missing\"><p><b>"
         << XmlEscape(title) << "</b>: " << NotComputedHtml(reason)
         << "</p></figure>\n";
  }
};

// The summary camera as a COLMAP camera (none when its model or parameters
// are not COLMAP 3.8's).
std::optional<colmap::Camera> SummaryCamera(const ReportJson& camera) {
  const std::string model = TextAt(camera, "model");
  const ReportJson* params = FindKey(camera, "params");
  if (!colmap::ExistsCameraModelWithName(model) || params == nullptr ||
      !params->is_array()) {
    return std::nullopt;
  }
  const int model_id = colmap::CameraModelNameToId(model);
  if (params->size() != colmap::CameraModelNumParams(model_id)) {
    return std::nullopt;
  }
  std::vector<double> values;
  for (const ReportJson& value : *params) {
    if (!value.is_number()) return std::nullopt;
    values.push_back(value.get<double>());
  }
  const double width = NumberAt(camera, "width");
  const double height = NumberAt(camera, "height");
  if (!(width >= 1 && height >= 1)) return std::nullopt;
  colmap::Camera result;
  result.SetModelId(model_id);
  result.SetWidth(static_cast<size_t>(width));
  result.SetHeight(static_cast<size_t>(height));
  result.SetParams(values);
  return result;
}

// A grid {"cols", "rows", key: [...]} of the summary, or none if malformed.
std::optional<ImageGridValues> SummaryGrid(const ReportJson& grid,
                                           const char* key,
                                           const bool zero_is_empty) {
  ImageGridValues values;
  values.cols = static_cast<int>(NumberAt(grid, "cols"));
  values.rows = static_cast<int>(NumberAt(grid, "rows"));
  const ReportJson* list = FindKey(grid, key);
  if (values.cols < 1 || values.rows < 1 || list == nullptr ||
      !list->is_array() ||
      list->size() != static_cast<size_t>(values.cols) * values.rows) {
    return std::nullopt;
  }
  for (const ReportJson& value : *list) {
    const double number = NumberOr(&value);
    values.values.push_back(zero_is_empty && number == 0 ? std::nan("")
                                                         : number);
  }
  return values;
}

void OverviewSection(const ReportInputs& inputs, Page* page) {
  const ReportJson& summary = inputs.summary;
  const ReportJson* metric = FindKey(summary, "map_looks_metric");
  std::ostringstream& html = page->html;
  html << "<section id=\"overview\"><h2>Overview</h2><table>"
       << "<tr><th>method</th><td>" << XmlEscape(TextAt(summary, "method"))
       << "</td></tr><tr><th>seed</th><td>"
       << FormatNumber(NumberAt(summary, "seed"), 10)
       << "</td></tr><tr><th>units</th><td>" << XmlEscape(TextAt(summary, "units"))
       << (metric != nullptr && metric->is_boolean()
               ? (metric->get<bool>() ? " (the map looks metric)"
                                      : " (the map does not look metric)")
               : "")
       << "</td></tr><tr><th>reference camera</th><td>"
       << XmlEscape(TextAt(summary, "reference_camera"))
       << "</td></tr><tr><th>framesets with a rig pose</th><td>"
       << FormatNumber(NumberAt(summary, "num_framesets_used"), 9) << " of "
       << FormatNumber(NumberAt(summary, "num_framesets"), 9)
       << "</td></tr><tr><th>uncertainty method</th><td>";
  const std::string method = TextAt(summary, "uncertainty_method");
  html << (method.empty() ? NotComputedHtml("no \"uncertainty_method\"")
                          : XmlEscape(method))
       << "</td></tr>";
  if (const ReportJson* map = FindKey(summary, "map_images")) {
    html << "<tr><th>map images: mean reprojection error input \u2192 "
            "output (px)</th><td>"
         << FormatNumber(NumberAt(*map, "input_mean_error_px")) << " \u2192 "
         << FormatNumber(NumberAt(*map, "output_mean_error_px")) << " ("
         << FormatNumber(NumberAt(*map, "num_output_observations"), 12)
         << " observations)</td></tr>";
  }
  html << "</table>\n";
  if (const ReportJson* known = FindKey(summary, "known_rig")) {
    html << "<p>Against the known rig of " << XmlEscape(TextAt(*known, "source"))
         << ":</p><table><tr><th>camera</th><th>rotation error (deg)</th>"
            "<th>translation error</th></tr>";
    if (const ReportJson* cameras = FindKey(*known, "cameras")) {
      for (const ReportJson& camera : *cameras) {
        html << "<tr><td>" << XmlEscape(TextAt(camera, "name")) << "</td><td>"
             << FormatNumber(NumberAt(camera, "rotation_error_deg"))
             << "</td><td>"
             << FormatNumber(NumberAt(camera, "translation_error"))
             << "</td></tr>";
      }
    }
    html << "</table>\n";
  }
  html << "</section>\n";
}

void CameraSection(const ReportJson& camera, const int index,
                   const CameraResiduals& residuals, Page* page) {
  const std::string i = std::to_string(index);
  const std::string name = TextAt(camera, "name");
  const ReportJson* calibrated = FindKey(camera, "calibrated");
  std::ostringstream& html = page->html;
  html << "<section class=\"camera\" id=\"camera-" << i << "\"><h3>"
       << XmlEscape(name) << " (" << XmlEscape(TextAt(camera, "model")) << ", "
       << FormatNumber(NumberAt(camera, "width"), 6) << " \u00d7 "
       << FormatNumber(NumberAt(camera, "height"), 6) << ")</h3>\n";
  const std::optional<colmap::Camera> model = SummaryCamera(camera);
  if (calibrated == nullptr || !calibrated->is_boolean() ||
      !calibrated->get<bool>() || !model) {
    html << "<p>Not calibrated: no figures.</p></section>\n";
    return;
  }
  html << "<p>" << residuals.num_observations;
  if (residuals.from_correspondences) {
    html << " rows of " << kCorrespondencesFile << " within "
         << FormatNumber(residuals.inlier_threshold_px, 3)
         << " px (3 × their median residual; the model has no 3D points "
            "to recompute the inliers from)";
  } else {
    html << " inlier observations in the output model";
  }
  html << ", RMS " << FormatNumber(residuals.rms_px)
       << " px recomputed (summary: "
       << FormatNumber(NumberAt(camera, "rms_px")) << " px), largest "
       << FormatNumber(residuals.max_error_px) << " px.</p>\n"
       << "<div class=\"figures\">\n";

  // Residuals over the image.
  if (residuals.num_observations > 0) {
    page->Figure("residuals-" + i,
                 ResidualFieldSvg("residuals-" + i, "Residuals over the image",
                                  residuals),
                 "Mean residual (observed \u2212 projected) per cell of a " +
                     std::to_string(residuals.cols) + " \u00d7 " +
                     std::to_string(residuals.rows) +
                     " grid, recomputed from the output model; colour: "
                     "the cell's RMS. Grey: no inlier.");
  } else {
    page->MissingFigure("residuals-" + i, "Residuals over the image",
                        "no observation of this camera in the output model");
  }

  // Coverage: the summary's grid, else the model's inliers counted.
  const double corner_radius = CornerRadiusPx(*model);
  HeatMapOptions coverage_options;
  coverage_options.id = "coverage-" + i;
  coverage_options.title = "Coverage of the image by the inliers";
  coverage_options.unit = "inliers";
  coverage_options.image_width = static_cast<int>(model->Width());
  coverage_options.image_height = static_cast<int>(model->Height());
  const ReportJson* coverage = FindKey(camera, "coverage");
  const ReportJson* coverage_grid =
      coverage != nullptr ? FindKey(*coverage, "grid") : nullptr;
  std::optional<ImageGridValues> counts =
      coverage_grid != nullptr ? SummaryGrid(*coverage_grid, "counts", true)
                               : std::nullopt;
  std::string coverage_caption;
  if (counts) {
    coverage_caption =
        "From \"coverage\": " +
        FormatNumber(100 * NumberAt(*coverage, "fraction_cells"), 3) +
        " % of the cells hold inliers; largest observed radius " +
        FormatNumber(NumberAt(*coverage, "max_observed_radius_px")) +
        " px of the corner's " +
        FormatNumber(NumberAt(*coverage, "corner_radius_px")) + " px (ratio " +
        FormatNumber(NumberAt(*coverage, "radius_ratio"), 3) +
        "). Grey: no inlier.";
  } else {
    counts.emplace();
    counts->cols = residuals.cols;
    counts->rows = residuals.rows;
    int occupied = 0;
    for (const ResidualCell& cell : residuals.cells) {
      counts->values.push_back(cell.count > 0 ? double(cell.count)
                                              : std::nan(""));
      occupied += cell.count > 0 ? 1 : 0;
    }
    coverage_caption =
        "Inliers of the output model counted per cell (no \"coverage\" in "
        "the summary): " +
        FormatNumber(
            100.0 * occupied / std::max<size_t>(1, residuals.cells.size()), 3) +
        " % of the cells; largest observed radius " +
        FormatNumber(residuals.max_radius_px) + " px of the corner's " +
        FormatNumber(corner_radius) + " px. Grey: no inlier.";
  }
  page->Figure("coverage-" + i, HeatMapSvg(coverage_options, *counts),
               XmlEscape(coverage_caption));

  // Projection uncertainty.
  const ReportJson* uncertainty = FindKey(camera, "uncertainty");
  const ReportJson* projection =
      uncertainty != nullptr ? FindKey(*uncertainty, "projection_stddev_px")
                             : nullptr;
  const ReportJson* projection_grid =
      projection != nullptr ? FindKey(*projection, "grid") : nullptr;
  const std::optional<ImageGridValues> stddevs =
      projection_grid != nullptr
          ? SummaryGrid(*projection_grid, "values", false)
          : std::nullopt;
  if (stddevs) {
    HeatMapOptions options = coverage_options;
    options.id = "uncertainty-" + i;
    options.title = "Projection uncertainty (1\u03c3)";
    options.unit = "px";
    const ReportJson* at = FindKey(*projection, "max_at");
    if (at != nullptr && at->is_array() && at->size() == 2 &&
        (*at)[0].is_number() && (*at)[1].is_number()) {
      options.marker =
          Eigen::Vector2d((*at)[0].get<double>(), (*at)[1].get<double>());
      options.marker_label = "max";
    }
    page->Figure(
        "uncertainty-" + i, HeatMapSvg(options, *stddevs),
        XmlEscape("1\u03c3 uncertainty of the projection of a ray, per cell "
               "centre: median " +
               FormatNumber(NumberAt(*projection, "median")) + " px, max " +
               FormatNumber(NumberAt(*projection, "max")) + " px (circled)."));
  } else {
    page->MissingFigure(
        "uncertainty-" + i, "Projection uncertainty",
        "no \"uncertainty.projection_stddev_px.grid\" in the summary");
  }

  // Radial profile.
  DistortionProfileOptions profile;
  profile.id = "distortion-" + i;
  profile.title = "Radial profile of " + model->ModelName();
  profile.min_observed_radius_px = residuals.min_radius_px;
  profile.max_observed_radius_px = residuals.max_radius_px;
  page->Figure(
      "distortion-" + i, DistortionProfileSvg(profile, *model),
      XmlEscape("Angle of a ray from the optical axis against where the model "
             "images it, towards the farthest corner (COLMAP's model). "
             "Observed radii " +
             FormatNumber(residuals.min_radius_px) + " to " +
             FormatNumber(residuals.max_radius_px) + " px; corner " +
             FormatNumber(corner_radius) +
             " px. A curve that turns back to the left folds back."));
  html << "</div></section>\n";
}

void RigSection(const ReportJson& summary, Page* page) {
  std::vector<RigViewCamera> cameras;
  for (const ReportJson& camera : *FindKey(summary, "cameras")) {
    const std::optional<Eigen::Quaterniond> rotation =
        CamFromRigRotation(camera);
    const std::optional<Eigen::Vector3d> translation =
        CamFromRigTranslation(camera);
    if (!rotation || !translation) continue;
    RigViewCamera view;
    view.name = TextAt(camera, "name");
    view.rig_from_cam = rotation->toRotationMatrix().transpose();
    view.center_in_rig = -(view.rig_from_cam * *translation);
    if (const ReportJson* uncertainty = FindKey(camera, "uncertainty")) {
      view.center_stddev = Vector3At(*uncertainty, "center_in_rig_stddev");
    }
    cameras.push_back(view);
  }
  std::ostringstream& html = page->html;
  html << "<section id=\"rig\"><h2>The rig</h2><div class=\"figures\">\n";
  const std::string units = TextAt(summary, "units");
  for (const RigView view : {RigView::kFromAbove, RigView::kFromSide}) {
    const std::string id =
        view == RigView::kFromAbove ? "rig-above" : "rig-side";
    const RigViewFigure figure = RigViewSvg(id, view, cameras, units);
    std::string caption =
        "Camera centres in the rig frame (the reference camera's) with each "
        "camera's axes; orange: 1\u03c3 position uncertainty.";
    bool any_stddev = false;
    for (const RigViewCamera& camera : cameras) {
      any_stddev = any_stddev || camera.center_stddev.has_value();
    }
    if (!any_stddev) {
      caption +=
          " Uncertainty ellipses: not computed (no "
          "\"center_in_rig_stddev\").";
    } else if (!figure.ellipses_too_small.empty()) {
      caption += " Smaller than a pixel at this scale:";
      for (const std::string& name : figure.ellipses_too_small) {
        caption += " " + name;
      }
      caption += ".";
    }
    page->Figure(id, figure.svg, XmlEscape(caption));
  }
  html << "</div></section>\n";
}

void FramesetsSection(const ModelResiduals& residuals,
                      const std::vector<std::string>& camera_names,
                      Page* page) {
  std::ostringstream& html = page->html;
  html << "<section id=\"framesets\"><h2>Reprojection error per frameset and "
          "per image</h2>\n";
  if (residuals.framesets.empty()) {
    page->MissingFigure("frameset-errors", "Reprojection error per frameset",
                        "no rig image in the output model");
    html << "</section>\n";
    return;
  }
  const std::vector<int> outlying =
      OutlyingFramesets(residuals.framesets, kOutlyingFramesetFactor);
  page->Figure(
      "frameset-errors",
      FramesetErrorsSvg("frameset-errors", residuals.framesets, camera_names),
      "RMS recomputed from the output model, per frameset (all its "
      "images) and per camera image.");
  html << "<p>" << outlying.size() << " of " << residuals.framesets.size()
       << " framesets have an RMS above " << kOutlyingFramesetFactor
       << " times the median (shaded in the table).</p>\n";
  std::vector<int> order(residuals.framesets.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return residuals.framesets[a].rms_px > residuals.framesets[b].rms_px;
  });
  html << "<table id=\"worst-framesets\"><tr><th>frameset</th><th>index</th>"
          "<th>observations</th><th>RMS (px)</th>";
  for (const std::string& name : camera_names) {
    html << "<th>" << XmlEscape(name) << "</th>";
  }
  html << "</tr>\n";
  for (size_t k = 0; k < std::min(kNumWorstRows, order.size()); ++k) {
    const FramesetError& frameset = residuals.framesets[order[k]];
    const bool bad =
        std::find(outlying.begin(), outlying.end(), order[k]) != outlying.end();
    html << (bad ? "<tr class=\"bad\">" : "<tr>") << "<td>"
         << XmlEscape(frameset.name) << "</td><td>" << order[k] << "</td><td>"
         << frameset.num_observations << "</td><td>"
         << FormatNumber(frameset.rms_px) << "</td>";
    for (const double rms : frameset.camera_rms_px) {
      html << "<td>" << FormatNumber(rms) << "</td>";
    }
    html << "</tr>\n";
  }
  html << "</table>\n<table id=\"worst-images\"><tr><th>image</th>"
          "<th>camera</th><th>frameset index</th><th>observations</th>"
          "<th>RMS (px)</th></tr>\n";
  std::vector<size_t> images(residuals.images.size());
  std::iota(images.begin(), images.end(), 0);
  std::stable_sort(images.begin(), images.end(), [&](size_t a, size_t b) {
    return residuals.images[a].rms_px > residuals.images[b].rms_px;
  });
  for (size_t k = 0; k < std::min(kNumWorstRows, images.size()); ++k) {
    const ImageError& image = residuals.images[images[k]];
    html << "<tr><td>" << XmlEscape(image.name) << "</td><td>"
         << XmlEscape(camera_names[image.camera]) << "</td><td>" << image.frameset
         << "</td><td>" << image.num_observations << "</td><td>"
         << FormatNumber(image.rms_px) << "</td></tr>\n";
  }
  html << "</table></section>\n";
}

// Whether some camera of the summary has a "timing" (camera_timing.h).
bool HasTiming(const ReportJson& summary) {
  for (const ReportJson& camera : *FindKey(summary, "cameras")) {
    if (FindKey(camera, "timing") != nullptr) return true;
  }
  return false;
}

// The cameras' capture timing (their "timing" in the summary,
// camera_timing.h): the time offsets and, when estimated, the line delays;
// nothing when no camera has a timing.
void TimingSection(const ReportJson& summary, Page* page) {
  std::vector<TimingFigurePoint> offsets, line_delays;
  std::string source;
  for (const ReportJson& camera : *FindKey(summary, "cameras")) {
    const ReportJson* timing = FindKey(camera, "timing");
    if (timing == nullptr) continue;
    const std::string name = TextAt(camera, "name");
    source = TextAt(*timing, "source");
    offsets.push_back({name, NumberAt(*timing, "time_offset_s") * 1e3,
                       NumberAt(*timing, "time_offset_sigma_s") * 1e3});
    if (FindKey(*timing, "line_delay_s_per_row") != nullptr) {
      line_delays.push_back(
          {name, NumberAt(*timing, "line_delay_s_per_row") * 1e6,
           NumberAt(*timing, "line_delay_sigma_s_per_row") * 1e6});
    }
  }
  if (offsets.empty()) return;
  const std::string reference = TextAt(summary, "reference_camera");
  const bool measured_after = source == "measured after calibration";
  std::ostringstream& html = page->html;
  html << "<section id=\"timing\"><h2>Capture timing</h2><div "
          "class=\"figures\">\n";
  page->Figure(
      "time-offsets",
      CaptureTimingSvg("time-offsets", "Capture-time offset per camera", "ms",
                       offsets),
      XmlEscape(
          "Each camera's capture-time offset δ against " + reference +
          ": it takes frameset f at t_f + δ, t_f on " + reference +
          "'s clock (" + reference +
          ": 0 by definition). Dot: the estimate; thick bar: ±1 "
          "σ; thin bar: ±3 σ. " +
          (measured_after
               ? "Measured after the calibration from each image's own pose "
                 "(" + source +
                     "): the calibration assumed synchronized cameras and its "
                     "intrinsics absorbed part of the rig's motion, so the "
                     "offsets are lower bounds of the true ones."
               : "Source: " + source + ".")));
  if (!line_delays.empty()) {
    page->Figure(
        "line-delays",
        CaptureTimingSvg("line-delays", "Rolling-shutter line delay per camera",
                         "us/row", line_delays),
        XmlEscape("Each camera's line delay ρ: image row v is taken at "
                  "t_f + δ + ρ v (µs per row; 0: a global "
                  "shutter). Bars: ±1 σ and ±3 σ. "
                  "Source: " +
                  source + "."));
  }
  html << "</div></section>\n";
}

}  // namespace

bool BuildReportHtml(const ReportInputs& inputs, std::string* html,
                     std::string* error) {
  try {
    const ReportJson& summary = inputs.summary;
    const ReportJson& cameras = *FindKey(summary, "cameras");
    std::vector<ReportCamera> report_cameras;
    std::vector<std::string> camera_names;
    for (const ReportJson& camera : cameras) {
      std::string prefix = TextAt(camera, "image_prefix");
      report_cameras.push_back({TextAt(camera, "name"), prefix});
      camera_names.push_back(TextAt(camera, "name"));
    }
    const ModelResiduals residuals =
        ComputeModelResiduals(inputs.model, inputs.rigs_frames, report_cameras,
                              kResidualGridCols, inputs.correspondences);
    Page page;
    page.html << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta "
                 "charset=\"utf-8\"/><title>rig_calibrator report</title>"
                 "<style>"
              << kStyle << "</style></head>\n<body>\n"
              << "<h1>Rig calibration report</h1>\n<nav><a "
                 "href=\"#overview\">overview</a><a "
                 "href=\"#parameters\">parameters</a><a "
                 "href=\"#model-choice\">model choice</a><a "
                 "href=\"#diagnostics\">diagnostics</a><a "
                 "href=\"#cameras\">cameras</a><a href=\"#rig\">rig</a><a "
                 "href=\"#framesets\">framesets</a>"
              << (HasTiming(summary) ? "<a href=\"#timing\">timing</a>" : "")
              << "<a href=\"#camchain\">camchain.yaml</a></nav>\n";
    OverviewSection(inputs, &page);
    page.html << "<section id=\"parameters\"><h2>Parameters</h2>\n"
              << IntrinsicsTableHtml(summary) << PosesTableHtml(summary)
              << "</section>\n<section id=\"model-choice\"><h2>Model "
                 "choice</h2>\n"
              << ModelChoiceHtml(summary)
              << "</section>\n<section id=\"diagnostics\"><h2>Diagnostics"
                 "</h2>\n"
              << DiagnosticsListHtml(summary)
              << "<h3>Model validity over "
                 "the whole image</h3>\n"
              << ValidityTableHtml(summary)
              << "</section>\n<section id=\"cameras\"><h2>Cameras</h2>\n";
    for (size_t c = 0; c < cameras.size(); ++c) {
      CameraSection(cameras[c], static_cast<int>(c), residuals.cameras[c],
                    &page);
    }
    page.html << "</section>\n";
    RigSection(summary, &page);
    FramesetsSection(residuals, camera_names, &page);
    TimingSection(summary, &page);
    page.html << "<section id=\"camchain\"><h2>camchain.yaml</h2>\n";
    if (inputs.camchain_yaml.empty()) {
      page.html << "<p>" << NotComputedHtml("no camchain.yaml in the folder")
                << "</p>";
    } else {
      page.html << "<details><summary>Kalibr-style camchain.yaml (as "
                   "written)</summary><pre>"
                << XmlEscape(inputs.camchain_yaml) << "</pre></details>";
    }
    page.html << "</section>\n<script>" << kSelfCheckScript
              << "</script>\n</body></html>\n";
    *html = page.html.str();
    // The figure count, for the browser test.
    const std::string body = "<body>";
    html->replace(html->find(body), body.size(),
                  "<body data-expected-figures=\"" +
                      std::to_string(page.num_figures) + "\">");
  } catch (const nlohmann::json::exception& exception) {
    *error = inputs.folder + "/" + kSummaryFile +
             " holds a value of an unexpected type: " + exception.what();
    return false;
  }
  return true;
}

bool WriteReportHtml(const std::string& folder, std::string* error) {
  ReportInputs inputs;
  std::string html;
  return ReadReportInputs(folder, &inputs, error) &&
         BuildReportHtml(inputs, &html, error) &&
         WriteFileAtomically(folder + "/" + kReportFile, html, error);
}

}  // namespace rig_calibrator
