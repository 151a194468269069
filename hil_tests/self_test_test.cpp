// self-test end to end: every check answers with its number, name and verdict; a port measures
// only what it can (the rest is unavailable, never a pass); the board refuses while sampling.
// On the emulator the converter noise is what its rig's sensor model gives, and the CLI prints
// and exits on the verdicts.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "emulator_process.hpp"
#include "run_cli.hpp"
#include "target.hpp"
#include "vibid/device/error.hpp"
#include "vibid/device/health_report.hpp"

namespace vibid::hil {
namespace {

using wire::SelfTestCheck;
using wire::SelfTestVerdict;

// What a converter reads of zero-mean Gaussian noise of sigma LSB rounded to whole codes: its
// rms, sqrt(sum_k k^2 P(k)) with P(k) = Phi((k + 1/2) / sigma) - Phi((k - 1/2) / sigma), and the
// standard errors of the rms and the mean over kSelfTestSamples independent samples (the rms's
// by the delta method from the variance of k^2).
struct RoundedNoise {
  double rms = 0.0;
  double rms_standard_error = 0.0;
  double mean_standard_error = 0.0;
};
RoundedNoise RoundedGaussian(double sigma) {
  const auto phi = [](double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); };
  double m2 = 0.0, m4 = 0.0;
  for (int k = -20; k <= 20; ++k) {
    const double p = phi((k + 0.5) / sigma) - phi((k - 0.5) / sigma);
    m2 += k * k * p;
    m4 += static_cast<double>(k * k * k * k) * p;
  }
  const double n = wire::kSelfTestSamples;
  RoundedNoise r;
  r.rms = std::sqrt(m2);
  r.rms_standard_error = std::sqrt((m4 - m2 * m2) / n) / (2.0 * r.rms);
  r.mean_standard_error = r.rms / std::sqrt(n);
  return r;
}

class SelfTest : public ::testing::Test {
 protected:
  void SetUp() override { target = MakeTarget(); }
  std::unique_ptr<Target> target;
};

TEST_F(SelfTest, EveryCheckAnswersAndNoneFails) {
  auto c = target->Connect();
  const wire::SelfTestResponse first = c->SelfTest(0);
  ASSERT_EQ(first.check_count, wire::kSelfTestCheckCount);
  std::vector<wire::SelfTestResponse> checks{first};
  for (std::uint8_t k = 1; k < first.check_count; ++k) checks.push_back(c->SelfTest(k));
  for (const auto& r : checks) {
    EXPECT_NE(r.verdict, SelfTestVerdict::kFail)
        << wire::SelfTestCheckName(r.check) << " = " << device::SelfTestValueText(r);
  }
  const auto at = [&](SelfTestCheck check) { return checks[static_cast<std::size_t>(check)]; };
  // The core's own checks answer on every port: erased or valid slots, the reset cause.
  EXPECT_EQ(at(SelfTestCheck::kCalSlotA).verdict, SelfTestVerdict::kPass);
  EXPECT_EQ(at(SelfTestCheck::kCalSlotB).verdict, SelfTestVerdict::kPass);
  EXPECT_EQ(at(SelfTestCheck::kResetCause).verdict, SelfTestVerdict::kPass);
  EXPECT_EQ(at(SelfTestCheck::kResetCause).mantissa,
            static_cast<std::int64_t>(c->info().reset_cause));

  const wire::BoardId board = c->info().board_id;
  if (board == wire::BoardId::kEmulator) {
    EXPECT_EQ(at(SelfTestCheck::kHsePpm).verdict, SelfTestVerdict::kPass);
    EXPECT_EQ(at(SelfTestCheck::kHsePpm).mantissa, 0);
    EXPECT_EQ(device::SelfTestValueText(at(SelfTestCheck::kVdda)), "3.300");
    EXPECT_EQ(at(SelfTestCheck::kBrownOut).verdict, SelfTestVerdict::kPass);
    EXPECT_EQ(at(SelfTestCheck::kImageCrc).verdict, SelfTestVerdict::kUnavailable);
    EXPECT_EQ(at(SelfTestCheck::kHsePpmLse).verdict, SelfTestVerdict::kUnavailable);
    // The built-in rig (DefaultRig, as host/emulator/rigs/default.json): force1 0.1 N rms of
    // +-500 N and force2 0.01 N of +-50 N are 0.4096 LSB, the accelerometers 0.05 of
    // +-200 m/s2 0.512 LSB, before the converter rounds to whole codes.
    const double sigma_lsb[4] = {0.4096, 0.4096, 0.512, 0.512};
    for (int ch = 0; ch < 4; ++ch) {
      const RoundedNoise expected = RoundedGaussian(sigma_lsb[ch]);
      const auto noise = at(static_cast<SelfTestCheck>(2 + ch));
      EXPECT_EQ(noise.verdict, SelfTestVerdict::kPass);
      EXPECT_NEAR(device::SelfTestValue(noise), expected.rms, 5.0 * expected.rms_standard_error)
          << "channel " << ch;
      const auto offset = at(static_cast<SelfTestCheck>(6 + ch));
      EXPECT_NEAR(device::SelfTestValue(offset), 0.0, 5.0 * expected.mean_standard_error)
          << "channel " << ch;
    }
  } else if (board == wire::BoardId::kQemuNetduinoPlus2 || board == wire::BoardId::kHostTest) {
    // Neither the QEMU machine nor the fake port has a crystal, converters or option bytes to
    // measure: those checks are unavailable, not passes.
    for (const auto check :
         {SelfTestCheck::kHsePpm, SelfTestCheck::kVdda, SelfTestCheck::kNoiseForce1,
          SelfTestCheck::kOffsetAccel2, SelfTestCheck::kEncoder1, SelfTestCheck::kBrownOut,
          SelfTestCheck::kHsePpmLse}) {
      EXPECT_EQ(at(check).verdict, SelfTestVerdict::kUnavailable)
          << wire::SelfTestCheckName(static_cast<std::uint8_t>(check));
    }
    // The QEMU image runs from the flash the build's ELF filled, CRC trailer and all: its own
    // CRC-32 (the board's table code) equals the one the build wrote (Python's zlib). The
    // in-process core has no image.
    const wire::SelfTestResponse crc = at(SelfTestCheck::kImageCrc);
    if (board == wire::BoardId::kQemuNetduinoPlus2) {
      EXPECT_EQ(crc.verdict, SelfTestVerdict::kPass) << device::SelfTestValueText(crc);
      EXPECT_EQ(crc.unit, wire::SelfTestUnit::kCrc32);
      // The value is the CRC word the build wrote last in the image (its .bin beside the ELF).
      std::filesystem::path bin = std::getenv("VIBID_QEMU_IMAGE");
      bin.replace_extension(".bin");
      std::ifstream in(bin, std::ios::binary);
      const std::vector<char> bytes{std::istreambuf_iterator<char>(in), {}};
      ASSERT_GE(bytes.size(), 4u) << bin;
      std::uint32_t stored = 0;
      for (std::size_t i = 0; i < 4; ++i)
        stored |= std::uint32_t{static_cast<std::uint8_t>(bytes[bytes.size() - 4 + i])} << (8 * i);
      EXPECT_EQ(crc.mantissa, static_cast<std::int64_t>(stored));
    } else {
      EXPECT_EQ(crc.verdict, SelfTestVerdict::kUnavailable);
    }
  }
}

TEST_F(SelfTest, RefusedWhileSampling) {
  auto c = target->Connect();
  wire::AcqConfigureRequest cfg;
  cfg.sample_period_us = 1000;
  cfg.channel_mask = 1;
  cfg.decimation = 1;
  c->Configure(cfg);
  c->StartAcquisition();
  try {
    (void)c->SelfTest(2);
    ADD_FAILURE() << "self-test answered while sampling";
  } catch (const device::DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("the board is acquiring"), std::string::npos) << e.what();
  }
  (void)c->StopAcquisition();
  EXPECT_NE(c->SelfTest(2).verdict, SelfTestVerdict::kFail);
}

