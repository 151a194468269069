#include "vibid/report/html.hpp"

#include <cstdlib>

#include "vibid/common/error.hpp"

namespace vibid::report {
namespace {

constexpr const char* kStyle =
    "body{font-family:sans-serif;max-width:60rem;margin:2rem auto;padding:0 1rem;color:#222}"
    "h1{font-size:1.6rem}h2{font-size:1.25rem;margin-top:2rem;border-bottom:1px solid #ccc}"
    "table{border-collapse:collapse;margin:0.5rem 0 1rem}th,td{border:1px solid #bbb;padding:2px "
    "8px}"
    "th{background:#f0f0f0}td.num{text-align:right;font-variant-numeric:tabular-nums}"
    "caption{caption-side:bottom;font-size:0.85rem;color:#555;text-align:left}"
    "figure{margin:1rem 0}figcaption{font-size:0.85rem;color:#555}"
    // A notice's tone is its colour: green ok, amber caution, red flagged or refused.
    ".notice{border:2px solid;border-radius:4px;padding:0.5rem 1rem;margin:1rem 0}"
    ".notice strong{font-size:1.1rem}"
    ".notice-ok{border-color:#2e7d32;background:#e8f5e9}"
    ".notice-caution{border-color:#b26a00;background:#fff3e0}"
    ".notice-flagged,.notice-refused{border-color:#c62828;background:#ffebee}";

bool IsNumber(const std::string& text) {
  if (text.empty()) return false;
  char* end = nullptr;
  (void)std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size();
}

}  // namespace

std::string HtmlEscape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

void HtmlPage::Heading(std::string_view text, int level) {
  Require(level >= 1 && level <= 6, "heading level must be 1..6");
  const std::string tag = "h" + std::to_string(level);
  body_ += "<" + tag + ">" + HtmlEscape(text) + "</" + tag + ">\n";
}

void HtmlPage::Paragraph(std::string_view text) { body_ += "<p>" + HtmlEscape(text) + "</p>\n"; }

void HtmlPage::Table(const std::vector<std::string>& header,
                     const std::vector<std::vector<std::string>>& rows, std::string_view caption) {
  std::vector<bool> numeric(header.size(), !rows.empty());
  for (const auto& row : rows) {
    Require(row.size() == header.size(), "table row has " + std::to_string(row.size()) +
                                             " cells, the header " + std::to_string(header.size()));
    for (std::size_t c = 0; c < row.size(); ++c)
      numeric[c] = numeric[c] && (row[c].empty() || IsNumber(row[c]));
  }
  body_ += "<table>\n";
  if (!caption.empty()) body_ += "<caption>" + HtmlEscape(caption) + "</caption>\n";
  body_ += "<tr>";
  for (const auto& h : header) body_ += "<th>" + HtmlEscape(h) + "</th>";
  body_ += "</tr>\n";
  for (const auto& row : rows) {
    body_ += "<tr>";
    for (std::size_t c = 0; c < row.size(); ++c) {
      body_ += (numeric[c] ? "<td class=\"num\">" : "<td>") + HtmlEscape(row[c]) + "</td>";
    }
    body_ += "</tr>\n";
  }
  body_ += "</table>\n";
}

void HtmlPage::Figure(std::string svg, std::string_view caption) {
  body_ += "<figure>\n" + svg + "<figcaption>" + HtmlEscape(caption) + "</figcaption>\n</figure>\n";
}

void HtmlPage::List(const std::vector<std::string>& items) {
  body_ += "<ul>\n";
  for (const auto& item : items) body_ += "<li>" + HtmlEscape(item) + "</li>\n";
  body_ += "</ul>\n";
}

void HtmlPage::Notice(std::string_view tone, std::string_view title,
                      const std::vector<std::string>& lines) {
  Require(tone == "ok" || tone == "caution" || tone == "flagged" || tone == "refused",
          "notice tone must be ok, caution, flagged or refused");
  body_ += "<div class=\"notice notice-" + std::string(tone) + "\" id=\"verdict\"><strong>" +
           HtmlEscape(title) + "</strong>";
  if (!lines.empty()) {
    body_ += "<ul>";
    for (const auto& line : lines) body_ += "<li>" + HtmlEscape(line) + "</li>";
    body_ += "</ul>";
  }
  body_ += "</div>\n";
}

std::string HtmlPage::Render() const {
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" +
         HtmlEscape(title_) + "</title>\n<style>" + kStyle + "</style>\n</head>\n<body>\n<h1>" +
         HtmlEscape(title_) + "</h1>\n" + body_ + "</body>\n</html>\n";
}

}  // namespace vibid::report
