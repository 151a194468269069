#include "vibid/report/svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "svg_frame.hpp"
#include "vibid/common/error.hpp"
#include "vibid/report/html.hpp"

namespace vibid::report {
namespace {

constexpr double kMarginLeft = 72.0, kMarginRight = 16.0, kMarginTop = 44.0, kMarginBottom = 46.0;
/// Legend: one row between the title and the plot area, so it never hides a trace.
constexpr double kLegendY = 34.0, kLegendSwatch = 22.0, kLegendCharPx = 6.2, kLegendGap = 18.0;

bool Drawable(double v, Scale scale) {
  return std::isfinite(v) && (scale == Scale::kLinear || v > 0.0);
}

// Axis coordinate: log axes map log10 of the value.
double AxisValue(double v, Scale scale) { return scale == Scale::kLog ? std::log10(v) : v; }

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  bool empty() const { return !(lo <= hi); }
};

// Widens a range to something a reader can label: flat data gets a band around it, log ranges
// whole decades, linear ranges the nearest ticks outside.
Range Padded(Range r, Scale scale) {
  if (scale == Scale::kLog) {
    // Out to the nearest 1, 2 or 5 times a power of ten on each side.
    const auto down = [](double v) {
      const double d = std::pow(10.0, std::floor(std::log10(v)));
      for (double m : {5.0, 2.0, 1.0}) {
        if (m * d <= v * (1 + 1e-12)) return m * d;
      }
      return d;
    };
    const auto up = [](double v) {
      const double d = std::pow(10.0, std::floor(std::log10(v)));
      for (double m : {1.0, 2.0, 5.0, 10.0}) {
        if (m * d >= v * (1 - 1e-12)) return m * d;
      }
      return 10.0 * d;
    };
    r.lo = down(r.lo);
    r.hi = up(r.hi);
    if (r.hi <= r.lo) r.hi = r.lo * 10.0;
    return r;
  }
  if (r.hi == r.lo) {
    const double half = r.lo == 0.0 ? 1.0 : 0.5 * std::abs(r.lo);
    return {r.lo - half, r.hi + half};
  }
  const std::vector<double> ticks = LinearTicks(r.lo, r.hi, 6);
  const double step = ticks.size() >= 2 ? ticks[1] - ticks[0] : (r.hi - r.lo);
  return {std::floor(r.lo / step) * step, std::ceil(r.hi / step) * step};
}

std::string TickLabel(double v) {
  char text[32];
  if (v == 0.0) return "0";
  const double a = std::abs(v);
  std::snprintf(text, sizeof text, a >= 1e5 || a < 1e-3 ? "%.0e" : "%g", v);
  return text;
}

// Minimum and maximum per pixel column, in x order, for one run of points in pixel coordinates.
void AppendReduced(const std::vector<std::pair<double, double>>& run, std::string& points) {
  const auto emit = [&points](double x, double y) {
    points += SvgNumber(x) + "," + SvgNumber(y) + " ";
  };
  if (run.size() <= 4) {
    for (const auto& [x, y] : run) emit(x, y);
    return;
  }
  std::size_t i = 0;
  while (i < run.size()) {
    const double column = std::floor(run[i].first);
    std::size_t j = i, lo = i, hi = i;
    for (; j < run.size() && std::floor(run[j].first) == column; ++j) {
      if (run[j].second < run[lo].second) lo = j;
      if (run[j].second > run[hi].second) hi = j;
    }
    if (j - i <= 2) {
      for (std::size_t k = i; k < j; ++k) emit(run[k].first, run[k].second);
    } else {
      const std::size_t first = std::min(lo, hi), second = std::max(lo, hi);
      emit(run[first].first, run[first].second);
      if (second != first) emit(run[second].first, run[second].second);
    }
    i = j;
  }
}

}  // namespace

PlotArea AreaOf(const PlotOptions& o) {
  return {kMarginLeft, kMarginTop, static_cast<double>(o.width_px) - kMarginRight,
          static_cast<double>(o.height_px) - kMarginBottom};
}

