// `vibid watch` against a vibid-emu process running the `operate` scenario on rigs that change
// while they run: on the board with a short reference and a large change, on a recording of the
// built-in 3 % mass step (rigs/chain2_mass_step.json, moved so a whole window precedes it), the
// options and the journal refused before the board starts, and Ctrl-C keeping the journal.
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "emulator_process.hpp"
#include "vibid/common/option_text.hpp"
#include "run_cli.hpp"
#include "state_wait.hpp"
#include "target.hpp"

namespace vibid::hil {
namespace {

using namespace std::chrono_literals;
using vibid::testing::ReadFileBytes;
using vibid::testing::RunVibid;
using vibid::testing::VibidProcess;

std::vector<nlohmann::json> JsonLines(const std::string& text) {
  std::vector<nlohmann::json> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(nlohmann::json::parse(line));
  return lines;
}

/// The built-in rig with the 3 % step of rigs/chain2_mass_step.json changed: `at_s`, `add_kg`.
std::string WriteRig(const std::string& dir, double at_s, double add_kg) {
  std::ifstream in(std::string(VIBID_SOURCE_DIR) + "/host/emulator/rigs/chain2_mass_step.json");
  nlohmann::json rig = nlohmann::json::parse(in);
  rig["changes"][0]["at_s"] = at_s;
  rig["changes"][0]["add_kg"] = add_kg;
  const std::string path = dir + "/rig.json";
  std::ofstream(path) << rig.dump(2);
  return path;
}

class WatchCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (MakeTarget()->Name() != "emu") GTEST_SKIP() << "needs the emu target (a vibid-emu process)";
    dir = vibid::testing::MakeTempDir("watch-cli");
  }
  void TearDown() override {
    std::error_code ec;
    if (!dir.empty()) std::filesystem::remove_all(dir, ec);
  }
  void StartEmulator(const std::string& rig) {
    emu =
        std::make_unique<EmulatorProcess>(EmulatorBinary(), std::vector<std::string>{"--rig", rig});
  }

  std::unique_ptr<EmulatorProcess> emu;
  std::string dir;
};

