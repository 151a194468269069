// A rig that changes while it runs (rig file "changes"): the modes before and after a mass step
// from the simulated free response against the model core's, drifts against their ramps,
// continuity across a step, determinism, the rig file's entries and refusals.
#include "rig_changes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <cstdio>
#include <numbers>
#include <string>

#include <Eigen/Dense>

#include "quiet_rig.hpp"
#include "rig.hpp"
#include "scenario.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/testing/input_error.hpp"
#include "vibid/model/modal.hpp"

namespace vibid::emu {
namespace {

constexpr double kFs = 5000.0;

void Select(RigSimulator& rig, const char* name, std::array<float, 4> params) {
  wire::ScenarioRequest r;
  std::snprintf(r.name.data(), r.name.size(), "%s", name);
  r.params = params;
  wire::Refusal why{};
  ASSERT_EQ(rig.SelectScenario(r, why), Status::kOk) << name;
}

RigChange MassStep(double at_s, int mass, double add_kg) {
  return RigChange{.at_s = at_s, .target = ChangeTarget::kMass, .index = mass, .add = add_kg};
}

// |lambda| of the modes of a free response: the sampled positions of a linear system with no
// input obey the recurrence of its discrete poles, x[k] = a1 x[k-d] + ... + a4 x[k-4d] for a
// 2-DOF chain (Prony's method, with every d-th sample so the poles z = exp(lambda d dt) stand
// apart from 1). The coefficients are fitted by least squares over every window that `use`
// accepts, in both masses' positions at once; the poles are the roots of the recurrence.
std::vector<double> FreeResponseModesHz(const std::vector<std::array<double, kMaxMasses>>& x,
                                        const std::vector<bool>& use, std::size_t d, double dt_s) {
  constexpr std::size_t kOrder = 4;
  std::vector<std::array<double, kOrder + 1>> rows;
  for (std::size_t k = kOrder * d; k < x.size(); ++k) {
    if (!use[k]) continue;
    for (std::size_t mass = 0; mass < 2; ++mass) {
      std::array<double, kOrder + 1> row{};
      for (std::size_t j = 0; j <= kOrder; ++j) row[j] = x[k - j * d][mass];
      rows.push_back(row);
    }
  }
  constexpr auto kCols = static_cast<Eigen::Index>(kOrder);
  Eigen::MatrixXd a(static_cast<Eigen::Index>(rows.size()), kCols);
  Eigen::VectorXd b(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t r = 0; r < rows.size(); ++r) {
    b(static_cast<Eigen::Index>(r)) = rows[r][0];
    for (Eigen::Index j = 0; j < kCols; ++j)
      a(static_cast<Eigen::Index>(r), j) = rows[r][static_cast<std::size_t>(j + 1)];
  }
  const Eigen::VectorXd coef = a.colPivHouseholderQr().solve(b);
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(kCols, kCols);
  companion.row(0) = coef.transpose();
  companion.bottomLeftCorner(kCols - 1, kCols - 1).setIdentity();
  const Eigen::VectorXcd z = companion.eigenvalues();
  std::vector<double> hz;
  for (Eigen::Index i = 0; i < z.size(); ++i) {
    if (z(i).imag() <= 0.0) continue;  // one of each conjugate pair
    hz.push_back(std::abs(std::log(z(i)) / (static_cast<double>(d) * dt_s)) /
                 (2.0 * std::numbers::pi));
  }
  std::sort(hz.begin(), hz.end());
  return hz;
}

// A weight of 0.08 kg put on mass 2 (1.53 kg: +5.2 %) at 30 s, the chain hit by the hammer
// every 6 s or so. The free responses between the hits before the step and after it give the
// modes by Prony's method (noise-free rig: the fit is exact to rounding); they are the model
// core's modes of TruthAt before and after. model::Modal gives the undamped frequencies, the
// free response |lambda|, which differ from them by a few parts in 1e6 at this light, not
// proportional damping (zeta 1.9 % and 4.4 %); ComplexModalDamping gives |lambda| itself. Measured:
// 4.444053 -> 4.362148 Hz and 10.646467 -> 10.573459 Hz, Modal 4.444042 -> 4.362138 Hz and
// 10.646492 -> 10.573484 Hz.
TEST(RigChanges, MassStepMovesTheModesToTheTruthAfterIt) {
  RigSpec spec = QuietRig();
  const double step_s = 30.0;
  spec.changes = {MassStep(step_s, 1, 0.08)};
  RigSimulator rig(spec, 3);
  Select(rig, "hammer", {1, 100, 6, 0});  // mass 1: both modes well excited
  rig.Start(1.0 / kFs);
  const auto ticks = static_cast<std::size_t>(60.0 * kFs);
  const auto step_tick = static_cast<std::size_t>(step_s * kFs);
  std::vector<std::array<double, kMaxMasses>> x;
  std::vector<bool> forced;
  std::array<std::int32_t, wire::kChannelCount> raw{};
  for (std::size_t k = 0; k < ticks; ++k) {
    rig.Step(raw);
    x.push_back(rig.last().x_m);
    forced.push_back(rig.last().force_n != 0.0);
  }
  // A window of samples k - 4d .. k is free when no force acts on any tick in it and it lies on
  // one side of the step.
  const std::size_t d = 25;  // 200 Hz: the modes at 0.14 and 0.34 rad a sample
  std::vector<bool> before(ticks, false), after(ticks, false);
  std::size_t last_forced = 0;
  for (std::size_t k = 0; k < ticks; ++k) {
    if (forced[k]) last_forced = k;
    const bool free = !forced[k] && k >= last_forced + 4 * d + 1 && last_forced > 0;
    before[k] = free && k < step_tick;
    after[k] = free && k >= step_tick + 4 * d;
  }
  const std::vector<double> fitted_before = FreeResponseModesHz(x, before, d, 1.0 / kFs);
  const std::vector<double> fitted_after = FreeResponseModesHz(x, after, d, 1.0 / kFs);
  ASSERT_EQ(fitted_before.size(), 2u);
  ASSERT_EQ(fitted_after.size(), 2u);
  const model::ModalResult truth_before = model::Modal(spec.TruthAt(step_s - 1e-3));
  const model::ModalResult truth_after = model::Modal(spec.TruthAt(step_s));
  const model::ComplexModes complex_after = model::ComplexModalDamping(spec.TruthAt(step_s));
  EXPECT_DOUBLE_EQ(spec.TruthAt(step_s).m_kg(1, 1), 1.53 + 0.08);
  for (int r = 0; r < 2; ++r) {
    const auto u = static_cast<std::size_t>(r);
    std::printf("mode %d: before %.6f Hz (Modal %.6f), after %.6f Hz (Modal %.6f, |lambda| %.6f)\n",
                r + 1, fitted_before[u], truth_before.freq_hz(r), fitted_after[u],
                truth_after.freq_hz(r), complex_after.omega_rad_s(r) / (2.0 * std::numbers::pi));
    // Against the undamped modes: 1e-5 (the damping's second-order part is 2.5e-6).
    EXPECT_NEAR(fitted_before[u], truth_before.freq_hz(r), 1e-5 * truth_before.freq_hz(r));
    EXPECT_NEAR(fitted_after[u], truth_after.freq_hz(r), 1e-5 * truth_after.freq_hz(r));
    // Against |lambda|: the rounding of the fit.
    EXPECT_NEAR(fitted_after[u] * 2.0 * std::numbers::pi, complex_after.omega_rad_s(r),
                1e-7 * complex_after.omega_rad_s(r));
    // The step moved each mode by far more than the tolerance: 1.8 % and 0.7 % lower.
    EXPECT_LT(fitted_after[u], fitted_before[u] * (1.0 - 3e-3));
  }
}

// A spring drift: k1 loses 200 N/m from 2 s over 5 s. TruthAt is the exact ramp (its end value
// from at_s + over_s on, linear between); the simulator holds it within 0.5 % of the drift's
// size (rebuilt every 1 % of the 5 s: 50 ticks at 1 kHz, 101 systems in all).
TEST(RigChanges, DriftIsLinearAndReachesItsEndValue) {
  RigSpec spec = QuietRig();
  spec.changes = {RigChange{
      .at_s = 2.0, .target = ChangeTarget::kSpring, .index = 0, .add = -200.0, .over_s = 5.0}};
  const auto k1 = [](const model::Model& m) { return m.k_n_per_m(0, 0) - m.k_n_per_m(1, 1); };
  EXPECT_DOUBLE_EQ(k1(spec.TruthAt(0.0)), 3520.0);
  EXPECT_DOUBLE_EQ(k1(spec.TruthAt(2.0)), 3520.0);
  EXPECT_DOUBLE_EQ(k1(spec.TruthAt(4.5)), 3420.0);  // half way
  EXPECT_DOUBLE_EQ(k1(spec.TruthAt(7.0)), 3320.0);  // at_s + over_s: the end value
  EXPECT_DOUBLE_EQ(k1(spec.TruthAt(1e4)), 3320.0);  // and after
  for (double t = 2.0; t <= 7.0; t += 0.25) {
    EXPECT_NEAR(k1(spec.TruthAt(t)), 3520.0 - 40.0 * (t - 2.0), 1e-9) << t;
  }

  const double fs = 1000.0;
  RigSimulator rig(spec, 1);
  Select(rig, "push", {5, 0, 0, 0});
  rig.Start(1.0 / fs);
  std::array<std::int32_t, wire::kChannelCount> raw{};
  double worst = 0.0, previous = -1.0;
  int systems = 0;
  for (int k = 0; k < static_cast<int>(9.0 * fs); ++k) {
    rig.Step(raw);
    const double held = k1(rig.HeldModel());
    if (held != previous) ++systems;
    previous = held;
    const double t = k / fs;
    worst = std::max(worst, std::abs(held - k1(spec.TruthAt(t))));
  }
  EXPECT_EQ(previous, 3320.0);
  EXPECT_LE(worst, 0.005 * 200.0 + 1e-6);
  EXPECT_EQ(systems, 102);  // the one before, 100 along the ramp, the end value
  std::printf(
      "drift: held k1 off the ramp by %.3f N/m at most (%.2f %% of the drift), %d systems\n", worst,
      100.0 * worst / 200.0, systems);

  // A drift of an hour is rebuilt every 0.1 s: 36 000 times along it, then never again.
  const ChangeSchedule hour(
      {RigChange{
          .at_s = 10.0, .target = ChangeTarget::kDamper, .index = 1, .add = 1.0, .over_s = 3600.0}},
      1.0 / fs);
  std::uint64_t tick = 0, rebuilds = 0;
  while ((tick = hour.NextRebuild(tick)) != ChangeSchedule::kNever) ++rebuilds;
  EXPECT_EQ(rebuilds, 36001u);
  EXPECT_EQ(hour.NextRebuild(0), 10000u);
  EXPECT_EQ(hour.NextRebuild(10000), 10100u);
}

// Across a mass step the state carries over: positions and velocities move by no more than a
// sample's worth, while mass 2's acceleration jumps so that the force on it (m a) goes on
// smoothly: the weight is put on the moving cart, its position and velocity kept.
TEST(RigChanges, StateIsContinuousAcrossAMassStep) {
  RigSpec spec = QuietRig();
  const double step_s = 2.5;
  spec.changes = {MassStep(step_s, 1, 0.08)};
  RigSimulator rig(spec, 1);
  Select(rig, "step", {2, 20, 1, 0});  // released at 1.8 s: ringing at 2.5 s
  rig.Start(1.0 / kFs);
  const int step_tick = static_cast<int>(step_s * kFs);
  std::array<std::int32_t, wire::kChannelCount> raw{};
  std::vector<Eigen::VectorXd> state;
  std::vector<double> force2;  // m2 a2: the force on mass 2
  for (int k = 0; k <= step_tick + 3; ++k) {
    state.push_back(rig.state());
    rig.Step(raw);
    force2.push_back(rig.HeldModel().m_kg(1, 1) * rig.last().a_m_s2[1]);
  }
  // The first tick under the changed system is the step's: the state goes from its edge, s, to
  // the next, s + 1, by the new system.
  const auto s = static_cast<std::size_t>(step_tick);
  ASSERT_GT(state[s].tail(2).norm(), 1e-3);  // moving
  for (Eigen::Index i = 0; i < 4; ++i) {
    const double across = std::abs(state[s + 1](i) - state[s](i));
    const double around = std::max(std::abs(state[s](i) - state[s - 1](i)),
                                   std::abs(state[s + 2](i) - state[s + 1](i)));
    EXPECT_LE(across, 1.01 * around) << (i < 2 ? "position " : "velocity ") << i % 2 + 1;
  }
  // The force on mass 2 extrapolated linearly from the two samples before the step, against
  // the one at it: off by the force's curvature only (the largest second difference around).
  const double predicted = 2.0 * force2[s - 1] - force2[s - 2];
  const double curvature = std::max(std::abs(force2[s - 1] - 2.0 * force2[s - 2] + force2[s - 3]),
                                    std::abs(force2[s + 2] - 2.0 * force2[s + 1] + force2[s]));
  EXPECT_LE(std::abs(force2[s] - predicted), 2.0 * curvature + 1e-12);
  EXPECT_GT(std::abs(force2[s]), 10.0 * curvature);  // a force that matters
  EXPECT_DOUBLE_EQ(rig.HeldModel().m_kg(1, 1), 1.61);
}

// Changes touch nothing of the random stream: with a drift and a step the same seed and the
// same commands give the same samples, the samples before the first change are those of the
// same rig without changes, and each acquisition starts from the rig as built.
TEST(RigChanges, SameSeedSameSamplesWithChanges) {
  RigSpec spec = DefaultRig();
  spec.changes = {
      MassStep(1.0, 1, 0.08),
      RigChange{
          .at_s = 0.5, .target = ChangeTarget::kDamper, .index = 0, .add = 2.0, .over_s = 1.0}};
  const auto run = [](const RigSpec& r, std::uint64_t seed, int acquisitions) {
    RigSimulator rig(r, seed);
    Select(rig, "operate", {2, 0, 0, 3});
    std::vector<std::int32_t> out;
    std::array<std::int32_t, wire::kChannelCount> raw{};
    for (int a = 0; a < acquisitions; ++a) {
      rig.Start(1.0 / kFs);
      EXPECT_DOUBLE_EQ(rig.HeldModel().m_kg(1, 1), 1.53);
      out.clear();
      for (int i = 0; i < static_cast<int>(2.0 * kFs); ++i) {
        rig.Step(raw);
        out.insert(out.end(), raw.begin(), raw.end());
      }
      EXPECT_DOUBLE_EQ(rig.HeldModel().m_kg(1, 1), r.changes.empty() ? 1.53 : 1.61);
    }
    return out;
  };
  const std::vector<std::int32_t> changed = run(spec, 42, 1);
  EXPECT_EQ(changed, run(spec, 42, 1));
  EXPECT_EQ(run(spec, 42, 2), run(spec, 42, 2));
  EXPECT_NE(changed, run(spec, 43, 1));
  const std::vector<std::int32_t> plain = run(DefaultRig(), 42, 1);
  // The damper drift starts at 0.5 s: up to there every channel of every sample is the same.
  const auto first_change = static_cast<std::ptrdiff_t>(0.5 * kFs) * wire::kChannelCount;
  EXPECT_TRUE(std::equal(changed.begin(), changed.begin() + first_change, plain.begin()));
  EXPECT_NE(changed, plain);
}

// Changes apply to a mass tested alone on its own spring as to the chain.
TEST(RigChanges, AMassAloneChangesToo) {
  RigSpec spec = QuietRig();
  spec.changes = {
      MassStep(0.2, 1, 0.08),
      RigChange{.at_s = 0.2, .target = ChangeTarget::kSpring, .index = 1, .add = 100.0}};
  RigSimulator rig(spec, 1);
  Select(rig, "hammer", {0, 0, 0, 2});
  rig.Start(1.0 / kFs);
  EXPECT_DOUBLE_EQ(rig.HeldModel().m_kg(0, 0), 1.53);
  std::array<std::int32_t, wire::kChannelCount> raw{};
  for (int k = 0; k <= static_cast<int>(0.2 * kFs); ++k) rig.Step(raw);
  ASSERT_EQ(rig.HeldModel().dofs(), 1);
  EXPECT_DOUBLE_EQ(rig.HeldModel().m_kg(0, 0), 1.61);
  EXPECT_DOUBLE_EQ(rig.HeldModel().k_n_per_m(0, 0), 2860.0);
}

TEST(RigFile, ChangesRoundTrip) {
  nlohmann::json j = RigToJson(DefaultRig());
  EXPECT_FALSE(j.contains("changes"));  // a rig without changes writes none
  j["changes"] = nlohmann::json::parse(R"([
    {"at_s": 600, "mass": 2, "add_kg": 0.08},
    {"at_s": 100, "spring": 1, "add_n_per_m": -50, "over_s": 300},
    {"at_s": 0, "damper": 2, "add_ns_per_m": 1.5, "over_s": 0.5}])");
  const RigSpec r = RigFromJson(j, "rig.json");
  ASSERT_EQ(r.changes.size(), 3u);
  EXPECT_EQ(r.changes[0], MassStep(600.0, 1, 0.08));
  EXPECT_EQ(r.changes[1], (RigChange{.at_s = 100.0,
                                     .target = ChangeTarget::kSpring,
                                     .index = 0,
                                     .add = -50.0,
                                     .over_s = 300.0}));
  EXPECT_EQ(r.changes[2].target, ChangeTarget::kDamper);
  EXPECT_EQ(RigToJson(r), j);
  EXPECT_DOUBLE_EQ(TruthToJson(r, 700.0)["masses"][1].get<double>(), 1.61);
  EXPECT_EQ(TruthToJson(r, 700.0)["springs"][0], 3470.0);

