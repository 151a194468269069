// The emulator's self-test measures its simulated parts: the noise and offset it reports come
// from sampling the idle rig, so they follow the rig's sensor model (not constants).
#include <gtest/gtest.h>

#include <cmath>

#include "emu_port.hpp"
#include "rig.hpp"

namespace vibid::emu {
namespace {

using wire::SelfTestCheck;

double Value(const fw::SystemControl::SelfTestMeasurement& m) {
  return static_cast<double>(m.mantissa) * std::pow(10.0, m.exp10);
}

TEST(EmulatorSelfTest, NoiseAndOffsetFollowTheRigsSensorModel) {
  // Noise of 5 LSB rms on every converter channel: well above the 12-bit quantization, whose
  // variance adds 1/12 LSB^2 (Sheppard's correction; exact enough at 5 LSB).
  RigSpec spec = DefaultRig();
  const double lsb_noise = 5.0;
  for (auto& s : spec.load_cells) s.noise_rms = lsb_noise * s.range / 2048.0;
  for (auto& s : spec.accelerometers) s.noise_rms = lsb_noise * s.range / 2048.0;
  spec.coulomb_n = {0.0, 0.0};
  RigSimulator rig(spec, 7);
  EmuSystemControl system(wire::ResetCause::kPowerOn, rig);

  const double expected_rms = std::sqrt(lsb_noise * lsb_noise + 1.0 / 12.0);  // 5.008 LSB
  // The sample standard deviation of N normal draws has a standard error of sigma / sqrt(2N):
  // 0.112 LSB for N = 1000; 5 of them is 0.56 LSB. The mean's is sigma / sqrt(N) = 0.158 LSB.
  const double n = static_cast<double>(wire::kSelfTestSamples);
  const double rms_tolerance = 5.0 * expected_rms / std::sqrt(2.0 * n);
  const double offset_tolerance = 5.0 * expected_rms / std::sqrt(n);
  for (int c = 0; c < 4; ++c) {
    const auto noise = system.MeasureSelfTest(
        static_cast<SelfTestCheck>(static_cast<int>(SelfTestCheck::kNoiseForce1) + c), 200);
    ASSERT_TRUE(noise.available);
    EXPECT_NEAR(Value(noise), expected_rms, rms_tolerance) << "channel " << c;
    const auto offset = system.MeasureSelfTest(
        static_cast<SelfTestCheck>(static_cast<int>(SelfTestCheck::kOffsetForce1) + c), 200);
    ASSERT_TRUE(offset.available);
    EXPECT_NEAR(Value(offset), 0.0, offset_tolerance) << "channel " << c;
  }

  // The default rig: force1 0.1 N rms over +-500 N is 0.41 LSB; with quantization about
  // 0.5 LSB rms (quantization of a Gaussian below 1 LSB only roughly adds 1/12 LSB^2).
  RigSimulator quiet_rig(DefaultRig(), 7);
  EmuSystemControl quiet(wire::ResetCause::kPowerOn, quiet_rig);
  const double force1 = Value(quiet.MeasureSelfTest(SelfTestCheck::kNoiseForce1, 200));
  EXPECT_GT(force1, 0.3);
  EXPECT_LT(force1, 0.7);
}

TEST(EmulatorSelfTest, SimulatedCrystalSupplyAndOptionBytes) {
  RigSimulator rig(DefaultRig(), 1);
  EmuSystemControl system(wire::ResetCause::kSoftware, rig);
  const auto hse = system.MeasureSelfTest(SelfTestCheck::kHsePpm, 200);
  ASSERT_TRUE(hse.available);
  EXPECT_EQ(hse.mantissa, 0);  // one simulated clock times the crystal and the host's frames
  const auto vdda = system.MeasureSelfTest(SelfTestCheck::kVdda, 200);
  ASSERT_TRUE(vdda.available);
  EXPECT_DOUBLE_EQ(Value(vdda), 3.3);
  EXPECT_FALSE(system.MeasureSelfTest(SelfTestCheck::kImageCrc, 200).available);
  const auto encoder = system.MeasureSelfTest(SelfTestCheck::kEncoder2, 200);
  ASSERT_TRUE(encoder.available);
  EXPECT_TRUE(encoder.ok);
  EXPECT_EQ(encoder.mantissa, 0);  // the idle rig rests at its zero position
  EXPECT_EQ(system.BrownOutLevel(), wire::BrownOut::kLevel3);
}

}  // namespace
}  // namespace vibid::emu
