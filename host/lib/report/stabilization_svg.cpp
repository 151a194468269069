#include "vibid/report/stabilization_svg.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "svg_frame.hpp"
#include "vibid/common/error.hpp"
#include "vibid/report/svg_plot.hpp"

namespace vibid::report {
namespace {

std::string Label(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

// Frequency (linear, or logarithmic over more than two decades) across, model order up.
struct DiagramAxes {
  PlotArea a;
  bool log_x = false;
  double lo = 0.0;
  double hi = 0.0;
  double top_order = 0.0;

  double Xv(double v) const { return log_x ? std::log10(v) : v; }
  double Px(double v) const {
    return a.left + (Xv(v) - Xv(lo)) / (Xv(hi) - Xv(lo)) * (a.right - a.left);
  }
  double Py(double order) const { return a.bottom - order / top_order * (a.bottom - a.top); }
  bool InBand(double freq_hz) const { return freq_hz >= lo && freq_hz <= hi; }
};

DiagramAxes AxesOf(const StabilizationFigure& f) {
  PlotOptions po;
  po.width_px = f.width_px;
  po.height_px = f.height_px;
  DiagramAxes ax;
  ax.a = AreaOf(po);
  ax.log_x = f.freq_min_hz > 0.0 && f.freq_max_hz / f.freq_min_hz > 100.0;
  ax.lo = f.freq_min_hz;
  ax.hi = f.freq_max_hz;
  if (ax.log_x) {
    ax.lo = std::pow(10.0, std::floor(std::log10(ax.lo)));
    ax.hi = std::pow(10.0, std::ceil(std::log10(ax.hi)));
  }
  int max_order = 0;
  for (const DiagramMarker& p : f.poles) max_order = std::max(max_order, p.order);
  ax.top_order = static_cast<double>(max_order) * 1.08 + 1.0;
  return ax;
}

void WriteFrame(const StabilizationFigure& f, const DiagramAxes& ax, std::ostringstream& svg) {
  const PlotArea& a = ax.a;
  WriteSvgOpening(svg, f.width_px, f.height_px, f.title, a);
  const std::vector<double> xt = ax.log_x ? LogTicks(ax.lo, ax.hi) : LinearTicks(ax.lo, ax.hi, 8);
  for (double t : xt) {
    svg << "<line x1=\"" << SvgNumber(ax.Px(t)) << "\" y1=\"" << SvgNumber(a.top) << "\" x2=\""
        << SvgNumber(ax.Px(t)) << "\" y2=\"" << SvgNumber(a.bottom)
        << "\" stroke=\"#e4e4e4\"/><text x=\"" << SvgNumber(ax.Px(t)) << "\" y=\""
        << SvgNumber(a.bottom + 14) << "\" text-anchor=\"middle\">" << Label(t) << "</text>\n";
  }
  for (double t : LinearTicks(0.0, ax.top_order, 6)) {
    svg << "<line x1=\"" << SvgNumber(a.left) << "\" y1=\"" << SvgNumber(ax.Py(t)) << "\" x2=\""
        << SvgNumber(a.right) << "\" y2=\"" << SvgNumber(ax.Py(t))
        << "\" stroke=\"#e4e4e4\"/><text x=\"" << SvgNumber(a.left - 4) << "\" y=\""
        << SvgNumber(ax.Py(t) + 4) << "\" text-anchor=\"end\">" << Label(t) << "</text>\n";
  }
  WriteAxisLabels(svg, f.height_px, "frequency (Hz)", "model order", a);
}

bool DrawsFrfLine(const StabilizationFigure& f, const DiagramAxes& ax, Eigen::Index i) {
  const double v = f.frf_magnitude[i], fr = f.frf_freq_hz[i];
  return v > 0.0 && ax.InBand(fr) && (!ax.log_x || fr > 0.0);
}

// Backdrop: log |H| scaled to the plot height, inside the band. False when there is none.
bool WriteFrfBackdrop(const StabilizationFigure& f, const DiagramAxes& ax,
                      std::ostringstream& svg) {
  double mlo = 0.0, mhi = 0.0;
  bool any = false;
  for (Eigen::Index i = 0; i < f.frf_freq_hz.size(); ++i) {
    if (!DrawsFrfLine(f, ax, i)) continue;
    const double v = f.frf_magnitude[i];
    mlo = any ? std::min(mlo, std::log10(v)) : std::log10(v);
    mhi = any ? std::max(mhi, std::log10(v)) : std::log10(v);
    any = true;
  }
  if (!(any && mhi > mlo)) return any;
  const PlotArea& a = ax.a;
  svg << "<polyline class=\"frf\" fill=\"none\" stroke=\"#9bb7d4\" stroke-width=\"1\" points=\"";
  double last_x = -1.0;
  for (Eigen::Index i = 0; i < f.frf_freq_hz.size(); ++i) {
    if (!DrawsFrfLine(f, ax, i)) continue;
    const double x = ax.Px(f.frf_freq_hz[i]);
    if (x - last_x < 0.5) continue;  // one point per half pixel is plenty
    last_x = x;
    const double y =
        a.bottom - (std::log10(f.frf_magnitude[i]) - mlo) / (mhi - mlo) * (a.bottom - a.top) * 0.9;
    svg << SvgNumber(x) << "," << SvgNumber(y) << " ";
  }
  svg << "\"/>\n";
  return any;
}

void WriteChosenPoles(const StabilizationFigure& f, const DiagramAxes& ax,
                      std::ostringstream& svg) {
  const PlotArea& a = ax.a;
  // Labels of neighbouring chosen poles are staggered over three rows so they do not overprint.
  std::vector<double> chosen = f.chosen_hz;
  std::sort(chosen.begin(), chosen.end());
  double last_label_x[3] = {-1e9, -1e9, -1e9};
  for (double c : chosen) {
    if (!ax.InBand(c)) continue;
    const std::string text = Label(std::round(c * 10.0) / 10.0);
    const double x = ax.Px(c);
    int row = 0;
    while (row < 2 && x < last_label_x[row]) ++row;
    last_label_x[row] = x + 6.0 * static_cast<double>(text.size()) + 6.0;
    svg << "<line class=\"chosen\" x1=\"" << SvgNumber(x) << "\" y1=\"" << SvgNumber(a.top)
        << "\" x2=\"" << SvgNumber(x) << "\" y2=\"" << SvgNumber(a.bottom)
        << "\" stroke=\"#d62728\" stroke-dasharray=\"4,3\"/><text x=\"" << SvgNumber(x + 2)
        << "\" y=\"" << SvgNumber(a.top + 10 + 11 * row) << "\" fill=\"#d62728\" font-size=\"10\">"
        << text << "</text>\n";
  }
}

void WritePoleMarkers(const StabilizationFigure& f, const DiagramAxes& ax,
                      std::ostringstream& svg) {
  for (const DiagramMarker& p : f.poles) {
    if (!ax.InBand(p.freq_hz)) continue;
    const double x = ax.Px(p.freq_hz), y = ax.Py(p.order);
    switch (p.mark) {
      case PoleMark::kStable:
        svg << "<circle class=\"stable\" cx=\"" << SvgNumber(x) << "\" cy=\"" << SvgNumber(y)
            << "\" r=\"2.6\" fill=\"#1f3f8f\"/>\n";
        break;
      case PoleMark::kFrequency:
        svg << "<circle class=\"freq\" cx=\"" << SvgNumber(x) << "\" cy=\"" << SvgNumber(y)
            << "\" r=\"2.6\" fill=\"none\" stroke=\"#2ca02c\" stroke-width=\"1\"/>\n";
        break;
      case PoleMark::kUnstable:
        svg << "<circle class=\"unstable\" cx=\"" << SvgNumber(x) << "\" cy=\"" << SvgNumber(y)
            << "\" r=\"1.2\" fill=\"#999\"/>\n";
        break;
    }
  }
}

// Legend row between the title and the plot.
void WriteLegend(const PlotArea& a, bool with_frf, std::ostringstream& svg) {
  const double ly = 34.0;
  double lx = a.left;
  svg << "<circle cx=\"" << SvgNumber(lx + 4) << "\" cy=\"" << SvgNumber(ly - 4)
      << "\" r=\"2.6\" fill=\"#1f3f8f\"/><text x=\"" << SvgNumber(lx + 10) << "\" y=\""
      << SvgNumber(ly) << "\">stable (frequency, damping, shape)</text>\n";
  lx += 215;
  svg << "<circle cx=\"" << SvgNumber(lx + 4) << "\" cy=\"" << SvgNumber(ly - 4)
      << "\" r=\"2.6\" fill=\"none\" stroke=\"#2ca02c\"/><text x=\"" << SvgNumber(lx + 10)
      << "\" y=\"" << SvgNumber(ly) << "\">stable in frequency</text>\n";
  lx += 125;
  svg << "<circle cx=\"" << SvgNumber(lx + 4) << "\" cy=\"" << SvgNumber(ly - 4)
      << "\" r=\"1.2\" fill=\"#999\"/><text x=\"" << SvgNumber(lx + 10) << "\" y=\""
      << SvgNumber(ly) << "\">not stable</text>\n";
  lx += 80;
  svg << "<line x1=\"" << SvgNumber(lx) << "\" y1=\"" << SvgNumber(ly - 4) << "\" x2=\""
      << SvgNumber(lx + 16) << "\" y2=\"" << SvgNumber(ly - 4)
      << "\" stroke=\"#d62728\" stroke-dasharray=\"4,3\"/><text x=\"" << SvgNumber(lx + 20)
      << "\" y=\"" << SvgNumber(ly) << "\">chosen pole</text>\n";
  lx += 95;
  if (with_frf) {
    svg << "<line x1=\"" << SvgNumber(lx) << "\" y1=\"" << SvgNumber(ly - 4) << "\" x2=\""
        << SvgNumber(lx + 16) << "\" y2=\"" << SvgNumber(ly - 4)
        << "\" stroke=\"#9bb7d4\"/><text x=\"" << SvgNumber(lx + 20) << "\" y=\"" << SvgNumber(ly)
        << "\">|H| (log)</text>\n";
  }
}

}  // namespace

std::string StabilizationSvg(const StabilizationFigure& f) {
  Require(f.freq_min_hz >= 0.0 && f.freq_max_hz > f.freq_min_hz,
          "stabilization figure: empty frequency band");
  Require(!f.poles.empty(), "stabilization figure: no pole to draw");
  Require(f.frf_freq_hz.size() == f.frf_magnitude.size(),
          "stabilization figure: FRF lines and magnitudes differ in length");
  const DiagramAxes ax = AxesOf(f);
  std::ostringstream svg;
  WriteFrame(f, ax, svg);
  const bool any_frf = WriteFrfBackdrop(f, ax, svg);
  WriteChosenPoles(f, ax, svg);
  WritePoleMarkers(f, ax, svg);
  WriteLegend(ax.a, any_frf, svg);
  svg << "</svg>\n";
  return svg.str();
}

}  // namespace vibid::report
