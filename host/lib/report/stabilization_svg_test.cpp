// The stabilization figure: markers where the poles are, chosen poles drawn, bad input refused.
#include "vibid/report/stabilization_svg.hpp"

#include <string>

#include <gtest/gtest.h>

#include "vibid/common/error.hpp"

namespace vibid::report {
namespace {

int Count(const std::string& text, const std::string& what) {
  int n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(StabilizationSvg, DrawsEveryPoleAndTheChosenOnes) {
  StabilizationFigure f;
  f.title = "diagram";
  f.freq_min_hz = 0.0;
  f.freq_max_hz = 100.0;
  for (int order = 4; order <= 20; order += 2) {
    f.poles.push_back({50.0, order, order >= 8 ? PoleMark::kStable : PoleMark::kFrequency});
    f.poles.push_back({10.0 + order, order, PoleMark::kUnstable});
  }
  f.chosen_hz = {50.0};
  f.frf_freq_hz = Eigen::VectorXd::LinSpaced(101, 0.0, 100.0);
  f.frf_magnitude = (1.0 + (f.frf_freq_hz.array() - 50.0).square()).inverse();
  const std::string svg = StabilizationSvg(f);
  EXPECT_EQ(Count(svg, "class=\"stable\""), 7);
  EXPECT_EQ(Count(svg, "class=\"freq\""), 2);
  EXPECT_EQ(Count(svg, "class=\"unstable\""), 9);
  EXPECT_EQ(Count(svg, "class=\"chosen\""), 1);
  EXPECT_EQ(Count(svg, "class=\"frf\""), 1);
  // The stable column sits at 50 Hz: halfway along the linear axis (plot area 72 .. 744 px).
  EXPECT_NE(svg.find("class=\"stable\" cx=\"408.0\""), std::string::npos);
}

TEST(StabilizationSvg, WideBandsGetALogAxisAndBadInputIsRefused) {
  StabilizationFigure f;
  f.freq_min_hz = 1.0;
  f.freq_max_hz = 25000.0;
  f.poles.push_back({36.0, 10, PoleMark::kStable});
  const std::string svg = StabilizationSvg(f);
  EXPECT_NE(svg.find(">1000<"), std::string::npos);  // decade ticks
  StabilizationFigure empty;
  empty.freq_max_hz = 10.0;
  EXPECT_THROW(StabilizationSvg(empty), InputError);
  f.freq_max_hz = 0.5;
  EXPECT_THROW(StabilizationSvg(f), InputError);
}

}  // namespace
}  // namespace vibid::report
