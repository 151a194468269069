// The simulated rig against closed forms: 1-DOF free decay, static deflection, force to
// acceleration at the first sample of a hit, converter codes, excitation shapes, determinism.
#include "quiet_rig.hpp"
#include "rig.hpp"

#include <gtest/gtest.h>

#include <filesystem>

#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>

#include "scenario.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/testing/input_error.hpp"
#include "vibid/model/modal.hpp"

namespace vibid::emu {
namespace {

constexpr double kFs = 5000.0;

Scenario Parse(const char* name, std::array<float, 4> params, int dofs = 2) {
  wire::ScenarioRequest r;
  std::snprintf(r.name.data(), r.name.size(), "%s", name);
  r.params = params;
  Scenario s;
  EXPECT_EQ(ParseScenario(r, dofs, s), Status::kOk) << name;
  return s;
}

TEST(Rig, DefaultTruthDiffersFromTheNominalModel) {
  // Nominal model shipped with the demo (examples/rig_nominal.json): m = 2.0, 1.5 kg,
  // k = 4000, 3000 N/m. The built-in rig: m1 −9 % (effective), m2 +2 %, k1 −12 %, k2 −8 %.
  const model::Model t = DefaultRig().Truth();
  EXPECT_NEAR(t.m_kg(0, 0), 2.0 * 0.91, 1e-12);
  EXPECT_NEAR(t.m_kg(1, 1), 1.5 * 1.02, 1e-12);
  EXPECT_NEAR(t.k_n_per_m(1, 1), 3000.0 * 0.92, 1e-9);                      // K22 = k2
  EXPECT_NEAR(t.k_n_per_m(0, 0) - t.k_n_per_m(1, 1), 4000.0 * 0.88, 1e-9);  // K11 − K22 = k1
  EXPECT_NEAR(t.k_n_per_m(0, 1), -2760.0, 1e-9);
}

TEST(Rig, SingleMassFreeDecayMatchesTheClosedForm) {
  RigSimulator rig(QuietRig(), 1);
  rig.Select(Parse("step", {1, 20, 5, 1}));  // mass 1 alone, pull 20 N for 5 s, release
  rig.Start(1.0 / kFs);
  const double m = 2.0 * 0.91, k = 3520.0, c = 5.0;
  // Closed form: ω_d = sqrt(k/m − (c/2m)²) for m ẍ + c ẋ + k x = 0.
  const double omega_d = std::sqrt(k / m - std::pow(c / (2.0 * m), 2));

  std::array<std::int32_t, wire::kChannelCount> raw{};
  const double release_s = 0.5 + 0.3 + 5.0;
  double static_x = 0.0;
  std::int32_t static_counts = 0;
  std::vector<double> crossings;
  double prev = 0.0;
  for (int i = 0; i < static_cast<int>(12.0 * kFs); ++i) {
    const double t = i / kFs;
    rig.Step(raw);
    const double x = rig.last().x_m[0];
    if (t < release_s && t > release_s - 0.01) {
      static_x = x;
      static_counts = raw[4];
    }
    if (t > release_s + 0.01 && prev > 0.0 && x <= 0.0)
      crossings.push_back(t - 1.0 / kFs + prev / (prev - x) / kFs);
    prev = x;
  }
  // After 5 s of hold (ζ ≈ 0.031, decay time 0.7 s) the pull stretches spring 1 by F/k.
  EXPECT_NEAR(static_x, 20.0 / k, 20.0 / k * 1e-3);
  EXPECT_EQ(static_counts, static_cast<std::int32_t>(std::floor(static_x * 1e5)));  // 10 µm counts
  EXPECT_EQ(raw[5], 0);  // mass 2 is not on the rig
  ASSERT_GE(crossings.size(), 20u);
  const double period =
      (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  EXPECT_NEAR(period, 2.0 * std::numbers::pi / omega_d, 1e-5 * period);
}

TEST(Rig, FirstSampleOfAHitAcceleratesTheMassAtFOverM) {
  RigSimulator rig(QuietRig(), 3);
  rig.Select(Parse("hammer", {2, 100, 1, 2}));  // mass 2 alone
  rig.Start(1.0 / kFs);
  const double m = 1.53;
  std::array<std::int32_t, wire::kChannelCount> raw{};
  for (int i = 0; i < static_cast<int>(kFs); ++i) {
    rig.Step(raw);
    if (rig.last().force_n > 0.0) break;
  }
  const auto& v = rig.last();
  ASSERT_GT(v.force_n, 0.0);
  // The accelerometer is read tau = 56 / 21 MHz after the edge (board_profile.hpp, in whole ns:
  // 2667 ns; the 0.33 ns of rounding alone would be 8e-10 of F/m here), when the
  // mass has just started to move. m a'' = -c a' - k a from rest under a step F gives
  // a(tau) = F/m (1 - (c/m) tau + ((c/m)^2 - k/m) tau^2 / 2 + O(tau^3)); the tau^3 term is
  // ~1e-13 of F/m here (mass 2 alone: k2 = 2760 N/m, c2 = 3.5 N s/m).
  const double tau = 2667e-9, k = 2760.0, c = 3.5;
  const double expected =
      v.force_n / m * (1.0 - c / m * tau + (c * c / (m * m) - k / m) * tau * tau / 2.0);
  EXPECT_NEAR(v.a_m_s2[1], expected, 1e-11 * v.force_n / m);
  EXPECT_GT(v.force_n / m - v.a_m_s2[1], 0.5 * c / m * tau * v.force_n / m);  // not at the edge
  EXPECT_EQ(raw[0], rig.spec().load_cells[0].Code(v.force_n));
  EXPECT_EQ(raw[3], rig.spec().accelerometers[1].Code(v.a_m_s2[1]));
  EXPECT_EQ(raw[2], 2048);  // mass 1 absent: accelerometer 1 reads zero
}

// The phase a common tone shows between two channels: arg of X_b / X_a at the tone's line, from
// a DFT over a whole number of cycles.
double TonePhase(const std::vector<double>& a, const std::vector<double>& b, double f_hz,
                 double fs_hz) {
  std::complex<double> xa, xb;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::complex<double> w =
        std::polar(1.0, -2.0 * std::numbers::pi * f_hz * static_cast<double>(i) / fs_hz);
    xa += a[i] * w;
    xb += b[i] * w;
  }
  return std::arg(xb / xa);
}

TEST(Rig, ToneOnTheConvertersShowsEachChannelsSamplingInstant) {
  // A 2437 Hz tone on the four converter inputs, sampled at 10 kHz for 1 s (2437 whole cycles,
  // its samples spread over the sine so the quantization averages out), with the rig's own
  // converter noise. Each channel converts it at its instant after the edge: force1, acc1, acc2
  // at 56 ADC clocks, force2 at 56 + 68 (RM0090 §13.5: sampling + 12 clocks per conversion;
  // 21 MHz ADC clock). force2 sees the tone 68 clocks later, so its phase is ahead of acc1's by
  // 2 pi f 68 / 21 MHz = 0.049583 rad (2.841 deg); the instants travel as whole ns (3238 ns:
  // 0.049581 rad). The hammer channels (force1, acc1, acc2) agree to the noise.
  const double fs = 10000.0, f = 2437.0;
  RigSimulator rig(DefaultRig(), 9);
  rig.Select(Parse("tone", {static_cast<float>(f), 0.9f, 0, 0}));
  rig.Start(1.0 / fs);
  std::array<std::vector<double>, 4> x;
  std::array<std::int32_t, wire::kChannelCount> raw{};
  for (int i = 0; i < static_cast<int>(fs); ++i) {
    rig.Step(raw);
    for (std::size_t c = 0; c < 4; ++c) x[c].push_back(raw[c] - 2048.0);
  }
  // Quantization (0.29 code rms) and noise (at most 0.5 code rms) against a 1843-code amplitude
  // over 10000 samples: a phase error of about 5e-6 rad rms. 3e-5 rad is 1.9 ns of instant.
  const double tolerance = 3e-5;
  const double expected = 2.0 * std::numbers::pi * f * 68.0 / 21e6;
  const double force2_vs_acc1 = TonePhase(x[2], x[1], f, fs);  // arg(force2 / acc1)
  EXPECT_NEAR(force2_vs_acc1, expected, tolerance);
  EXPECT_NEAR(TonePhase(x[0], x[1], f, fs), expected, tolerance);  // force2 against force1
  EXPECT_NEAR(TonePhase(x[0], x[2], f, fs), 0.0, tolerance);       // force1 and acc1
  EXPECT_NEAR(TonePhase(x[0], x[3], f, fs), 0.0, tolerance);       // force1 and acc2
  std::printf(
      "tone %.0f Hz: force2 - acc1 %.6f rad (expected %.6f), acc1 - force1 %.2e rad, "
      "acc2 - force1 %.2e rad\n",
      f, force2_vs_acc1, expected, TonePhase(x[0], x[2], f, fs), TonePhase(x[0], x[3], f, fs));
  // The encoders see the rig at rest.
  EXPECT_EQ(raw[4], 0);
  EXPECT_EQ(raw[5], 0);
}

TEST(Rig, ToneParameters) {
  const Scenario s = Parse("tone", {0, 0, 0, 0});
  EXPECT_EQ(s.kind, ScenarioKind::kTone);
  EXPECT_EQ(s.frequency_hz, 1000.0);
  EXPECT_EQ(s.amplitude, 0.5);
  wire::ScenarioRequest r;
  std::snprintf(r.name.data(), r.name.size(), "tone");
  Scenario out;
  r.params = {1000, 1.5f, 0, 0};  // beyond the converters' range
  EXPECT_EQ(ParseScenario(r, 2, out), Status::kInvalidArgument);
  r.params = {1000, 0.5f, 1, 0};
  EXPECT_EQ(ParseScenario(r, 2, out), Status::kInvalidArgument);
}

TEST(Rig, ConverterCodes) {
  const AnalogSensor s{500.0, 0.0, 12};  // ±500 N on a 12-bit converter: 500/2048 N per code
  EXPECT_EQ(s.Code(0.0), 2048);
  EXPECT_EQ(s.Code(500.0 / 2048.0), 2049);
  EXPECT_EQ(s.Code(-500.0 / 2048.0), 2047);
  EXPECT_EQ(s.Code(499.0), 4092);  // round(499/500 · 2048) + 2048 = 2044 + 2048
  EXPECT_EQ(s.Code(1e6), 4095);    // clipped at the top code
  EXPECT_EQ(s.Code(-1e6), 0);
  EXPECT_DOUBLE_EQ(s.Value(2049), 500.0 / 2048.0);
}

TEST(Rig, HammerPulsesAreHalfSinesWithDoubleHits) {
  RigSimulator rig(QuietRig(), 11);
  rig.Select(Parse("hammer", {2, 100, 0.5f, 0}));
  rig.Start(1.0 / kFs);
  std::array<std::int32_t, wire::kChannelCount> raw{};
  std::vector<double> impulses, starts;
  double impulse = 0.0, start = 0.0;
  bool in_pulse = false;
  for (int i = 0; i < static_cast<int>(120.0 * kFs); ++i) {
    rig.Step(raw);
    const double f = rig.last().force_n;
    if (f > 0.0 && !in_pulse) {
      in_pulse = true;
      start = i / kFs;
      impulse = 0.0;
    }
    if (in_pulse) impulse += f / kFs;
    if (f == 0.0 && in_pulse) {
      in_pulse = false;
      impulses.push_back(impulse);
      starts.push_back(start);
    }
  }
  ASSERT_GT(starts.size(), 150u);
  EXPECT_NEAR(starts.front(), 0.5, 1.0 / kFs);  // quiet lead-in for a pre-trigger
  int doubles = 0;
  for (std::size_t i = 0; i < impulses.size(); ++i) {
    const bool rebound = i > 0 && starts[i] - starts[i - 1] < 0.015;
    doubles += rebound ? 1 : 0;
    // Half-sine of height h and width T: impulse 2hT/π, h in [0.6, 1.4] × 100 N (rebounds 20–40 %
    // of the hit before them), T = 2 ms; the midpoint sampling is exact to O((π/10)²/24).
    const double lo = (rebound ? 0.2 * 0.6 : 0.6) * 100.0 * 0.002 * 2.0 / std::numbers::pi;
    const double hi = (rebound ? 0.4 * 1.4 : 1.4) * 100.0 * 0.002 * 2.0 / std::numbers::pi;
    EXPECT_GT(impulses[i], lo * 0.99) << i;
    EXPECT_LT(impulses[i], hi * 1.01) << i;
  }
  EXPECT_GT(doubles, 0);
  EXPECT_LT(doubles, static_cast<int>(impulses.size()) / 4);
}

// A rig file's test hits: hit 1 struck twice (a second blow 15 ms after its start, 60 % of its
// height), hit 2 a blow of twice the load cell's range (1000 N), which its converter holds at its
// top code while the blow exceeds the range, as the board's converter does; every later hit as
// on the same rig without test hits (the random stream is the same).
TEST(Rig, TestHitsStrikeTwiceAndOverloadTheConverter) {
  RigSpec spec = QuietRig();
  spec.double_hits = {1};
  spec.overloads = {2};
  RigSimulator rig(spec, 11);
  RigSimulator plain(QuietRig(), 11);
  rig.Select(Parse("hammer", {2, 100, 0.5f, 0}));
  plain.Select(Parse("hammer", {2, 100, 0.5f, 0}));
  rig.Start(1.0 / kFs);
  plain.Start(1.0 / kFs);
  std::array<std::int32_t, wire::kChannelCount> raw{}, raw_plain{};
  const std::int32_t top = spec.load_cells[0].Code(1e9);
  std::vector<double> starts, peaks;
  bool in_pulse = false;
  int top_run = 0, longest_top_run = 0;
  bool later_hits_same = true;
  for (int i = 0; i < static_cast<int>(20.0 * kFs); ++i) {
    rig.Step(raw);
    plain.Step(raw_plain);
    const double f = rig.last().force_n;
    if (f > 0.0 && !in_pulse) {
      starts.push_back(i / kFs);
      peaks.push_back(0.0);
    }
    in_pulse = f > 0.0;
    if (in_pulse) peaks.back() = std::max(peaks.back(), f);
    top_run = raw[0] == top ? top_run + 1 : 0;
    longest_top_run = std::max(longest_top_run, top_run);
    // From the third hit on (the first two and their pulses are over by 1.8 s: spacing >= 0.35 s).
    if (starts.size() >= 4 && i / kFs > starts[3])
      later_hits_same = later_hits_same && f == plain.last().force_n;
  }
  ASSERT_GE(starts.size(), 6u);
  EXPECT_NEAR(starts[0], 0.5, 1.0 / kFs);
  EXPECT_NEAR(starts[1] - starts[0], 0.015, 1.0 / kFs);  // the second blow
  // Half-sines sampled at mid-sample: the peaks' ratio is the heights' (60 %) within a sample's
  // curvature, (pi / 10)^2 / 8 of the peak for a 2 ms pulse at 5 kHz.
  EXPECT_NEAR(peaks[1] / peaks[0], 0.6, 0.6 * 0.013);
  EXPECT_NEAR(peaks[2], 2.0 * spec.load_cells[0].range, 0.013 * 1000.0);
  // Above 500 N for the middle 2/3 of the 2 ms pulse (asin(0.5) = pi/6 each side): 6 samples.
  EXPECT_GE(longest_top_run, 6);
  EXPECT_LE(longest_top_run, 7);
  EXPECT_TRUE(later_hits_same);
}

TEST(Rig, ShakerSineAndHandPush) {
  RigSimulator rig(QuietRig(), 5);
  rig.Select(Parse("shaker", {16, 10, 8, 0}));
  rig.Start(1.0 / kFs);
  std::array<std::int32_t, wire::kChannelCount> raw{};
  int crossings = 0;
  double prev_f = 0.0, peak = 0.0, prev_push = 0.0, max_slope = 0.0, max_push = 0.0, min_push = 1e9;
  for (int i = 0; i < static_cast<int>(10.0 * kFs); ++i) {
    rig.Step(raw);
    const double f = rig.last().force_n;
    const double p = rig.last().push_n;
    if (i > 0 && prev_f < 0.0 && f >= 0.0) ++crossings;
    peak = std::max(peak, f);
    if (i > 0) max_slope = std::max(max_slope, std::abs(p - prev_push) * kFs);
    max_push = std::max(max_push, p);
    min_push = std::min(min_push, p);
    prev_f = f;
    prev_push = p;
  }
  EXPECT_EQ(crossings, 159);  // 16 Hz over 10 s from sin(0): upward crossings at 1/16 … 159/16 s
  EXPECT_NEAR(peak, 10.0, 10.0 * (1.0 - std::cos(2.0 * std::numbers::pi * 16.0 / kFs)));
  // One-sided push within [0, A]; its four tones lie in 0.2–2 Hz, so |dp/dt| ≤ A(π·2 + π/2)
  // (tones: A/2 · mean of 2πf ≤ 2πA; fade-in over 1 s: ≤ πA/2).
  EXPECT_GE(min_push, 0.0);
  EXPECT_LE(max_push, 8.0);
  EXPECT_GT(max_push, 2.0);
  EXPECT_LE(max_slope, 8.0 * (2.0 * std::numbers::pi + std::numbers::pi / 2.0));
}

TEST(Rig, SameSeedSameSamples) {
  auto run = [](std::uint64_t seed, int acquisitions) {
    RigSimulator rig(DefaultRig(), seed);
    rig.Select(Parse("hammer", {2, 100, 0.3f, 0}));
    std::vector<std::int32_t> out;
    std::array<std::int32_t, wire::kChannelCount> raw{};
    for (int a = 0; a < acquisitions; ++a) {
      rig.Start(1.0 / kFs);
      out.clear();
      for (int i = 0; i < 20000; ++i) {
        rig.Step(raw);
        out.insert(out.end(), raw.begin(), raw.end());
      }
    }
    return out;
  };
  EXPECT_EQ(run(42, 1), run(42, 1));
  EXPECT_EQ(run(42, 2), run(42, 2));
  EXPECT_NE(run(42, 1), run(43, 1));
  EXPECT_NE(run(42, 1), run(42, 2));  // each acquisition draws new hits and noise
}

TEST(Scenario, ParametersAndRefusals) {
  Scenario s = Parse("hammer", {0, 0, 0, 0});
  EXPECT_EQ(s.kind, ScenarioKind::kHammer);
  EXPECT_EQ(s.mass, 1);  // default: the last mass, m2
  EXPECT_DOUBLE_EQ(s.force_n, 100.0);
  EXPECT_DOUBLE_EQ(s.spacing_s, 0.0);  // left to the rig (HammerSpacingFollowsTheRig)
  s = Parse("hammer", {0, 0, 0, 1});
  EXPECT_EQ(s.configuration, Configuration::kMass1Alone);
  EXPECT_EQ(s.mass, 0);
  s = Parse("shaker", {0, 0, 0, 0});
  EXPECT_DOUBLE_EQ(s.frequency_hz, 16.0);
  EXPECT_DOUBLE_EQ(s.push_n, 0.0);
  s = Parse("step", {1, 30, 2, 0});
  EXPECT_DOUBLE_EQ(s.hold_s, 2.0);
  EXPECT_EQ(Parse("idle", {}).kind, ScenarioKind::kIdle);

  auto refused = [](const char* name, std::array<float, 4> p, int dofs = 2) {
    wire::ScenarioRequest r;
    std::snprintf(r.name.data(), r.name.size(), "%s", name);
    r.params = p;
    Scenario out;
    return ParseScenario(r, dofs, out) == Status::kInvalidArgument;
  };
  EXPECT_TRUE(refused("tornado", {}));
  EXPECT_TRUE(refused("hammer", {3, 0, 0, 0}));
  EXPECT_TRUE(refused("hammer", {1, 0, 0, 2}));     // mass 1 is not on the rig when m2 is alone
  EXPECT_TRUE(refused("hammer", {0, 0, 0, 2}, 1));  // a 1-DOF rig has no mass 2
  EXPECT_TRUE(refused("hammer", {1.5f, 0, 0, 0}));
  EXPECT_TRUE(refused("hammer", {0, -5, 0, 0}));
  EXPECT_TRUE(refused("hammer", {0, 0, 0.01f, 0}));
  EXPECT_TRUE(refused("shaker", {0, std::nanf(""), 0, 0}));
  EXPECT_TRUE(refused("push", {5, 1, 0, 0}));
}

// The default spacing lets the slowest mode ring down to 1 % in the shortest spacing. Reference
// by hand: the built-in chain (m 1.82, 1.53 kg; k 3520, 2760 N/m; c 5, 3.5 N s/m) has its slower
// decay in mode 1, -Re(lambda) = zeta omega = 0.019167 x 27.9227 = 0.53519 1/s (`vibid modal` of
// `vibid-emu --print-truth`): ln 100 / 0.53519 = 8.605 s, / 0.7 = 12.29 s, up to 12.5 s. Mass 1
// alone: zeta omega = c / (2 m) = 5 / 3.64 = 1.3736 1/s: 3.353 s, / 0.7 = 4.79 s, up to 5 s.
TEST(Scenario, HammerSpacingFollowsTheRig) {
  RigSimulator rig(DefaultRig(), 1);
  rig.Select(Parse("hammer", {0, 0, 0, 0}));
  EXPECT_DOUBLE_EQ(rig.scenario().spacing_s, 12.5);
  rig.Select(Parse("hammer", {0, 0, 0, 1}));
  EXPECT_DOUBLE_EQ(rig.scenario().spacing_s, 5.0);
  rig.Select(Parse("hammer", {0, 0, 2, 0}));  // given: kept
  EXPECT_DOUBLE_EQ(rig.scenario().spacing_s, 2.0);
}

TEST(RigFile, ShippedFiles) {
  // rigs/default.json is the built-in rig written out: the README documents the schema with it.
  const RigSpec file = LoadRig(std::string(VIBID_SOURCE_DIR) + "/host/emulator/rigs/default.json");
  EXPECT_EQ(RigToJson(file), RigToJson(DefaultRig()));
  // rigs/cart_1dof.json: the ECP cart with spring Khigh as its lab published it
  // (../shared/data/README.md: k = 712.60 N/m, m_c = 0.5848 kg, ζ = 0.0179 unloaded).
  const RigSpec cart =
      LoadRig(std::string(VIBID_SOURCE_DIR) + "/host/emulator/rigs/cart_1dof.json");
  ASSERT_EQ(cart.dofs(), 1);
  const double zeta =
      cart.dampers_ns_per_m[0] / (2.0 * std::sqrt(cart.springs_n_per_m[0] * cart.masses_kg[0]));
  EXPECT_NEAR(zeta, 0.0179, 0.0005);
  RigSimulator rig(cart, 1);
  rig.Select(Parse("hammer", {0, 0, 0, 0}, 1));
  rig.Start(1.0 / kFs);
  std::array<std::int32_t, wire::kChannelCount> raw{};
  for (int i = 0; i < 5000; ++i) rig.Step(raw);
  EXPECT_EQ(raw[5], 0);  // no second mass: encoder 2 never moves
}

TEST(RigFile, TestHitsRoundTripAndRefusals) {
  nlohmann::json j = RigToJson(DefaultRig());
  EXPECT_FALSE(j.contains("hammer_test_hits"));  // a rig without them writes none
  j["hammer_test_hits"] = {{"double_hit", {3}}, {"overload", {5, 7}}};
  const RigSpec r = RigFromJson(j, "rig.json");
  EXPECT_EQ(r.double_hits, std::vector<int>{3});
  EXPECT_EQ(r.overloads, (std::vector<int>{5, 7}));
  EXPECT_EQ(RigToJson(r), j);
  const auto message = [](const nlohmann::json& bad) {
    return InputErrorOf([&] { RigFromJson(bad, "rig.json"); }, "accepted");
  };
  j["hammer_test_hits"] = {{"double_hits", {3}}};
  EXPECT_NE(message(j).find("unknown key 'double_hits'"), std::string::npos) << message(j);
  j["hammer_test_hits"] = {{"overload", {0}}};
  EXPECT_NE(message(j).find("hit numbers from 1"), std::string::npos) << message(j);
  j["hammer_test_hits"] = {{"overload", 5}};
  EXPECT_NE(message(j).find("list of hit numbers"), std::string::npos) << message(j);
}

TEST(RigFile, RoundTripAndClearErrors) {
  const RigSpec r = RigFromJson(RigToJson(DefaultRig()));
  EXPECT_EQ(r.masses_kg, DefaultRig().masses_kg);
  EXPECT_EQ(r.accelerometers[1].adc_bits, 12);
  EXPECT_DOUBLE_EQ(r.encoder_counts_per_m, 1e5);

  auto message = [](const nlohmann::json& j) {
    return InputErrorOf([&] { RigFromJson(j, "rig.json"); }, "accepted");
  };
  nlohmann::json j = RigToJson(DefaultRig());
  j.erase("springs_n_per_m");
  EXPECT_EQ(message(j), "rig.json: missing \"springs_n_per_m\"");
  j = RigToJson(DefaultRig());
  j["masses_kg"] = {1.0, 1.0, 1.0, 1.0, 1.0};
  EXPECT_EQ(message(j),
            "rig.json: the rig has 1 to 4 masses (the board has four response inputs, acc1, acc2, "
            "x1, x2, and each mass needs one)");
  j = RigToJson(DefaultRig());
  j["springs_n_per_m"] = {1000.0, -1.0};
  EXPECT_EQ(message(j), "rig.json: \"springs_n_per_m\" values must be > 0");
  j = RigToJson(DefaultRig());
  j["load_cells"][1]["adc_bits"] = 40;
  EXPECT_EQ(message(j),
            "rig.json load_cells[1]: \"adc_bits\" is 40, but the board's converters have 12 bits: "
            "write 12 (a finer sensor is quantized by the board's ADC)");
  j = RigToJson(DefaultRig());
  j["topology"] = "cart";
  EXPECT_NE(message(j).find("\"topology\" must be \"chain\""), std::string::npos);
  // A misspelt key is refused, not left at a default, at either level.
  j = RigToJson(DefaultRig());
  j["damper_ns_per_m"] = j["dampers_ns_per_m"];
  j.erase("dampers_ns_per_m");
  EXPECT_EQ(
      message(j),
      "unknown key 'damper_ns_per_m' in rig file rig.json (did you mean 'dampers_ns_per_m'?)");
  j = RigToJson(DefaultRig());
  j["accelerometers"][0]["noise_n"] = 0.1;
  EXPECT_EQ(message(j),
            "unknown key 'noise_n' in rig file rig.json accelerometers[0] (valid keys: "
            "range_m_s2, noise_m_s2, adc_bits)");
  // The option bytes' brown-out level: level 3 unless the file says, and only a BOR_LEV name.
  EXPECT_EQ(DefaultRig().brown_out, wire::BrownOut::kLevel3);
  j = RigToJson(DefaultRig());
  j["brown_out_level"] = "off";
  EXPECT_EQ(RigFromJson(j).brown_out, wire::BrownOut::kOff);
  EXPECT_EQ(RigToJson(RigFromJson(j))["brown_out_level"], "off");
  j["brown_out_level"] = "level4";
  EXPECT_EQ(message(j),
            "rig.json: \"brown_out_level\" must be \"level3\", \"level2\", \"level1\" or \"off\" "
            "(the option bytes' BOR_LEV)");
}

// The emulator never does what the board cannot: a converter other than the board's 12-bit ADC
// (kBoardProfile) or a rate beyond its fastest is refused, naming the value and the way out.
TEST(RigFile, PartsTheBoardCannotHaveAreRefused) {
  auto message = [](const nlohmann::json& j) {
    return InputErrorOf([&] { RigFromJson(j, "rig.json"); }, "accepted");
  };
  for (const int bits : {8, 11, 13, 16, 24}) {
    nlohmann::json j = RigToJson(DefaultRig());
    j["accelerometers"][0]["adc_bits"] = bits;
    EXPECT_EQ(message(j), "rig.json accelerometers[0]: \"adc_bits\" is " + std::to_string(bits) +
                              ", but the board's converters have 12 bits: write 12 (a finer "
                              "sensor is quantized by the board's ADC)");
  }
  nlohmann::json j = RigToJson(DefaultRig());
  j["max_sample_rate_hz"] = 20000.0;
  EXPECT_EQ(message(j),
            "rig.json: \"max_sample_rate_hz\" is 20000 Hz, but the board samples at 10000 Hz at "
            "most: write 10000 Hz or less");
  j["max_sample_rate_hz"] = 10000.0;  // the board's own limit (board_profile.hpp: 100 us)
  EXPECT_NO_THROW(RigFromJson(j, "rig.json"));
}

// Every rig file shipped in rigs/ loads: each is a board the emulator can be.
TEST(RigFile, EveryShippedRigIsValid) {
  int files = 0;
  for (const auto& e :
       std::filesystem::directory_iterator(std::string(VIBID_SOURCE_DIR) + "/host/emulator/rigs")) {
    if (e.path().extension() != ".json") continue;
    ++files;
    RigSpec r;
    EXPECT_NO_THROW(r = LoadRig(e.path().string())) << e.path();
    for (const AnalogSensor& s : r.load_cells) EXPECT_EQ(s.adc_bits, 12) << e.path();
    for (const AnalogSensor& s : r.accelerometers) EXPECT_EQ(s.adc_bits, 12) << e.path();
  }
  EXPECT_GE(files, 4);  // default.json, cart_1dof.json, chain3.json and chain4.json at least
}

// A chain of n equal masses m on equal springs k from ground (fixed-free) has the closed-form
// modes theta_r = (2r - 1) pi / (2n + 1), omega_r = 2 sqrt(k/m) sin(theta_r / 2), shapes
// phi_r(i) = sin(i theta_r), i = 1..n (e.g. Rao, Mechanical Vibrations, the lumped string with a
// free end; n = 2 gives omega^2 = (3 -+ sqrt 5)/2 k/m). Closed form, not the model library.
struct UniformChain {
  int n;
  double m_kg, k_n_per_m;
  double theta(int r) const { return (2.0 * r - 1.0) * std::numbers::pi / (2.0 * n + 1.0); }
  double omega(int r) const { return 2.0 * std::sqrt(k_n_per_m / m_kg) * std::sin(theta(r) / 2); }
  double shape(int r, int i) const { return std::sin(i * theta(r)); }  // i from 1
};

// Selects a scenario as the wire's select-scenario does (against the rig: its hammer_mass).
void Select(RigSimulator& rig, const char* name, std::array<float, 4> params) {
  wire::ScenarioRequest r;
  std::snprintf(r.name.data(), r.name.size(), "%s", name);
  r.params = params;
  wire::Refusal why{};
  ASSERT_EQ(rig.SelectScenario(r, why), Status::kOk) << name;
}

RigSpec UniformRig(const UniformChain& u, std::array<int, 4> input_mass, int hammer_mass) {
  RigSpec r = QuietRig();
  const auto n = static_cast<std::size_t>(u.n);
  r.masses_kg.assign(n, u.m_kg);
  r.effective_mass_loss.assign(n, 0.0);
  r.springs_n_per_m.assign(n, u.k_n_per_m);
  r.dampers_ns_per_m.assign(n, 0.0);  // undamped: each modal coordinate rings as a pure sine
  r.coulomb_n.assign(n, 0.0);
  r.input_mass = input_mass;
  r.hammer_mass = hammer_mass;
  return r;
}

// The emulated 3- and 4-mass chains ring at the closed-form frequencies in the closed-form
// shapes: after the hammer's blow (on an inner mass, chosen by the rig's hammer_mass), each
// modal coordinate q_r = phi_r^T M x of the simulated positions is a pure sampled sine, so
// q[k+1] + q[k-1] = 2 cos(omega_r dt) q[k] holds to rounding (a frequency 1e-6 off leaves a
// residual of 2 sin(omega dt) omega dt 1e-6, about 1e-8 of the amplitude here; the bound is
// 1e-9). The model library's modal frequencies of the rig's truth agree with the closed form too.
TEST(Rig, ThreeAndFourMassChainsRingAtTheClosedFormModes) {
  for (const int n : {3, 4}) {
    const UniformChain u{n, 0.8, 2500.0};
    const int hit = 1;  // 0-based: mass 2
    RigSimulator rig(UniformRig(u, {0, 1, 2, n - 1}, hit), 7);
    Select(rig, "hammer", {0, 100, 30, 0});
    ASSERT_EQ(rig.scenario().mass, hit);
    const model::ModalResult modes = model::Modal(rig.spec().Truth());
    for (int r = 1; r <= n; ++r)
      EXPECT_NEAR(modes.omega_rad_s[r - 1], u.omega(r), 1e-9 * u.omega(r)) << n << " mode " << r;
    rig.Start(1.0 / kFs);
    std::array<std::int32_t, wire::kChannelCount> raw{};
    std::vector<std::array<double, kMaxMasses>> x;
    bool hit_checked = false;
    for (int i = 0; i < static_cast<int>(3.0 * kFs); ++i) {
      rig.Step(raw);
      const auto& v = rig.last();
      if (v.force_n > 0.0 && !hit_checked) {
        // The blow's first sample: the hit mass alone accelerates (F/m, less the springs'
        // reaction over the 2.667 us since the edge), its neighbours not yet.
        hit_checked = true;
        for (int mass = 0; mass < n; ++mass) {
          const double expected = mass == hit ? v.force_n / u.m_kg : 0.0;
          EXPECT_NEAR(v.a_m_s2[static_cast<std::size_t>(mass)], expected, 1e-6 * v.force_n / u.m_kg)
              << n << " masses, mass " << mass + 1;
        }
      }
      if (i / kFs > 0.55) x.push_back(v.x_m);  // after the first blow (0.5 s + 2 ms)
    }
    ASSERT_TRUE(hit_checked);
    for (int r = 1; r <= n; ++r) {
      double norm = 0.0;
      for (int i = 1; i <= n; ++i) norm += u.m_kg * u.shape(r, i) * u.shape(r, i);
      std::vector<double> q;
      for (const auto& xs : x) {
        double s = 0.0;
        for (int i = 1; i <= n; ++i)
          s += u.m_kg * u.shape(r, i) * xs[static_cast<std::size_t>(i - 1)];
        q.push_back(s / norm);
      }
      const double c = 2.0 * std::cos(u.omega(r) / kFs);
      double amplitude = 0.0, residual = 0.0;
      for (std::size_t k = 1; k + 1 < q.size(); ++k) {
        amplitude = std::max(amplitude, std::abs(q[k]));
        residual = std::max(residual, std::abs(q[k + 1] + q[k - 1] - c * q[k]));
      }
      EXPECT_GT(amplitude, 1e-5) << n << " masses: mode " << r << " is excited";
      EXPECT_LT(residual, 1e-9 * amplitude) << n << " masses, mode " << r;
    }
  }
}

// Each response input reads the mass the rig file mounts it on, accelerations and encoder
// displacements mixed; an unmounted input reads the rig at rest.
TEST(Rig, EachResponseInputReadsItsMass) {
  const UniformChain u{4, 1.0, 3000.0};
  RigSpec spec = UniformRig(u, {0, 2, 1, 3}, 3);  // acc1 m1, acc2 m3, x1 m2, x2 m4
  spec.coulomb_n.assign(4, 0.003);                // friction per mass changes nothing here
  RigSimulator rig(spec, 2);
  Select(rig, "hammer", {0, 100, 0, 0});
  EXPECT_EQ(rig.scenario().mass, 3);  // the rig's hammer_mass
  rig.Start(1.0 / kFs);
  std::array<std::int32_t, wire::kChannelCount> raw{};
  int moving = 0;
  for (int i = 0; i < static_cast<int>(2.0 * kFs); ++i) {
    rig.Step(raw);
    const auto& v = rig.last();
    EXPECT_EQ(raw[2], spec.accelerometers[0].Code(v.a_m_s2[0]));
    EXPECT_EQ(raw[3], spec.accelerometers[1].Code(v.a_m_s2[2]));
    EXPECT_EQ(raw[4], static_cast<std::int32_t>(std::floor(v.x_m[1] * 1e5)));
    EXPECT_EQ(raw[5], static_cast<std::int32_t>(std::floor(v.x_m[3] * 1e5)));
    moving += raw[4] != 0 && raw[5] != 0 ? 1 : 0;
  }
  EXPECT_GT(moving, 1000);

  spec.input_mass = {0, kUnmounted, 1, kUnmounted};
  spec.masses_kg.resize(2);
  spec.effective_mass_loss.resize(2);
  spec.springs_n_per_m.resize(2);
  spec.dampers_ns_per_m.resize(2);
  spec.coulomb_n.resize(2);
  spec.hammer_mass = 0;
  RigSimulator two(spec, 2);
  Select(two, "hammer", {0, 100, 0, 0});
  two.Start(1.0 / kFs);
  for (int i = 0; i < static_cast<int>(1.0 * kFs); ++i) {
    two.Step(raw);
    EXPECT_EQ(raw[3], 2048);  // acc2 on no mass: mid code (no noise here)
    EXPECT_EQ(raw[5], 0);
  }
}

// Mass k of a 3-mass rig alone on spring k (configuration k): its own 1-DOF frequency.
TEST(Rig, AnyMassAloneOnItsSpring) {
  RigSimulator rig(LoadRig(std::string(VIBID_SOURCE_DIR) + "/host/emulator/rigs/chain3.json"), 4);
  Select(rig, "hammer", {0, 0, 0, 3});
  EXPECT_EQ(rig.scenario().mass, 2);
  const model::Model alone = rig.ActiveModel();
  ASSERT_EQ(alone.dofs(), 1);
  EXPECT_DOUBLE_EQ(alone.m_kg(0, 0), 0.9);
  EXPECT_DOUBLE_EQ(alone.k_n_per_m(0, 0), 2100.0);
}

TEST(Scenario, MassesAndConfigurationsOfLargerChains) {
  const auto refused = [](std::array<float, 4> p, int dofs) {
    wire::ScenarioRequest r;
    std::snprintf(r.name.data(), r.name.size(), "hammer");
    r.params = p;
    Scenario out;
    wire::Refusal why{};
    const bool bad = ParseScenario(r, dofs, out, &why) == Status::kInvalidArgument;
    return bad ? static_cast<int>(why.detail) : -1;
  };
  EXPECT_EQ(Parse("hammer", {4, 0, 0, 0}, 4).mass, 3);
  EXPECT_EQ(Parse("hammer", {0, 0, 0, 0}, 4).mass, 3);  // the last mass
  EXPECT_EQ(Parse("hammer", {0, 0, 0, 4}, 4).configuration, Configuration::kMass4Alone);
  EXPECT_EQ(Parse("step", {3, 0, 0, 0}, 3).mass, 2);
  EXPECT_EQ(refused({5, 0, 0, 0}, 4), 0);  // no mass 5
  EXPECT_EQ(refused({4, 0, 0, 0}, 3), 0);
  EXPECT_EQ(refused({0, 0, 0, 4}, 3), 3);  // a 3-mass rig has no mass 4 to leave alone
  EXPECT_EQ(refused({2, 0, 0, 3}, 3), 0);  // mass 2 is not on the rig when mass 3 is alone
  // The rig file's hammer mass is the default, a given mass overrides it.
  wire::ScenarioRequest r;
  std::snprintf(r.name.data(), r.name.size(), "hammer");
  Scenario s;
  r.params = {0, 0, 0, 0};
  ASSERT_EQ(ParseScenario(r, 3, s, nullptr, 0), Status::kOk);
  EXPECT_EQ(s.mass, 0);
  r.params = {2, 0, 0, 0};
  ASSERT_EQ(ParseScenario(r, 3, s, nullptr, 0), Status::kOk);
  EXPECT_EQ(s.mass, 1);
}

TEST(RigFile, ResponseInputsAndHammerMass) {
  const std::string dir = std::string(VIBID_SOURCE_DIR) + "/host/emulator/rigs/";
  const RigSpec c3 = LoadRig(dir + "chain3.json");
  ASSERT_EQ(c3.dofs(), 3);
  EXPECT_EQ(c3.input_mass, (std::array<int, 4>{0, 1, 2, kUnmounted}));  // acc1, acc2, x1
  EXPECT_EQ(c3.hammer_mass, 2);
  const RigSpec c4 = LoadRig(dir + "chain4.json");
  ASSERT_EQ(c4.dofs(), 4);
  EXPECT_EQ(c4.input_mass, (std::array<int, 4>{0, 2, 1, 3}));  // acc1 m1, acc2 m3, x1 m2, x2 m4
  EXPECT_EQ(RigToJson(RigFromJson(RigToJson(c4))), RigToJson(c4));
  // Without the key, one or two masses carry acc<i> and x<i> on mass i.
  nlohmann::json j = RigToJson(DefaultRig());
  j.erase("response_inputs");
  EXPECT_EQ(RigFromJson(j).input_mass, (std::array<int, 4>{0, 1, 0, 1}));

  const auto message = [](const nlohmann::json& bad) {
    return InputErrorOf([&] { RigFromJson(bad, "rig.json"); }, "accepted");
  };
  j = RigToJson(c3);
  j.erase("response_inputs");
  EXPECT_EQ(message(j),
            "rig.json: a rig of 3 masses names the response input on each mass: "
            "\"response_inputs\": {\"acc1\": 1, \"acc2\": 2, \"x1\": 3, ...} (inputs acc1, "
            "acc2, x1, x2; masses from 1)");
  j["response_inputs"] = {{"acc1", 1}, {"acc2", 2}};
  EXPECT_EQ(message(j),
            "rig.json: \"response_inputs\": no input measures mass 3 (each mass needs one of "
            "acc1, acc2, x1, x2)");
  j["response_inputs"] = {{"acc1", 1}, {"acc2", 2}, {"x3", 3}};
  EXPECT_NE(message(j).find("unknown key 'x3'"), std::string::npos) << message(j);
  j["response_inputs"] = {{"acc1", 1}, {"acc2", 2}, {"x1", 4}};
  EXPECT_EQ(message(j),
            "rig.json: \"response_inputs\": \"x1\" must name a mass of the rig, 1 to 3");
  j["response_inputs"] = {{"acc1", 1}, {"acc2", 2}, {"x1", 3}};
  j["hammer_mass"] = 4;
  EXPECT_EQ(message(j), "rig.json: \"hammer_mass\" must be a mass of the rig, 1 to 3");
}

}  // namespace
}  // namespace vibid::emu
