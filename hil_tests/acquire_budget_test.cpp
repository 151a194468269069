// `vibid acquire` against the board's link budget, through the CLI and a default vibid-emu
// process (the board's 96 KiB log, one 64-byte report per 1 ms frame):
// - an acquisition whose records the link cannot carry, and whose excess the log cannot hold
//   until the end, is refused before the board starts, naming the figures and the way out;
// - with --allow-drops the board drops exactly the records the log size and link rate predict;
// - the anti-aliased log rate makes the same acquisition fit, with nothing dropped;
// - load cell 1 and both accelerometers stream at 5 kHz for 10 simulated minutes, none dropped.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "run_cli.hpp"
#include "target.hpp"
#include "vibid/device/link_budget.hpp"
#include "vibid/shared/board_profile.hpp"
#include "vibid/shared/wire/log_record.hpp"

namespace vibid::hil {
namespace {

using vibid::testing::RunVibid;

/// Rows after the header row (the opening '#' lines, such as the sampling instants, are not rows).
std::size_t DataRows(const std::string& path) {
  std::ifstream in(path);
  std::size_t n = 0;
  std::string line;
  while (std::getline(in, line)) {
    if (!line.starts_with('#')) ++n;
  }
  return n == 0 ? 0 : n - 1;
}

class AcquireBudgetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (MakeTarget()->Name() != "emu") GTEST_SKIP() << "needs the emu target (a vibid-emu process)";
    emu = std::make_unique<EmulatorProcess>(EmulatorBinary());
    dir = vibid::testing::MakeTempDir("acq-budget");
  }
  void TearDown() override {
    std::error_code ec;
    if (!dir.empty()) std::filesystem::remove_all(dir, ec);
  }
  vibid::testing::CliResult Vibid(std::vector<std::string> args) {
    args.insert(args.begin(), {"--device", emu->device_spec()});
    return RunVibid(args);
  }
  /// Nominal model, an observer designed at `fs_hz` for the sensors' 500 N load cell, uploaded,
  /// committed and started: acquisitions at that rate log d_hat.
  void CalibrateWithObserver(const std::string& fs_hz) {
    const std::string design = dir + "/design.json";
    ASSERT_EQ(RunVibid({"dob", "design", VIBID_SOURCE_DIR "/examples/rig_nominal.json", "--fs-hz",
                        fs_hz, "--force-fs-n", "500", "-o", design})
                  .exit_code,
              0);
    const auto up =
        Vibid({"cal", "upload", VIBID_SOURCE_DIR "/examples/rig_nominal.json", "--design", design,
               "--sensors", VIBID_SOURCE_DIR "/examples/sensors.json"});
    ASSERT_EQ(up.exit_code, 0) << up.err;
    ASSERT_EQ(Vibid({"cal", "commit"}).exit_code, 0);
    ASSERT_EQ(Vibid({"dob", "start"}).exit_code, 0);
  }

  std::unique_ptr<EmulatorProcess> emu;
  std::string dir;
};

// Every channel and d_hat at the fastest rate: 10 kHz of 20-byte records against the link's
// 2 records per report (2000 records/s): the log (4096 records of 24 bytes) overflows after
// 4096 / 8000 s = 0.51 s.
TEST_F(AcquireBudgetTest, BeyondTheBudgetIsRefusedOrDropsWhatIsPredicted) {
  CalibrateWithObserver("10000");
  const std::string out = dir + "/fast.csv";
  const auto refused = Vibid({"acquire", "--rate-hz", "10000", "--seconds", "2", "-o", out});
  EXPECT_EQ(refused.exit_code, 1) << refused.err;
  EXPECT_NE(refused.err.find(
                "200000 B/s of log records (10000 records/s of 20 B) exceed the link's 40000 B/s"),
            std::string::npos)
      << refused.err;
  EXPECT_NE(refused.err.find("the 96 KiB log overflows after 0.5 s of the 2.0 s"),
            std::string::npos)
      << refused.err;
  EXPECT_NE(refused.err.find("use --log-rate-hz 2000 or lower"), std::string::npos) << refused.err;
  EXPECT_FALSE(std::filesystem::exists(out)) << "nothing written";

  const auto allowed =
      Vibid({"acquire", "--rate-hz", "10000", "--seconds", "2", "--allow-drops", "-o", out});
  ASSERT_EQ(allowed.exit_code, 0) << allowed.err;
  const wire::LogLayout layout{wire::kAllChannelsMask, wire::kAcqFlagLogDob};
  const device::StreamPrediction p = device::PredictStream(
      20000, 10, static_cast<std::uint32_t>(kBoardProfile.log_bytes / layout.StoredRecordBytes()),
      static_cast<std::uint32_t>(layout.RecordsPerReport()));
  std::printf("10 kHz, all channels and d_hat, 2 s: predicted %llu kept, %llu dropped; %s",
              static_cast<unsigned long long>(p.kept), static_cast<unsigned long long>(p.dropped),
              allowed.err.c_str());
  EXPECT_NE(allowed.err.find("the board dropped " + std::to_string(p.dropped) + " records"),
            std::string::npos)
      << allowed.err;
  EXPECT_EQ(DataRows(out), p.kept);
}

