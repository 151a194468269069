// The board's own model test end to end on a vibid-emu process: an observer designed from the
// rig's truth and uploaded, a calibration day recorded with it running under the `operate`
// scenario, the test built into the record from that day (`cal upload --watch-day`), then the
// built-in 3 % mass step (rigs/chain2_mass_step.json, at 600 s) run under the same scenario: the
// log's model columns stay clear before the step and turn stale after it, `vibid info --json`
// says when it tripped, and an unchanged rig keeps the flag down.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "emulator_process.hpp"
#include "run_cli.hpp"
#include "target.hpp"
#include "vibid/common/csv.hpp"

namespace vibid::hil {
namespace {

using vibid::testing::RunVibid;

class ModelStaleTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (MakeTarget()->Name() != "emu") GTEST_SKIP() << "needs the emu target (a vibid-emu process)";
    dir = vibid::testing::MakeTempDir("model-stale");
  }
  void TearDown() override {
    std::error_code ec;
    if (!dir.empty()) std::filesystem::remove_all(dir, ec);
  }
  vibid::testing::CliResult Vibid(std::vector<std::string> args) {
    args.insert(args.begin(), {"--device", emu->device_spec()});
    return RunVibid(args);
  }
  // The observer (force 1 and the last mass's position, 1 kHz) from the rig's truth, running,
  // and the test designed from `day_s` seconds of the rig in operation.
  void Calibrate(const std::string& rig, double day_s) {
    emu =
        std::make_unique<EmulatorProcess>(EmulatorBinary(), std::vector<std::string>{"--rig", rig});
    const std::string model = dir + "/truth.json";
    const auto printed =
        vibid::testing::RunProgram(EmulatorBinary(), {"--rig", rig, "--print-truth"});
    ASSERT_EQ(printed.exit_code, 0) << printed.err;
    std::ofstream(model) << printed.out;
    const std::string sensors = std::string(VIBID_SOURCE_DIR) + "/examples/sensors.json";
    ASSERT_EQ(RunVibid({"dob", "design", model, "--fs-hz", "1000", "--sensors", sensors, "-o",
                        dir + "/design.json"})
                  .exit_code,
              0);
    const auto up =
        Vibid({"cal", "upload", model, "--design", dir + "/design.json", "--sensors", sensors});
    ASSERT_EQ(up.exit_code, 0) << up.err;
    ASSERT_EQ(Vibid({"cal", "commit"}).exit_code, 0);
    ASSERT_EQ(Vibid({"dob", "start"}).exit_code, 0);
    const std::string day = dir + "/day.csv";
    const auto rec = Vibid({"acquire", "--seconds", std::to_string(day_s), "--rate-hz", "1000",
                            "--channels", "force1,x2", "--scenario", "operate", "-o", day});
    ASSERT_EQ(rec.exit_code, 0) << rec.err;
    const auto with_test = Vibid({"cal", "upload", model, "--design", dir + "/design.json",
                                  "--sensors", sensors, "--watch-day", day});
    ASSERT_EQ(with_test.exit_code, 0) << with_test.err;
    design_text = with_test.out;
    ASSERT_EQ(Vibid({"cal", "commit"}).exit_code, 0);
    ASSERT_EQ(Vibid({"dob", "start"}).exit_code, 0);
  }

  std::unique_ptr<EmulatorProcess> emu;
  std::string dir;
  std::string design_text;
};

