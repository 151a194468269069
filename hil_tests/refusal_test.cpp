// Off the scripted path, through the `vibid` binary against a vibid-emu process: every refusal a
// new user meets says its cause and the way out on one line and exits nonzero (the board names
// its reason on the wire, protocol 2.1); a sensor's range is never overwritten; clipped samples
// are counted per channel and reported; monitor says what it shows when the board is not
// sampling; the emulator refuses a rig with parts the board cannot have.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "run_cli.hpp"
#include "target.hpp"

namespace vibid::hil {
namespace {

using vibid::testing::CliResult;
using vibid::testing::RunVibid;

std::size_t Lines(const std::string& s) {
  return static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n'));
}

bool Has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// A recording's header row (its first line).
std::string ReadHeader(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

class RefusalTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (MakeTarget()->Name() != "emu") GTEST_SKIP() << "needs the emu target (a vibid-emu process)";
    emu = std::make_unique<EmulatorProcess>(EmulatorBinary());
    dir = vibid::testing::MakeTempDir("refusal");
  }
  void TearDown() override {
    std::error_code ec;
    if (!dir.empty()) std::filesystem::remove_all(dir, ec);
  }
  CliResult Vibid(std::vector<std::string> args) {
    args.insert(args.begin(), {"--device", emu->device_spec()});
    return RunVibid(args);
  }
  /// An observer for the 500 N load cell of examples/sensors.json at `fs_hz`; returns its file.
  std::string Design(const std::string& force_fs_n, const std::string& fs_hz = "5000") {
    const std::string design = dir + "/design_" + force_fs_n + "_" + fs_hz + ".json";
    const CliResult r = RunVibid({"dob", "design", VIBID_SOURCE_DIR "/examples/rig_nominal.json",
                                  "--force-fs-n", force_fs_n, "--fs-hz", fs_hz, "-o", design});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return design;
  }
  CliResult Upload(const std::string& design) {
    return Vibid({"cal", "upload", VIBID_SOURCE_DIR "/examples/rig_nominal.json", "--design",
                  design, "--sensors", VIBID_SOURCE_DIR "/examples/sensors.json"});
  }

