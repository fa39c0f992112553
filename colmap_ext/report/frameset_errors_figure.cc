#include "colmap_ext/report/frameset_errors_figure.h"

#include <algorithm>
#include <cmath>

#include "colmap_ext/report/svg_plot.h"

namespace rig_calibrator {

std::string FramesetErrorsSvg(const std::string& id,
                              const std::vector<FramesetError>& framesets,
                              const std::vector<std::string>& camera_names) {
  std::vector<PlotSeries> series;
  PlotSeries all{"all cameras", {}, {}, false};
  for (size_t f = 0; f < framesets.size(); ++f) {
    all.x.push_back(static_cast<double>(f));
    all.y.push_back(framesets[f].num_observations > 0 ? framesets[f].rms_px
                                                      : std::nan(""));
  }
  series.push_back(all);
  for (size_t c = 0; c < camera_names.size(); ++c) {
    PlotSeries camera{camera_names[c], {}, {}, false};
    for (size_t f = 0; f < framesets.size(); ++f) {
      if (c >= framesets[f].camera_rms_px.size()) continue;
      camera.x.push_back(static_cast<double>(f));
      camera.y.push_back(framesets[f].camera_rms_px[c]);
    }
    series.push_back(camera);
  }
  PlotOptions plot;
  plot.inline_id = id;
  plot.title = "Reprojection error per frameset";
  plot.x_label = "frameset (index in the order of the frames)";
  plot.y_label = "RMS (px)";
  plot.width = 900;
  plot.height = 320;
  plot.x_min = 0;
  plot.x_max = std::max<double>(1, framesets.size() - 1);
  plot.y_min = 0;
  return LinePlotSvg(plot, series);
}

std::vector<int> OutlyingFramesets(const std::vector<FramesetError>& framesets,
                                   const double factor) {
  std::vector<double> rms;
  for (const FramesetError& frameset : framesets) {
    if (frameset.num_observations > 0) rms.push_back(frameset.rms_px);
  }
  std::vector<int> outlying;
  if (rms.empty()) return outlying;
  std::nth_element(rms.begin(), rms.begin() + rms.size() / 2, rms.end());
  const double median = rms[rms.size() / 2];
  for (size_t f = 0; f < framesets.size(); ++f) {
    if (framesets[f].num_observations > 0 &&
        framesets[f].rms_px > factor * median) {
      outlying.push_back(static_cast<int>(f));
    }
  }
  std::sort(outlying.begin(), outlying.end(), [&](int a, int b) {
    return framesets[a].rms_px > framesets[b].rms_px;
  });
  return outlying;
}

}  // namespace rig_calibrator