std::vector<double> LinearTicks(double lo, double hi, int target) {
  std::vector<double> ticks;
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi) || target < 2) return ticks;
  const double raw = (hi - lo) / target;
  const double decade = std::pow(10.0, std::floor(std::log10(raw)));
  double step = decade;
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    step = m * decade;
    if (step >= raw) break;
  }
  // Integer multiples of the step, so 0.1 * 3 prints as 0.3 and zero is exactly zero.
  const auto first = static_cast<long long>(std::ceil(lo / step - 1e-9));
  const auto last = static_cast<long long>(std::floor(hi / step + 1e-9));
  for (long long k = first; k <= last; ++k) ticks.push_back(static_cast<double>(k) * step);
  return ticks;
}

std::vector<double> LogTicks(double lo, double hi) {
  std::vector<double> ticks;
  if (!(lo > 0.0) || !(hi > lo) || !std::isfinite(hi)) return ticks;
  for (int e = static_cast<int>(std::ceil(std::log10(lo) - 1e-9));
       e <= static_cast<int>(std::floor(std::log10(hi) + 1e-9)); ++e) {
    ticks.push_back(std::pow(10.0, e));
  }
  if (ticks.size() >= 3) return ticks;
  ticks.clear();
  for (int e = static_cast<int>(std::floor(std::log10(lo)));
       e <= static_cast<int>(std::ceil(std::log10(hi))); ++e) {
    for (double m : {1.0, 2.0, 5.0}) {
      const double v = m * std::pow(10.0, e);
      if (v >= lo * (1 - 1e-9) && v <= hi * (1 + 1e-9)) ticks.push_back(v);
    }
  }
  return ticks;
}

std::string SvgNumber(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", v);
  return text;
}

namespace {

// The ranges the axes show: the drawable points, padded.
void AxisRanges(const std::vector<Series>& series, const PlotOptions& o, Range& xr, Range& yr) {
  for (const Series& s : series) {
    Require(s.x.size() == s.y.size(),
            "plot '" + o.title + "': series '" + s.label + "' has x and y of different lengths");
    for (Eigen::Index i = 0; i < s.x.size(); ++i) {
      if (!Drawable(s.x[i], o.x.scale) || !Drawable(s.y[i], o.y.scale)) continue;
      xr.lo = std::min(xr.lo, s.x[i]);
      xr.hi = std::max(xr.hi, s.x[i]);
      yr.lo = std::min(yr.lo, s.y[i]);
      yr.hi = std::max(yr.hi, s.y[i]);
    }
  }
  Require(!xr.empty() && !yr.empty(), "plot '" + o.title + "': no point can be drawn");
  if (o.x.scale == Scale::kLinear && xr.hi == xr.lo) xr = Padded(xr, Scale::kLinear);
  if (o.x.scale == Scale::kLog) xr = Padded(xr, Scale::kLog);
  yr = Padded(yr, o.y.scale);
}

// Data to pixel coordinates.
struct PixelMap {
  PlotArea a;
  Scale x_scale = Scale::kLinear;
  Scale y_scale = Scale::kLinear;
  double x0 = 0.0, x1 = 0.0, y0 = 0.0, y1 = 0.0;

  PixelMap(const PlotOptions& o, const Range& xr, const Range& yr)
      : a(AreaOf(o)),
        x_scale(o.x.scale),
        y_scale(o.y.scale),
        x0(AxisValue(xr.lo, o.x.scale)),
        x1(AxisValue(xr.hi, o.x.scale)),
        y0(AxisValue(yr.lo, o.y.scale)),
        y1(AxisValue(yr.hi, o.y.scale)) {}