  std::unique_ptr<EmulatorProcess> emu;
  std::string dir;
};

// A refusal: exit code, one line, the cause and the way out.
void ExpectRefusal(const CliResult& r, int exit_code, const std::string& cause,
                   const std::string& way_out) {
  EXPECT_EQ(r.exit_code, exit_code) << r.err;
  EXPECT_EQ(Lines(r.err), 1u) << "one line: " << r.err;
  EXPECT_TRUE(Has(r.err, cause)) << "cause '" << cause << "' in: " << r.err;
  EXPECT_TRUE(Has(r.err, way_out)) << "way out '" << way_out << "' in: " << r.err;
}

TEST_F(RefusalTest, DobStartBeforeAnyCalibration) {
  ExpectRefusal(Vibid({"dob", "start"}), 4, "the board's calibration holds no observer",
                "vibid cal upload MODEL.json --design DESIGN.json --sensors SENSORS.json");
}

TEST_F(RefusalTest, CalCommitWithNothingStaged) {
  ExpectRefusal(Vibid({"cal", "commit"}), 4, "no calibration record is staged",
                "stage one first (vibid cal upload");
}

TEST_F(RefusalTest, UnknownScenario) {
  const std::string out = dir + "/x.csv";
  const CliResult r = Vibid({"acquire", "--seconds", "0.1", "--scenario", "hamer", "-o", out});
  ExpectRefusal(r, 4, "refused select-scenario 'hamer': the emulator has no such scenario",
                "choose hammer, shaker, push, step, tone, operate or idle");
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST_F(RefusalTest, RateBeyondTheBoard) {
  ExpectRefusal(Vibid({"acquire", "--seconds", "0.1", "--rate-hz", "20000", "-o", dir + "/x.csv"}),
                1, "--rate-hz 20000: the board samples at 10000 Hz at most",
                "choose --rate-hz 10000 or less");
  ExpectRefusal(Vibid({"acquire", "--seconds", "0.1", "--rate-hz", "3000", "-o", dir + "/x.csv"}),
                1, "1000000 / 3000 = 333.333 is not", "choose a rate that divides 1000000");
}

TEST_F(RefusalTest, AcquireAtAnotherRateThanTheRunningObserver) {
  ASSERT_EQ(Upload(Design("500", "5000")).exit_code, 0);
  ASSERT_EQ(Vibid({"cal", "commit"}).exit_code, 0);
  ASSERT_EQ(Vibid({"dob", "start"}).exit_code, 0);
  const std::string out = dir + "/x.csv";
  const CliResult r = Vibid({"acquire", "--seconds", "0.5", "--rate-hz", "1000", "-o", out});
  // The host knows the board's rule (the calibration's observer and its rate) and refuses
  // before the board is configured, in the board's words (exit 1: the request, not the board).
  ExpectRefusal(r, 1, "--rate-hz 1000: the board's observer was designed for 5000 Hz",
                "acquire at --rate-hz 5000, or without the observer (--no-dob)");
  EXPECT_FALSE(std::filesystem::exists(out));
  // The ways out work.
  EXPECT_EQ(
      Vibid({"acquire", "--seconds", "0.5", "--rate-hz", "1000", "--no-dob", "-o", out}).exit_code,
      0);
  EXPECT_EQ(Vibid({"acquire", "--seconds", "0.5", "--rate-hz", "5000", "-o", out}).exit_code, 0);
  EXPECT_NE(ReadHeader(out).find("d_hat_q31"), std::string::npos) << "the running observer's";
  // Stopped, the observer estimates nothing: d_hat is not logged by default, so a plain
  // acquisition at any rate runs (and one the link carries only without d_hat: 1.6 s of every
  // channel at 5 kHz).
  ASSERT_EQ(Vibid({"dob", "stop"}).exit_code, 0);
  const CliResult plain = Vibid({"acquire", "--seconds", "0.5", "--rate-hz", "1000", "-o", out});
  EXPECT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_EQ(ReadHeader(out).find("d_hat"), std::string::npos) << ReadHeader(out);
  const CliResult fast = Vibid({"acquire", "--seconds", "1.6", "-o", out});
  EXPECT_EQ(fast.exit_code, 0) << fast.err;
  EXPECT_EQ(ReadHeader(out), "t_s,force1_n,force2_n,acc1_m_s2,acc2_m_s2,x1_m,x2_m");
}

// One range per channel: the default observer (100 N) against the 500 N cell is refused; the
// record is not staged, so the board keeps what it had.
TEST_F(RefusalTest, AnObserverForAnotherRangeDoesNotOverwriteTheSensors) {
  const CliResult r = Upload(Design("100"));
  ExpectRefusal(r, 1,
                "force1: the sensors give a full scale of 500 N, the observer's input 2 "
                "was designed for 100 N",
                "vibid dob design --force-fs-n 500");
  ExpectRefusal(Vibid({"cal", "commit"}), 4, "no calibration record is staged", "vibid cal upload");
  ASSERT_EQ(Upload(Design("500")).exit_code, 0);
  ASSERT_EQ(Vibid({"cal", "commit"}).exit_code, 0);
  const CliResult show = Vibid({"cal", "show"});
  EXPECT_TRUE(Has(show.out, "force1: 4.096 counts/N, offset 2048, full scale 500 N")) << show.out;
}

// Hammer hits of 0.6 to 1.4 x 900 N on mass 2: the ±500 N load cell and the ±200 m/s2
// accelerometer (1.53 kg: about 590 m/s2) sit at their converters' ends. The board counts each
// such sample; the counts equal the rows of the CSV at the converter's ends (codes 4095 or 0 with
// offset 2048: force1 499.756 or -500 N at 4.096 counts/N, acc2 199.902 or -200 m/s2 at 10.24
// counts/(m/s2), examples/sensors.json), and acquire and info say so.
TEST_F(RefusalTest, ClippedSamplesAreCountedAndReported) {
  ASSERT_EQ(Upload(Design("500")).exit_code, 0);
  ASSERT_EQ(Vibid({"cal", "commit"}).exit_code, 0);
  const std::string out = dir + "/hammer.csv";
  const CliResult r = Vibid({"acquire", "--seconds", "3", "--channels", "force1,acc2", "--scenario",
                             "hammer", "--scenario-param", "2,900,1,0", "--no-dob", "-o", out});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream csv(out);
  std::string line;
  while (std::getline(csv, line) && line.starts_with('#')) {
  }  // the recording's opening '#' lines (sampling instants)
  ASSERT_EQ(line, "t_s,force1_n,acc2_m_s2");
  std::size_t force_at_end = 0, accel_at_end = 0;
  while (std::getline(csv, line)) {
    std::istringstream fields(line);
    std::string t, f, a;
    std::getline(fields, t, ',');
    std::getline(fields, f, ',');
    std::getline(fields, a, ',');
    const double force_n = std::stod(f), accel_m_s2 = std::stod(a);
    if (force_n >= 499.7 || force_n <= -500.0) ++force_at_end;
    if (accel_m_s2 >= 199.85 || accel_m_s2 <= -200.0) ++accel_at_end;
  }
  ASSERT_GT(force_at_end, 0u) << "900 N hits must reach the converter's end";
  std::printf(
      "hammer 900 N on mass 2, 3 s at 5 kHz: force1 %zu and acc2 %zu of 15000 samples at "
      "the converter's end\n",
      force_at_end, accel_at_end);
  const std::string counts = "force1 " + std::to_string(force_at_end) + ", acc2 " +
                             std::to_string(accel_at_end) + " of 15000";
  EXPECT_TRUE(Has(r.err, "vibid: warning: clipped samples: " + counts)) << r.err;
  EXPECT_TRUE(Has(r.err, "force1 500 N, acc2 200 m/s2")) << r.err;
  const CliResult info = Vibid({"info"});
  EXPECT_TRUE(Has(info.out, "clipped       " + counts + " samples in the last acquisition"))
      << info.out;
}

TEST_F(RefusalTest, MonitorSaysWhatItShows) {
  const CliResult idle = Vibid({"monitor", "--count", "2", "--interval-s", "0.01"});
  ASSERT_EQ(idle.exit_code, 0) << idle.err;
  EXPECT_TRUE(Has(idle.out,
                  "-\tidle: no samples (the board samples only while an acquisition "
                  "runs)\n-\tidle: no samples"))
      << idle.out;
  ASSERT_EQ(Vibid({"acquire", "--seconds", "0.2", "-o", dir + "/x.csv"}).exit_code, 0);
  const CliResult after = Vibid({"monitor", "--count", "1", "--interval-s", "0.01"});
  ASSERT_EQ(after.exit_code, 0) << after.err;
  // 0.2 s at 5 kHz: ticks 0..999; the last frame is tick 999.
  EXPECT_TRUE(Has(after.out, "\n999\t")) << after.out;
  EXPECT_TRUE(Has(after.out, "stopped: the last frame of the acquisition that ended\n"))
      << after.out;
  ExpectRefusal(Vibid({"monitor", "--count", "1", "--interval-s", "0.001"}), 1,
                "a line takes two exchanges", "use 0.002 or more");
}

// The emulator is the board: a rig with 16-bit converters (the board's are 12-bit) is refused
// at start, naming the file, the field and the way out.
TEST(RigRefusal, ARigWithConvertersTheBoardCannotHaveIsRefused) {
  const std::string binary = EmulatorBinary();
  if (binary.empty()) GTEST_SKIP() << "no vibid-emu";
  const std::string dir = vibid::testing::MakeTempDir("rig-refusal");
  std::ifstream in(VIBID_SOURCE_DIR "/host/emulator/rigs/default.json");
  std::stringstream text;
  text << in.rdbuf();
  std::string rig = text.str();
  const std::size_t at = rig.find("\"adc_bits\": 12");
  ASSERT_NE(at, std::string::npos);
  rig.replace(at, 14, "\"adc_bits\": 16");
  const std::string path = dir + "/rig16.json";
  std::ofstream(path) << rig;
  const CliResult r = vibid::testing::RunProgram(binary, {"--rig", path, "--port", "0"});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(r.err, "vibid-emu: " + path +
                       " load_cells[0]: \"adc_bits\" is 16, but the board's converters have 12 "
                       "bits: write 12 (a finer sensor is quantized by the board's ADC)\n");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace vibid::hil
