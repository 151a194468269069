#include "vibid/report/html.hpp"

#include <gtest/gtest.h>

#include "vibid/common/error.hpp"

namespace vibid::report {
namespace {

TEST(Html, EscapesTheFiveSpecialCharacters) {
  EXPECT_EQ(HtmlEscape("a&b<c>d\"e'f"), "a&amp;b&lt;c&gt;d&quot;e&#39;f");
  EXPECT_EQ(HtmlEscape("plain"), "plain");
}

TEST(Html, TablesAlignNumericColumnsAndCheckRowWidths) {
  HtmlPage page("Rig <A>");
  page.Table({"quantity", "value"}, {{"m1", "1.82"}, {"k1", "3520"}}, "truth");
  const std::string html = page.Render();
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(html.find("<title>Rig &lt;A&gt;</title>"), std::string::npos);
  EXPECT_NE(html.find("<td>m1</td><td class=\"num\">1.82</td>"), std::string::npos) << html;
  EXPECT_NE(html.find("<caption>truth</caption>"), std::string::npos);
  EXPECT_THROW(page.Table({"a", "b"}, {{"only one"}}), InputError);
}

}  // namespace
}  // namespace vibid::report
