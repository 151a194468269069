// The simulated rig against closed forms: 1-DOF free decay, static deflection, force to
// acceleration at the first sample of a hit, converter codes, excitation shapes, determinism.
#include "rig.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "scenario.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/testing/input_error.hpp"

namespace vibid::emu {
namespace {

constexpr double kFs = 5000.0;

RigSpec Quiet() {
  RigSpec r = DefaultRig();
  r.coulomb_n = {0.0, 0.0};
  for (auto& s : r.load_cells) s.noise_rms = 0.0;
  for (auto& s : r.accelerometers) s.noise_rms = 0.0;
  return r;
}

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
  RigSimulator rig(Quiet(), 1);
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
  RigSimulator rig(Quiet(), 3);
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
  // At rest, the sample's acceleration output is D u = F / m exactly (state-space D = M⁻¹).
  EXPECT_NEAR(v.a_m_s2[1], v.force_n / m, 1e-12 * v.force_n / m);
  EXPECT_EQ(raw[0], rig.spec().load_cells[0].Code(v.force_n));
  EXPECT_EQ(raw[3], rig.spec().accelerometers[1].Code(v.force_n / m));
  EXPECT_EQ(raw[2], 2048);  // mass 1 absent: accelerometer 1 reads zero
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
  RigSimulator rig(Quiet(), 11);
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

TEST(Rig, ShakerSineAndHandPush) {
  RigSimulator rig(Quiet(), 5);
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
  j["masses_kg"] = {1.0, 1.0, 1.0};
  EXPECT_EQ(message(j), "rig.json: the rig has 1 or 2 masses (the board has two accelerometers)");
  j = RigToJson(DefaultRig());
  j["springs_n_per_m"] = {1000.0, -1.0};
  EXPECT_EQ(message(j), "rig.json: \"springs_n_per_m\" values must be > 0");
  j = RigToJson(DefaultRig());
  j["load_cells"][1]["adc_bits"] = 40;
  EXPECT_EQ(message(j), "rig.json load_cells[1]: \"adc_bits\" must be 8..24");
  j = RigToJson(DefaultRig());
  j["topology"] = "cart";
  EXPECT_NE(message(j).find("\"topology\" must be \"chain\""), std::string::npos);
}

}  // namespace
}  // namespace vibid::emu
