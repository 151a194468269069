// The watch session on a simulated running rig (the demo rig's truth, white forces on both
// masses, accelerations at 200 Hz): the modes against the model's, the false alarms of both
// tests against the rate asked for, a large change flagged in its first block, the times and
// the options refused up front (named as the CLI and as Python spell them), the columns watched.
#include "vibid/workflow/watch_session.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include <cstdio>

#include "vibid/common/error.hpp"
#include "vibid/model/modal.hpp"
#include "vibid/model/model.hpp"
#include "vibid/oma/testing/ambient.hpp"
#include "vibid/workflow/watch_columns.hpp"
#include "testing/count_band.hpp"

namespace vibid::workflow {
namespace {

using testing::CountBand;

model::Model DemoRig(double m2_kg = 1.53) {
  // The emulator's default rig truth (host/emulator/rigs/default.json).
  return model::MakeChain(Eigen::Vector2d(1.82, m2_kg), Eigen::Vector2d(3520.0, 2760.0),
                          Eigen::Vector2d(5.0, 3.5));
}

WatchOptions Options() {
  WatchOptions o;
  o.fs_hz = 200.0;
  o.channels = 2;
  o.reference_s = 1200.0;  // shorter than the default: the tests here need no 3 % sensitivity
  return o;
}

oma::testing::AmbientOptions Sim(std::uint64_t seed) {
  oma::testing::AmbientOptions sim;
  sim.fs_hz = 200.0;
  sim.seed = seed;
  return sim;
}

TEST(WatchSession, ReferenceAndBlockModesAreTheRigs) {
  const model::Model rig = DemoRig();
  oma::testing::AmbientRig sim(rig, Sim(31));
  WatchOptions o = Options();
  o.modes_s = 300.0;
  WatchSession s(o);
  EXPECT_TRUE(s.Feed(sim.Next(200 * 1200), 0.0).empty());
  ASSERT_TRUE(s.has_reference());
  const model::ComplexModes truth = model::ComplexModalDamping(rig);
  const WatchReference& ref = s.reference();
  EXPECT_EQ(ref.order, 4);
  EXPECT_EQ(ref.dof, 8);
  EXPECT_EQ(ref.reference_blocks, 96);  // 80 % of 1200 s in 10 s blocks
  ASSERT_EQ(ref.modes.size(), 2u);
  std::vector<WatchBlock> blocks = s.Feed(sim.Next(200 * 300));
  ASSERT_EQ(blocks.size(), 30u);
  const WatchBlock& last = blocks.back();
  EXPECT_DOUBLE_EQ(last.t_s, 1500.0);
  EXPECT_EQ(last.index, 30);
  EXPECT_EQ(last.window_count, 30);
  ASSERT_EQ(last.modes.size(), 2u) << last.modes_message;
  // SSI-cov's targets (docs/watch.md): ω within 0.5 %, ζ within 15 % of the model's modes, on
  // the reference and on the last 300 s alike; the moved mode's change within its interval.
  for (int m = 0; m < 2; ++m) {
    for (const WatchMode& found :
         {ref.modes[static_cast<std::size_t>(m)], last.modes[static_cast<std::size_t>(m)]}) {
      EXPECT_NEAR(found.omega_rad_s / truth.omega_rad_s(m) - 1.0, 0.0, 0.005) << m;
      EXPECT_NEAR(found.zeta / truth.zeta(m) - 1.0, 0.0, 0.15) << m;
      EXPECT_GT(found.omega_ci95_rad_s, 0.0);
    }
  }
  ASSERT_TRUE(last.moved.has_value());
  EXPECT_LE(std::abs(last.moved->change_rad_s), last.moved->ci95_rad_s * 1.5);
}

TEST(WatchSession, AShortReferenceHoldsTheRigsTwoModesAndNoOther) {
  // On the emulator's recording of this rig, a 690 s reference at 200 Hz gave a third "mode" at
  // 16 Hz, ± 0.97 Hz, where the rig's spectrum has nothing, and doubled the test's order to 6. Its
  // two modes are at 5.1 and 9.7 Hz (model); over seeds, the reference holds exactly those, each
  // known within 3 % of its frequency, and the test's order stays 4.
  const model::ComplexModes truth = model::ComplexModalDamping(DemoRig());
  for (std::uint64_t seed = 61; seed < 67; ++seed) {
    oma::testing::AmbientRig sim(DemoRig(), Sim(seed));
    WatchOptions o = Options();
    o.reference_s = 690.0;
    o.modes_s = 0.0;
    WatchSession s(o);
    s.Feed(sim.Next(200 * 690), 0.0);
    ASSERT_TRUE(s.has_reference()) << seed;
    const WatchReference& ref = s.reference();
    std::printf("seed %llu: %zu modes, order %d\n", static_cast<unsigned long long>(seed),
                ref.modes.size(), ref.order);
    ASSERT_EQ(ref.modes.size(), 2u) << seed;
    EXPECT_EQ(ref.order, 4) << seed;
    for (int m = 0; m < 2; ++m) {
      const WatchMode& found = ref.modes[static_cast<std::size_t>(m)];
      EXPECT_NEAR(found.omega_rad_s / truth.omega_rad_s(m) - 1.0, 0.0, 0.01) << seed << " " << m;
      EXPECT_LE(found.omega_ci95_rad_s, 0.03 * found.omega_rad_s) << seed << " " << m;
    }
  }
}

TEST(WatchSession, TwentyPercentMassIsOverTheBlockThresholdAndAlarmsWithItsWindow) {
  oma::testing::AmbientRig sim(DemoRig(), Sim(32));
  WatchOptions o = Options();
  o.modes_s = 0.0;
  WatchSession s(o);
  EXPECT_TRUE(s.Feed(sim.Next(200 * 1200), 100.0).empty());
  // 700 s unchanged: the first window (blocks 1 … 60) is judged whole before the change, and
  // passes; the change falls 10 blocks into the second.
  const std::vector<WatchBlock> before = s.Feed(sim.Next(200 * 700));
  ASSERT_EQ(before.size(), 70u);
  int judged = 0;
  for (const WatchBlock& b : before) {
    judged += b.window_count == b.window_blocks;
    EXPECT_FALSE(b.alarm) << b.t_s;
  }
  EXPECT_EQ(judged, 1);
  sim.Change(DemoRig(1.53 * 1.2));
  const std::vector<WatchBlock> after = s.Feed(sim.Next(200 * 500));
  ASSERT_EQ(after.size(), 50u);
  int over = 0;
  for (const WatchBlock& b : after) over += b.block_over;
  EXPECT_GE(over, 40);  // a block's own test has power of about 90 % here (44 of 50 measured)
  // The sequential test alarms first, within its shortest onset (6 blocks: a block's T² here is
  // several times h's share of it); the second window (blocks
  // 61 … 120 after the reference) ends 1 200 s after it and alarms when full, and no block inside
  // the window alarms on the window's test.
  std::size_t first = after.size();
  for (std::size_t k = 0; k < after.size(); ++k) {
    if (after[k].sequential_alarm && first == after.size()) first = k;
  }
  ASSERT_LT(first, 6u);
  // Its onset is at least the shortest (6 blocks) and, the change dominating each block's
  // residual, no more than twice that back.
  EXPECT_GE(after[first].sequential_onset_blocks, static_cast<int>(first) + 1);
  EXPECT_LE(after[first].sequential_onset_blocks, 12);
  EXPECT_GT(after[first].sequential_statistic, after[first].sequential_threshold);
  for (std::size_t k = 0; k + 1 < after.size(); ++k) EXPECT_FALSE(after[k].window_alarm);
  EXPECT_TRUE(after.back().alarm);
  EXPECT_TRUE(after.back().window_alarm);
  ASSERT_TRUE(after.back().first_alarm_t_s.has_value());
  EXPECT_DOUBLE_EQ(*after.back().first_alarm_t_s, after[first].t_s);
  const std::vector<WatchBlock> later = s.Feed(sim.Next(200 * 10));
  ASSERT_EQ(later.size(), 1u);
  EXPECT_EQ(later[0].first_alarm_t_s, after.back().first_alarm_t_s);
  EXPECT_FALSE(later[0].window_alarm);  // a new window has begun
}

// What moved is named by the quantity that moved most against its interval: both dampers doubled
// (mode 1's ζ about doubles, its ω barely moves) is reported as ζ; spring 2 made 10 % softer moves
// mode 1 2.6 % lower and turns its shape (the first entry 0.568 to 0.536 of the second: the
// model's), and the shape, known within 0.003 over 300 s, is the more significant. Each change
// reported is the model's (model::ComplexModalDamping and model::Modal before and after) within
// the interval reported for it.
TEST(WatchSession, WhatMovedIsTheQuantityThatMovedMostSignificantly) {
  struct Case {
    const char* quantity;
    model::Model after;
  };
  const model::Model before = DemoRig();
  const Case cases[] = {
      {"zeta", model::MakeChain(Eigen::Vector2d(1.82, 1.53), Eigen::Vector2d(3520.0, 2760.0),
                                Eigen::Vector2d(10.0, 7.0))},
      {"shape", model::MakeChain(Eigen::Vector2d(1.82, 1.53), Eigen::Vector2d(3520.0, 2484.0),
                                 Eigen::Vector2d(5.0, 3.5))}};
  const model::ComplexModes was = model::ComplexModalDamping(before);
  std::uint64_t seed = 41;
  for (const Case& c : cases) {
    oma::testing::AmbientRig sim(before, Sim(seed++));
    WatchOptions o = Options();
    o.block_s = 20.0;
    o.modes_s = 300.0;
    WatchSession s(o);
    ASSERT_TRUE(s.Feed(sim.Next(200 * 1200), 0.0).empty());
    sim.Change(c.after);
    const std::vector<WatchBlock> blocks = s.Feed(sim.Next(200 * 300));
    ASSERT_EQ(blocks.size(), 15u);
    const WatchBlock& last = blocks.back();  // its modes: the changed rig's 300 s alone
    ASSERT_TRUE(last.moved.has_value()) << last.modes_message;
    const WatchMove& m = *last.moved;
    const model::ComplexModes now = model::ComplexModalDamping(c.after);
    const auto k = static_cast<Eigen::Index>(m.mode - 1);
    std::printf("%s: mode %d, ω %+.2f %% (%.1f×), ζ %+.4f (%.1f×), shape %.1f×, MAC %.4f\n",
                c.quantity, m.mode, 100.0 * m.relative, m.omega_significance, m.zeta_change,
                m.zeta_significance, m.shape_significance, m.mac);
    EXPECT_EQ(m.quantity, c.quantity) << WatchBlockText(last);
    EXPECT_GT(m.significance, 1.0) << WatchBlockText(last);
    EXPECT_NEAR(m.zeta_change, now.zeta(k) - was.zeta(k), m.zeta_ci95);
    EXPECT_NEAR(m.change_rad_s, now.omega_rad_s(k) - was.omega_rad_s(k), m.ci95_rad_s);
    // The model's shapes, real-normalised as SSI-cov's (largest entry +1).
    const auto shape = [k](const model::Model& rig) {
      const Eigen::VectorXd phi = model::Modal(rig).shapes.col(k);
      Eigen::Index top = 0;
      phi.cwiseAbs().maxCoeff(&top);
      return Eigen::VectorXd(phi / phi(top));
    };
    ASSERT_GE(m.shape_entry, 0);
    const auto e = static_cast<Eigen::Index>(m.shape_entry);
    EXPECT_NEAR(m.shape_change, shape(c.after)(e) - shape(before)(e), m.shape_ci95);
    const std::string said = std::string("mode ") + std::to_string(m.mode) +
                             (m.quantity == "zeta" ? " ζ " : " shape entry ");
    EXPECT_NE(WatchBlockText(last).find(said), std::string::npos) << WatchBlockText(last);
    const nlohmann::json j = WatchBlockJson(last);
    EXPECT_EQ(j["moved"]["quantity"], c.quantity);
    EXPECT_DOUBLE_EQ(j["moved"]["zeta"]["change"].get<double>(), m.zeta_change);
    ASSERT_TRUE(j["moved"]["shape"].is_object());
    EXPECT_GT(j["moved"]["shape"]["mac"].get<double>(), 0.99);  // a small turn: MAC near 1
  }
}

// A partial window is no test: its line gives its count of blocks, not a statistic against the
// full window's threshold; the header (the journal's first line) gives the options, the
// reference's span and source, its modes and the thresholds.
TEST(WatchSession, APartialWindowIsNotPrintedAsATestAndTheHeaderSaysWhatWasWatched) {
  oma::testing::AmbientRig sim(DemoRig(), Sim(33));
  WatchOptions o = Options();
  o.modes_s = 0.0;
  o.window_blocks = 3;
  WatchSession s(o);
  ASSERT_TRUE(s.Feed(sim.Next(200 * 1200), 50.0).empty());
  const nlohmann::json h = WatchHeaderJson(s);
  EXPECT_EQ(h["header"], "vibid watch");
  EXPECT_EQ(h["reference"]["source"], "watched");
  EXPECT_DOUBLE_EQ(h["reference"]["span"]["from_t_s"].get<double>(), 50.0);
  EXPECT_DOUBLE_EQ(h["reference"]["span"]["to_t_s"].get<double>(), 50.0 + 1200.0 - 1.0 / 200.0);
  EXPECT_EQ(h["reference"]["modes"].size(), 2u);
  EXPECT_DOUBLE_EQ(h["reference"]["window_threshold"].get<double>(),
                   s.reference().window_threshold);
  EXPECT_DOUBLE_EQ(h["options"]["window_false_alarm"].get<double>(), o.WindowFalseAlarm());
  EXPECT_EQ(h["options"]["window_blocks"], 3);
  const std::vector<WatchBlock> blocks = s.Feed(sim.Next(200 * 30));
  ASSERT_EQ(blocks.size(), 3u);
  for (int k = 0; k < 2; ++k) {
    const std::string text = WatchBlockText(blocks[static_cast<std::size_t>(k)]);
    EXPECT_NE(text.find("window " + std::to_string(k + 1) + "/3 blocks, tested when full"),
              std::string::npos)
        << text;
    EXPECT_FALSE(WatchBlockJson(blocks[static_cast<std::size_t>(k)])["accumulated"]["tested"]);
  }
  char full[64];
  std::snprintf(full, sizeof full, "window %.1f/%.1f (3 blocks)", blocks[2].accumulated_statistic,
                blocks[2].accumulated_threshold);
  EXPECT_NE(WatchBlockText(blocks[2]).find(full), std::string::npos) << WatchBlockText(blocks[2]);
  EXPECT_TRUE(WatchBlockJson(blocks[2])["accumulated"]["tested"]);
  for (const WatchBlock& b : blocks) EXPECT_FALSE(WatchBlockJson(b).contains("header"));
}

TEST(WatchSession, FalseAlarmsAtHighRatesAreTheCalibratedOnes) {
  // 10 references of the unchanged rig, each watched for 2 h: windows of 60 blocks at 2.5 false
  // alarms per hour asked and windows of 6 blocks at 5 per hour. Each reference keeps its own
  // rate at or below the one asked (97.5 %), so the counts are expected at the references' mean
  // rates, below the rates asked, within the band of their spread (CountBand).
  // The sequential test, at 2.5 per hour, is counted the same way beside them.
  int alarms_60 = 0;
  int alarms_6 = 0;
  int sequential = 0;
  int over = 0;
  CountBand band_60;
  CountBand band_6;
  CountBand band_sequential;
  for (std::uint64_t seed = 40; seed < 50; ++seed) {
    oma::testing::AmbientRig sim(DemoRig(), Sim(seed));
    WatchOptions o = Options();
    o.modes_s = 0.0;
    o.false_alarm_per_hour = 2.5;
    WatchSession long_windows(o);
    o.window_blocks = 6;
    o.false_alarm_per_hour = 5.0;
    WatchSession short_windows(o);
    const Eigen::MatrixXd reference = sim.Next(200 * 1200);
    long_windows.SetReference(reference);
    short_windows.SetReference(reference);
    band_60.Add(long_windows.reference(), 2.0);
    band_6.Add(short_windows.reference(), 2.0);
    band_sequential.AddSequential(long_windows.reference(), 2.0);
    for (int part = 0; part < 12; ++part) {
      const Eigen::MatrixXd y = sim.Next(200 * 600);
      for (const WatchBlock& b : long_windows.Feed(y)) {
        alarms_60 += b.window_alarm;
        sequential += b.sequential_alarm;
        over += b.block_over;
      }
      for (const WatchBlock& b : short_windows.Feed(y)) alarms_6 += b.window_alarm;
    }
  }
  std::printf(
      "windows of 60: %d alarms (%.1f expected, %.1f … %.1f; 50 asked); of 6: %d (%.1f, "
      "%.1f … %.1f; 100 asked); blocks over the F quantile: %d (50)\n",
      alarms_60, band_60.expected, band_60.Low(), band_60.High(), alarms_6, band_6.expected,
      band_6.Low(), band_6.High(), over);
  EXPECT_GE(alarms_60, band_60.Low());
  EXPECT_LE(alarms_60, band_60.High());
  EXPECT_GE(alarms_6, band_6.Low());
  EXPECT_LE(alarms_6, band_6.High());
  // The correction is not slack: without it the counts would be near the rates asked.
  EXPECT_LT(band_60.High(), 50.0);
  EXPECT_LT(band_6.High(), 100.0);
  std::printf("sequential at 2.5 per hour: %d alarms (%.1f expected, %.1f … %.1f; 50 asked)\n",
              sequential, band_sequential.expected, band_sequential.Low(), band_sequential.High());
  EXPECT_LE(sequential, band_sequential.High());
  EXPECT_LT(band_sequential.High(), 50.0);
}

TEST(WatchSession, AGapDropsTheBlockUnderWay) {
  oma::testing::AmbientRig sim(DemoRig(), Sim(33));
  WatchOptions o = Options();
  o.modes_s = 0.0;
  WatchSession s(o);
  s.Feed(sim.Next(200 * 1200));
  EXPECT_EQ(s.Feed(sim.Next(200 * 5)).size(), 0u);
  s.Gap(200 * 3);
  const std::vector<WatchBlock> b = s.Feed(sim.Next(200 * 10));
  ASSERT_EQ(b.size(), 1u);
  EXPECT_DOUBLE_EQ(b[0].t_s, 1200.0 + 5.0 + 3.0 + 10.0);
  WatchSession fresh(o);
  fresh.Feed(sim.Next(200 * 10));
  EXPECT_THROW(fresh.Gap(10), InputError);
}

TEST(WatchSession, EachBlockCarriesTheBoardsFlagAtItsEndAndWhenItFirstTripped) {
  oma::testing::AmbientRig sim(DemoRig(), Sim(34));
  WatchOptions o = Options();
  o.modes_s = 0.0;
  WatchSession s(o);
  s.SetBoardThreshold(8.25);
  const Eigen::MatrixXd reference = sim.Next(200 * 1200);
  Eigen::MatrixXd quiet = Eigen::MatrixXd::Zero(reference.rows(), 2);
  quiet.col(0).setConstant(0.5);
  EXPECT_TRUE(s.Feed(reference, quiet, 10.0).empty());
  // 25 s fed in one piece whose flag trips at its sample 2 345 (the board's g ramps to it): the
  // blocks end at 10 s and 20 s into the piece, so the first is clean and the second stale since
  // 10 + 1200 + 2345 / 200 s (the sample's own time: the fed count over the rate).
  const Eigen::MatrixXd y = sim.Next(200 * 25);
  Eigen::MatrixXd board(y.rows(), 2);
  for (Eigen::Index i = 0; i < y.rows(); ++i) {
    board(i, 0) = 0.001 * static_cast<double>(i);
    board(i, 1) = i >= 2345 ? 1.0 : 0.0;
  }
  const std::vector<WatchBlock> b = s.Feed(y, board);
  ASSERT_EQ(b.size(), 2u);
  ASSERT_TRUE(b[0].board.has_value());
  EXPECT_FALSE(b[0].board->stale);
  EXPECT_DOUBLE_EQ(b[0].board->statistic, 0.001 * 1999);  // the block's last sample
  EXPECT_DOUBLE_EQ(b[0].board->threshold, 8.25);
  EXPECT_FALSE(b[0].board->stale_since_t_s.has_value());
  ASSERT_TRUE(b[1].board.has_value());
  EXPECT_TRUE(b[1].board->stale);
  EXPECT_DOUBLE_EQ(b[1].board->statistic, 0.001 * 3999);
  ASSERT_TRUE(b[1].board->stale_since_t_s.has_value());
  EXPECT_DOUBLE_EQ(*b[1].board->stale_since_t_s, 10.0 + 1200.0 + 2345.0 / 200.0);
  const nlohmann::json j = WatchBlockJson(b[1]);
  EXPECT_EQ(j["board"]["stale"], true);
  EXPECT_DOUBLE_EQ(j["board"]["stale_since_t_s"].get<double>(), 10.0 + 1200.0 + 2345.0 / 200.0);
  EXPECT_NE(WatchBlockText(b[1]).find("board STALE since 1221.7 s"), std::string::npos)
      << WatchBlockText(b[1]);
  EXPECT_NE(WatchBlockText(b[0]).find("board g 2.00/8.25"), std::string::npos)
      << WatchBlockText(b[0]);
  // Fed without the board's columns, a session's blocks carry none.
  WatchSession plain(o);
  plain.SetReference(reference);
  EXPECT_FALSE(plain.Feed(y).front().board.has_value());
  EXPECT_THROW(plain.Feed(y, board.leftCols(1)), InputError);
}

TEST(WatchSession, RefusesBadOptionsNamingThem) {
  const auto message = [](WatchOptions o) {
    try {
      o.Validate();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  WatchOptions o = Options();
  EXPECT_EQ(message(o), "");
  o.reference_s = 300.0;
  EXPECT_NE(message(o).find("--reference-s 300 is too short: the test needs at least 450 s"),
            std::string::npos)
      << message(o);
  o = Options();
  o.block_s = 2.0;
  EXPECT_NE(message(o).find("--block-s 2 is too short for the band"), std::string::npos)
      << message(o);
  o = Options();
  o.fmax_hz = 100.0;
  EXPECT_NE(message(o).find("--fmax-hz"), std::string::npos);
  o = Options();
  o.false_alarm_per_hour = 20.0;
  EXPECT_NE(message(o).find("--false-alarm-per-hour 20 is too high"), std::string::npos);
  o = Options();
  o.modes_s = 5.0;
  EXPECT_NE(message(o).find("--modes-s"), std::string::npos);
  // Python's vibid.watch: the same refusals, each option as Python spells it.
  o = Options();
  o.spelling = OptionSpelling::kPython;
  o.reference_s = 300.0;
  EXPECT_NE(message(o).find("reference_s=300 is too short: the test needs at least 450 s of the "
                            "rig unchanged at block_s=10 (shorten block_s"),
            std::string::npos)
      << message(o);
  EXPECT_EQ(message(o).find("--"), std::string::npos) << message(o);
  o.reference_s = 1200.0;
  o.false_alarm_per_hour = 20.0;
  EXPECT_NE(message(o).find("false_alarm_per_hour=20 is too high"), std::string::npos);
  EXPECT_NE(message(o).find("lower it or window_blocks"), std::string::npos);
  o.false_alarm_per_hour = 0.01;
  o.modes_s = 5.0;
  EXPECT_NE(message(o).find("modes_s must be 0 (no modes) or at least block_s"), std::string::npos);
}

TEST(WatchColumns, ResponsesByDefaultOrAsNamedAndTheBoardsModelColumnsWhenThere) {
  const std::vector<std::string> log{"force1_n",  "acc1_m_s2", "acc2_counts", "x1_m",
                                     "d_hat_q31", "model_g",   "model_stale"};
  const WatchColumns all = ChooseWatchColumns(log, {}, "rec.csv", OptionSpelling::kCli);
  EXPECT_EQ(all.responses, (std::vector<std::string>{"acc1_m_s2", "acc2_counts", "x1_m"}));
  EXPECT_EQ(all.board_statistic, "model_g");
  EXPECT_EQ(all.board_flag, "model_stale");
  const WatchColumns named =
      ChooseWatchColumns(log, {"x1_m", "acc1_m_s2"}, "rec.csv", OptionSpelling::kCli);
  EXPECT_EQ(named.responses, (std::vector<std::string>{"x1_m", "acc1_m_s2"}));
  // Without both model columns: no board state (half a test is none).
  EXPECT_FALSE(ChooseWatchColumns({"acc1_m_s2", "model_g"}, {}, "r", OptionSpelling::kCli)
                   .board_statistic.has_value());
  const auto refusal = [](const std::vector<std::string>& names,
                          const std::vector<std::string>& requested, OptionSpelling spelling) {
    try {
      (void)ChooseWatchColumns(names, requested, "rec.csv", spelling);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(refusal(log, {"acc3_m_s2"}, OptionSpelling::kCli),
            "--response: rec.csv has no column 'acc3_m_s2' (its columns: force1_n, acc1_m_s2, "
            "acc2_counts, x1_m, d_hat_q31, model_g, model_stale); name one of them");
  EXPECT_EQ(refusal(log, {"acc3_m_s2"}, OptionSpelling::kPython).rfind("responses: rec.csv", 0),
            0u);
  EXPECT_NE(refusal(log, {"x1_m", "x1_m"}, OptionSpelling::kPython).find("named twice"),
            std::string::npos);
  EXPECT_EQ(refusal({"force1_n", "d_hat_q31"}, {}, OptionSpelling::kPython),
            "watch: rec.csv has no acceleration or position column; name the responses with "
            "responses");
}

}  // namespace
}  // namespace vibid::workflow
