// The stabilization diagram as a self-contained SVG: model order against frequency, one marker
// per pole (filled: stable in frequency, damping and shape; open: stable in frequency only; a grey
// dot: not stable), the chosen poles as labelled vertical lines, and a measured FRF magnitude drawn
// faintly behind on its own log scale so the poles can be matched with the peaks.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "vibid/report/svg_plot.hpp"

namespace vibid::report {

enum class PoleMark { kUnstable, kFrequency, kStable };

struct DiagramMarker {
  double freq_hz = 0.0;
  int order = 0;
  PoleMark mark = PoleMark::kUnstable;
};

struct StabilizationFigure {
  std::string title;
  std::vector<DiagramMarker> poles;
  std::vector<double> chosen_hz;
  double freq_min_hz = 0.0;  ///< Frequency axis range (the fitted band).
  double freq_max_hz = 0.0;
  /// Optional backdrop: |H| at these lines (any positive unit; scaled to the plot height).
  Eigen::VectorXd frf_freq_hz;
  Eigen::VectorXd frf_magnitude;
  int width_px = 760;
  int height_px = 420;
};

/// Log frequency axis when the band spans more than two decades, linear otherwise. InputError for
/// an empty band or no pole.
std::string StabilizationSvg(const StabilizationFigure& figure);

}  // namespace vibid::report
