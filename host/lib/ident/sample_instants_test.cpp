// Sampling-instant compensation: the header line round trip and its refusals, and the FRF of a
// pure delay (two samplings of one signal, dt apart) brought back to 1 against the closed form
// H = exp(j omega dt).
#include "vibid/ident/sample_instants.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "vibid/common/error.hpp"

namespace vibid::ident {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(SampleInstants, SidecarRoundTrip) {
  const std::vector<std::string> columns = {"t_s", "force1_n", "force2_n", "x1_m"};
  const std::string text =
      FormatRecordingSidecar(columns, {{"force1_n", 2.667}, {"force2_n", 5.905}, {"x1_m", 0.0}});
  // Version 2: each channel's instant among its facts (recording_facts.hpp).
  EXPECT_NE(text.find("\"version\": 2"), std::string::npos) << text;
  EXPECT_NE(text.find("\"sample_instant_us\": 5.905"), std::string::npos) << text;
  const SampleInstants back = ParseRecordingSidecar(text, columns, "r.csv.json");
  EXPECT_DOUBLE_EQ(*back.Of("force1_n"), 2.667e-6);
  EXPECT_DOUBLE_EQ(*back.Of("force2_n"), 5.905e-6);
  EXPECT_EQ(*back.Of("x1_m"), 0.0);
  EXPECT_FALSE(back.Of("t_s").has_value());
  EXPECT_EQ(RecordingSidecarPath("dir/rec.csv"), "dir/rec.csv.json");
  // A version 1 sidecar, as recordings before version 2 have it, reads the same.
  const std::string v1 =
      "{\n  \"format\": \"vibid-recording\",\n  \"version\": 1,\n  \"columns\": [\n"
      "    \"t_s\",\n    \"force1_n\",\n    \"force2_n\",\n    \"x1_m\"\n  ],\n"
      "  \"sample_instants_us\": {\n    \"force1_n\": 2.667,\n    \"force2_n\": 5.905,\n"
      "    \"x1_m\": 0.0\n  }\n}\n";
  EXPECT_EQ(ParseRecordingSidecar(v1, columns, "old.csv.json").instants_us, back.instants_us);
}

TEST(SampleInstants, ASidecarOfAnotherRecordingOrMalformedIsRefused) {
  const std::vector<std::string> columns = {"t_s", "force1_n"};
  const std::string good = FormatRecordingSidecar(columns, {{"force1_n", 2.667}});
  const auto refused = [&](const std::string& text, const std::vector<std::string>& csv,
                           const std::string& part) {
    try {
      (void)ParseRecordingSidecar(text, csv, "r.csv.json");
      ADD_FAILURE() << text << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  refused(good, {"t_s", "force2_n"},
          "r.csv.json: describes columns [\"t_s\",\"force1_n\"], the "
          "recording's are t_s,force2_n: it belongs to another recording");
  refused(R"({"format": "vibid-frf"})", columns, "not a vibid-recording sidecar");
  refused(R"({"format": "vibid-recording", "version": 1, "columns": ["t_s", "force1_n"],
              "sample_instants_us": {}, "instants": 1})",
          columns, "unknown key 'instants'");
  refused(R"({"format": "vibid-recording", "version": 3, "columns": ["t_s", "force1_n"],
              "sample_instants_us": {}})",
          columns, "version 3 is not one this vibid reads");
  refused(R"({"format": "vibid-recording", "version": 1, "columns": ["t_s", "force1_n"],
              "sample_instants_us": {"force1_n": -1}})",
          columns, "sample_instants_us of 'force1_n' is not a number >= 0: -1");
  refused(R"({"format": "vibid-recording", "version": 1, "columns": ["t_s", "force1_n"],
              "sample_instants_us": {"acc1_m_s2": 1}})",
          columns, "names 'acc1_m_s2', not a column of the recording");
}

