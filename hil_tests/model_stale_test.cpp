// The board's own model test end to end on a vibid-emu process: an observer designed from the
// rig's truth and uploaded, a calibration day recorded with it running under the `operate`
// scenario, the test built into the record from that day (`cal upload --watch-day`), then the
// built-in 3 % mass step (rigs/chain2_mass_step.json, at 600 s) run under the same scenario: the
// log's model columns stay clear before the step and turn stale after it within a bound on the
// delay, `vibid info --json` says when it tripped; on the unchanged rig the flag's trips, counted
// with the board's kernel restarted after each, are the stated rate's count within its two-sided
// Poisson band; and the same test built from the same day without a board (`cal build`).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "emulator_process.hpp"
#include "run_cli.hpp"
#include "target.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/shared/fixed/residual_cusum.hpp"

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
  void Calibrate(const std::string& rig, double day_s, const std::string& per_hour = "") {
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
    std::vector<std::string> upload = {
        "cal",       "upload", model,         "--design", dir + "/design.json",
        "--sensors", sensors,  "--watch-day", day};
    if (!per_hour.empty()) upload.insert(upload.end(), {"--watch-false-alarms-per-hour", per_hour});
    const auto with_test = Vibid(upload);
    ASSERT_EQ(with_test.exit_code, 0) << with_test.err;
    design_text = with_test.out;
    ASSERT_EQ(Vibid({"cal", "commit"}).exit_code, 0);
    ASSERT_EQ(Vibid({"dob", "start"}).exit_code, 0);
  }

  std::unique_ptr<EmulatorProcess> emu;
  std::string dir;
  std::string design_text;
};

