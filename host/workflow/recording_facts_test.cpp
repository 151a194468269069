// The clip check reads the recording's facts: a clip is a sample at the converter's rail as the
// sidecar states it. Good hits well inside the range are used however often their top value
// repeats; hits at the rail for 1 to 3 samples are rejected; a recording without a sidecar, or
// with one of version 1 (instants only), still reads and the check says it is unavailable.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "vibid/common/atomic_file.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/ident/recording_facts.hpp"
#include "vibid/workflow/estimate.hpp"

namespace vibid::workflow {
namespace {

constexpr double kFsHz = 1000.0;
// The rails of examples/sensors.json's force1 and acc1 through the board's scaling (codes 0 and
// 4095, offset 2048, 4.096 and 10.24 counts per unit): (code - 2048) / counts_per_unit.
constexpr double kForceLo = -2048.0 / 4.096;
constexpr double kForceHi = 2047.0 / 4.096;
constexpr double kAccLo = -2048.0 / 10.24;
constexpr double kAccHi = 2047.0 / 10.24;

struct Hammer {
  std::vector<std::string> names{"t_s", "force1_n", "acc1_m_s2"};
  std::vector<Eigen::VectorXd> columns;
};

// Seven hits 1.5 s apart on a 30 Hz resonator, every 5th hit's force and every response well
// inside the range except where a test puts samples on a rail.
Hammer MakeHammer() {
  const int n = 12000;
  Eigen::VectorXd t(n), f = Eigen::VectorXd::Zero(n), a = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < n; ++i) t(i) = i / kFsHz;
  const double peaks_n[] = {120.0, 90.0, 150.0, 110.0, 100.0, 130.0, 95.0};
  for (int h = 0; h < 7; ++h) {
    const int s = 500 + 1500 * h;
    for (int k = 0; k < 5; ++k) f(s + k) = peaks_n[h] * std::sin(std::numbers::pi * (k + 0.5) / 5);
  }
  // x'' + 2 zeta w x' + w^2 x = f / m, acceleration out (semi-implicit Euler, fine at 1 kHz).
  const double w = 2.0 * std::numbers::pi * 30.0;
  const double zeta = 0.02;
  double x = 0.0, v = 0.0;
  for (int i = 0; i < n; ++i) {
    const double acc = f(i) / 2.0 - 2.0 * zeta * w * v - w * w * x;
    v += acc / kFsHz;
    x += v / kFsHz;
    // Quantized as a 12-bit converter of +-200 m/s2 would: its top value repeats.
    a(i) = std::round(acc * 10.24) / 10.24;
  }
  Hammer out;
  out.columns = {t, f, a};
  return out;
}

std::string Write(const std::string& name, const Hammer& h) {
  const std::string path = (std::filesystem::temp_directory_path() / name).string();
  std::filesystem::remove(path + ".json");
  WriteFileAtomic(path, FormatCsv(h.names, h.columns));
  return path;
}

ident::RecordingFacts FactsOf(const Hammer& h) {
  ident::RecordingFacts f;
  f.columns = h.names;
  f.fs = kFsHz;
  ident::ChannelFacts force;
  force.name = "force1_n";
  force.unit_str = "N";
  force.rails = std::make_pair(kForceLo, kForceHi);
  ident::ChannelFacts acc;
  acc.name = "acc1_m_s2";
  acc.unit_str = "m/s2";
  acc.rails = std::make_pair(kAccLo, kAccHi);
  f.channels = {force, acc};
  return f;
}

Estimated EstimateHits(const std::string& path) {
  EstimationOptions o;
  o.force = "force1_n";
  o.responses = "acc1_m_s2";
  o.impact = true;
  o.keep_bad_hits = false;
  return EstimateFromRecording(path, o);
}

bool Warns(const Estimated& e, const std::string& part) {
  for (const std::string& w : e.warnings) {
    if (w.find(part) != std::string::npos) return true;
  }
  return false;
}

TEST(RecordingFacts, AClipIsASampleAtTheRailTheSidecarStates) {
  Hammer h = MakeHammer();
  // Hit 2's response holds its own top value for 6 samples, far inside +-200 m/s2: not a clip.
  const Eigen::Index top = 2000;
  for (Eigen::Index i = top; i < top + 6; ++i) h.columns[2](i) = 7.6;
  // Hits 3 and 4: the load cell on its top code for 1 and 3 samples; hit 6: the accelerometer on
  // its bottom code for 2 samples.
  h.columns[1](3502) = kForceHi;
  for (Eigen::Index i = 5001; i < 5004; ++i) h.columns[1](i) = kForceHi;
  h.columns[2](8003) = kAccLo;
  h.columns[2](8004) = kAccLo;
  const std::string path = Write("facts_clip.csv", h);
  ident::WriteRecordingFacts(path, FactsOf(h));
  const Estimated e = EstimateHits(path);
  ASSERT_EQ(e.hits.size(), 7u);
  const bool clipped[] = {false, false, true, true, false, true, false};
  for (std::size_t i = 0; i < 7; ++i) {
    EXPECT_EQ(e.hits[i].clipped, clipped[i]) << "hit " << i + 1 << ": " << e.hits[i].note;
    EXPECT_EQ(e.hits[i].used, !clipped[i]) << "hit " << i + 1 << ": " << e.hits[i].note;
  }
  EXPECT_NE(e.hits[2].note.find("force channel clipped"), std::string::npos) << e.hits[2].note;
  EXPECT_NE(e.hits[5].note.find("response 1 clipped"), std::string::npos) << e.hits[5].note;
  EXPECT_FALSE(Warns(e, "clip check unavailable"));
}

TEST(RecordingFacts, WithoutRailsTheClipCheckSaysItIsUnavailable) {
  Hammer h = MakeHammer();
  h.columns[1](3502) = kForceHi;
  const std::string path = Write("facts_none.csv", h);
  // No sidecar: nothing guessed, every hit used, and the check named as unavailable.
  const Estimated none = EstimateHits(path);
  for (const ident::Hit& hit : none.hits) EXPECT_FALSE(hit.clipped) << hit.note;
  EXPECT_TRUE(Warns(none, "clip check unavailable for the force and response 1"));
  // A version 1 sidecar (instants only, as recordings before the facts have) reads, instants
  // included, and states no rails either.
  {
    std::ofstream(path + ".json")
        << R"({"format": "vibid-recording", "version": 1, "columns": ["t_s", "force1_n", "acc1_m_s2"],
               "sample_instants_us": {"force1_n": 2.667, "acc1_m_s2": 2.667}})";
  }
  const Estimated v1 = EstimateHits(path);
  for (const ident::Hit& hit : v1.hits) EXPECT_FALSE(hit.clipped) << hit.note;
  EXPECT_TRUE(Warns(v1, "clip check unavailable"));
  EXPECT_NE(v1.compensation.find("sampling instants compensated"), std::string::npos);
  // The board's column names in counts imply their converter: 0 .. 4095.
  const ColumnSpec counts{"acc1_counts", 1.0, ""};
  const ident::ImpactOptions::ConverterLimits l = ConverterLimitsOf(counts, nullptr);
  EXPECT_EQ(l.lo, 0.0);
  EXPECT_EQ(l.hi, 4095.0);
  // A scaled column's rails are scaled with it (mm of a column in m).
  ident::RecordingFacts f = FactsOf(h);
  const ident::ImpactOptions::ConverterLimits mm =
      ConverterLimitsOf(ColumnSpec{"acc1_m_s2", 1000.0, ""}, &f);
  EXPECT_DOUBLE_EQ(mm.hi, 1000.0 * kAccHi);
  EXPECT_DOUBLE_EQ(mm.lo, 1000.0 * kAccLo);
}