// The form recordings had before the sidecar: an opening comment line.
TEST(SampleInstants, TheOpeningLineOfEarlierRecordingsIsStillRead) {
  const std::string line =
      "# vibid-recording sample_instants_us=force1_n:2.667,force2_n:5.905,x1_m:0";
  const auto parsed = ParseSampleInstants("# other line\n" + line + "\nt_s,force1_n\n0,1\n", "r");
  ASSERT_TRUE(parsed.has_value());
  EXPECT_DOUBLE_EQ(*parsed->Of("force1_n"), 2.667e-6);
  EXPECT_DOUBLE_EQ(*parsed->Of("force2_n"), 5.905e-6);
  EXPECT_EQ(*parsed->Of("x1_m"), 0.0);
  EXPECT_FALSE(parsed->Of("acc1_m_s2").has_value());
  // A recording from elsewhere states nothing; a line after the header row is data, not header.
  EXPECT_FALSE(ParseSampleInstants("t_s,a\n0,1\n", "r").has_value());
  EXPECT_FALSE(ParseSampleInstants("t_s,a\n" + line + "\n", "r").has_value());
}

TEST(SampleInstants, MalformedListsAreRefusedWithTheFile) {
  for (const char* bad : {"force1_n", "force1_n:", "force1_n:-1", "force1_n:nan", "force1_n:2x",
                          ":2", "a:1,a:2", "a:1,"}) {
    const std::string text = std::string("# vibid-recording sample_instants_us=") + bad + "\n";
    try {
      (void)ParseSampleInstants(text, "rec.csv");
      ADD_FAILURE() << bad << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("rec.csv: sample_instants_us"), std::string::npos)
          << e.what();
    }
  }
}

TEST(SampleInstants, ADelayedSamplingOfOneSignalComesBackToUnity) {
  // One signal, sampled at the edge (the force) and dt later (the response), as the board's
  // force1 and force2 are (2.667 and 5.905 us: dt = 68 ADC clocks / 21 MHz = 3.238 us). Tones on
  // every other line of the 1000-sample segment, so the Hann window's leakage (one line each
  // side) never mixes two tones: the estimate at a tone's line is exactly exp(j omega dt).
  const double fs_hz = 10000.0;
  const double dt_s = 68.0 / 21e6;
  const std::size_t n = 20000, segment = 1000;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> phase(0.0, 2.0 * kPi);
  std::vector<double> tone_hz, tone_phase;
  for (int k = 2; k < 500; k += 2) {
    tone_hz.push_back(k * fs_hz / segment);
    tone_phase.push_back(phase(rng));
  }
  Eigen::VectorXd force(n), response(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / fs_hz;
    double f = 0.0, r = 0.0;
    for (std::size_t m = 0; m < tone_hz.size(); ++m) {
      f += std::sin(2.0 * kPi * tone_hz[m] * t + tone_phase[m]);
      r += std::sin(2.0 * kPi * tone_hz[m] * (t + dt_s) + tone_phase[m]);
    }
    force(static_cast<Eigen::Index>(i)) = f;
    response(static_cast<Eigen::Index>(i)) = r;
  }
  WelchOptions o;
  o.segment_samples = segment;
  o.overlap_samples = segment / 2;
  const std::vector<const Eigen::VectorXd*> responses{&response};
  Frf frf = FrfFromSpectra(WelchSpectra(force, responses, fs_hz, o), Estimator::kH1,
                           Quantity::kAcceleration);
  const Eigen::Index line_2500 = 250;  // 2500 Hz
  ASSERT_DOUBLE_EQ(frf.freq_hz(line_2500), 2500.0);
  // Before: the phase of the delay, 2 pi 2500 Hz x 3.238 us = 0.050865 rad (2.914 deg).
  EXPECT_NEAR(std::arg(frf.h(line_2500, 0)), 2.0 * kPi * 2500.0 * dt_s, 1e-9);
  CompensateSampleInstants(frf, 2.667e-6, {2.667e-6 + dt_s});
  double worst_phase = 0.0, worst_gain = 0.0;
  for (int k = 2; k < 500; k += 2) {
    const std::complex<double> h = frf.h(k, 0);
    worst_phase = std::max(worst_phase, std::abs(std::arg(h)));
    worst_gain = std::max(worst_gain, std::abs(std::abs(h) - 1.0));
  }
  EXPECT_LT(worst_phase, 1e-9);
  EXPECT_LT(worst_gain, 1e-9);
  EXPECT_THROW(CompensateSampleInstants(frf, 0.0, {}), InputError);
}

}  // namespace
}  // namespace vibid::ident
