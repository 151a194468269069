#include "vibid/common/csv.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "vibid/common/error.hpp"
#include "vibid/common/testing/real_data.hpp"

namespace vibid {
namespace {

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Csv, ParsesHeaderAndColumns) {
  const auto t = ParseCsv("t_s, force_n\n0,1.5\n0.001,-2e-3\n", "mem");
  ASSERT_EQ(t.names.size(), 2u);
  EXPECT_EQ(t.names[1], "force_n");
  EXPECT_EQ(t.rows(), 2u);
  EXPECT_DOUBLE_EQ(t.Column("force_n")[1], -2e-3);
}

TEST(Csv, ErrorsNameTheLine) {
  EXPECT_NE(ErrorOf([] { ParseCsv("a,b\n1,2\n3,x\n", "f.csv"); }).find("f.csv:3:"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] { ParseCsv("a,b\n1,2\n3\n", "f.csv"); }).find("f.csv:3: expected 2 cells"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] { ParseCsv("1,2\n3,4\n", "f.csv"); }).find("header"), std::string::npos);
  EXPECT_NE(ErrorOf([] { ParseCsv("a,b\n1,nan\n", "f.csv"); }).find("f.csv:2:"), std::string::npos);
  EXPECT_NE(ErrorOf([] { ParseCsv("", "f.csv"); }).find("empty"), std::string::npos);
  EXPECT_NE(ErrorOf([] { ParseCsv("a,a\n1,2\n", "f.csv"); }).find("duplicate"), std::string::npos);
}

TEST(Csv, ErrorsNameTheColumn) {
  EXPECT_NE(ErrorOf([] {
              ParseCsv("a,b\n1,2\n3,x\n", "f.csv");
            }).find("f.csv:3: column 2 'b': 'x' is not a number"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] {
              ParseCsv("a,b\n1,2\ninf,4\n", "f.csv");
            }).find("f.csv:3: column 1 'a': non-finite value 'inf'"),
            std::string::npos);
  // Comment and blank lines count as lines.
  EXPECT_NE(ErrorOf([] {
              ParseCsv("# c\na,b\n\n1,2\n3,4,5\n", "f.csv");
            }).find("f.csv:5: expected 2 cells, found 3"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] {
              ParseCsv("a,b\n1,2\n1,\n", "f.csv");
            }).find("f.csv:3: column 2 'b': '' is not a number"),
            std::string::npos);
}

TEST(Csv, AcceptsBlanksSignsCommentsAndCrLf) {
  const auto t = ParseCsv("a , b\r\n +1.5 ,\t-2\r\n\r\n  # note\n3e2,+.25", "mem");
  ASSERT_EQ(t.rows(), 2u);
  EXPECT_EQ(t.names[0], "a");
  EXPECT_EQ(t.Column("a")[0], 1.5);
  EXPECT_EQ(t.Column("b")[0], -2.0);
  EXPECT_EQ(t.Column("a")[1], 300.0);
  EXPECT_EQ(t.Column("b")[1], 0.25);
}

// The fast decimal path and std::from_chars against strtod (the C library), cell by cell: signs,
// "1.", -0, exponents at and past the exact-power limit, 2^53 + 1, more than 19 digits, subnormals.
TEST(Csv, NumbersMatchStrtod) {
  const char* cells[] = {"0",
                         "-0",
                         "1.",
                         "+2.5",
                         "-3.25e-2",
                         "1e22",
                         "1e23",
                         "1E-22",
                         "1e-23",
                         "9007199254740992",
                         "9007199254740993",
                         "12345678901234567890123",
                         "0.1",
                         "0.30000000000000004",
                         "4.9406564584124654e-324",
                         "1.7976931348623157e308",
                         "123.456e+7",
                         "000012.5000",
                         "-1234567891e-14",
                         "2.2250738585072014e-308"};
  std::string text = "v\n";
  for (const char* c : cells) text += std::string(c) + "\n";
  const CsvTable t = ParseCsv(text, "mem");
  ASSERT_EQ(t.rows(), std::size(cells));
  for (std::size_t i = 0; i < std::size(cells); ++i) {
    const double want = std::strtod(cells[i][0] == '+' ? cells[i] + 1 : cells[i], nullptr);
    const double got = t.columns[0][static_cast<Eigen::Index>(i)];
    EXPECT_EQ(std::memcmp(&want, &got, sizeof got), 0) << cells[i];
  }
}

