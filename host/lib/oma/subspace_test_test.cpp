// The subspace residual test on a simulated running rig: its false-alarm rate over many
// unchanged blocks against the rate asked for (a binomial band), and a 3 % mass added found.
#include "vibid/oma/subspace_test.hpp"

#include <gtest/gtest.h>

#include "vibid/common/error.hpp"
#include "vibid/model/model.hpp"
#include "vibid/oma/testing/ambient.hpp"

namespace vibid::oma {
namespace {

model::Model DemoRig(double m2_kg = 1.53) {
  // The emulator's default rig truth (host/emulator/rigs/default.json).
  return model::MakeChain(Eigen::Vector2d(1.82, m2_kg), Eigen::Vector2d(3520.0, 2760.0),
                          Eigen::Vector2d(5.0, 3.5));
}

SubspaceTestOptions Options() {
  SubspaceTestOptions o;
  o.fs_hz = 200.0;
  o.fmax_hz = 25.0;
  o.order = 4;
  o.block_s = 10.0;
  o.false_alarm = 0.01;
  return o;
}

TEST(SubspaceTest, FalseAlarmRateIsTheOneAskedFor) {
  testing::AmbientOptions sim;
  sim.fs_hz = 200.0;
  sim.seed = 21;
  testing::AmbientRig rig(DemoRig(), sim);
  const SubspaceDetector detector(rig.Next(200 * 900), Options());
  EXPECT_EQ(detector.dof(), 8);  // (3·2 − 4) null-space rows × 2·2 columns
  const int blocks = 1500;
  int alarms = 0;
  for (int b = 0; b < blocks; ++b)
    alarms += detector.Test(rig.Next(detector.block_samples())).alarm;
  // Binomial(1500, 0.01): mean 15, 99.9 % of outcomes within 4 … 30.
  EXPECT_GE(alarms, 4);
  EXPECT_LE(alarms, 30);
}

TEST(SubspaceTest, TwentyPercentMassAddedIsFlaggedInOneBlock) {
  testing::AmbientOptions sim;
  sim.fs_hz = 200.0;
  sim.seed = 22;
  testing::AmbientRig rig(DemoRig(), sim);
  const SubspaceDetector detector(rig.Next(200 * 900), Options());
  int before = 0;
  for (int b = 0; b < 20; ++b) before += detector.Test(rig.Next(detector.block_samples())).alarm;
  rig.Change(DemoRig(1.53 * 1.2));
  int after = 0;
  for (int b = 0; b < 20; ++b) after += detector.Test(rig.Next(detector.block_samples())).alarm;
  EXPECT_LE(before, 2);
  EXPECT_GE(after, 18);
}

TEST(SubspaceTest, ExcitationLevelAloneIsNoChange) {
  testing::AmbientOptions sim;
  sim.fs_hz = 200.0;
  sim.seed = 23;
  testing::AmbientRig reference(DemoRig(), sim);
  const SubspaceDetector detector(reference.Next(200 * 900), Options());
  sim.force_rms_n = 3.0;
  sim.seed = 24;
  testing::AmbientRig louder(DemoRig(), sim);
  int alarms = 0;
  for (int b = 0; b < 100; ++b)
    alarms += detector.Test(louder.Next(detector.block_samples())).alarm;
  EXPECT_LE(alarms, 5);
}

TEST(SubspaceTest, RefusesAShortReferenceNamingWhatIsNeeded) {
  const Eigen::MatrixXd y = Eigen::MatrixXd::Random(200 * 100, 2);
  try {
    SubspaceDetector detector(y, Options());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("720 s of reference"), std::string::npos) << e.what();
  }
  SubspaceTestOptions o = Options();
  o.order = 3;
  EXPECT_THROW(SubspaceDetector(y, o), InputError);
}

}  // namespace
}  // namespace vibid::oma