// Every fact round-trips through the sidecar's text, and a sidecar of another recording or with
// an unknown key is refused naming it.
TEST(RecordingFacts, TheSidecarRoundTripsAndRefusesWhatItDoesNotKnow) {
  ident::RecordingFacts f = FactsOf(MakeHammer());
  f.start_timestamp = "2026-12-07T04:30:00.125Z";
  f.board = ident::BoardFacts{"emulator", "EMU0000000000000007", "2.1.0", "2.1", 0xDEADBEEF, 12};
  f.calibration = ident::CalibrationFacts{"rig A", 0x1234ABCD, 1765000000};
  ident::AcquisitionFacts a;
  a.sample_rate_hz = 1000.0;
  a.decimation = 1;
  a.seconds = 12.0;
  a.trigger = "force>5";
  a.pretrigger_s = 0.1;
  a.records = 12000;
  a.scenario = "hammer";
  a.scenario_params = {0.0, 2.0};
  a.emulator_seed = 7;
  f.acquisition = a;
  f.channels[0].counts_per_unit = 4.096;
  f.channels[0].offset_counts = 2048;
  f.channels[0].full_scale = 500.0;
  f.channels[0].code_range = std::make_pair(0.0, 4095.0);
  f.channels[0].sample_instant_us = 2.667;
  f.channels[0].clipped_samples = 3;
  const std::string text = ident::FormatRecordingFacts(f);
  const ident::RecordingFacts back = ident::ParseRecordingFacts(text, f.columns, "r.csv.json");
  EXPECT_EQ(back, f) << text;
  // SEP005's channel fields are there: name, unit_str, fs, start_timestamp.
  EXPECT_NE(text.find("\"unit_str\": \"N\""), std::string::npos) << text;
  EXPECT_NE(text.find("\"fs\": 1000.0"), std::string::npos) << text;
  EXPECT_THROW((void)ident::ParseRecordingFacts(text, {"t_s", "force1_n"}, "r.csv.json"),
               InputError);
  std::string unknown = text;
  unknown.replace(unknown.find("\"rails\""), 7, "\"rail\"");
  try {
    (void)ident::ParseRecordingFacts(unknown, f.columns, "r.csv.json");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown key 'rail'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace vibid::workflow