// A text big enough to be cut into chunks, with comment and blank lines scattered through it.
std::string LargeText(std::size_t rows) {
  std::string text = "# generated\nt_s,x,y\n";
  char buf[96];
  for (std::size_t i = 0; i < rows; ++i) {
    const double t = static_cast<double>(i) / 1000.0;
    const int n = std::snprintf(buf, sizeof buf, "%.17g,%.17g,%.6e\n", t, std::sin(t) * 1e-3,
                                std::cos(3.0 * t));
    text.append(buf, static_cast<std::size_t>(n));
    if (i % 9973 == 0) text += "# marker\n";
    if (i % 7919 == 0) text += "\n";
  }
  return text;
}

TEST(Csv, ThreadCountDoesNotChangeTheResult) {
  const std::string text = LargeText(100000);  // about 4.5 MB: several chunks of the 1 MB minimum
  const CsvTable one = ParseCsv(text, "mem", 1);
  ASSERT_EQ(one.rows(), 100000u);
  // Independent reference: every data line read with strtod (the C library's parser).
  std::size_t row = 0;
  std::size_t mismatches = 0;
  for (const char* p = text.c_str(); *p; p = std::strchr(p, '\n') + 1) {
    if (*p == '#' || *p == '\n' || *p == 't') continue;
    char* q = nullptr;
    for (std::size_t c = 0; c < 3; ++c, p = q + 1) {
      if (std::strtod(p, &q) != one.columns[c][static_cast<Eigen::Index>(row)]) ++mismatches;
    }
    ++row;
    p = q - 1;
  }
  EXPECT_EQ(row, 100000u);
  EXPECT_EQ(mismatches, 0u);
  for (const std::size_t threads : {2u, 3u, 8u}) {
    const CsvTable many = ParseCsv(text, "mem", threads);
    ASSERT_EQ(many.rows(), one.rows()) << threads;
    for (std::size_t c = 0; c < one.columns.size(); ++c) {
      EXPECT_EQ(0, std::memcmp(one.columns[c].data(), many.columns[c].data(),
                               one.rows() * sizeof(double)))
          << threads;
    }
  }
}

TEST(Csv, FirstBadLineIsReportedWhateverTheThreads) {
  std::string text = LargeText(100000);
  // Two bad rows, one in each half: the earlier one must be named.
  const auto late = text.find('\n', text.size() * 3 / 4) + 1;
  text.replace(late, 1, "x");
  const auto early = text.find('\n', text.size() / 3) + 1;
  text.replace(early, 1, "?");
  const auto line =
      1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(early), '\n');
  const std::string want = "mem:" + std::to_string(line) + ": column 1 't_s': '?";
  for (const std::size_t threads : {1u, 2u, 4u}) {
    const std::string msg = ErrorOf([&] { ParseCsv(text, "mem", threads); });
    EXPECT_EQ(msg.substr(0, want.size()), want) << threads << ": " << msg;
  }
}