// A refusal's advice leads to an acquisition the board takes. With a 1 kHz observer running,
// every channel and d_hat for 60 s at the default 5 kHz is beyond the link, but the way out is
// not the log rate that fits the link (1250 Hz: the board would then refuse the sample rate, the
// observer running at 1 kHz only): the observer's rate is said first, and at that rate the
// acquisition runs.
TEST_F(AcquireBudgetTest, TheAdviceGivenLeadsToAnAcquisitionTheBoardTakes) {
  CalibrateWithObserver("1000");
  const std::string out = dir + "/advised.csv";
  const auto refused = Vibid({"acquire", "--seconds", "60", "-o", out});
  EXPECT_EQ(refused.exit_code, 1) << refused.err;
  EXPECT_EQ(refused.err,
            "vibid: error: --rate-hz 5000: the board's observer was designed for 1000 Hz and runs "
            "at that rate only; acquire at --rate-hz 1000, or without the observer (--no-dob), or "
            "design and upload an observer for this rate (vibid dob design --fs-hz)\n");
  EXPECT_FALSE(std::filesystem::exists(out)) << "nothing written";
  const auto advised = Vibid({"acquire", "--seconds", "2", "--rate-hz", "1000", "-o", out});
  ASSERT_EQ(advised.exit_code, 0) << advised.err;
  EXPECT_EQ(DataRows(out), 2000u);
}

// The same rate and channels, logged at 2 kHz through the board's anti-aliasing decimator.
TEST_F(AcquireBudgetTest, TheDecimatedLogFitsAndDropsNothing) {
  CalibrateWithObserver("10000");
  const std::string out = dir + "/decimated.csv";
  const auto r = Vibid(
      {"acquire", "--rate-hz", "10000", "--log-rate-hz", "2000", "--seconds", "3", "-o", out});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("the board dropped"), std::string::npos) << r.err;
  EXPECT_EQ(DataRows(out), 6000u);
  std::ifstream in(out);
  std::string header;
  std::getline(in, header);  // the header row comes first
  EXPECT_NE(header.find("d_hat_q31"), std::string::npos) << header;
  const auto bad = Vibid(
      {"acquire", "--rate-hz", "10000", "--log-rate-hz", "3000", "--seconds", "1", "-o", out});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(
      bad.err.find("--log-rate-hz 3000: the sample rate 10000 Hz must be a whole multiple of it"),
      std::string::npos)
      << bad.err;
}

// Load cell 1 and both accelerometers at 5 kHz: 6-byte records, 9 per report (9000 records/s on
// the link for 5000 made), for 10 simulated minutes.
TEST_F(AcquireBudgetTest, ThreeChannelsStreamTenMinutesAtFiveKilohertz) {
  const std::string out = dir + "/ten_minutes.csv";
  const auto r =
      Vibid({"acquire", "--rate-hz", "5000", "--channels", "force1,acc1,acc2", "--seconds", "600",
             "--scenario", "hammer", "--scenario-param", "2,200,2,0", "-o", out});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("the board dropped"), std::string::npos) << r.err;
  EXPECT_EQ(DataRows(out), 3'000'000u);
}

}  // namespace
}  // namespace vibid::hil
