// Faults as a user meets them at the command line: the `vibid` binary against a vibid-emu process
// that dies mid-pull, and Ctrl-C during an acquisition (the emulator runs in real time here, so a
// 60 s acquisition is certainly still being pulled when the fault comes); and against the core
// target's in-process firmware, reached over a serial socket, with faults injected on its
// answers: another protocol major, corrupted, truncated and lost reports, an unknown command.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "run_cli.hpp"
#include "serial_bridge.hpp"
#include "state_wait.hpp"
#include "target.hpp"

namespace vibid::hil {
namespace {

using namespace std::chrono_literals;
using vibid::testing::ReadFileBytes;
using vibid::testing::RunVibid;
using vibid::testing::VibidProcess;

std::vector<std::string> FilesIn(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

class CliFaultTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // The suite's target picks the case: only a vibid-emu process can be killed or signalled
    // around from outside while a separate `vibid` process talks to it.
    if (MakeTarget()->Name() != "emu") GTEST_SKIP() << "needs the emu target (a vibid-emu process)";
    emu =
        std::make_unique<EmulatorProcess>(EmulatorBinary(), std::vector<std::string>{"--realtime"});
    dir = vibid::testing::MakeTempDir("cli-fault");
  }
  void TearDown() override {
    std::error_code ec;
    if (!dir.empty()) std::filesystem::remove_all(dir, ec);
  }

  /// `vibid acquire` for 60 s into `output`, returned once the board samples (the emulator says
  /// so): the acquisition is configured, started and being pulled.
  std::unique_ptr<VibidProcess> StartAcquire(const std::string& output) {
    auto p = std::make_unique<VibidProcess>(
        std::vector<std::string>{"--device", emu->device_spec(), "acquire", "--seconds", "60",
                                 "--channels", "force1,acc1,acc2", "-o", output});
    EXPECT_TRUE(emu->AwaitLog("vibid-emu: sampling started", 1, hil::kStateWait))
        << "waited " << hil::kStateWait.count() << " s for the board to sample:\n"
        << emu->Log();
    return p;
  }

  std::unique_ptr<EmulatorProcess> emu;
  std::string dir;
};

TEST_F(CliFaultTest, EmulatorKilledMidPullLeavesTheOutputUntouched) {
  const std::string output = dir + "/OUT.csv";
  const std::string previous = "t_s,x1_m\n0,0.001\n0.0002,0.0015\n";
  std::ofstream(output, std::ios::binary) << previous;
  auto acquire = StartAcquire(output);
  const std::string spec = emu->device_spec();
  emu->Kill();
  const auto r = acquire->Wait();
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
  EXPECT_EQ(r.err.rfind("vibid: error: lost the device", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(spec), std::string::npos) << "names the device: " << r.err;
  EXPECT_EQ(ReadFileBytes(output), previous);
  EXPECT_EQ(FilesIn(dir), std::vector<std::string>{"OUT.csv"}) << "no temporary file left";
}

/// A recording's header row and data rows (its opening '#' lines left out).
std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.starts_with('#')) lines.push_back(line);
  }
  return lines;
}

/// The acquisition state a `monitor` line reports (its last column).
std::string BoardState(const std::string& device_spec) {
  const auto monitor = RunVibid({"--device", device_spec, "monitor", "--count", "1"});
  EXPECT_EQ(monitor.exit_code, 0) << monitor.err;
  const std::vector<std::string> lines = Lines(monitor.out);
  return lines.empty() ? "" : lines.back().substr(lines.back().rfind('\t') + 1);
}

