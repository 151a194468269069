// Line plots as self-contained SVG, for reports that must open anywhere without scripts: axes
// with 1-2-5 (linear) or decade (log) ticks, a legend, one polyline per series.
//
// Long records are reduced per pixel column to their minimum and maximum, so a 150 000-sample
// trace costs a few thousand points and still shows every peak. Non-finite points, and points at
// or below zero on a log axis, break a series into separate polylines instead of being joined.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace vibid::report {

enum class Scale { kLinear, kLog };

struct Axis {
  std::string label;
  Scale scale = Scale::kLinear;
};

struct Series {
  std::string label;
  Eigen::VectorXd x;
  Eigen::VectorXd y;
  std::string color = "#1f77b4";  ///< any SVG colour
  bool dashed = false;
};

struct PlotOptions {
  std::string title;
  Axis x;
  Axis y;
  int width_px = 760;
  int height_px = 340;
};

/// Plot area inside the SVG, in pixels (the margins hold tick labels, axis labels and the title).
struct PlotArea {
  double left = 0.0, top = 0.0, right = 0.0, bottom = 0.0;
};
PlotArea AreaOf(const PlotOptions& options);

/// Ticks at 1, 2 or 5 times a power of ten, about `target` of them, all within [lo, hi].
std::vector<double> LinearTicks(double lo, double hi, int target = 6);
/// Powers of ten within [lo, hi] (lo > 0); when the range holds fewer than two, 1-2-5 multiples.
std::vector<double> LogTicks(double lo, double hi);

/// The SVG element. InputError for no series, x/y of different lengths, a size below 200 x 120,
/// or no point that can be drawn.
std::string SvgPlot(const std::vector<Series>& series, const PlotOptions& options);

/// An SVG coordinate: one decimal (a tenth of a pixel is finer than any screen shows).
std::string SvgNumber(double v);

}  // namespace vibid::report