// A recording with a text column (a note per row) that no command reads: only the asked-for
// columns are parsed, and only they must be numbers.
TEST(Csv, OnlyAskedForColumnsMustBeNumbers) {
  const std::string text = "t_s,force1_n,note,acc1_m_s2\n0,1.5,first hit,2\n0.001,-2e-3,,3.25\n";
  EXPECT_NE(ErrorOf([&] { ParseCsv(text, "f.csv"); }).find("f.csv:2: column 3 'note': 'first hit'"),
            std::string::npos);
  const CsvTable t = ParseCsvColumns(text, "f.csv", {{"acc1_m_s2", "force1_n"}, {"t_s", "x"}});
  EXPECT_EQ(t.names, (std::vector<std::string>{"t_s", "force1_n", "acc1_m_s2"}));
  ASSERT_EQ(t.rows(), 2u);
  EXPECT_DOUBLE_EQ(t.Column("force1_n")[1], -2e-3);
  EXPECT_DOUBLE_EQ(t.Column("acc1_m_s2")[1], 3.25);
  EXPECT_DOUBLE_EQ(t.Column("t_s")[1], 0.001);
  // The text column asked for: refused, naming the line and the column.
  EXPECT_NE(ErrorOf([&] {
              ParseCsvColumns(text, "f.csv", {{"note"}, {}});
            }).find("f.csv:2: column 3 'note': 'first hit' is not a number"),
            std::string::npos);
  // An absent column is named with the file's columns; a short row is still a short row.
  EXPECT_NE(ErrorOf([&] {
              ParseCsvColumns(text, "f.csv", {{"acc2_m_s2"}, {}});
            }).find("f.csv: no column 'acc2_m_s2' (columns: t_s, force1_n, note, acc1_m_s2)"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              ParseCsvColumns("a,note,b\n1,x,2\n1,y\n", "f.csv", {{"a"}, {}});
            }).find("f.csv:3: expected 3 cells, found 2"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              ParseCsvColumns("a,note\n1,x,2\n", "f.csv", {{"a"}, {}});
            }).find("f.csv:2: expected 2 cells, found 3"),
            std::string::npos);
}

TEST(Csv, SkippedColumnsDoNotChangeTheResultWhateverTheThreads) {
  const std::string text = LargeText(100000);
  const CsvTable all = ParseCsv(text, "mem", 1);
  // Column x skipped: the others come out bit-identical on any thread count.
  for (const std::size_t threads : {1u, 2u, 4u}) {
    const CsvTable some = ParseCsvColumns(text, "mem", {{"y"}, {"t_s"}}, threads);
    ASSERT_EQ(some.names, (std::vector<std::string>{"t_s", "y"}));
    EXPECT_EQ(some.Column("t_s"), all.Column("t_s"));
    EXPECT_EQ(some.Column("y"), all.Column("y"));
  }
}

TEST(Recording, ReadsTheAskedForChannelsOnly) {
  const std::string path = ::testing::TempDir() + "/with_note.csv";
  {
    std::FILE* f = std::fopen(path.c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs("t_s,force1_n,operator,acc1_m_s2\n0,1,ann,2\n0.01,3,bob,4\n0.02,5,ann,6\n", f);
    std::fclose(f);
  }
  const Recording r = LoadRecording(path, {.min_samples = 3, .channels = {"acc1_m_s2"}});
  EXPECT_NEAR(r.fs_hz, 100.0, 1e-9);
  EXPECT_EQ(r.table.names, (std::vector<std::string>{"t_s", "acc1_m_s2"}));
  EXPECT_NE(ErrorOf([&] {
              LoadRecording(path, {.min_samples = 3, .channels = {"operator"}});
            }).find(":2: column 3 'operator': 'ann' is not a number"),
            std::string::npos);
  std::remove(path.c_str());
}

TEST(Csv, MissingColumnListsAvailable) {
  const auto t = ParseCsv("t_s,x\n0,1\n", "f.csv");
  EXPECT_NE(ErrorOf([&] { t.Column("y"); }).find("columns: t_s, x"), std::string::npos);
}

TEST(Csv, FormatRoundTripsBitExact) {
  Eigen::VectorXd a(3), b(3);
  a << 0.1, 1.0 / 3.0, -1e-300;
  b << 12345.678901234567, 2.0, 3.5;
  const auto t = ParseCsv(FormatCsv({"a", "b"}, {a, b}), "mem");
  EXPECT_EQ(t.Column("a"), a);
  EXPECT_EQ(t.Column("b"), b);
}

TEST(SplitList, KeepsEmptyItems) {
  EXPECT_EQ(SplitList("a,b,c"), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(SplitList("a,,b"), (std::vector<std::string>{"a", "", "b"}));
  EXPECT_EQ(SplitList(""), (std::vector<std::string>{""}));
  EXPECT_EQ(SplitList("x,"), (std::vector<std::string>{"x", ""}));
}

TEST(ColumnSpec, UnitsAndFactors) {
  EXPECT_DOUBLE_EQ(ParseColumnSpec("X_cm:cm").scale, 0.01);
  EXPECT_DOUBLE_EQ(ParseColumnSpec("acc:g").scale, 9.80665);  // standard gravity, CGPM 1901
  EXPECT_DOUBLE_EQ(ParseColumnSpec("X*1e-5").scale, 1e-5);
  EXPECT_EQ(ParseColumnSpec(" force_n ").name, "force_n");
  EXPECT_NE(ErrorOf([] { ParseColumnSpec("x:furlong"); }).find("unknown unit"), std::string::npos);
  EXPECT_NE(ErrorOf([] { ParseColumnSpec("x*0"); }).find("nonzero"), std::string::npos);
  EXPECT_EQ(ParseColumnList("a,b:mm").size(), 2u);
}

TEST(Recording, DerivesRateAndChecksTime) {
  const auto r =
      MakeRecording(ParseCsv("t_s,x\n0,1\n0.005,2\n0.01,3\n0.015,4\n", "f"), {.min_samples = 3});
  EXPECT_NEAR(r.fs_hz, 200.0, 1e-9);
  EXPECT_NE(ErrorOf([] {
              MakeRecording(ParseCsv("t_s,x\n0,1\n0.005,2\n0.005,3\n", "f"), {.min_samples = 2});
            }).find("f:4: time does not increase"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] {
              MakeRecording(ParseCsv("t_s,x\n0,1\n0.005,2\n0.02,3\n0.025,4\n", "f"),
                            {.min_samples = 2});
            }).find("non-uniform"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] { MakeRecording(ParseCsv("t_s,x\n0,1\n", "f"), {}); }).find("too short"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] {
              MakeRecording(ParseCsv("k,x\n0,1\n1,2\n", "f"), {.min_samples = 2});
            }).find("--fs-hz"),
            std::string::npos);
  const auto k = MakeRecording(ParseCsv("k,x\n0,1\n1,2\n", "f"), {.fs_hz = 1.0, .min_samples = 2});
  EXPECT_DOUBLE_EQ(k.fs_hz, 1.0);
}