TEST_F(CliFaultTest, CtrlCStopsTheAcquisitionAndKeepsTheRecord) {
  const std::string output = dir + "/REC.csv";
  auto acquire = StartAcquire(output);
  acquire->Signal(SIGINT);
  const auto r = acquire->Wait();
  EXPECT_EQ(r.exit_code, 130) << "128 + SIGINT, as the shell reports an interrupt: " << r.err;
  // The record: 5 kHz rows from t = 0, none missing or repeated where the stream was cut and
  // the log read on.
  const std::vector<std::string> rows = Lines(ReadFileBytes(output));
  ASSERT_GT(rows.size(), 1u) << r.err;
  EXPECT_EQ(rows[0], "t_s,force1_counts,acc1_counts,acc2_counts");
  const std::size_t records = rows.size() - 1;
  EXPECT_GT(records, 0u) << "what the board sampled before the Ctrl-C";
  EXPECT_LT(records, 60u * 5000u) << "stopped well before the 60 s";
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const double t_s = std::stod(rows[i].substr(0, rows[i].find(',')));
    ASSERT_NEAR(t_s, static_cast<double>(i - 1) * 0.0002, 1e-9) << "row " << i;
  }
  char kept[160];
  std::snprintf(kept, sizeof kept,
                "vibid: stopped by Ctrl-C: kept %zu records (%.3f s at 5000 Hz) in ", records,
                static_cast<double>(records) / 5000.0);
  EXPECT_NE(r.err.find(std::string(kept) + output + "\n"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.rfind("vibid: Ctrl-C: stopping the acquisition, keeping what it recorded", 0), 0u)
      << r.err;
  EXPECT_EQ(FilesIn(dir), (std::vector<std::string>{"REC.csv", "REC.csv.json"}))
      << "the recording and its sidecar, no temporary file left";
  EXPECT_EQ(BoardState(emu->device_spec()),
            "stopped: the last frame of the acquisition that was stopped");
}

// A board another program holds: named as in use, by that program (this machine can tell), with
// the way out; free again once it ends.
TEST_F(CliFaultTest, ABusyBoardIsNamedInUseByWhatHoldsIt) {
  auto acquire = StartAcquire(dir + "/HELD.csv");
  const auto info = RunVibid({"--device", emu->device_spec(), "info"});
  EXPECT_EQ(info.exit_code, 4) << info.err;
  EXPECT_EQ(info.err, "vibid: error: the board at " + emu->device_spec() + " is in use by vibid " +
                          "--device " + emu->device_spec() + " acquire --seconds 60 --channels " +
                          "force1,acc1,acc2 -o " + dir + "/HELD.csv (pid " +
                          std::to_string(acquire->pid()) +
                          "): close it, or wait until it ends, and try again\n");
  acquire->Signal(SIGINT);
  EXPECT_EQ(acquire->Wait().exit_code, 130);
  EXPECT_EQ(RunVibid({"--device", emu->device_spec(), "info"}).exit_code, 0) << "free again";
}

TEST_F(CliFaultTest, AnOutputThatCannotBeWrittenIsRefusedBeforeTheBoardStarts) {
  for (const std::vector<std::string>& command :
       {std::vector<std::string>{"acquire", "--seconds", "60", "-o", dir + "/nodir/x.csv"},
        std::vector<std::string>{"log", "pull", "-o", dir + "/nodir/x.csv"},
        std::vector<std::string>{"acquire", "--seconds", "60", "-o", dir}}) {
    std::vector<std::string> args = {"--device", emu->device_spec()};
    args.insert(args.end(), command.begin(), command.end());
    const auto r = RunVibid(args);
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_EQ(r.err.rfind("vibid: error: cannot write '" + command.back() + "': ", 0), 0u) << r.err;
  }
  // Refused before the device was even opened.
  EXPECT_EQ(emu->Log().find("USB/IP client imported"), std::string::npos) << emu->Log();
  EXPECT_TRUE(FilesIn(dir).empty());
}

class CliTriggerTest : public CliFaultTest {
 protected:
  /// The nominal model, its observer and the example sensors on the board: force triggers in N.
  void Calibrate() {
    const std::string design = dir + "/design.json";
    ASSERT_EQ(RunVibid({"dob", "design", VIBID_SOURCE_DIR "/examples/rig_nominal.json",
                        "--force-fs-n", "500", "-o", design})
                  .exit_code,
              0);
    const auto up = RunVibid({"--device", emu->device_spec(), "cal", "upload",
                              VIBID_SOURCE_DIR "/examples/rig_nominal.json", "--design", design,
                              "--sensors", VIBID_SOURCE_DIR "/examples/sensors.json"});
    ASSERT_EQ(up.exit_code, 0) << up.err;
    ASSERT_EQ(RunVibid({"--device", emu->device_spec(), "cal", "commit"}).exit_code, 0);
    std::filesystem::remove(design);
  }
};