  double Px(double v) const {
    return a.left + (AxisValue(v, x_scale) - x0) / (x1 - x0) * (a.right - a.left);
  }
  double Py(double v) const {
    return a.bottom - (AxisValue(v, y_scale) - y0) / (y1 - y0) * (a.bottom - a.top);
  }
};

void WriteFrame(const PlotOptions& o, const PixelMap& map, const Range& xr, const Range& yr,
                std::ostringstream& svg) {
  const PlotArea& a = map.a;
  WriteSvgOpening(svg, o.width_px, o.height_px, o.title, a);
  const std::vector<double> xt =
      o.x.scale == Scale::kLog ? LogTicks(xr.lo, xr.hi) : LinearTicks(xr.lo, xr.hi, 8);
  const std::vector<double> yt =
      o.y.scale == Scale::kLog ? LogTicks(yr.lo, yr.hi) : LinearTicks(yr.lo, yr.hi, 6);
  for (double t : xt) {
    const double x = map.Px(t);
    svg << "<line class=\"grid\" x1=\"" << SvgNumber(x) << "\" y1=\"" << SvgNumber(a.top)
        << "\" x2=\"" << SvgNumber(x) << "\" y2=\"" << SvgNumber(a.bottom) << "\" stroke=\"#ddd\"/>"
        << "<text x=\"" << SvgNumber(x) << "\" y=\"" << SvgNumber(a.bottom + 14)
        << "\" text-anchor=\"middle\">" << TickLabel(t) << "</text>\n";
  }
  for (double t : yt) {
    const double y = map.Py(t);
    svg << "<line class=\"grid\" x1=\"" << SvgNumber(a.left) << "\" y1=\"" << SvgNumber(y)
        << "\" x2=\"" << SvgNumber(a.right) << "\" y2=\"" << SvgNumber(y) << "\" stroke=\"#ddd\"/>"
        << "<text x=\"" << SvgNumber(a.left - 4) << "\" y=\"" << SvgNumber(y + 4)
        << "\" text-anchor=\"end\">" << TickLabel(t) << "</text>\n";
  }
  WriteAxisLabels(svg, o.height_px, o.x.label, o.y.label, a);
}

// One polyline per run of drawable points: a point that cannot be drawn breaks the line.
void WriteSeries(const Series& s, std::size_t k, const PixelMap& map, std::ostringstream& svg) {
  std::vector<std::pair<double, double>> run;
  const auto flush = [&] {
    if (run.empty()) return;
    std::string points;
    AppendReduced(run, points);
    if (!points.empty()) points.pop_back();
    svg << "<polyline class=\"series\" data-series=\"" << k << "\" fill=\"none\" stroke=\""
        << HtmlEscape(s.color) << "\" stroke-width=\"1.3\""
        << (s.dashed ? " stroke-dasharray=\"5,3\"" : "") << " points=\"" << points << "\"/>\n";
    run.clear();
  };
  for (Eigen::Index i = 0; i < s.x.size(); ++i) {
    if (!Drawable(s.x[i], map.x_scale) || !Drawable(s.y[i], map.y_scale)) {
      flush();
      continue;
    }
    run.emplace_back(map.Px(s.x[i]), map.Py(s.y[i]));
  }
  flush();
}

// The series' legend entry at `legend_x`; returns where the next one starts.
double WriteLegendEntry(const Series& s, double legend_x, std::ostringstream& svg) {
  svg << "<line x1=\"" << SvgNumber(legend_x) << "\" y1=\"" << SvgNumber(kLegendY - 4) << "\" x2=\""
      << SvgNumber(legend_x + kLegendSwatch) << "\" y2=\"" << SvgNumber(kLegendY - 4)
      << "\" stroke=\"" << HtmlEscape(s.color) << "\" stroke-width=\"2\""
      << (s.dashed ? " stroke-dasharray=\"5,3\"" : "") << "/><text x=\""
      << SvgNumber(legend_x + kLegendSwatch + 4) << "\" y=\"" << SvgNumber(kLegendY) << "\">"
      << HtmlEscape(s.label) << "</text>\n";
  return legend_x +
         (kLegendSwatch + 4 + kLegendCharPx * static_cast<double>(s.label.size()) + kLegendGap);
}

}  // namespace

std::string SvgPlot(const std::vector<Series>& series, const PlotOptions& o) {
  Require(!series.empty(), "plot '" + o.title + "': no series");
  Require(o.width_px >= 200 && o.height_px >= 120,
          "plot '" + o.title + "': smaller than 200 x 120 px");
  Range xr, yr;
  AxisRanges(series, o, xr, yr);
  const PixelMap map(o, xr, yr);
  std::ostringstream svg;
  WriteFrame(o, map, xr, yr, svg);
  double legend_x = map.a.left;
  for (std::size_t k = 0; k < series.size(); ++k) {
    WriteSeries(series[k], k, map, svg);
    legend_x = WriteLegendEntry(series[k], legend_x, svg);
  }
  svg << "</svg>\n";
  return svg.str();
}

}  // namespace vibid::report