// A logger stamping whole milliseconds at 113 Hz: steps of 8 and 9 ms. The refusal names the
// rounding and the option that reads the rate, with the rate it would use (the mean step's:
// 49 steps over t = round(49 / 113, 3) = 0.434 s, 112.903 Hz; 113 Hz the rate written).
TEST(Recording, RoundedStampsNameTheRateOption) {
  std::string csv = "t_s,x\n";
  for (int i = 0; i < 50; ++i) {
    char line[64];
    std::snprintf(line, sizeof line, "%.3f,%d\n", std::round(i / 113.0 * 1000.0) / 1000.0, i);
    csv += line;
  }
  const std::string why = ErrorOf([&] { MakeRecording(ParseCsv(csv, "f"), {.min_samples = 2}); });
  EXPECT_NE(why.find("non-uniform sampling"), std::string::npos) << why;
  EXPECT_NE(why.find("rounded to 0.001 s"), std::string::npos) << why;
  const std::size_t at = why.find("--fs-hz ");
  ASSERT_NE(at, std::string::npos) << why;
  EXPECT_NEAR(std::stod(why.substr(at + 8)), 49.0 / 0.434, 1e-3) << why;
  // The rate it names reads the same file.
  const Recording r = MakeRecording(ParseCsv(csv, "f"), {.fs_hz = 49.0 / 0.434, .min_samples = 2});
  EXPECT_EQ(r.samples(), 50u);
}

TEST(Recording, ReadsSharedMeasuredRecord) {
  // ../shared/data/ecp_cart_free_decay: 200 Hz records in cm (data README).
  VIBID_SHARED_DATA_OR_SKIP(dir, "ecp_cart_free_decay");
  const auto r = LoadRecording(dir + "/Khigh_load-none_Khigh_hand_Nomass.csv");
  EXPECT_NEAR(r.fs_hz, 200.0, 1e-6);
  EXPECT_NEAR(r.Signal(ParseColumnSpec("X_cm:cm"))[0], -0.00178571e-2, 1e-12);
}

}  // namespace
}  // namespace vibid