// 30 % on mass 2 at 300 s; the reference is the first 230 s, 5 s blocks, windows of 6: the
// windows ending at 260 s and 290 s are whole and before the change, and do not alarm; the window
// that holds the change (ending at 320 s) or the next one does. Every line is JSON with the keys,
// the same lines in the journal.
TEST_F(WatchCliTest, OnTheBoardALargeChangeIsFlaggedByItsWindow) {
  constexpr double kChangeS = 300.0;
  constexpr double kWindowS = 6 * 5.0;
  StartEmulator(WriteRig(dir, kChangeS, 0.459));
  const std::string journal = dir + "/watch.jsonl";
  const auto r = RunVibid({"--device", emu->device_spec(), "watch", "--seconds",
                           "380",      "--rate-hz",        "200",   "--scenario",
                           "operate",  "--reference-s",    "230",   "--block-s",
                           "5",        "--window-blocks",  "6",     "--modes-s",
                           "0",        "--json",           "-o",    journal});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("vibid: reference of 230 s: modes 4.4"), std::string::npos) << r.err;
  std::vector<nlohmann::json> lines = JsonLines(r.out);
  ASSERT_EQ(lines.size(), 31u) << r.out;  // the header, then (380 − 230) / 5 blocks
  EXPECT_EQ(ReadFileBytes(journal), r.out);
  // The first line says what was watched: the options, the reference's span and source, its
  // modes with intervals, the thresholds, the board's model test as it stood at the start.
  const nlohmann::json header = lines.front();
  lines.erase(lines.begin());
  EXPECT_EQ(header["header"], "vibid watch") << header.dump();
  EXPECT_EQ(header["options"]["window_blocks"], 6);
  EXPECT_DOUBLE_EQ(header["options"]["fs_hz"].get<double>(), 200.0);
  EXPECT_EQ(header["reference"]["source"], "watched");
  EXPECT_DOUBLE_EQ(header["reference"]["span"]["from_t_s"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(header["reference"]["span"]["to_t_s"].get<double>(), 230.0 - 0.005);
  ASSERT_EQ(header["reference"]["modes"].size(), 2u) << header.dump();
  EXPECT_GT(header["reference"]["modes"][0]["ci95"]["omega_rad_s"].get<double>(), 0.0);
  EXPECT_GT(header["reference"]["window_threshold"].get<double>(), 0.0);
  EXPECT_TRUE(header.contains("model_stale"));
  EXPECT_NE(r.err.find("alarms over " +
                       OptionNumber(header["reference"]["window_threshold"].get<double>())),
            std::string::npos)
      << "stderr says the journal's threshold: " << r.err;
  int whole_windows_before = 0;
  for (const nlohmann::json& j : lines) {
    for (const char* key : {"t_s", "modes", "statistic", "f_quantile", "alarm", "accumulated",
                            "first_alarm_t_s", "moved"})
      EXPECT_TRUE(j.contains(key)) << key << " in " << j.dump();
    if (j["t_s"].get<double>() <= kChangeS - 5.0) {
      EXPECT_FALSE(j["alarm"].get<bool>()) << j.dump();
      EXPECT_FALSE(j["accumulated"]["alarm"].get<bool>()) << j.dump();
      if (j["accumulated"]["blocks"] == j["accumulated"]["window_blocks"]) ++whole_windows_before;
    }
  }
  // The check above judged whole windows, not only partial ones.
  EXPECT_EQ(whole_windows_before, 2) << r.out;
  EXPECT_DOUBLE_EQ(lines.front()["t_s"].get<double>(), 235.0);
  const nlohmann::json& last = lines.back();
  ASSERT_FALSE(last["first_alarm_t_s"].is_null()) << r.out;
  const double first = last["first_alarm_t_s"].get<double>();
  EXPECT_GT(first, kChangeS);
  EXPECT_LE(first, kChangeS + 2 * kWindowS) << "within two windows of the change";
}

// The acceptance case on a recording: the built-in 3 % step (0.0459 kg on mass 2), here at
// 2 650 s so that a whole default window (60 blocks of 10 s after the default 30-minute
// reference, ending at 2 400 s) lies before it and is seen not to alarm; 3 850 s of the rig in
// operation at 200 Hz.
// A window after the step alarms, within 120 blocks (two windows) of it, and the sequential test
// before it.
TEST_F(WatchCliTest, OnARecordingTheBuiltInThreePercentStepIsFlagged) {
  constexpr double kStepS = 2650.0;
  StartEmulator(WriteRig(dir, kStepS, 0.0459));
  const std::string rec = dir + "/operate.csv";
  const auto acquire =
      RunVibid({"--device", emu->device_spec(), "acquire", "--seconds", "3850", "--rate-hz", "200",
                "--channels", "acc1,acc2", "--scenario", "operate", "-o", rec});
  ASSERT_EQ(acquire.exit_code, 0) << acquire.err;
  // The default 30-minute reference: one of 590 s leaves a window's threshold that holds the
  // rate asked for its reference (45.9, where F gives 37.3) over what a 3 % step gives.
  const auto r = RunVibid({"watch", rec, "--modes-s", "0", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The rate this reference gives, stated with it (the calibration's band at these sizes: 8
  // residuals over 144 blocks, windows of 60 at 0.01 per hour), and the longer reference that
  // would narrow it.
  EXPECT_NE(r.err.find("this reference gives between 1.8e-05 and 0.01 false alarms per hour "
                       "(95 %); a reference of 10800 s would give at least 0.0024"),
            std::string::npos)
      << r.err;
  std::vector<nlohmann::json> lines = JsonLines(r.out);
  ASSERT_EQ(lines.size(), 206u) << r.out;  // the header, then (3850 − 1800) / 10 blocks
  EXPECT_EQ(lines.front()["reference"]["source"], "watched") << lines.front().dump();
  lines.erase(lines.begin());
  std::optional<double> first;
  std::optional<double> first_window;
  int whole_windows_before = 0;
  for (const nlohmann::json& j : lines) {
    const double t_s = j["t_s"].get<double>();
    if (t_s <= kStepS) {
      EXPECT_FALSE(j["alarm"].get<bool>()) << j.dump();
      if (j["accumulated"]["blocks"] == j["accumulated"]["window_blocks"]) ++whole_windows_before;
    }
    if (j["alarm"].get<bool>() && !first) first = t_s;
    if (j["accumulated"]["alarm"].get<bool>() && !first_window) first_window = t_s;
  }
  EXPECT_EQ(whole_windows_before, 1) << "the window ending at 2 400 s is judged whole";
  ASSERT_TRUE(first.has_value()) << r.out;
  EXPECT_GT(*first, kStepS);
  EXPECT_LE(*first, kStepS + 120 * 10.0);
  // The sequential test alarms before the window after the step is full (at 3 180 s, its onset
  // 53 blocks back: the step's own block; the window at 3 600 s).
  ASSERT_TRUE(first_window.has_value()) << r.out;
  EXPECT_LT(*first, *first_window);
}

TEST_F(WatchCliTest, BadOptionsAndAnUnwritableJournalAreRefusedBeforeTheBoardStarts) {
  StartEmulator(WriteRig(dir, 240.0, 0.459));
  const auto short_block = RunVibid({"--device", emu->device_spec(), "watch", "--rate-hz", "200",
                                     "--block-s", "1", "--scenario", "operate"});
  EXPECT_EQ(short_block.exit_code, 1) << short_block.err;
  EXPECT_NE(short_block.err.find("--block-s 1 is too short for the band"), std::string::npos)
      << short_block.err;
  const auto short_ref = RunVibid({"--device", emu->device_spec(), "watch", "--rate-hz", "200",
                                   "--reference-s", "60", "--scenario", "operate"});
  EXPECT_EQ(short_ref.exit_code, 1) << short_ref.err;
  EXPECT_NE(short_ref.err.find("--reference-s 60 is too short"), std::string::npos)
      << short_ref.err;
  const auto journal = RunVibid({"--device", emu->device_spec(), "watch", "--rate-hz", "200",
                                 "--scenario", "operate", "-o", dir + "/no/such/dir/j.jsonl"});
  EXPECT_EQ(journal.exit_code, 1) << journal.err;
  EXPECT_NE(journal.err.find("cannot create the journal"), std::string::npos) << journal.err;
  EXPECT_EQ(emu->Log().find("sampling started"), std::string::npos) << emu->Log();
}

// Until Ctrl-C: once the journal holds blocks, SIGINT stops the board; exit 130, every line of
// the journal whole and the same as printed.
TEST_F(WatchCliTest, CtrlCStopsTheBoardAndKeepsTheJournal) {
  StartEmulator(WriteRig(dir, 240.0, 0.459));
  const std::string journal = dir + "/watch.jsonl";
  VibidProcess watch({"--device", emu->device_spec(), "watch", "--rate-hz", "200", "--scenario",
                      "operate", "--reference-s", "230", "--block-s", "5", "--window-blocks", "6",
                      "--modes-s", "0", "--json", "-o", journal});
  // Wait for a state (two whole lines in the journal), not for a time.
  const auto deadline = std::chrono::steady_clock::now() + hil::kStateWait;
  for (;;) {
    const std::string text = std::filesystem::exists(journal) ? ReadFileBytes(journal) : "";
    if (std::count(text.begin(), text.end(), '\n') >= 2) break;
    ASSERT_LT(std::chrono::steady_clock::now(), deadline)
        << "waited " << hil::kStateWait.count() << " s for two journal lines:\n"
        << emu->Log();
    std::this_thread::sleep_for(20ms);
  }
  watch.Signal(SIGINT);
  const auto r = watch.Wait();
  EXPECT_EQ(r.exit_code, 130) << r.err;
  EXPECT_NE(r.err.find("vibid: Ctrl-C: stopping the acquisition; the journal is kept"),
            std::string::npos)
      << r.err;
  const std::string kept = ReadFileBytes(journal);
  ASSERT_FALSE(kept.empty());
  EXPECT_EQ(kept.back(), '\n');
  const std::vector<nlohmann::json> lines = JsonLines(kept);
  EXPECT_GE(lines.size(), 2u);
  EXPECT_EQ(kept, r.out) << "printed and journaled alike";
  EXPECT_TRUE(emu->AwaitLog("sampling stopped", 1, hil::kStateWait))
      << "waited " << hil::kStateWait.count() << " s for the board to stop:\n"
      << emu->Log();
}

}  // namespace
}  // namespace vibid::hil
