// SVG plots: tick rules by hand, point placement against the plot-area mapping, per-pixel
// reduction keeping the extremes, gaps for points a log axis cannot show, escaping.
#include "vibid/report/svg_plot.hpp"

#include <cmath>
#include <numbers>
#include <regex>
#include <string>

#include <gtest/gtest.h>

#include "vibid/common/error.hpp"

namespace vibid::report {
namespace {

std::vector<std::string> Polylines(const std::string& svg) {
  std::vector<std::string> out;
  const std::regex re("<polyline class=\"series\"[^>]* points=\"([^\"]*)\"");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), re); it != std::sregex_iterator();
       ++it)
    out.push_back((*it)[1]);
  return out;
}

std::vector<std::pair<double, double>> Points(const std::string& list) {
  std::vector<std::pair<double, double>> out;
  std::size_t i = 0;
  while (i < list.size()) {
    std::size_t comma = list.find(',', i), space = list.find(' ', comma);
    if (space == std::string::npos) space = list.size();
    out.emplace_back(std::stod(list.substr(i, comma - i)),
                     std::stod(list.substr(comma + 1, space - comma - 1)));
    i = space + 1;
  }
  return out;
}

TEST(Ticks, LinearStepsAreOneTwoFiveTimesAPowerOfTen) {
  // By hand: range 1 in ~5 steps -> 0.2; 0..7 in ~6 -> 1 (7/6 = 1.17 -> 2); -0.37..2.1 -> 0.5.
  EXPECT_EQ(LinearTicks(0, 1, 5), (std::vector<double>{0, 0.2, 0.4, 0.6000000000000001, 0.8, 1}));
  EXPECT_EQ(LinearTicks(0, 7, 6), (std::vector<double>{0, 2, 4, 6}));
  EXPECT_EQ(LinearTicks(-0.37, 2.1, 6), (std::vector<double>{0, 0.5, 1, 1.5, 2}));
  EXPECT_EQ(LinearTicks(-30, -10, 4), (std::vector<double>{-30, -25, -20, -15, -10}));
  EXPECT_TRUE(LinearTicks(1, 1).empty());
}

TEST(Ticks, LogTicksAreDecadesOrOneTwoFive) {
  EXPECT_EQ(LogTicks(0.3, 250), (std::vector<double>{1, 10, 100}));
  EXPECT_EQ(LogTicks(0.5, 50), (std::vector<double>{0.5, 1, 2, 5, 10, 20, 50}));
  EXPECT_EQ(LogTicks(1e-6, 1e-3), (std::vector<double>{1e-6, 1e-5, 1e-4, 1e-3}));
  EXPECT_EQ(LogTicks(1.5, 30), (std::vector<double>{2, 5, 10, 20}));
  EXPECT_TRUE(LogTicks(0, 10).empty());
}

TEST(SvgPlot, PointsLandWhereTheAxesSayTheyShould) {
  // y from 0 to 10 on a linear axis padded to ticks 0..10: (0, 0) at the bottom left corner,
  // (10, 10) at the top right, (5, 2.5) a quarter up the middle.
  PlotOptions o{.title = "line",
                .x = {"x", Scale::kLinear},
                .y = {"y", Scale::kLinear},
                .width_px = 400,
                .height_px = 300};
  Series s{.label = "s", .x = Eigen::Vector3d(0, 5, 10), .y = Eigen::Vector3d(0, 2.5, 10)};
  const std::string svg = SvgPlot({s}, o);
  const auto lines = Polylines(svg);
  ASSERT_EQ(lines.size(), 1u);
  const auto p = Points(lines[0]);
  const PlotArea a = AreaOf(o);
  ASSERT_EQ(p.size(), 3u);
  EXPECT_NEAR(p[0].first, a.left, 0.05);
  EXPECT_NEAR(p[0].second, a.bottom, 0.05);
  EXPECT_NEAR(p[1].first, 0.5 * (a.left + a.right), 0.05);
  EXPECT_NEAR(p[1].second, a.bottom - 0.25 * (a.bottom - a.top), 0.05);
  EXPECT_NEAR(p[2].first, a.right, 0.05);
  EXPECT_NEAR(p[2].second, a.top, 0.05);
}

