#include "vibid/common/csv.hpp"

#include <gtest/gtest.h>

#include "vibid/common/error.hpp"

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
  EXPECT_NE(ErrorOf([] { ParseCsv("a,b\n1,2\n3,x\n", "f.csv"); }).find("f.csv:3:"), std::string::npos);
  EXPECT_NE(ErrorOf([] { ParseCsv("a,b\n1,2\n3\n", "f.csv"); }).find("f.csv:3: expected 2 cells"), std::string::npos);
  EXPECT_NE(ErrorOf([] { ParseCsv("1,2\n3,4\n", "f.csv"); }).find("header"), std::string::npos);
  EXPECT_NE(ErrorOf([] { ParseCsv("a,b\n1,nan\n", "f.csv"); }).find("f.csv:2:"), std::string::npos);
  EXPECT_NE(ErrorOf([] { ParseCsv("", "f.csv"); }).find("empty"), std::string::npos);
  EXPECT_NE(ErrorOf([] { ParseCsv("a,a\n1,2\n", "f.csv"); }).find("duplicate"), std::string::npos);
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
  const auto r = MakeRecording(ParseCsv("t_s,x\n0,1\n0.005,2\n0.01,3\n0.015,4\n", "f"), {.min_samples = 3});
  EXPECT_NEAR(r.fs_hz, 200.0, 1e-9);
  EXPECT_NE(ErrorOf([] { MakeRecording(ParseCsv("t_s,x\n0,1\n0.005,2\n0.005,3\n", "f"), {.min_samples = 2}); })
                .find("f:4: time does not increase"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] { MakeRecording(ParseCsv("t_s,x\n0,1\n0.005,2\n0.02,3\n0.025,4\n", "f"), {.min_samples = 2}); })
                .find("non-uniform"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] { MakeRecording(ParseCsv("t_s,x\n0,1\n", "f"), {}); }).find("too short"), std::string::npos);
  EXPECT_NE(ErrorOf([] { MakeRecording(ParseCsv("k,x\n0,1\n1,2\n", "f"), {.min_samples = 2}); }).find("--fs-hz"),
            std::string::npos);
  const auto k = MakeRecording(ParseCsv("k,x\n0,1\n1,2\n", "f"), {.fs_hz = 1.0, .min_samples = 2});
  EXPECT_DOUBLE_EQ(k.fs_hz, 1.0);
}

TEST(Recording, ReadsSharedMeasuredRecord) {
  // ../shared/data/ecp_cart_free_decay: 200 Hz records in cm (data README).
  const auto r = LoadRecording(std::string(VIBID_DATA_DIR) + "/ecp_cart_free_decay/Khigh_load-none_Khigh_hand_Nomass.csv");
  EXPECT_NEAR(r.fs_hz, 200.0, 1e-6);
  EXPECT_NEAR(r.Signal(ParseColumnSpec("X_cm:cm"))[0], -0.00178571e-2, 1e-12);
}

}  // namespace
}  // namespace vibid
