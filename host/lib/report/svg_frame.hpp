// The parts of an SVG figure every plot of the report draws the same way: the opening element
// with the title, the plot area's frame and the axis labels.
#pragma once

#include <ostream>
#include <string_view>

#include "vibid/report/svg_plot.hpp"

namespace vibid::report {

/// Opens the `width_px` x `height_px` SVG element: its <title>, the title drawn above the plot
/// area, and the plot area's frame.
void WriteSvgOpening(std::ostream& svg, int width_px, int height_px, std::string_view title,
                     const PlotArea& a);

/// `x_label` centred below the plot area, `y_label` rotated along its left edge.
void WriteAxisLabels(std::ostream& svg, int height_px, std::string_view x_label,
                     std::string_view y_label, const PlotArea& a);

}  // namespace vibid::report
