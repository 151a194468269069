// FRF files: CSV round trip (bit-exact), UFF58 round trip and field layout, malformed input.
#include "vibid/ident/frf_io.hpp"

#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "vibid/common/error.hpp"

namespace vibid::ident {
namespace {

Frf Sample() {
  Frf frf = testing::ChainFrf(1.2, 0.8, 3000, 2000, 0.6, 0.4, 1, 0.25, 37);
  frf.quantity = Quantity::kAcceleration;
  frf.estimator = Estimator::kH2;
  frf.averages = 7;
  frf.exp_window_tau_s = 0.125;
  frf.pretrigger_s = 0.0625;
  frf.record_s = 3.5;
  frf.measured = Quantity::kVelocity;
  frf.force_name = "force_n";
  frf.coherence(3, 1) = 0.5;
  return frf;
}

TEST(FrfCsv, RoundTripIsExact) {
  const Frf a = Sample();
  const std::string text = FormatFrfCsv(a);
  EXPECT_TRUE(LooksLikeFrfCsv(text));
  // A plain header row first (the metadata is in the sidecar).
  EXPECT_EQ(text.rfind("freq_hz,", 0), 0u) << text.substr(0, 80);
  Frf b = ParseFrfCsv(text, "mem");
  ApplyFrfSidecar(FormatFrfSidecar(a), "mem.json", b);
  EXPECT_EQ(b.quantity, Quantity::kAcceleration);
  EXPECT_EQ(b.estimator, Estimator::kH2);
  EXPECT_EQ(b.averages, 7u);
  EXPECT_EQ(b.exp_window_tau_s, 0.125);
  EXPECT_EQ(b.pretrigger_s, 0.0625);
  EXPECT_EQ(b.record_s, 3.5);
  EXPECT_EQ(b.measured, Quantity::kVelocity);
  EXPECT_EQ(b.force_name, "force_n");
  EXPECT_EQ(b.response_names, a.response_names);
  EXPECT_TRUE(b.freq_hz == a.freq_hz);
  EXPECT_TRUE(b.h == a.h);
  EXPECT_TRUE(b.coherence == a.coherence);
}

// A file written before `measured=` existed: the responses are taken to have measured its kind.
TEST(FrfCsv, WithoutMeasuredTheKindIsWhatWasMeasured) {
  const Frf b = ParseFrfCsv(
      "# vibid-frf kind=mobility estimator=h1 averages=1\nfreq_hz,h_re,h_im\n1,2,0\n2,2,0\n3,2,0\n"
      "4,2,0\n",
      "old.csv");
  EXPECT_EQ(b.measured, Quantity::kVelocity);
  EXPECT_EQ(b.record_s, 0.0);
}

TEST(FrfCsv, MalformedFilesNameTheProblem) {
  EXPECT_THROW(ParseFrfCsv("a,b\n1,2\n", "x.csv"), InputError);
  EXPECT_THROW(ParseFrfCsv("freq_hz,h_re\n1,2\n2,2\n3,2\n4,2\n", "x.csv"), InputError);  // no _im
  try {
    ParseFrfCsv("freq_hz,h_re,h_im\n1,2,0\n3,2,0\n2,2,0\n4,2,0\n", "x.csv");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("increase"), std::string::npos);
  }
  // A negative exponential-window time constant is refused, not read as "no window": in the
  // sidecar, and on the opening line of a file written before it.
  std::string sidecar = FormatFrfSidecar(Sample());
  sidecar.replace(sidecar.find("\"exp_window_tau_s\": ") + 20, 0, "-");
  try {
    Frf f = ParseFrfCsv(FormatFrfCsv(Sample()), "x.csv");
    ApplyFrfSidecar(sidecar, "x.csv.json", f);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("x.csv.json: exp_window_tau_s must not be negative"),
              std::string::npos)
        << e.what();
  }
  // A sidecar of other columns is refused, naming both.
  Frf other = Sample();
  other.response_names[0] = "acc9";
  try {
    Frf f = ParseFrfCsv(FormatFrfCsv(Sample()), "x.csv");
    ApplyFrfSidecar(FormatFrfSidecar(other), "x.csv.json", f);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("belongs to another file"), std::string::npos) << e.what();
  }
  const std::string written =
      "# vibid-frf kind=accelerance estimator=h1 averages=1 "
      "exp_window_tau_s=0.125\n" +
      FormatFrfCsv(Sample());
  const std::string key = "exp_window_tau_s=";
  const std::size_t at = written.find(key);
  ASSERT_NE(at, std::string::npos);
  const std::size_t value = at + key.size();
  const std::string text = written.substr(0, value) + "-" + written.substr(value);
  try {
    ParseFrfCsv(text, "x.csv");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("x.csv: line 1: exp_window_tau_s must not be negative"),
              std::string::npos)
        << e.what();
  }
}

TEST(Uff58, RoundTripAndFixedFields) {
  const Frf a = Sample();
  const std::string text = FormatUff58(a, 2);
  std::istringstream in(text);
  std::string line;
  std::vector<std::string> lines;
  while (std::getline(in, line)) lines.push_back(line);
  ASSERT_GT(lines.size(), 14u);
  EXPECT_EQ(lines[0], "    -1");
  EXPECT_EQ(lines[1].substr(0, 6), "    58");
  // Record 6: function type 4 (FRF) in I5, response node 1 and reference node 2, direction 1.
  EXPECT_EQ(lines[7].substr(0, 5), "    4");
  EXPECT_EQ(lines[7].substr(41, 10), "         1");
  EXPECT_EQ(lines[7].substr(66, 10), "         2");
  // Record 7: complex double (6), 37 points, even spacing.
  EXPECT_EQ(lines[8].substr(0, 30), "         6        37         1");
  // Record 8/9/10: frequency (18); acceleration (12) over force (13).
  EXPECT_EQ(lines[9].substr(0, 10), "        18");
  EXPECT_EQ(lines[10].substr(0, 10), "        12");
  EXPECT_EQ(lines[11].substr(0, 10), "        13");
  // Data: 4E20.12 per line.
  EXPECT_EQ(lines[13].size(), 80u);

  const Frf b = ParseUff58(text, "mem.uff");
  EXPECT_EQ(b.quantity, Quantity::kAcceleration);
  ASSERT_EQ(b.h.cols(), 2);
  ASSERT_EQ(b.freq_hz.size(), a.freq_hz.size());
  for (Eigen::Index i = 0; i < a.freq_hz.size(); ++i) {
    EXPECT_NEAR(b.freq_hz[i], a.freq_hz[i], 1e-5 * a.freq_hz[i]);  // E13.5 abscissa fields
    for (Eigen::Index j = 0; j < 2; ++j) {
      EXPECT_LT(std::abs(b.h(i, j) - a.h(i, j)), 1e-12 * std::abs(a.h(i, j)));
      EXPECT_NEAR(b.coherence(i, j), a.coherence(i, j), 1e-12);
    }
  }
}

TEST(Uff58, MalformedInputNamesTheLine) {
  const std::string good = FormatUff58(Sample(), 2);
  // Drop the closing delimiter of the last dataset.
  const std::string cut = good.substr(0, good.rfind("    -1"));
  EXPECT_THROW(ParseUff58(cut, "a.uff"), InputError);
  std::string bad = good;
  bad.replace(bad.find("         6        37"), 20, "         6        99");
  try {
    ParseUff58(bad, "a.uff");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("a.uff: line"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ParseUff58("    -1\n   151\n    -1\n", "c.uff"), InputError);  // no FRF dataset
}

}  // namespace
}  // namespace vibid::ident
