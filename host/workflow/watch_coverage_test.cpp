// The watch's figures stated in docs/watch.md, over seeded simulations of the demo rig (white
// forces on both masses, accelerations at 200 Hz, the default options: 30-minute reference,
// 10 s blocks, windows of 60): false alarms over 100 hours of the unchanged rig, and the blocks
// it takes to flag a 3 % mass on mass 2.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "vibid/model/model.hpp"
#include "vibid/oma/testing/ambient.hpp"
#include "vibid/workflow/watch_session.hpp"
#include "testing/count_band.hpp"

namespace vibid::workflow {
namespace {

using testing::CountBand;

model::Model DemoRig(double m2_kg = 1.53) {
  return model::MakeChain(Eigen::Vector2d(1.82, m2_kg), Eigen::Vector2d(3520.0, 2760.0),
                          Eigen::Vector2d(5.0, 3.5));
}

WatchOptions Options(double per_hour) {
  WatchOptions o;
  o.fs_hz = 200.0;
  o.channels = 2;
  o.modes_s = 0.0;
  o.false_alarm_per_hour = per_hour;
  return o;
}

oma::testing::AmbientOptions Sim(std::uint64_t seed) {
  oma::testing::AmbientOptions sim;
  sim.fs_hz = 200.0;
  sim.seed = seed;
  return sim;
}

TEST(WatchCoverage, FalseAlarmsOverAHundredHours) {
  // 20 references, each watched for 5 h: 100 h at 1 per hour and at the default 0.01 per hour
  // asked. Each reference keeps its own rate at or below the one asked (97.5 %): the counts are
  // expected at the references' mean rates, two-sided at 1 per hour. At the default rate 100 h
  // hold about 0.1 alarm: only the upper bound can fail here (the default rate's two-sided
  // check is oma_test's WindowCalibration over 40 000 h of the residuals' law).
  int at_one = 0;
  int at_default = 0;
  double hours = 0.0;
  CountBand one_band;
  CountBand default_band;
  for (std::uint64_t seed = 100; seed < 120; ++seed) {
    oma::testing::AmbientRig sim(DemoRig(), Sim(seed));
    WatchSession one(Options(1.0));
    WatchSession rare(Options(0.01));
    const Eigen::MatrixXd reference = sim.Next(200 * 1800);
    one.SetReference(reference);
    rare.SetReference(reference);
    one_band.Add(one.reference(), 5.0);
    default_band.Add(rare.reference(), 5.0);
    for (int part = 0; part < 30; ++part) {
      const Eigen::MatrixXd y = sim.Next(200 * 600);
      for (const WatchBlock& b : one.Feed(y)) at_one += b.window_alarm;
      for (const WatchBlock& b : rare.Feed(y)) at_default += b.window_alarm;
      hours += 600.0 / 3600.0;
    }
  }
  std::printf(
      "%.0f h unchanged: %d false alarms at 1/h (%.1f expected, %.1f … %.1f; 100 asked), %d at "
      "0.01/h (%.2f expected, at most %.1f; 1 asked)\n",
      hours, at_one, one_band.expected, one_band.Low(), one_band.High(), at_default,
      default_band.expected, default_band.High());
  EXPECT_GE(hours, 100.0 - 1e-9);
  EXPECT_GE(at_one, one_band.Low());
  EXPECT_LE(at_one, one_band.High());
  EXPECT_GT(one_band.Low(), 0.0);  // the lower bound can fail
  EXPECT_LE(at_default, std::max(default_band.High(), 1.0));
}

TEST(WatchCoverage, ThreePercentMassIsFlaggedWithinTwoWindows) {
  // 40 seeds: the 30-minute reference, 850 s unchanged (a whole window judged, then the change
  // falls 25 blocks into the second), then m2 3 % heavier (mode 1 1.07 % lower). Flagged within
  // 120 blocks of the change in at least 38 of 40 (95 %); the 40 windows judged before it pass.
  int flagged = 0;
  int before = 0;
  int judged_before = 0;
  double worst_blocks = 0.0;
  double ms = 0.0;
  int blocks = 0;
  for (std::uint64_t seed = 200; seed < 240; ++seed) {
    oma::testing::AmbientRig sim(DemoRig(), Sim(seed));
    WatchSession s(Options(0.01));
    s.Feed(sim.Next(200 * 1800), 0.0);
    for (const WatchBlock& b : s.Feed(sim.Next(200 * 850))) {
      before += b.window_alarm;
      judged_before += b.window_count == b.window_blocks;
    }
    const double change_s = 1800.0 + 850.0;
    sim.Change(DemoRig(1.53 * 1.03));
    std::optional<double> first;
    for (const WatchBlock& b : s.Feed(sim.Next(200 * 1200))) {
      if (b.window_alarm && !first) first = b.t_s;
      ms += b.analysis_ms;
      ++blocks;
    }
    if (first && *first - change_s <= 120 * 10.0 + 1e-9) {
      ++flagged;
      worst_blocks = std::max(worst_blocks, (*first - change_s) / 10.0);
    }
  }
  std::printf(
      "3 %% mass: flagged in %d of 40 within 120 blocks (latest after %.0f blocks); "
      "%d false alarms before; %.2f ms per block without modes\n",
      flagged, worst_blocks, before, ms / blocks);
  EXPECT_GE(flagged, 38);
  EXPECT_EQ(judged_before, 40);
  EXPECT_EQ(before, 0);
}

}  // namespace
}  // namespace vibid::workflow