// The 3 % step at 600 s: the first record logged stale comes after it, within the run, and the
// board's own trip time says the same.
TEST_F(ModelStaleTest, TheBuiltInThreePercentStepTripsTheBoardsFlag) {
  Calibrate(std::string(VIBID_SOURCE_DIR) + "/host/emulator/rigs/chain2_mass_step.json", 500.0);
  EXPECT_NE(design_text.find("model test: windows of"), std::string::npos) << design_text;
  const std::string run = dir + "/run.csv";
  const auto r = Vibid({"acquire", "--seconds", "1200", "--rate-hz", "1000", "--log-rate-hz", "200",
                        "--channels", "acc1,acc2", "--scenario", "operate", "-o", run});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Recording rec = LoadRecording(run);
  ASSERT_TRUE(rec.table.Has("model_g") && rec.table.Has("model_stale"));
  const Eigen::VectorXd& stale = rec.table.Column("model_stale");
  const Eigen::VectorXd t = rec.Time();
  Eigen::Index first = -1;
  for (Eigen::Index i = 0; i < stale.size() && first < 0; ++i)
    if (stale(i) != 0.0) first = i;
  ASSERT_GE(first, 0) << "never stale; " << design_text;
  std::printf("the 3 %% step at 600 s: logged stale from %.2f s\n", t(first));
  // benchmarks/watch/board_flag_study.py: over seeds the flag trips 1 to 5 minutes after the step
  // (docs/dob.md); this seed's run is one of them.
  EXPECT_GT(t(first), 600.0);
  for (Eigen::Index i = first; i < stale.size(); ++i) ASSERT_EQ(stale(i), 1.0) << "latched";
  const auto info = Vibid({"info", "--json"});
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const nlohmann::json m = nlohmann::json::parse(info.out)["model_stale"];
  ASSERT_TRUE(m["stale"].get<bool>()) << m.dump();
  // The log's rows keep the trip's time to within a record (5 ms at 200 Hz).
  EXPECT_GE(t(first), m["tripped_at_s"].get<double>()) << m.dump();
  EXPECT_LT(t(first), m["tripped_at_s"].get<double>() + 0.005) << m.dump();
}

// `vibid watch` on the board with the test running: every block carries the board's flag as the
// log has it at the block's end, with its threshold, and says since when it is stale.
TEST_F(ModelStaleTest, WatchShowsTheBoardsFlagAtEveryBlock) {
  Calibrate(std::string(VIBID_SOURCE_DIR) + "/host/emulator/rigs/chain2_mass_step.json", 500.0);
  const auto r =
      Vibid({"watch", "--seconds", "1200", "--rate-hz", "1000", "--log-rate-hz", "200",
             "--scenario", "operate", "--reference-s", "590", "--modes-s", "0", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto info = Vibid({"info", "--json"});
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const nlohmann::json m = nlohmann::json::parse(info.out)["model_stale"];
  ASSERT_TRUE(m["stale"].get<bool>()) << m.dump();
  const double tripped_s = m["tripped_at_s"].get<double>();
  std::istringstream in(r.out);
  int blocks = 0;
  int stale = 0;
  for (std::string line; std::getline(in, line);) {
    const nlohmann::json j = nlohmann::json::parse(line);
    ++blocks;
    ASSERT_TRUE(j["board"].is_object()) << line;
    EXPECT_DOUBLE_EQ(j["board"]["threshold"].get<double>(), m["threshold"].get<double>());
    const double t = j["t_s"].get<double>();
    const bool is_stale = j["board"]["stale"].get<bool>();
    // A block ends at t; the flag is the one logged at its last record (5 ms before t).
    EXPECT_EQ(is_stale, t - 0.005 >= tripped_s) << line;
    if (is_stale) {
      ++stale;
      EXPECT_GE(j["board"]["stale_since_t_s"].get<double>(), tripped_s) << line;
      EXPECT_LT(j["board"]["stale_since_t_s"].get<double>(), tripped_s + 0.005) << line;
    }
  }
  EXPECT_EQ(blocks, 61);  // (1200 - 590) / 10
  EXPECT_GT(stale, 0);
}

// The same rig without its step: the flag stays down over the run.
TEST_F(ModelStaleTest, AnUnchangedRigKeepsTheFlagDown) {
  std::ifstream in(std::string(VIBID_SOURCE_DIR) + "/host/emulator/rigs/chain2_mass_step.json");
  nlohmann::json rig = nlohmann::json::parse(in);
  rig.erase("changes");
  const std::string path = dir + "/rig.json";
  std::ofstream(path) << rig.dump(2);
  Calibrate(path, 500.0);
  const std::string run = dir + "/run.csv";
  const auto r = Vibid({"acquire", "--seconds", "1200", "--rate-hz", "1000", "--log-rate-hz", "200",
                        "--channels", "acc1,acc2", "--scenario", "operate", "-o", run});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Recording rec = LoadRecording(run);
  ASSERT_TRUE(rec.table.Has("model_stale"));
  EXPECT_EQ(rec.table.Column("model_stale").maxCoeff(), 0.0);
  EXPECT_GT(rec.table.Column("model_g").maxCoeff(), 0.0);  // the test ran
}

}  // namespace
}  // namespace vibid::hil