  // The shipped example: the built-in rig and a 3 % mass step on mass 2 at 600 s.
  const RigSpec step =
      LoadRig(std::string(VIBID_SOURCE_DIR) + "/host/emulator/rigs/chain2_mass_step.json");
  RigSpec expected = DefaultRig();
  expected.changes = {MassStep(600.0, 1, 0.0459)};
  EXPECT_EQ(RigToJson(step), RigToJson(expected));
  EXPECT_DOUBLE_EQ(step.TruthAt(600.0).m_kg(1, 1), 1.53 * 1.03);
  EXPECT_DOUBLE_EQ(step.TruthAt(599.9).m_kg(1, 1), 1.53);
}

TEST(RigFile, BadChangesAreRefusedNamingTheEntryAndField) {
  const struct {
    const char* change;
    const char* message;
  } cases[] = {
      {R"({"at_s": 1, "mass": 3, "add_kg": 0.1})",
       R"(rig.json: "changes"[0]: "mass" must be a mass of the rig, 1 to 2)"},
      {R"({"at_s": 1, "spring": 0, "add_n_per_m": 10})",
       R"(rig.json: "changes"[0]: "spring" must be a spring of the rig, 1 to 2)"},
      {R"({"at_s": 1, "damper": 1.5, "add_ns_per_m": 1})",
       R"(rig.json: "changes"[0]: "damper" must be a damper of the rig, 1 to 2)"},
      {R"({"at_s": 1, "add_kg": 0.1})",
       R"(rig.json: "changes"[0]: name one target, "mass", "spring" or "damper" (counted from 1))"},
      {R"({"at_s": 1, "mass": 1, "spring": 1, "add_kg": 0.1})",
       R"(rig.json: "changes"[0]: name one target, "mass", "spring" or "damper" (counted from 1))"},
      {R"({"mass": 1, "add_kg": 0.1})",
       R"(rig.json: "changes"[0]: missing "at_s" (seconds from the acquisition's start))"},
      {R"({"at_s": -1, "mass": 1, "add_kg": 0.1})",
       R"(rig.json: "changes"[0]: "at_s" must be >= 0 (seconds from the acquisition's start))"},
      {R"({"at_s": "600", "mass": 1, "add_kg": 0.1})",
       R"(rig.json: "changes"[0]: "at_s" must be a finite number)"},
      {R"({"at_s": 1, "mass": 1})",
       R"(rig.json: "changes"[0]: missing "add_kg" (the mass's change, kg))"},
      {R"({"at_s": 1, "mass": 1, "add_n_per_m": 10})",
       R"(rig.json: "changes"[0]: "add_n_per_m" is a spring's change; a mass takes "add_kg" (kg))"},
      {R"({"at_s": 1, "spring": 2, "add_kg": 0.1})",
       R"(rig.json: "changes"[0]: "add_kg" is a mass's change; a spring takes "add_n_per_m" (N/m))"},
      {R"({"at_s": 1, "mass": 1, "add_kg": 0.1, "over_s": 0})",
       R"(rig.json: "changes"[0]: "over_s" must be > 0 (a drift's duration, s; leave it out for a step))"},
      {R"({"at_s": 1, "mass": 1, "add_kgs": 0.1})",
       R"(unknown key 'add_kgs' in rig file rig.json "changes"[0] (did you mean 'add_kg'?))"},
      {R"({"at_s": 5, "mass": 2, "add_kg": -1.53})",
       R"(rig.json: "changes"[0]: "add_kg" takes mass 2 to 0 kg at 5 s; a mass must stay above 0 kg)"},
      {R"({"at_s": 5, "spring": 1, "add_n_per_m": -4000, "over_s": 10})",
       R"(rig.json: "changes"[0]: "add_n_per_m" takes spring 1 to -480 N/m at 15 s; a spring must stay above 0 N/m)"},
      {R"({"at_s": 5, "damper": 2, "add_ns_per_m": -3.6})",
       R"(rig.json: "changes"[0]: "add_ns_per_m" takes damper 2 to -0.1 N s/m at 5 s; a damper must stay at 0 N s/m or above)"},
      {R"(600)",
       R"(rig.json: "changes"[0] must be an object: {"at_s": 600, "mass": 2, "add_kg": 0.08} (a step; with "over_s", a drift))"},
  };
  for (const auto& c : cases) {
    nlohmann::json j = RigToJson(DefaultRig());
    j["changes"] = nlohmann::json::array({nlohmann::json::parse(c.change)});
    EXPECT_EQ(InputErrorOf([&] { RigFromJson(j, "rig.json"); }, "accepted"), c.message) << c.change;
  }
  // Not a list; a number that is not finite (a JSON file cannot hold one, a program can).
  nlohmann::json j = RigToJson(DefaultRig());
  j["changes"] = {{"at_s", 1}};
  EXPECT_EQ(
      InputErrorOf([&] { RigFromJson(j, "rig.json"); }, "accepted"),
      R"(rig.json: "changes" must be a list of changes: [{"at_s": 600, "mass": 2, "add_kg": 0.08}, ...])");
  j["changes"] = nlohmann::json::array(
      {{{"at_s", 1}, {"mass", 1}, {"add_kg", std::numeric_limits<double>::infinity()}}});
  EXPECT_EQ(InputErrorOf([&] { RigFromJson(j, "rig.json"); }, "accepted"),
            R"(rig.json: "changes"[0]: "add_kg" must be a finite number)");
  // A drift that a later step would take below zero is blamed on the drift: the later step
  // adds, only the drift takes away. Checked before the step too (just before 20 s: -0.18 kg).
  j["changes"] = nlohmann::json::parse(R"([
    {"at_s": 20, "mass": 1, "add_kg": 1},
    {"at_s": 0, "mass": 1, "add_kg": -2, "over_s": 20}])");
  EXPECT_EQ(
      InputErrorOf([&] { RigFromJson(j, "rig.json"); }, "accepted"),
      R"(rig.json: "changes"[1]: "add_kg" takes mass 1 to -0.18 kg at 20 s; a mass must stay above 0 kg)");
  // A rig built in a program is checked by the simulator.
  RigSpec r = DefaultRig();
  r.changes = {MassStep(1.0, 2, 0.1)};
  EXPECT_EQ(InputErrorOf([&] { RigSimulator rig(r, 1); }, "accepted"),
            R"(rig: "changes"[0]: the rig has no mass 3)");
}

}  // namespace
}  // namespace vibid::emu