// The 3 % step at 600 s: the first record logged stale comes after it and within the delay bound
// the study over seeds gives, and the board's own trip time says the same.
TEST_F(ModelStaleTest, TheBuiltInThreePercentStepTripsTheBoardsFlag) {
  Calibrate(std::string(VIBID_SOURCE_DIR) + "/host/emulator/rigs/chain2_mass_step.json", 500.0);
  EXPECT_NE(design_text.find("model test: windows of"), std::string::npos) << design_text;
  const std::string run = dir + "/run.csv";
  // 900 s after the step: longer than the delay bound, so that the bound is what is checked.
  const auto r = Vibid({"acquire", "--seconds", "1500", "--rate-hz", "1000", "--log-rate-hz", "200",
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
  // benchmarks/watch/board_flag_study.py: over 12 seeds the flag trips 21 to 967 s after the
  // step, 11 of them within 600 s (docs/dob.md); this seed's delay is held to that bound.
  constexpr double kStepS = 600.0;
  constexpr double kDelayBoundS = 600.0;
  EXPECT_GT(t(first), kStepS);
  EXPECT_LE(t(first) - kStepS, kDelayBoundS);
  for (Eigen::Index i = first; i < stale.size(); ++i) ASSERT_EQ(stale(i), 1.0) << "latched";
  const auto info = Vibid({"info", "--json"});
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const nlohmann::json m = nlohmann::json::parse(info.out)["model_stale"];
  ASSERT_TRUE(m["stale"].get<bool>()) << m.dump();
  // The log's rows keep the trip's time to within a record (5 ms at 200 Hz).
  EXPECT_GE(t(first), m["tripped_at_s"].get<double>()) << m.dump();
  EXPECT_LT(t(first), m["tripped_at_s"].get<double>() + 0.005) << m.dump();
}

// `vibid cal build` builds the same test from the same calibration day without a board: the
// record file's kernel parameters (read back by `cal show --record`, and in the JSON file) are
// the ones the board holds after `cal upload --watch-day`, its observer and channels too, and it
// prints the same design line.
TEST_F(ModelStaleTest, AnOfflineBuildFromTheSameDayGivesTheBoardsTest) {
  Calibrate(std::string(VIBID_SOURCE_DIR) + "/host/emulator/rigs/chain2_mass_step.json", 120.0,
            "60");
  const std::string sensors = std::string(VIBID_SOURCE_DIR) + "/examples/sensors.json";
  const std::vector<std::string> build = {
      "cal",       "build", dir + "/truth.json", "--design",       dir + "/design.json",
      "--sensors", sensors, "--watch-day",       dir + "/day.csv", "--watch-false-alarms-per-hour",
      "60",        "-o"};
  auto to_bin = build, to_json = build;
  to_bin.push_back(dir + "/cal.bin");
  to_json.push_back(dir + "/cal.json");
  const auto bin = RunVibid(to_bin);
  ASSERT_EQ(bin.exit_code, 0) << bin.err;
  ASSERT_EQ(RunVibid(to_json).exit_code, 0);
  const auto first_line = [](const std::string& s) { return s.substr(0, s.find('\n')); };
  EXPECT_EQ(first_line(bin.out), first_line(design_text));
  EXPECT_NE(first_line(bin.out).find("false alarms per hour (95 %"), std::string::npos) << bin.out;

  const auto board = Vibid({"cal", "show", "--json"});
  ASSERT_EQ(board.exit_code, 0) << board.err;
  const auto file = RunVibid({"cal", "show", "--record", dir + "/cal.bin", "--json"});
  ASSERT_EQ(file.exit_code, 0) << file.err;
  const nlohmann::json on_board = nlohmann::json::parse(board.out);
  const nlohmann::json from_bin = nlohmann::json::parse(file.out);
  nlohmann::json from_json;
  std::ifstream(dir + "/cal.json") >> from_json;
  ASSERT_TRUE(on_board["model_test"].is_object()) << board.out;
  for (const char* key : {"model_test", "observer", "channels", "M", "C", "K", "label"}) {
    EXPECT_EQ(from_bin[key], on_board[key]) << key;
    EXPECT_EQ(from_json[key], on_board[key]) << key;
  }
  EXPECT_TRUE(from_bin["slot"].is_null());
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
  std::string first_line;
  ASSERT_TRUE(std::getline(in, first_line));
  // The header: the board's model test as it stood at the start, with the same threshold.
  const nlohmann::json header = nlohmann::json::parse(first_line);
  ASSERT_EQ(header["header"], "vibid watch") << first_line;
  EXPECT_DOUBLE_EQ(header["model_stale"]["threshold"].get<double>(), m["threshold"].get<double>());
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

// The central 95 % of a Poisson count of mean `mean`: [lo, hi] with P(N < lo) and P(N > hi)
// each at most 2.5 % (the quantiles scipy.stats.poisson.ppf(0.025, mean) and ppf(0.975, mean)).
std::pair<int, int> PoissonBand(double mean) {
  double p = std::exp(-mean), cdf = 0.0;
  int lo = -1;
  for (int k = 0;; ++k) {
    if (k > 0) p *= mean / k;
    cdf += p;
    if (lo < 0 && cdf > 0.025) lo = k;
    if (cdf >= 0.975) return {lo, k};
  }
}

// The board's flag counted in control: the same rig without its step, the test built from its
// calibration day of 500 s asking for at most 60 false alarms per hour, then 600 s of the rig in
// operation logged at the observer's rate. The design states the band of rates this calibration
// gives (95 %, its upper end the rate asked); the board latches at its first trip, so the count
// restarts the board's own kernel (fixed::ResidualCusum, the firmware's code) from rest after each
// trip on the logged d_hat, with the parameters the board holds (`cal show --json`), after
// checking that up to the board's trip the kernel's g is the logged model_g bit for bit. The
// count must lie in the band's Poisson extent (the low end's 2.5 % point to the high end's
// 97.5 %), both sides: fewer trips fail as surely as more.
// (benchmarks/watch/board_flag_rate_study.py: the same at 10 to 60 per hour over days,
// docs/dob.md.)
TEST_F(ModelStaleTest, InControlTheFlagTripsAtTheStatedRateBothSides) {
  std::ifstream in(std::string(VIBID_SOURCE_DIR) + "/host/emulator/rigs/chain2_mass_step.json");
  nlohmann::json rig = nlohmann::json::parse(in);
  rig.erase("changes");
  const std::string path = dir + "/rig.json";
  std::ofstream(path) << rig.dump(2);
  Calibrate(path, 500.0, "60");
  ASSERT_NE(design_text.find("for at most 60 false alarms per hour"), std::string::npos)
      << design_text;
  double low_per_hour = 0.0;
  double high_per_hour = 0.0;
  const auto at = design_text.find("gives between ");
  ASSERT_NE(at, std::string::npos) << design_text;
  ASSERT_EQ(std::sscanf(design_text.c_str() + at, "gives between %lf and %lf", &low_per_hour,
                        &high_per_hour),
            2)
      << design_text;
  const auto shown = Vibid({"cal", "show", "--json"});
  ASSERT_EQ(shown.exit_code, 0) << shown.err;
  const nlohmann::json t = nlohmann::json::parse(shown.out)["model_test"];
  ASSERT_TRUE(t.is_object()) << shown.out;
  fixed::ResidualCusumParams p;
  p.window_samples = t["window_samples"].get<std::uint32_t>();
  p.residual_gain = t["residual_gain"].get<std::int32_t>();
  p.reference_gain = t["reference_gain"].get<std::int32_t>();
  p.sum_shift = t["sum_shift"].get<std::uint8_t>();
  p.z_shift = t["z_shift"].get<std::uint8_t>();
  p.center = t["center"].get<std::int32_t>();
  p.z_gain = t["z_gain"].get<std::int32_t>();
  p.k = t["k_q16"].get<std::int32_t>();
  p.h = t["h_q16"].get<std::int32_t>();
  p.holdoff_windows = t["holdoff_windows"].get<std::uint8_t>();
  ASSERT_EQ(p.reference_gain, 0);  // r = d_hat: no reference load cell
  fixed::ResidualCusum kernel;
  ASSERT_EQ(kernel.Init(p), Status::kOk);

  constexpr double kRunS = 600.0;
  const std::string run = dir + "/run.csv";
  const auto r = Vibid({"acquire", "--seconds", "600", "--rate-hz", "1000", "--channels",
                        "force1,x2", "--scenario", "operate", "-o", run});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Recording rec = LoadRecording(run);
  const Eigen::VectorXd& d_hat = rec.table.Column("d_hat_q31");
  const Eigen::VectorXd& board_g = rec.table.Column("model_g");
  const Eigen::VectorXd& board_stale = rec.table.Column("model_stale");
  int trips = 0;
  Eigen::Index checked = 0;
  bool board_tripped = false;
  for (Eigen::Index n = 0; n < d_hat.size(); ++n) {
    if (!kernel.Step(static_cast<std::int32_t>(d_hat(n)), 0)) continue;
    if (!board_tripped) {
      // The log's model_g is g in Q16 as the board held it after this sample.
      ASSERT_EQ(std::lround(board_g(n) * 65536.0), kernel.statistic()) << "window end " << n;
      ASSERT_EQ(board_stale(n) != 0.0, kernel.tripped()) << n;
      ++checked;
      board_tripped = kernel.tripped();
    }
    if (kernel.tripped()) {
      ++trips;
      kernel.Reset();
    }
  }
  ASSERT_TRUE(board_tripped) << "at tens per hour the board trips within the run";
  const double hours =
      static_cast<double>(d_hat.size() / p.window_samples * p.window_samples) / 1000.0 / 3600.0;
  const int lo = PoissonBand(low_per_hour * hours).first;
  const int hi = PoissonBand(high_per_hour * hours).second;
  std::printf(
      "in control, %g s asking at most 60 per hour: %d trips; this calibration gives %.3g to "
      "%.3g per hour, %d to %d trips with the count's scatter; the kernel checked against the "
      "board's log over %ld windows\n",
      kRunS, trips, low_per_hour, high_per_hour, lo, hi, static_cast<long>(checked));
  EXPECT_NEAR(high_per_hour, 60.0, 3.0);  // the band's upper end is the rate asked
  EXPECT_LT(low_per_hour, high_per_hour);
  EXPECT_GE(lo, 1);  // the low side can fail: no trip at all is outside the band
  EXPECT_GE(trips, lo);
  EXPECT_LE(trips, hi);
}

}  // namespace
}  // namespace vibid::hil