TEST(SelfTestCli, PrintsEachCheckAndTheBrownOutLevel) {
  if (MakeTarget()->Name() != "emu") GTEST_SKIP() << "needs the emu target (a vibid-emu process)";
  EmulatorProcess emu(EmulatorBinary());
  const auto json = vibid::testing::RunVibid({"--device", emu.device_spec(), "selftest", "--json"});
  ASSERT_EQ(json.exit_code, 0) << json.err;
  const auto j = nlohmann::json::parse(json.out);
  ASSERT_EQ(j["checks"].size(), 18u);
  EXPECT_EQ(j["checks"][0]["name"], "hse-ppm");
  EXPECT_EQ(j["checks"][0]["unit"], "ppm");
  EXPECT_EQ(j["checks"][0]["pass"], true);
  EXPECT_EQ(j["checks"][6]["reference"], "mid-code");  // the rig has no calibrated zero yet
  EXPECT_TRUE(j["checks"][1]["reference"].is_null());
  EXPECT_EQ(j["checks"][17]["name"], "hse-ppm-lse");
  EXPECT_TRUE(j["checks"][17]["pass"].is_null());  // the rig has no LSE crystal
  EXPECT_EQ(j["checks"][12]["name"], "image-crc");
  EXPECT_TRUE(j["checks"][12]["pass"].is_null());  // unavailable on the emulator
  EXPECT_TRUE(j["checks"][12]["value"].is_null());
  EXPECT_EQ(j["checks"][15]["value"], "level3");
  EXPECT_NEAR(j["checks"][2]["value"].get<double>(), RoundedGaussian(0.4096).rms, 0.07);

  const auto text = vibid::testing::RunVibid({"--device", emu.device_spec(), "selftest"});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find(" 1  vdda           3.300         V        pass"), std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("18 checks: 16 pass, 0 fail, 2 not measured on this board"),
            std::string::npos)
      << text.out;

  const auto info = vibid::testing::RunVibid({"--device", emu.device_spec(), "info", "--json"});
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const auto info_json = nlohmann::json::parse(info.out);
  EXPECT_EQ(info_json["brown_out_level"], "level3");
  EXPECT_EQ(info_json["clock"], "unknown");  // the emulator has no crystal to report
  EXPECT_EQ(info_json["sampler_recoveries"], 0);
  EXPECT_EQ(info.err.find("warning"), std::string::npos) << info.err;  // level 3: no warning
}

