#include "svg_frame.hpp"

#include "vibid/report/html.hpp"

namespace vibid::report {

void WriteSvgOpening(std::ostream& svg, int width_px, int height_px, std::string_view title,
                     const PlotArea& a) {
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width_px << "\" height=\""
      << height_px << "\" viewBox=\"0 0 " << width_px << " " << height_px
      << "\" font-family=\"sans-serif\" font-size=\"11\">\n";
  svg << "<title>" << HtmlEscape(title) << "</title>\n";
  svg << "<text x=\"" << SvgNumber(0.5 * (a.left + a.right))
      << "\" y=\"18\" text-anchor=\"middle\" font-size=\"13\">" << HtmlEscape(title) << "</text>\n";
  svg << "<rect x=\"" << SvgNumber(a.left) << "\" y=\"" << SvgNumber(a.top) << "\" width=\""
      << SvgNumber(a.right - a.left) << "\" height=\"" << SvgNumber(a.bottom - a.top)
      << "\" fill=\"none\" stroke=\"#444\"/>\n";
}

void WriteAxisLabels(std::ostream& svg, int height_px, std::string_view x_label,
                     std::string_view y_label, const PlotArea& a) {
  svg << "<text x=\"" << SvgNumber(0.5 * (a.left + a.right)) << "\" y=\""
      << SvgNumber(height_px - 8.0) << "\" text-anchor=\"middle\">" << HtmlEscape(x_label)
      << "</text>\n";
  svg << "<text transform=\"translate(14," << SvgNumber(0.5 * (a.top + a.bottom))
      << ") rotate(-90)\" text-anchor=\"middle\">" << HtmlEscape(y_label) << "</text>\n";
}

}  // namespace vibid::report