// The rig at rest never reaches 40 N: the wait says so every second, and the timeout ends it.
TEST_F(CliTriggerTest, AWaitForTheTriggerSaysSoAndTimesOut) {
  Calibrate();
  const std::string output = dir + "/T.csv";
  const auto r = RunVibid({"--device", emu->device_spec(), "acquire", "--seconds", "1",
                           "--channels", "force1,acc1", "--trigger", "force>40",
                           "--trigger-timeout-s", "2.5", "-o", output});
  EXPECT_EQ(r.exit_code, 4) << r.err;
  const std::vector<std::string> lines = Lines(r.err);
  ASSERT_GE(lines.size(), 3u) << r.err;
  for (std::size_t i = 0; i + 1 < lines.size(); ++i) {
    EXPECT_EQ(
        lines[i].rfind("vibid: waiting for the trigger on load cell 1: force1 > 40 N, now ", 0), 0u)
        << lines[i];
  }
  EXPECT_EQ(lines.back(),
            "vibid: error: the trigger did not fire within 2.5 s (--trigger-timeout-s): "
            "acquisition stopped before anything was recorded, nothing written");
  EXPECT_FALSE(std::filesystem::exists(output));
  EXPECT_EQ(BoardState(emu->device_spec()),
            "stopped: the last frame of the acquisition that was stopped");
}