// A board whose option bytes leave the brown-out reset off (a new chip): info warns and still
// exits 0, and the self-test's brown-out check fails (exit 4, naming it).
TEST(SelfTestCli, ABrownOutBelowLevel3WarnsAndFailsTheCheck) {
  if (MakeTarget()->Name() != "emu") GTEST_SKIP() << "needs the emu target (a vibid-emu process)";
  const std::string dir = vibid::testing::MakeTempDir("brown-out");
  const std::string rig = dir + "/rig.json";
  {
    auto j = nlohmann::json::parse(
        vibid::testing::ReadFileBytes(VIBID_SOURCE_DIR "/host/emulator/rigs/default.json"));
    j["brown_out_level"] = "off";
    std::ofstream(rig) << j.dump();
  }
  EmulatorProcess emu(EmulatorBinary(), {"--rig", rig});
  const auto info = vibid::testing::RunVibid({"--device", emu.device_spec(), "info", "--json"});
  EXPECT_EQ(info.exit_code, 0) << info.err;
  EXPECT_EQ(nlohmann::json::parse(info.out)["brown_out_level"], "off");
  EXPECT_EQ(
      info.err,
      "vibid: warning: the board's brown-out reset is off (power-on reset only, about 1.8 V), "
      "below level 3 (2.75-2.88 V), which holds it above the 2.7 V its x32 flash programming "
      "takes: a sagging "
      "supply can lose a calibration commit; set BOR_LEV to level 3 in the option bytes "
      "(docs/board.md, \"Brown-out level\")\n");
  const auto self = vibid::testing::RunVibid({"--device", emu.device_spec(), "selftest"});
  EXPECT_EQ(self.exit_code, 4);
  EXPECT_NE(self.out.find("15  brown-out      off                    FAIL"), std::string::npos)
      << self.out;
  EXPECT_EQ(self.err,
            "vibid: error: self-test: 1 of 18 checks failed (15 brown-out); docs/board.md, "
            "\"Self-test\", says what each one means\n");
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
}

}  // namespace
}  // namespace vibid::hil