TEST(SvgPlot, LogAxesMapDecadesEvenlyAndBreakAtNonPositiveValues) {
  PlotOptions o{.title = "frf",
                .x = {"f", Scale::kLog},
                .y = {"|H|", Scale::kLog},
                .width_px = 400,
                .height_px = 300};
  // x 1, 10, 100 and y 1e-4, 1e-3, (0: not drawable), 1e-2 at x = 100: the axes end on those
  // values (1-2-5 padding leaves 1-2-5 values as they are).
  Series s{.label = "h",
           .x = Eigen::Vector4d(1, 10, 50, 100),
           .y = Eigen::Vector4d(1e-4, 1e-3, 0.0, 1e-2)};
  const auto lines = Polylines(SvgPlot({s}, o));
  ASSERT_EQ(lines.size(), 2u);
  const auto first = Points(lines[0]);
  const auto second = Points(lines[1]);
  const PlotArea a = AreaOf(o);
  ASSERT_EQ(first.size(), 2u);
  ASSERT_EQ(second.size(), 1u);
  EXPECT_NEAR(first[1].first, 0.5 * (a.left + a.right), 0.05);  // 10 is half way between 1 and 100
  EXPECT_NEAR(first[1].second, 0.5 * (a.top + a.bottom),
              0.05);  // 1e-3 half way between 1e-4 and 1e-2
  EXPECT_NEAR(second[0].first, a.right, 0.05);
}

TEST(SvgPlot, LongRecordsKeepTheirExtremesInFewPoints) {
  const Eigen::Index n = 150000;
  Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(n, 0.0, 30.0);
  Eigen::VectorXd y = (2 * std::numbers::pi * 16.0 * t.array()).sin().matrix();
  y[77777] = 3.0;  // one spike must survive the reduction
  PlotOptions o{.title = "d",
                .x = {"t", Scale::kLinear},
                .y = {"F", Scale::kLinear},
                .width_px = 600,
                .height_px = 300};
  const auto lines = Polylines(SvgPlot({Series{.label = "y", .x = t, .y = y}}, o));
  ASSERT_EQ(lines.size(), 1u);
  const auto p = Points(lines[0]);
  EXPECT_LE(p.size(), 2u * 600u);
  double top = 1e9;
  for (const auto& q : p) top = std::min(top, q.second);
  // Axis padded to ticks -1..3 (step 1 for a range of 4): the spike sits on the top edge.
  EXPECT_NEAR(top, AreaOf(o).top, 0.05);
}

TEST(SvgPlot, EscapesTextAndRefusesBadInput) {
  PlotOptions o{.title = "a<b & \"c\"", .x = {"x", Scale::kLinear}, .y = {"y", Scale::kLinear}};
  const std::string svg =
      SvgPlot({Series{.label = "<s>", .x = Eigen::Vector2d(0, 1), .y = Eigen::Vector2d(1, 2)}}, o);
  EXPECT_NE(svg.find("a&lt;b &amp; &quot;c&quot;"), std::string::npos);
  EXPECT_NE(svg.find("&lt;s&gt;"), std::string::npos);
  EXPECT_EQ(svg.find("<s>"), std::string::npos);
  EXPECT_THROW(SvgPlot({}, o), InputError);
  EXPECT_THROW(
      SvgPlot({Series{.label = "s", .x = Eigen::Vector2d(0, 1), .y = Eigen::Vector3d(1, 2, 3)}}, o),
      InputError);
  o.y.scale = Scale::kLog;
  EXPECT_THROW(
      SvgPlot({Series{.label = "s", .x = Eigen::Vector2d(0, 1), .y = Eigen::Vector2d(-1, 0)}}, o),
      InputError);
}

}  // namespace
}  // namespace vibid::report