TEST_F(CliTriggerTest, CtrlCStopsAWaitForTheTrigger) {
  Calibrate();
  const std::string output = dir + "/T.csv";
  VibidProcess acquire({"--device", emu->device_spec(), "acquire", "--seconds", "1", "--channels",
                        "force1,acc1", "--trigger", "force>40", "-o", output});
  // Armed: the board samples, waiting for the trigger (the calibration's acquisitions came before).
  ASSERT_TRUE(emu->AwaitLog("vibid-emu: sampling started", 1, hil::kStateWait))
      << "waited " << hil::kStateWait.count() << " s for the board to arm:\n"
      << emu->Log();
  acquire.Signal(SIGINT);
  const auto r = acquire.Wait();
  EXPECT_EQ(r.exit_code, 130) << r.err;
  EXPECT_NE(r.err.find("vibid: stopped by Ctrl-C: acquisition stopped before anything was "
                       "recorded (the trigger had not fired), nothing written\n"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(output));
  EXPECT_EQ(BoardState(emu->device_spec()),
            "stopped: the last frame of the acquisition that was stopped");
}

// --device before or after the command, or VIBID_DEVICE: the same board; the option wins.
TEST_F(CliFaultTest, DeviceOptionEitherSideOfTheCommandAndFromTheEnvironment) {
  const std::string spec = emu->device_spec();
  const auto before = RunVibid({"--device", spec, "info", "--json"});
  ASSERT_EQ(before.exit_code, 0) << before.err;
  const auto after = RunVibid({"info", "--json", "--device", spec});
  ASSERT_EQ(after.exit_code, 0) << after.err;
  EXPECT_EQ(after.out, before.out);
  EXPECT_EQ(RunVibid({"--device", spec, "info", "--device", spec}).exit_code, 2) << "given twice";
  EXPECT_EQ(RunVibid({"modal", VIBID_SOURCE_DIR "/examples/rig_nominal.json", "--device", spec})
                .exit_code,
            2)
      << "not a device command";

  ::setenv("VIBID_DEVICE", spec.c_str(), 1);
  const auto from_variable = RunVibid({"info", "--json"});
  const auto probed = RunVibid({"devices"});
  ::setenv("VIBID_DEVICE", "usbip://127.0.0.1:1", 1);
  const auto option_wins = RunVibid({"info", "--json", "--device", spec});
  const auto nothing_there = RunVibid({"devices"});
  ::unsetenv("VIBID_DEVICE");
  EXPECT_EQ(from_variable.exit_code, 0) << from_variable.err;
  EXPECT_EQ(from_variable.out, before.out);
  EXPECT_EQ(option_wins.exit_code, 0) << option_wins.err;
  EXPECT_EQ(option_wins.out, before.out);
  ASSERT_EQ(probed.exit_code, 0) << probed.err;
  EXPECT_EQ(probed.out.rfind(spec + "\temulator, firmware ", 0), 0u) << probed.out;
  EXPECT_EQ(nothing_there.exit_code, 4);
  EXPECT_EQ(nothing_there.err,
            "vibid: error: no vibid board answers at usbip://127.0.0.1:1 (from VIBID_DEVICE): no "
            "USB/IP server at 127.0.0.1:1 (is vibid-emu running?)\n");
}

// A pull broken off by the host (the `vibid` process killed outright) loses nothing on the board:
// the next `log pull` returns the acquisition's log again, and `--from N` resumes at record N.
TEST(CliPullTest, PullKilledMidwayIsRepeatedAndResumedWithNothingLostOrDuplicated) {
  if (MakeTarget()->Name() != "emu") GTEST_SKIP() << "needs the emu target (a vibid-emu process)";
  // In real time, so the pull (1000 reports, one per 1 ms frame) is still going when it is killed.
  EmulatorProcess emu(EmulatorBinary(), {"--realtime"});
  const std::string dir = vibid::testing::MakeTempDir("cli-pull");
  const std::string acquired = dir + "/acquired.csv", pulled = dir + "/pulled.csv",
                    tail = dir + "/tail.csv";
  // 1.6 s at 5 kHz of three channels (10 bytes a record in the board's RAM): 8000 records, all
  // still in the 96 KiB log (9830) when the pulls below ask for them.
  const auto a = RunVibid({"--device", emu.device_spec(), "acquire", "--seconds", "1.6",
                           "--channels", "force1,acc1,acc2", "-o", acquired});
  ASSERT_EQ(a.exit_code, 0) << a.err;
  const std::vector<std::string> rows = Lines(ReadFileBytes(acquired));
  ASSERT_EQ(rows.size(), 8001u) << "header and 1.6 s at 5 kHz";

  const int imports = 2;  // the acquire above, then the pull about to be killed
  {
    VibidProcess pull({"--device", emu.device_spec(), "log", "pull", "-o", pulled});
    ASSERT_TRUE(emu.AwaitLog("USB/IP client imported", imports, hil::kStateWait))
        << "waited " << hil::kStateWait.count() << " s for the pull to import the board:\n"
        << emu.Log();
    std::this_thread::sleep_for(100ms);
    pull.Signal(SIGKILL);
    EXPECT_EQ(pull.Wait().exit_code, 128 + SIGKILL);
  }
  EXPECT_FALSE(std::filesystem::exists(pulled)) << "a killed pull leaves no output";

  const auto again = RunVibid({"--device", emu.device_spec(), "log", "pull", "-o", pulled});
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(ReadFileBytes(pulled), ReadFileBytes(acquired))
      << "the whole log again, record for record";

  const auto resumed =
      RunVibid({"--device", emu.device_spec(), "log", "pull", "--from", "6000", "-o", tail});
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  const std::vector<std::string> tail_rows = Lines(ReadFileBytes(tail));
  ASSERT_EQ(tail_rows.size(), 2001u);
  EXPECT_EQ(tail_rows.front(), rows.front());
  EXPECT_TRUE(std::equal(tail_rows.begin() + 1, tail_rows.end(), rows.begin() + 6001))
      << "records 6000.. as acquired";
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
}

class CliCoreFaultTest : public ::testing::Test {
 protected:
  void SetUp() override {
    target = MakeTarget();
    loop = target->loopback();
    if (loop == nullptr) GTEST_SKIP() << "needs fault injection (the core target)";
    dir = vibid::testing::MakeTempDir("cli-core");
    bridge = std::make_unique<SerialBridge>([this] { return loop->Connect(); }, dir + "/core.sock");
  }
  void TearDown() override {
    bridge.reset();
    std::error_code ec;
    if (!dir.empty()) std::filesystem::remove_all(dir, ec);
  }
  vibid::testing::CliResult Vibid(std::vector<std::string> args) {
    args.insert(args.begin(), {"--device", bridge->device_spec()});
    return RunVibid(args);
  }

  std::unique_ptr<Target> target;
  CoreLoopback* loop = nullptr;
  std::string dir;
  std::unique_ptr<SerialBridge> bridge;
};

TEST_F(CliCoreFaultTest, AnotherProtocolMajorIsRefusedNamingBothVersions) {
  loop->SetProtocolMajor(wire::kProtocolMajor + 1);
  const auto r = Vibid({"info"});
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_EQ(r.err,
            "vibid: error: the device speaks protocol 3.x, this host speaks 2." +
                std::to_string(wire::kProtocolMinor) +
                ": flash firmware that matches this host (vibid flash) or use a matching host\n");
  EXPECT_TRUE(r.out.empty()) << r.out;
}

TEST_F(CliCoreFaultTest, CorruptedAndTruncatedAnswersAreRetriedUnseen) {
  const auto clean = Vibid({"info"});
  ASSERT_EQ(clean.exit_code, 0) << clean.err;
  loop->CorruptNext(1);
  loop->TruncateNext(1);
  const auto r = Vibid({"info"});
  EXPECT_FALSE(loop->FaultsPending()) << "both faults reached the link";
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, clean.out) << "the same answer in the end";
  EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST_F(CliCoreFaultTest, AnswersThatNeverComeFailWithOneLine) {
  loop->DropNext(100);
  const auto r = Vibid({"info"});
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("no answer to get-info"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(bridge->device_spec()), std::string::npos) << "names the device: " << r.err;
}

// The host stops receiving the acquisition's stream for longer than its timeout while the board
// goes on sending (and releasing) records: the log wraps over the ones it missed. Every record
// the board still holds is pulled and written, and the command fails naming what is missing.
TEST_F(CliCoreFaultTest, AcquisitionThatLostRecordsWritesWhatWasKeptAndNamesTheRest) {
  loop->SetFramesPerStep(20);
  loop->DropStreamReports(100, 1 << 30);  // until the host gives up on the stream
  const std::string out = dir + "/rec.csv";
  const auto r = Vibid({"acquire", "--seconds", "10", "--rate-hz", "1000", "-o", out});
  EXPECT_EQ(r.exit_code, 4) << r.err;
  const std::size_t why = r.err.find("vibid: error: the board's log wrapped over records ");
  ASSERT_NE(why, std::string::npos) << r.err;
  const std::size_t kept_at = r.err.find("before they could be pulled; kept ", why);
  ASSERT_NE(kept_at, std::string::npos) << r.err;
  const std::size_t kept = std::stoul(r.err.substr(kept_at + 34));
  EXPECT_GT(kept, 0u);
  EXPECT_LT(kept, 10000u);
  EXPECT_NE(r.err.find("records: 0.."), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("..9999; the records kept are written to " + out), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("vibid: " + std::to_string(kept) + " records"), std::string::npos) << r.err;
  const std::vector<std::string> rows = Lines(ReadFileBytes(out));
  EXPECT_EQ(rows.size(), kept + 1) << "the header and every record kept";
}

TEST_F(CliCoreFaultTest, UnknownCommandNamesItAndWritesNothing) {
  // The scenario command exists on the emulator only; this board answers unimplemented.
  const auto r =
      Vibid({"acquire", "--seconds", "0.1", "--scenario", "hammer", "-o", dir + "/rec.csv"});
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("select-scenario"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("does not know this command"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/rec.csv"));
}

}  // namespace
}  // namespace vibid::hil
