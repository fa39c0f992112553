#include "colmap_ext/report/svg_plot.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace rig_calibrator {
namespace svg_plot_test {

// Checks that the document is one well-nested tree of elements (a small
// well-formedness check: tags open and close in order, attribute quotes are
// balanced, text holds no raw '<' or '&' outside entities) and counts the
// elements by name.
bool WellFormed(const std::string& svg, std::map<std::string, int>* counts,
                std::string* problem) {
  std::vector<std::string> open;
  size_t position = 0;
  while (position < svg.size()) {
    const size_t start = svg.find('<', position);
    const std::string text = svg.substr(
        position, (start == std::string::npos ? svg.size() : start) - position);
    for (size_t amp = text.find('&'); amp != std::string::npos;
         amp = text.find('&', amp + 1)) {
      if (text.find(';', amp) == std::string::npos) {
        *problem = "raw & in text: " + text;
        return false;
      }
    }
    if (start == std::string::npos) break;
    const size_t end = svg.find('>', start);
    if (end == std::string::npos) {
      *problem = "unterminated tag";
      return false;
    }
    const std::string tag = svg.substr(start + 1, end - start - 1);
    if (std::count(tag.begin(), tag.end(), '"') % 2 != 0 ||
        tag.find('<') != std::string::npos) {
      *problem = "bad tag: " + tag;
      return false;
    }
    position = end + 1;
    if (tag.empty() || tag[0] == '?') continue;
    if (tag[0] == '/') {
      if (open.empty() || open.back() != tag.substr(1)) {
        *problem = "unexpected </" + tag.substr(1) + ">";
        return false;
      }
      open.pop_back();
      continue;
    }
    const std::string name = tag.substr(0, tag.find_first_of(" /"));
    ++(*counts)[name];
    if (tag.back() != '/') open.push_back(name);
  }
  if (!open.empty()) {
    *problem = "unclosed <" + open.back() + ">";
    return false;
  }
  return (*counts)["svg"] == 1;
}

TEST(SvgPlot, LinearTicksAreNiceAndCoverTheRange) {
  const std::vector<double> unit = LinearTicks(0, 1, 5);
  ASSERT_EQ(unit.size(), 6u);
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(unit[k], 0.2 * k, 1e-12);
  const std::vector<double> ticks = LinearTicks(0, 100, 5);
  ASSERT_EQ(ticks.size(), 6u);
  EXPECT_DOUBLE_EQ(ticks[1], 20);
  EXPECT_DOUBLE_EQ(ticks.back(), 100);
  const std::vector<double> offset = LinearTicks(3.2, 17.9, 4);
  ASSERT_FALSE(offset.empty());
  EXPECT_DOUBLE_EQ(offset.front(), 5);
  EXPECT_DOUBLE_EQ(offset.back(), 15);
  EXPECT_TRUE(LinearTicks(1, 1, 5).empty());
  EXPECT_TRUE(LinearTicks(0, std::nan(""), 5).empty());
}

TEST(SvgPlot, XmlEscapeEscapesMarkup) {
  EXPECT_EQ(XmlEscape("a<b & \"c\" > 'd'"),
            "a&lt;b &amp; &quot;c&quot; &gt; &apos;d&apos;");
}

TEST(SvgPlot, CumulativeDistributionCountsFailuresInTheDenominator) {
  const PlotSeries series = CumulativeDistribution(
      "m", {3, 1, std::numeric_limits<double>::infinity(), 2});
  EXPECT_TRUE(series.step);
  EXPECT_EQ(series.x, (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(series.y, (std::vector<double>{0.25, 0.5, 0.75}));
}

TEST(SvgPlot, LinePlotIsWellFormedWithAxesAndLegend) {
  PlotOptions options;
  options.title = "Errors <initial> & final";
  options.x_label = "error (deg)";
  options.y_label = "fraction";
  options.log_x = true;
  options.y_min = 0;
  options.y_max = 1;
  options.x_markers = {1.0};
  options.x_marker_labels = {"good"};
  const std::vector<PlotSeries> series = {
      CumulativeDistribution("rd", {0.02, 0.3, 5, 40}),
      CumulativeDistribution("1dr", {0.01, 0.05, 0.2, 0})};
  const std::string svg = LinePlotSvg(options, series);
  std::map<std::string, int> counts;
  std::string problem;
  ASSERT_TRUE(WellFormed(svg, &counts, &problem)) << problem << "\n" << svg;
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  EXPECT_EQ(counts["polyline"], 2);
  EXPECT_NE(svg.find("Errors &lt;initial&gt; &amp; final"), std::string::npos);
  for (const char* text :
       {">rd<", ">1dr<", ">error (deg)<", ">fraction<", ">good<", ">0.01<",
        ">0.1<", ">1<", ">10<", ">100<", ">0.2<"}) {
    EXPECT_NE(svg.find(text), std::string::npos) << text;
  }
  // x = 0 cannot be drawn on a log axis: 3 points, 5 staircase vertices.
  const size_t second = svg.find("<polyline", svg.find("<polyline") + 1);
  const std::string points =
      svg.substr(second, svg.find("/>", second) - second);
  EXPECT_EQ(std::count(points.begin(), points.end(), ','), 5);
}

// Two charts inlined in one HTML page: no XML declaration, and ids of their
// own, so that each polyline is clipped by its own chart's plot area.
TEST(SvgPlot, InlineChartsHaveUniqueIdsAndNoDeclaration) {
  PlotOptions options;
  options.inline_id = "cam0-profile";
  const std::vector<PlotSeries> series = {{"a", {0, 1, 2}, {1, 2, 3}, false}};
  const std::string svg = LinePlotSvg(options, series);
  std::map<std::string, int> counts;
  std::string problem;
  ASSERT_TRUE(WellFormed(svg, &counts, &problem)) << problem << "\n" << svg;
  EXPECT_EQ(svg.find("<?xml"), std::string::npos);
  EXPECT_EQ(svg.rfind("<svg id=\"cam0-profile\" xmlns=", 0), 0u);
  EXPECT_NE(svg.find("<clipPath id=\"cam0-profile-plot-area\">"),
            std::string::npos);
  EXPECT_NE(svg.find("clip-path=\"url(#cam0-profile-plot-area)\""),
            std::string::npos);
  EXPECT_EQ(svg.find("\"plot-area\""), std::string::npos);
}

TEST(SvgPlot, BarChartHasOneBarPerValue) {
  PlotOptions options;
  options.title = "good";
  options.y_min = 0;
  options.y_max = 100;
  options.slant_x_labels = true;
  const std::string svg = BarChartSvg(
      options, {"ring5 easy", "ring5 hard", "car"}, {"rd", "rd_ra", "1dr"},
      {{100, 50, 20}, {100, 70, std::nan("")}, {100, 80, 60}});
  std::map<std::string, int> counts;
  std::string problem;
  ASSERT_TRUE(WellFormed(svg, &counts, &problem)) << problem << "\n" << svg;
  // 8 bars + 3 legend boxes + background + plot frame.
  EXPECT_EQ(counts["rect"], 8 + 3 + 2);
  EXPECT_EQ(counts["title"], 8);
  EXPECT_NE(svg.find("rotate(30"), std::string::npos);
  EXPECT_NE(svg.find(">ring5 hard<"), std::string::npos);
}

}  // namespace svg_plot_test
}  // namespace rig_calibrator
