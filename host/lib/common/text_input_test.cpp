// UTF-8 validation against RFC 3629's table of well-formed sequences (section 4) and the
// Unicode Standard's Table 3-7; the byte-order-mark handling of the CSV reader.
#include <gtest/gtest.h>

#include <string>

#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/testing/input_error.hpp"
#include "vibid/common/text_input.hpp"

namespace vibid {
namespace {

std::string Utf8Error(const std::string& text) {
  return InputErrorOf([&] { RequireUtf8(text, "f"); });
}

TEST(RequireUtf8, AcceptsWellFormedSequences) {
  EXPECT_EQ(Utf8Error("plain ASCII, tabs\tand\nnewlines"), "");
  EXPECT_EQ(Utf8Error("\xC2\xB5m"), "");         // U+00B5 micro sign, 2 bytes
  EXPECT_EQ(Utf8Error("\xE2\x82\xAC"), "");      // U+20AC euro sign, 3 bytes
  EXPECT_EQ(Utf8Error("\xED\x9F\xBF"), "");      // U+D7FF, last before the surrogates
  EXPECT_EQ(Utf8Error("\xF0\x9F\x98\x80"), "");  // U+1F600, 4 bytes
  EXPECT_EQ(Utf8Error("\xF4\x8F\xBF\xBF"), "");  // U+10FFFF, the last code point
}

TEST(RequireUtf8, RefusesIllFormedSequencesWithLineAndColumn) {
  EXPECT_EQ(Utf8Error("ab\n\xC0\xAF"), "f:2:1: not UTF-8 text (byte 0xC0)");   // overlong '/'
  EXPECT_EQ(Utf8Error("\xE0\x80\xAF"), "f:1:1: not UTF-8 text (byte 0xE0)");   // overlong, 3 bytes
  EXPECT_EQ(Utf8Error("x\xED\xA0\x80"), "f:1:2: not UTF-8 text (byte 0xED)");  // surrogate U+D800
  EXPECT_EQ(Utf8Error("\xF4\x90\x80\x80"), "f:1:1: not UTF-8 text (byte 0xF4)");  // past U+10FFFF
  EXPECT_EQ(Utf8Error("abc\x80"), "f:1:4: not UTF-8 text (byte 0x80)");   // lone continuation
  EXPECT_EQ(Utf8Error("\xE2\x82"), "f:1:1: not UTF-8 text (byte 0xE2)");  // cut short at the end
  EXPECT_EQ(Utf8Error("Latin-1 caf\xE9!"), "f:1:12: not UTF-8 text (byte 0xE9)");
  EXPECT_EQ(Utf8Error(std::string("a\0b", 3)), "f:1:2: not UTF-8 text (byte 0x00)");
  EXPECT_EQ(Utf8Error("\xFF\xFEh\0"), "f: UTF-16 text; save it as UTF-8");
}

TEST(Printable, EscapesWhatATerminalWouldMangle) {
  EXPECT_EQ(Printable("1.5e3"), "1.5e3");
  EXPECT_EQ(Printable("a\xFF\tb"), "a\\xFF\\x09b");
  EXPECT_EQ(Printable(std::string(50, 'x'), 10), "xxxxxxxxxx...");
}

TEST(FormatBytes, PicksTheUnit) {
  EXPECT_EQ(FormatBytes(512), "512 B");
  EXPECT_EQ(FormatBytes(1536), "1.5 KiB");
  EXPECT_EQ(FormatBytes(std::uint64_t{64} << 20), "64.0 MiB");
  EXPECT_EQ(FormatBytes(std::uint64_t{5} << 30), "5.00 GiB");
}

TEST(ParseCsv, SkipsAUtf8ByteOrderMark) {
  // Spreadsheets' "CSV UTF-8" starts with EF BB BF; the first column must still be t_s.
  const CsvTable t = ParseCsv("\xEF\xBB\xBFt_s,x_m\n0,1\n0.5,2\n", "bom.csv");
  ASSERT_EQ(t.names.size(), 2u);
  EXPECT_EQ(t.names[0], "t_s");
  EXPECT_DOUBLE_EQ(t.columns[1][1], 2.0);
}

}  // namespace
}  // namespace vibid
