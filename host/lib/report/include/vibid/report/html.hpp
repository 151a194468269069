// A report page: headings, paragraphs, tables and inline SVG figures in one HTML file with its
// own style sheet, so it can be mailed or archived and opened years later as it was.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace vibid::report {

/// Text safe inside HTML elements and attribute values (& < > " ').
std::string HtmlEscape(std::string_view text);

class HtmlPage {
 public:
  explicit HtmlPage(std::string title) : title_(std::move(title)) {}

  void Heading(std::string_view text, int level = 2);
  void Paragraph(std::string_view text);
  /// Rows of cells; every row must have as many cells as the header (InputError otherwise).
  /// Cells are text; numbers are right-aligned when a whole column parses as numbers.
  void Table(const std::vector<std::string>& header,
             const std::vector<std::vector<std::string>>& rows, std::string_view caption = {});
  /// `svg` is trusted markup from SvgPlot.
  void Figure(std::string svg, std::string_view caption);
  void List(const std::vector<std::string>& items);
  /// A coloured box (the verdict's): `tone` ok (green), caution (amber), flagged or refused (red);
  /// a bold title and a line per reason.
  void Notice(std::string_view tone, std::string_view title, const std::vector<std::string>& lines);

  std::string Render() const;

 private:
  std::string title_;
  std::string body_;
};

}  // namespace vibid::report
