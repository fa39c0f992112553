#include "colmap_ext/report/report_tables.h"

#include <colmap/base/camera_models.h>

#include <sstream>
#include <vector>

#include "colmap_ext/report/svg_plot.h"

namespace rig_calibrator {
namespace {

// COLMAP's parameter names of a model ("fx", "cx", "k1", ...); p0, p1, ...
// for a model COLMAP 3.8 does not know.
std::vector<std::string> ParamNames(const std::string& model, size_t count) {
  std::vector<std::string> names;
  if (colmap::ExistsCameraModelWithName(model)) {
    std::istringstream info(
        colmap::CameraModelParamsInfo(colmap::CameraModelNameToId(model)));
    std::string name;
    while (std::getline(info, name, ',')) {
      names.push_back(name.substr(name.find_first_not_of(' ')));
    }
  }
  while (names.size() < count)
    names.push_back("p" + std::to_string(names.size()));
  return names;
}

// "value ± stddev" (the ± part only when the stddev is known).
std::string WithStddev(const double value, const double stddev,
                       const int digits = 6) {
  std::string text = FormatNumber(value, digits);
  if (std::isfinite(stddev)) text += " \u00b1 " + FormatNumber(stddev, 2);
  return text;
}

std::string Cell(const std::string& html) { return "<td>" + html + "</td>"; }

const ReportJson& Cameras(const ReportJson& summary) {
  static const ReportJson kEmpty = ReportJson::array();
  const ReportJson* cameras = FindKey(summary, "cameras");
  return cameras != nullptr && cameras->is_array() ? *cameras : kEmpty;
}

std::string Vector3Html(const std::optional<Eigen::Vector3d>& value,
                        const std::optional<Eigen::Vector3d>& stddev) {
  if (!value) return "\u2013";
  std::string text;
  for (int k = 0; k < 3; ++k) {
    if (k > 0) text += "<br/>";
    text += WithStddev((*value)[k], stddev ? (*stddev)[k] : std::nan(""), 5);
  }
  return text;
}

}  // namespace

std::string NotComputedHtml(const std::string& reason) {
  return "<span class=\"not-computed\">not computed</span> <span "
         "class=\"why\">(" +
         XmlEscape(reason) + ")</span>";
}

std::optional<Eigen::Vector3d> Vector3At(const ReportJson& node,
                                         const char* key) {
  const ReportJson* value = FindKey(node, key);
  if (value == nullptr || !value->is_array() || value->size() != 3) {
    return std::nullopt;
  }
  Eigen::Vector3d vector;
  for (int k = 0; k < 3; ++k) {
    if (!(*value)[k].is_number()) return std::nullopt;
    vector[k] = (*value)[k].get<double>();
  }
  return vector;
}

std::optional<Eigen::Quaterniond> CamFromRigRotation(const ReportJson& camera) {
  const ReportJson* pose = FindKey(camera, "cam_from_rig");
  if (pose == nullptr) return std::nullopt;
  const ReportJson* wxyz = FindKey(*pose, "rotation_wxyz");
  if (wxyz == nullptr || !wxyz->is_array() || wxyz->size() != 4) {
    return std::nullopt;
  }
  for (const ReportJson& value : *wxyz) {
    if (!value.is_number()) return std::nullopt;
  }
  Eigen::Quaterniond rotation(
      (*wxyz)[0].get<double>(), (*wxyz)[1].get<double>(),
      (*wxyz)[2].get<double>(), (*wxyz)[3].get<double>());
  if (!(rotation.norm() > 0)) return std::nullopt;
  return rotation.normalized();
}

std::optional<Eigen::Vector3d> CamFromRigTranslation(const ReportJson& camera) {
  const ReportJson* pose = FindKey(camera, "cam_from_rig");
  if (pose == nullptr) return std::nullopt;
  return Vector3At(*pose, "translation");
}

std::string IntrinsicsTableHtml(const ReportJson& summary) {
  std::ostringstream html;
  html << "<table id=\"intrinsics-table\"><tr><th>camera</th><th>model</th>"
          "<th>image</th><th>focal length (px) \u00b1 1\u03c3</th>"
          "<th>principal point (px) \u00b1 1\u03c3</th><th>distortion "
          "\u00b1 1\u03c3</th><th>refined</th></tr>\n";
  for (const ReportJson& camera : Cameras(summary)) {
    const std::string model = TextAt(camera, "model");
    const ReportJson* params = FindKey(camera, "params");
    const size_t count =
        params != nullptr && params->is_array() ? params->size() : 0;
    const std::vector<std::string> names = ParamNames(model, count);
    const ReportJson* uncertainty = FindKey(camera, "uncertainty");
    const ReportJson* stddevs = uncertainty != nullptr
                                    ? FindKey(*uncertainty, "params_stddev")
                                    : nullptr;
    // COLMAP's grouping of the model's parameters; all "distortion" for a
    // model COLMAP 3.8 does not know.
    std::vector<int> group(count, 2);
    if (colmap::ExistsCameraModelWithName(model)) {
      const int model_id = colmap::CameraModelNameToId(model);
      for (const size_t k : colmap::CameraModelFocalLengthIdxs(model_id)) {
        if (k < count) group[k] = 0;
      }
      for (const size_t k : colmap::CameraModelPrincipalPointIdxs(model_id)) {
        if (k < count) group[k] = 1;
      }
    }
    std::string cells[3];
    for (size_t k = 0; k < count; ++k) {
      const double stddev =
          stddevs != nullptr && stddevs->is_array() && k < stddevs->size()
              ? NumberOr(&(*stddevs)[k])
              : std::nan("");
      std::string& cell = cells[group[k]];
      if (!cell.empty()) cell += "<br/>";
      cell +=
          XmlEscape(names[k]) + " " + WithStddev(NumberOr(&(*params)[k]), stddev);
    }
    if (stddevs == nullptr) {
      cells[0] += "<br/>\u03c3: " + NotComputedHtml("no \"uncertainty\"");
    }
    const ReportJson* refined = FindKey(camera, "refined");
    std::string refined_html = NotComputedHtml("no \"refined\" in the summary");
    if (refined != nullptr) {
      refined_html.clear();
      for (const char* key :
           {"focal_length", "principal_point", "extra_params"}) {
        const ReportJson* flag = FindKey(*refined, key);
        if (!refined_html.empty()) refined_html += "<br/>";
        refined_html += std::string(key) + ": " +
                        (flag != nullptr && flag->is_boolean()
                             ? (flag->get<bool>() ? "yes" : "no (held)")
                             : "\u2013");
      }
    }
    html << "<tr>" << Cell(XmlEscape(TextAt(camera, "name")))
         << Cell(XmlEscape(model))
         << Cell(FormatNumber(NumberAt(camera, "width"), 6) + " \u00d7 " +
                 FormatNumber(NumberAt(camera, "height"), 6))
         << Cell(cells[0]) << Cell(cells[1])
         << Cell(cells[2].empty() ? "none" : cells[2]) << Cell(refined_html)
         << "</tr>\n";
  }
  html << "</table>\n";
  return html.str();
}

std::string PosesTableHtml(const ReportJson& summary) {
  std::ostringstream html;
  html << "<table id=\"poses-table\"><tr><th>camera</th><th>centre in the "
          "rig \u00b1 1\u03c3 (x, y, z)</th><th>rotation from the reference "
          "camera (deg) \u00b1 1\u03c3</th><th>cam_from_rig translation "
          "\u00b1 1\u03c3</th><th>images localized / used / all</th>"
          "<th>inliers</th><th>RMS (px)</th><th>radial RMS (px)</th>"
          "<th>noise \u03c3 from the data (px)</th></tr>\n";
  for (const ReportJson& camera : Cameras(summary)) {
    const std::optional<Eigen::Quaterniond> rotation =
        CamFromRigRotation(camera);
    const std::optional<Eigen::Vector3d> translation =
        CamFromRigTranslation(camera);
    const ReportJson* uncertainty = FindKey(camera, "uncertainty");
    const ReportJson kNone;
    const ReportJson& u = uncertainty != nullptr ? *uncertainty : kNone;
    std::optional<Eigen::Vector3d> center;
    if (rotation && translation) {
      center = -(rotation->inverse() * *translation);
    }
    html << "<tr>" << Cell(XmlEscape(TextAt(camera, "name")));
    if (!rotation || !translation) {
      html << "<td colspan=\"3\">not calibrated</td>";
    } else {
      html << Cell(Vector3Html(center, Vector3At(u, "center_in_rig_stddev")))
           << Cell(WithStddev(Eigen::AngleAxisd(*rotation).angle() * 180 / M_PI,
                              NumberAt(u, "rotation_stddev_deg"), 5))
           << Cell(
                  Vector3Html(translation, Vector3At(u, "translation_stddev")));
    }
    html << Cell(FormatNumber(NumberAt(camera, "num_localized"), 9) + " / " +
                 FormatNumber(NumberAt(camera, "num_used"), 9) + " / " +
                 FormatNumber(NumberAt(camera, "num_images"), 9))
         << Cell(FormatNumber(NumberAt(camera, "num_inliers"), 12))
         << Cell(FormatNumber(NumberAt(camera, "rms_px")))
         << Cell(FormatNumber(NumberAt(camera, "radial_rms_px")))
         << Cell(uncertainty != nullptr
                     ? FormatNumber(NumberAt(u, "residual_scale_px"))
                     : NotComputedHtml("no \"uncertainty\""))
         << "</tr>\n";
  }
  html << "</table>\n";
  return html.str();
}

std::string ModelChoiceHtml(const ReportJson& summary) {
  std::ostringstream rows;
  int num_cameras = 0;
  for (const ReportJson& camera : Cameras(summary)) {
    const ReportJson* choice = FindKey(camera, "model_choice");
    if (choice == nullptr) continue;
    ++num_cameras;
    const ReportJson* candidates = FindKey(*choice, "candidates");
    const size_t count = candidates != nullptr && candidates->is_array()
                             ? candidates->size()
                             : 0;
    const std::string span =
        "<td rowspan=\"" + std::to_string(std::max<size_t>(1, count)) + "\">";
    rows << "<tr>" << span << XmlEscape(TextAt(camera, "name")) << "</td>" << span
         << "<b>" << XmlEscape(TextAt(*choice, "chosen"))
         << "</b>: " << XmlEscape(TextAt(*choice, "reason")) << "</td>";
    if (count == 0) rows << "<td colspan=\"6\">no candidates</td></tr>\n";
    for (size_t k = 0; k < count; ++k) {
      const ReportJson& candidate = (*candidates)[k];
      const ReportJson* valid = FindKey(candidate, "valid");
      const ReportJson* chosen = FindKey(candidate, "chosen");
      const bool is_chosen =
          chosen != nullptr && chosen->is_boolean() && chosen->get<bool>();
      if (k > 0) rows << "<tr>";
      rows << Cell(std::string(is_chosen ? "<b class=\"chosen\">" : "") +
                   XmlEscape(TextAt(candidate, "model")) +
                   (is_chosen ? " \u2714</b>" : ""))
           << Cell(valid != nullptr && valid->is_boolean()
                       ? (valid->get<bool>() ? "yes" : "no")
                       : "\u2013")
           << Cell(FormatNumber(NumberAt(candidate, "heldout_rms_px")))
           << Cell(FormatNumber(NumberAt(candidate, "train_rms_px")))
           << Cell(FormatNumber(NumberAt(candidate, "num_params")))
           << "</tr>\n";
    }
  }
  if (num_cameras == 0) {
    return "<p>" +
           NotComputedHtml(
               "no camera has \"model_choice\": it is written for cameras "
               "whose --RigCalibrator.camera_model is auto") +
           "</p>\n";
  }
  return "<table id=\"model-choice-table\"><tr><th>camera</th><th>chosen, "
         "and why</th><th>candidate</th><th>valid</th><th>held-out RMS "
         "(px)</th><th>training RMS (px)</th><th>parameters</th></tr>\n" +
         rows.str() + "</table>\n";
}

std::string ValidityTableHtml(const ReportJson& summary) {
  std::ostringstream html;
  html << "<table id=\"validity-table\"><tr><th>camera</th><th>model valid "
          "over the image</th><th>monotonic</th><th>undistort-distort "
          "round trip (px)</th><th>fits the data (radial residual rings)"
          "</th><th>fold radius (px)</th><th>corner radius "
          "(px)</th><th>suggested model</th><th>message</th></tr>\n";
  for (const ReportJson& camera : Cameras(summary)) {
    html << "<tr>" << Cell(XmlEscape(TextAt(camera, "name")));
    const ReportJson* validity = FindKey(camera, "validity");
    if (validity == nullptr) {
      html << "<td colspan=\"8\">"
           << NotComputedHtml("no \"validity\" in the summary")
           << "</td></tr>\n";
      continue;
    }
    const auto yes_no = [&](const char* key) -> std::string {
      const ReportJson* flag = FindKey(*validity, key);
      if (flag == nullptr || !flag->is_boolean()) return "\u2013";
      return flag->get<bool>() ? "yes" : "<b class=\"bad\">no</b>";
    };
    const std::string suggested = TextAt(*validity, "suggested_model");
    html << Cell(yes_no("valid")) << Cell(yes_no("monotonic"))
         << Cell(FormatNumber(NumberAt(*validity, "max_roundtrip_error_px")))
         << Cell(yes_no("fits_data"))
         << Cell(FormatNumber(NumberAt(*validity, "fold_radius_px")))
         << Cell(FormatNumber(NumberAt(*validity, "corner_radius_px")))
         << Cell(suggested.empty() ? "\u2013" : XmlEscape(suggested))
         << Cell(XmlEscape(TextAt(*validity, "message"))) << "</tr>\n";
  }
  html << "</table>\n";
  return html.str();
}

std::string DiagnosticsListHtml(const ReportJson& summary) {
  const ReportJson* diagnostics = FindKey(summary, "diagnostics");
  if (diagnostics == nullptr || !diagnostics->is_array() ||
      diagnostics->empty()) {
    return "<p id=\"diagnostics-list\">No diagnostics.</p>\n";
  }
  std::ostringstream html;
  html << "<ul id=\"diagnostics-list\">\n";
  for (const ReportJson& line : *diagnostics) {
    const std::string text =
        line.is_string() ? line.get<std::string>() : line.dump();
    std::string level = "note";
    for (const char* name : {"error", "warning", "info"}) {
      if (text.rfind(std::string(name) + " ", 0) == 0) level = name;
    }
    html << "<li class=\"" << level << "\"><b>" << level << "</b> "
         << XmlEscape(level == "note" ? text : text.substr(level.size() + 1))
         << "</li>\n";
  }
  html << "</ul>\n";
  return html.str();
}

}  // namespace rig_calibrator
