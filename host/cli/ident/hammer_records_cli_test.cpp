// Hammer records that are not clean, and a record with no hammer, each named with its way out:
// a rebound under a noisy force, a hit on the record's first sample, a rotating unbalance, and a
// ringing record whose advice is checked against the modes it would bury. Inputs: DAQ records
// simulated independently of vibid (scripts/golden/hammer_records.py: scipy, exact first-order-
// hold integration of each mode at 8 times the rate, FIR anti-aliasing and decimation, Gaussian
// noise), committed in testdata/ with the command that wrote each.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "run_cli.hpp"
#include "ident_cli_text.hpp"

namespace vibid::testing {
namespace {

using nlohmann::json;

std::string TempDir() { return ::testing::TempDir(); }

CliResult Estimate(const std::string& record) {
  return RunVibid({"frf-estimate", TestData(record), "--force", "force1_n", "--response",
                   "acc1_m_s2", "-o", TempDir() + "/hammer_records_" + record});
}

// Each hit has a rebound of 12 % of its peak 15 ms after it, under force noise of 2 % of the
// largest force (hammer_records.py --rebound 0.12 --rebound-delay-s 0.015 --noise 0.02): the
// record-wide noise level (6 standard deviations, 12 % of the peak) hid it on one hit of three,
// which was then used as a clean single hit. Within the double-hit window the level is the one
// noise alone passes once in 10^4 hits; every hit is now named a double hit.
TEST(HammerRecordsCli, AReboundOfTwelvePercentUnderANoisyForceIsADoubleHit) {
  const auto r = Estimate("wing_rebound_noisy_force.csv");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto hits = Lines(r.out, "hit ");
  ASSERT_EQ(hits.size(), 3u) << r.out;
  for (const std::string& h : hits) EXPECT_NE(h.find("double hit"), std::string::npos) << h;
  EXPECT_EQ(Lines(r.err, "every hit is a double hit").size(), 1u) << r.err;
}

// The same force noise without a rebound (--noise 0.02 --hits 2): no hit is called double.
TEST(HammerRecordsCli, NoiseAloneIsNoDoubleHit) {
  const auto r = Estimate("wing_noisy_force.csv");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto hits = Lines(r.out, "hit ");
  ASSERT_EQ(hits.size(), 2u) << r.out;
  for (const std::string& h : hits) EXPECT_EQ(h.find("double hit"), std::string::npos) << h;
}

// The first hit starts on the record's first sample (--first-s 0), as an analyzer without a
// pretrigger records it: it passed without a word. Now a warning names it and the way out.
TEST(HammerRecordsCli, AHitOnTheFirstSampleAsksForAPretrigger) {
  const auto r = RunVibid({"modes", TestData("wing_no_pretrigger.csv"), "--force", "force1_n",
                           "--response", "acc1_m_s2"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto w = Lines(r.err, "the first hit starts on the record's first sample");
  ASSERT_EQ(w.size(), 1u) << r.err;
  EXPECT_NE(w[0].find("record with a pretrigger"), std::string::npos) << w[0];
}

// A rotating unbalance at 24.7 Hz and no hammer (--kind unbalance): it went to Welch and a mode
// was listed (13.05 Hz, zeta 0.014, from an FRF that is noise away from 24.7 Hz). Now refused,
// naming the harmonic force's frequency (within one 1280/4096 Hz line of the simulated speed)
// and the time-domain methods.
TEST(HammerRecordsCli, AHarmonicForceIsRefusedWithTheTimeDomainMethods) {
  const auto r = RunVibid({"modes", TestData("unbalance_no_hammer.csv"), "--force", "force1_n",
                           "--response", "acc1_m_s2"});
  EXPECT_NE(r.exit_code, 0) << r.out;
  EXPECT_EQ(r.out.find("freq_hz"), std::string::npos) << r.out;
  const auto e = Lines(r.err, "a harmonic force");
  ASSERT_EQ(e.size(), 1u) << r.err;
  EXPECT_NEAR(NumberAfter(e[0], " lines of "), 24.7, 1280.0 / 4096.0) << e[0];
  EXPECT_NE(e[0].find("vibid tfest"), std::string::npos) << e[0];
  // Welch all the same when asked for.
  const auto forced = RunVibid({"frf-estimate", TestData("unbalance_no_hammer.csv"), "--force",
                                "force1_n", "--response", "acc1_m_s2", "--welch", "-o",
                                TempDir() + "/hammer_records_unbalance_welch.csv"});
  EXPECT_EQ(forced.exit_code, 0) << forced.err;
}

// A beam whose 34 Hz mode has zeta 0.0004 (decay rate 0.0854 1/s: hammer_records.py --structure
// beam) rings at the end of its 3.2 s records. The advice was "an exponential window
// (--exp-window)"; the window that quiets it (end value 0.1 adds ln(10) / 3.15 s = 0.73 1/s,
// 8.5 times that mode's own decay) made the curve fit drop the 34 Hz mode without a word on
// the window. The advice is now a record length (the window it would take adds more than the
// longest-ringing mode's own decay: not advised), and a window that does that is named per mode.
TEST(HammerRecordsCli, RingingAdviceNeverBuriesTheLightestMode) {
  const auto r = Estimate("beam_light.csv");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto w = Lines(r.err, "still ring at their record's end");
  ASSERT_EQ(w.size(), 1u) << r.err;
  const double advised_s = NumberAfter(w[0], "records of at least ");
  // At least the present record; its own decay read from the record's late part (0.14 1/s,
  // the 212.5 Hz mode still adding to it) gives 10.8 s; the 34 Hz mode alone needs
  // 3.15 + ln(0.14 / 0.05) / 0.0854 = 15.2 s.
  EXPECT_GT(advised_s, 3.2) << w[0];
  EXPECT_NE(w[0].find("not advised"), std::string::npos) << w[0];

  const auto fit = RunVibid({"modes", TestData("beam_light.csv"), "--force", "force1_n",
                             "--response", "acc1_m_s2", "--exp-window", "0.1", "--method", "fit"});
  ASSERT_EQ(fit.exit_code, 0) << fit.err;
  const auto lost = Lines(fit.err, "lost under the window");
  ASSERT_EQ(lost.size(), 1u) << fit.err;
  EXPECT_NEAR(NumberAfter(lost[0], "pole at "), 34.0, 0.1) << lost[0];

  const auto lscf = RunVibid({"modes", TestData("beam_light.csv"), "--force", "force1_n",
                              "--response", "acc1_m_s2", "--exp-window", "0.1"});
  ASSERT_EQ(lscf.exit_code, 0) << lscf.err;
  const auto wider = Lines(lscf.err, "the exponential window adds");
  ASSERT_GE(wider.size(), 1u) << lscf.err;
  EXPECT_NEAR(NumberAfter(wider[0], "mode at "), 34.0, 0.1) << wider[0];
  // 0.731 / 0.0854 = 8.6 times its own (closed form; the estimate of zeta moves it a little).
  EXPECT_NEAR(NumberAfter(wider[0], "Hz: the exponential window adds "), 8.6, 1.5) << wider[0];
}

// The advice run as given: the same beam struck every 11 s (at least the 10.8 s the 3.2 s
// records' warning asks for) still rings a little (12 % on one hit of two); the window that takes
// it to 5 % adds about the 34 Hz mode's own decay, so it is advised with its end value. Run with
// it, the ringing warning is gone, no mode is named as swamped by the window, and the 34 Hz mode's
// damping interval holds the simulator's 0.0004.
TEST(HammerRecordsCli, TheAdvisedWindowKeepsTheLightestMode) {
  const auto r = Estimate("beam_light_11s.csv");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto w = Lines(r.err, "still ring at their record's end");
  ASSERT_EQ(w.size(), 1u) << r.err;
  const double end = NumberAfter(w[0], "an exponential window --exp-window ");
  ASSERT_TRUE(end > 0.0 && end < 1.0) << w[0];
  std::ostringstream value;
  value << end;
  const auto m = RunVibid({"modes", TestData("beam_light_11s.csv"), "--force", "force1_n",
                           "--response", "acc1_m_s2", "--exp-window", value.str(), "--json"});
  ASSERT_EQ(m.exit_code, 0) << m.err;
  EXPECT_TRUE(Lines(m.err, "still ring").empty()) << m.err;
  EXPECT_TRUE(Lines(m.err, "the exponential window adds").empty()) << m.err;
  const json j = json::parse(m.out);
  const json* beam = nullptr;
  for (const json& mode : j["modes"])
    if (std::abs(mode["freq_hz"].get<double>() - 34.0) < 0.05) beam = &mode;
  ASSERT_NE(beam, nullptr) << m.out;
  ASSERT_TRUE((*beam)["ci95"]["zeta"][0].is_number()) << beam->dump();
  EXPECT_LE((*beam)["ci95"]["zeta"][0].get<double>(), 0.0004) << beam->dump();
  EXPECT_GE((*beam)["ci95"]["zeta"][1].get<double>(), 0.0004) << beam->dump();
}

// Two repeats of one test (the same wing, noise seeds 11 and 12: sub_line_wing.csv and
// wing_repeat_seed12.csv): each mode's damping interval holds the simulator's own zeta (13.44 Hz:
// 0.002; 167.8 Hz: 0.0003, a half-power band of a third of a line) and the two intervals overlap.
// Over seeds 1-6 the 167.8 Hz mode's zeta fell 1.4 to 0.8 of its standard deviation from the
// truth (interval +-6e-7, 0.2 %): the lines' bias is below the interval's width.
TEST(HammerRecordsCli, RepeatTestsDampingIntervalsOverlapAndHoldTheTruth) {
  constexpr double kTruthHz[2] = {13.44, 167.8};
  constexpr double kTruthZeta[2] = {0.002, 0.0003};
  std::vector<std::vector<double>> lo(2);
  std::vector<std::vector<double>> hi(2);
  for (const char* record : {"sub_line_wing.csv", "wing_repeat_seed12.csv"}) {
    const auto r = RunVibid(
        {"modes", TestData(record), "--force", "force1_n", "--response", "acc1_m_s2", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const json j = json::parse(r.out);
    for (std::size_t k = 0; k < 2; ++k) {
      const json* mode = nullptr;
      for (const json& m : j["modes"])
        if (std::abs(m["freq_hz"].get<double>() - kTruthHz[k]) < 0.01 * kTruthHz[k]) mode = &m;
      ASSERT_NE(mode, nullptr) << record << r.out;
      ASSERT_TRUE((*mode)["ci95"]["zeta"][0].is_number()) << mode->dump();
      const double l = (*mode)["ci95"]["zeta"][0].get<double>();
      const double h = (*mode)["ci95"]["zeta"][1].get<double>();
      EXPECT_LE(l, kTruthZeta[k]) << record << " " << kTruthHz[k];
      EXPECT_GE(h, kTruthZeta[k]) << record << " " << kTruthHz[k];
      lo[k].push_back(l);
      hi[k].push_back(h);
    }
  }
  for (std::size_t k = 0; k < 2; ++k)
    EXPECT_LE(std::max(lo[k][0], lo[k][1]), std::min(hi[k][0], hi[k][1])) << kTruthHz[k];
}

// The beam's 596 Hz mode (zeta 0.001, 44 Hz below the Nyquist limit of a 1 280 Hz record; the
// simulation has no friction) was called dry friction and lost its intervals: demodulated at
// 596 Hz, its own image at -1 192 Hz folds to 88 Hz, which the envelope's three-period boxcar
// passed at 56 %, so the envelope met its floor a third early. The smoothing now rejects the
// folded image: no friction word, and the mode's intervals hold the simulator's zeta.
TEST(HammerRecordsCli, AModeNearTheNyquistLimitIsNoFriction) {
  const auto r = RunVibid({"modes", TestData("beam_light.csv"), "--force", "force1_n", "--response",
                           "acc1_m_s2", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(Lines(r.err, "friction").empty()) << r.err;
  const json j = json::parse(r.out);
  const json* mode = nullptr;
  for (const json& m : j["modes"])
    if (std::abs(m["freq_hz"].get<double>() - 596.0) < 0.5) mode = &m;
  ASSERT_NE(mode, nullptr) << r.out;
  ASSERT_TRUE((*mode)["ci95"]["zeta"][0].is_number()) << mode->dump();
  // hammer_records.py STRUCTURES["beam"]: zeta 0.001 at 596 Hz.
  EXPECT_LE((*mode)["ci95"]["zeta"][0].get<double>(), 0.001) << mode->dump();
  EXPECT_GE((*mode)["ci95"]["zeta"][1].get<double>(), 0.001) << mode->dump();
}

// Bumps of the receptance's noise were named as clear peaks with no mode: 0.15 and 0.37 Hz at the
// low edge of the 11 s beam records, 2.19 Hz on the 3.2 s ones, 6.95 Hz on the wing record
// without a pretrigger. Their coherence over 2-3 hits, with its bias for that few averages taken
// off, is 0.04-0.4: their random error is larger than their height. None is named now; the
// simulated structures (13.44 and 167.8 Hz; 34, 212.5 and 596 Hz) have no other resonance.
TEST(HammerRecordsCli, NoiseBumpsAreNoClearPeaks) {
  for (const char* record : {"beam_light.csv", "beam_light_11s.csv", "wing_no_pretrigger.csv"}) {
    const auto r =
        RunVibid({"modes", TestData(record), "--force", "force1_n", "--response", "acc1_m_s2"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(Lines(r.err, "a clear peak at").empty()) << record << "\n" << r.err;
  }
}

// The curve fit on the 11 s beam records started from every noise peak of the receptance's low
// band (about forty below 13 Hz, each listed as a mode). Peaks within the FRF's random error no
// longer start a pole: the structure's three modes are listed, and nothing below 13 Hz.
TEST(HammerRecordsCli, TheCurveFitListsTheStructuresModes) {
  const auto r = RunVibid({"modes", TestData("beam_light_11s.csv"), "--force", "force1_n",
                           "--response", "acc1_m_s2", "--method", "fit", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  std::size_t below_13_hz = 0;
  std::vector<double> found;
  for (const json& m : j["modes"]) {
    const double f = m["freq_hz"].get<double>();
    if (f < 13.0) ++below_13_hz;
    found.push_back(f);
  }
  EXPECT_EQ(below_13_hz, 0u) << r.out;
  EXPECT_EQ(found.size(), 3u) << r.out;
  // The fit's zeta at 212.5 Hz (0.00061 for the simulator's 0.0008: the records are cut while it
  // rings) put the ring-downs' floor "early"; their own envelope decays at the simulator's rate
  // with no friction term, so no friction is named.
  EXPECT_TRUE(Lines(r.err, "friction").empty()) << r.err;
  // hammer_records.py STRUCTURES["beam"].
  for (const double truth : {34.0, 212.5, 596.0})
    EXPECT_TRUE(std::any_of(found.begin(), found.end(),
                            [&](double f) { return std::abs(f - truth) < 0.002 * truth; }))
        << truth << "\n"
        << r.out;
}

}  // namespace
}  // namespace vibid::testing
