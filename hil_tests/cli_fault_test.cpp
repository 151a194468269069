// Faults as a user meets them at the command line: the `vibid` binary against a vibid-emu process
// that dies mid-pull, and Ctrl-C during an acquisition (the emulator runs in real time here, so a
// 60 s acquisition is certainly still being pulled when the fault comes); and against the core
// target's in-process firmware, reached over a serial socket, with faults injected on its
// answers: another protocol major, corrupted, truncated and lost reports, an unknown command.
#include <gtest/gtest.h>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "run_cli.hpp"
#include "serial_bridge.hpp"
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

  /// `vibid acquire` for 60 s into `output`, returned once it imported the device and had time to
  /// configure, start and begin pulling.
  std::unique_ptr<VibidProcess> StartAcquire(const std::string& output) {
    auto p = std::make_unique<VibidProcess>(
        std::vector<std::string>{"--device", emu->device_spec(), "acquire", "--seconds", "60",
                                 "--channels", "force1,acc1,acc2", "-o", output});
    EXPECT_TRUE(emu->AwaitLog("USB/IP client imported", 1, 5s)) << emu->Log();
    std::this_thread::sleep_for(300ms);
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

TEST_F(CliFaultTest, CtrlCStopsTheAcquisitionAndWritesNothing) {
  const std::string output = dir + "/REC.csv";
  auto acquire = StartAcquire(output);
  acquire->Signal(SIGINT);
  const auto r = acquire->Wait();
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(r.exit_code, 4) << "the device exit code, not death by the signal: " << r.err;
  EXPECT_EQ(r.err, "vibid: error: interrupted: acquisition stopped, nothing written\n");
  EXPECT_TRUE(FilesIn(dir).empty()) << "no partial file";
  // The board is idle: a monitor line reports its acquisition state.
  const auto monitor = RunVibid({"--device", emu->device_spec(), "monitor", "--count", "1"});
  ASSERT_EQ(monitor.exit_code, 0) << monitor.err;
  const std::string last_line =
      monitor.out.substr(monitor.out.rfind('\n', monitor.out.size() - 2) + 1);
  EXPECT_EQ(last_line.substr(last_line.rfind('\t') + 1), "idle\n") << monitor.out;
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
    ASSERT_TRUE(emu.AwaitLog("USB/IP client imported", imports, 5s)) << emu.Log();
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
