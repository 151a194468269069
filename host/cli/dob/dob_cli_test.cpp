// `vibid dob ...` run as a user would: the real binary, real files.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "run_cli.hpp"
#include "vibid/common/atomic_file.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/model/model.hpp"
#include "vibid/model/simulate.hpp"

namespace vibid::testing {
namespace {

class DobCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = MakeTempDir("dob_cli");
    WriteFileAtomic(
        dir_ + "/rig.json",
        R"({"topology": "chain", "masses": [2.5, 2.0], "springs": [4000, 3000], "dampers": [3, 3]})");
    WriteFileAtomic(dir_ + "/undamped.json",
                    R"({"topology": "chain", "masses": [2.5, 2.0], "springs": [4000, 3000]})");
    // The source's experiment: shaker 40 N at 16 Hz on m2, a 10 N push sweeping 0.2-2 Hz on m2.
    const model::Model m = model::MakeChain(Eigen::Vector2d(2.5, 2.0), Eigen::Vector2d(4000, 3000),
                                            Eigen::Vector2d(3, 3));
    model::ForceInput shaker;
    shaker.shapes.push_back(model::ParseForceShape("sine:dof=2,amp=40,freq_hz=16"));
    model::ForceInput push;
    push.shapes.push_back(model::ParseForceShape("chirp:dof=2,amp=10,f0_hz=0.2,f1_hz=2,t1=6"));
    model::SimulationOptions o;
    o.method = model::Method::kExact;
    o.dt_s = 1.0 / 5000.0;
    o.t_end_s = 6.0;
    const model::SimulationResult r = model::Simulate(m, shaker, push, o);
    WriteFileAtomic(dir_ + "/rec.csv",
                    FormatCsv({"t_s", "shaker_n", "push_n", "x1_m", "x2_m_mm"},
                              {r.t_s, r.force_n.col(1), r.disturbance_n.col(1), r.x_m.col(0),
                               Eigen::VectorXd(r.x_m.col(1) * 1000.0)}));
    const auto d = RunVibid({"dob", "design", dir_ + "/rig.json", "-o", dir_ + "/design.json"});
    ASSERT_EQ(d.exit_code, 0) << d.err;
  }

  /// `vibid dob run RECORD --design DESIGN --force FORCE --response RESPONSE MORE... -o OUT`.
  struct DobRun {
    std::string record = dir_ + "/rec.csv";
    std::string design = dir_ + "/design.json";
    std::string force = "shaker_n";
    std::string response = "x2_m_mm:mm";
    std::vector<std::string> more;
    std::string out;
  };
  static CliResult RunDob(const DobRun& run) {
    std::vector<std::string> args = {"dob",     "run",     run.record,   "--design",  run.design,
                                     "--force", run.force, "--response", run.response};
    args.insert(args.end(), run.more.begin(), run.more.end());
    args.insert(args.end(), {"-o", run.out});
    return RunVibid(args);
  }

  static std::string dir_;
};

std::string DobCli::dir_;

nlohmann::json ReadJson(const std::string& path) {
  return nlohmann::json::parse(std::ifstream(path));
}

TEST_F(DobCli, DesignWritesTheContract) {
  const auto r = RunVibid({"dob",
                           "design",
                           dir_ + "/rig.json",
                           "--N",
                           "5",
                           "--r",
                           "4",
                           "--tau-s",
                           "0.002",
                           "--fs-hz",
                           "5000",
                           "--input-dof",
                           "2",
                           "--output-dof",
                           "2",
                           "--sensor",
                           "disp",
                           "--json",
                           "-o",
                           dir_ + "/d1.json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = ReadJson(dir_ + "/d1.json");
  EXPECT_EQ(nlohmann::json::parse(r.out), j);  // --json also prints it
  // Eq. 14, N = 5, r = 4, tau = 2 ms: den = sum a_k tau^k s^k (Butterworth a_k), num = 1 + a_1 tau
  // s.
  const auto den = j["q"]["den"].get<std::vector<double>>();
  const auto num = j["q"]["num"].get<std::vector<double>>();
  ASSERT_EQ(den.size(), 6u);
  ASSERT_EQ(num.size(), 2u);
  EXPECT_NEAR(den[0], std::pow(0.002, 5), 1e-25);
  EXPECT_NEAR(den[4], 3.2360679774997896 * 0.002, 1e-15);
  EXPECT_NEAR(num[0], 3.2360679774997896 * 0.002, 1e-15);
  EXPECT_NEAR(j["butterworth"][2].get<double>(), 5.23606797749979, 1e-12);
  EXPECT_TRUE(j["stable"].get<bool>());
  EXPECT_EQ(j["valid_band_hz"][0].get<double>(), 0.0);
  EXPECT_GT(j["valid_band_hz"][1].get<double>(), 5.0);
  EXPECT_LT(j["valid_band_hz"][1].get<double>(), 80.0);
  EXPECT_GT(j["predicted_snr_db"].get<double>(), 120.0);
  EXPECT_EQ(j["fixed"]["description_hex"].get<std::string>().size(), 1280u);
  EXPECT_EQ(j["discrete"]["inputs"].size(), 2u);
}

TEST_F(DobCli, DesignRefusesWithReasons) {
  const std::string out = dir_ + "/never.json";
  auto r = RunVibid({"dob", "design", dir_ + "/rig.json", "--r", "1", "-o", out});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("r = 1 is below the relative degree 2"), std::string::npos) << r.err;
  r = RunVibid({"dob", "design", dir_ + "/rig.json", "--N", "3", "--r", "4", "-o", out});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("0 <= r <= N"), std::string::npos) << r.err;
  r = RunVibid({"dob", "design", dir_ + "/undamped.json", "-o", out});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("undamped"), std::string::npos) << r.err;
  r = RunVibid({"dob", "design", dir_ + "/missing.json", "-o", out});
  EXPECT_EQ(r.exit_code, 1);
  r = RunVibid({"dob", "design", dir_ + "/rig.json", "--output-dof", "3", "-o", out});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--output-dof 3"), std::string::npos) << r.err;
  r = RunVibid({"dob", "design", dir_ + "/rig.json", "--sensor", "strain", "-o", out});
  EXPECT_EQ(r.exit_code, 1);  // a value out of its set is bad input, not a usage error
  EXPECT_NE(r.err.find("--sensor"), std::string::npos) << r.err;
  r = RunVibid({"dob", "design", dir_ + "/rig.json", "--tau-s", "0.00001", "-o", out});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("Nyquist"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST_F(DobCli, RunRecoversThePushAndCompareScoresIt) {
  const std::string out = dir_ + "/out.csv";
  const auto r = RunDob({.more = {"--lowpass-hz", "4"}, .out = out});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const CsvTable t = ReadCsv(out);
  EXPECT_TRUE(t.Has("d_hat_n"));
  EXPECT_TRUE(t.Has("d_hat_lp_n"));
  EXPECT_TRUE(t.Has("x1_m"));
  const auto c = RunVibid({"dob", "compare", out, "--estimate", "d_hat_lp_n", "--measured",
                           "push_n", "--skip-s", "1", "--json"});
  ASSERT_EQ(c.exit_code, 0) << c.err;
  const nlohmann::json j = nlohmann::json::parse(c.out);
  EXPECT_GE(j["fit_percent"].get<double>(), 99.0);
  EXPECT_GT(j["correlation"].get<double>(), 0.9999);
  EXPECT_EQ(j["delay_s"].get<double>(), 0.0);
  EXPECT_LT(j["rmse_n"].get<double>(), 0.1);
  // The double design gives the same estimate within the fixed point's error.
  const auto f = RunDob({.more = {"--float"}, .out = dir_ + "/float.csv"});
  ASSERT_EQ(f.exit_code, 0) << f.err;
  const Eigen::VectorXd diff = ReadCsv(dir_ + "/float.csv").Column("d_hat_n") - t.Column("d_hat_n");
  EXPECT_LT(diff.cwiseAbs().maxCoeff(), 1e-3);
}

// --verify: a second replay of the first replay's Q31 column under another --name equals it bit
// for bit; one sample changed by one LSB is found and named, exit 3, nothing written.
TEST_F(DobCli, VerifyFindsAOneLsbDifference) {
  const std::string first = dir_ + "/first.csv";
  ASSERT_EQ(RunDob({.out = first}).exit_code, 0);
  CsvTable t = ReadCsv(first);
  ASSERT_TRUE(t.Has("d_hat_q31"));
  auto r = RunDob({.record = first,
                   .more = {"--name", "host", "--verify", "d_hat_q31"},
                   .out = dir_ + "/second.csv"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("bit-exact: " + std::to_string(t.Column("t_s").size()) + " samples"),
            std::string::npos)
      << r.err;
  EXPECT_TRUE(ReadCsv(dir_ + "/second.csv").Has("host_q31"));

  const std::size_t q = static_cast<std::size_t>(
      std::find(t.names.begin(), t.names.end(), "d_hat_q31") - t.names.begin());
  t.columns[q][1234] += 1.0;
  WriteFileAtomic(dir_ + "/tampered.csv", FormatCsv(t.names, t.columns));
  const std::string out = dir_ + "/third.csv";
  r = RunDob({.record = dir_ + "/tampered.csv",
              .more = {"--name", "host", "--verify", "d_hat_q31"},
              .out = out});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("differs from the replay in 1 of"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("row 1235"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  // The default stem is taken already.
  r = RunDob({.record = first, .out = out});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--name"), std::string::npos) << r.err;
}

TEST_F(DobCli, RunRefusesBadInput) {
  const std::string out = dir_ + "/bad.csv";
  const std::string design = dir_ + "/design.json";
  auto r = RunDob({.force = "nope", .out = out});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("nope"), std::string::npos) << r.err;
  r = RunDob({.response = "x1_m,x2_m_mm", .out = out});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("takes 1 response column"), std::string::npos) << r.err;
  r = RunDob({.design = dir_ + "/rig.json", .response = "x1_m", .out = out});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("not a vibid DOB design"), std::string::npos) << r.err;
  r = RunDob({.response = "x1_m", .more = {"--fixed", "--float"}, .out = out});
  EXPECT_EQ(r.exit_code, 2);
  // A design for another sample rate.
  ASSERT_EQ(
      RunVibid({"dob", "design", dir_ + "/rig.json", "--fs-hz", "2000", "-o", dir_ + "/d2k.json"})
          .exit_code,
      0);
  r = RunDob({.design = dir_ + "/d2k.json", .response = "x1_m", .out = out});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("designed for 2000"), std::string::npos) << r.err;
  // A tampered fixed-point description is refused by the same validation the board runs.
  nlohmann::json j = ReadJson(design);
  std::string hex = j["fixed"]["description_hex"].get<std::string>();
  hex[200] = hex[200] == '0' ? '1' : '0';
  j["fixed"]["description_hex"] = hex;
  WriteFileAtomic(dir_ + "/tampered.json", j.dump());
  r = RunDob({.design = dir_ + "/tampered.json", .response = "x1_m", .out = out});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("data-loss"), std::string::npos) << r.err;
  // A misspelt key is refused wherever it sits, the nearest valid one named.
  j = ReadJson(design);
  j["discrete"]["inputs"][0]["full_scale_n"] = j["discrete"]["inputs"][0]["full_scale"];
  WriteFileAtomic(dir_ + "/misspelt.json", j.dump());
  r = RunDob({.design = dir_ + "/misspelt.json", .response = "x1_m", .out = out});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err, "vibid: error: unknown key 'full_scale_n' in design file " + dir_ +
                       "/misspelt.json discrete.inputs (did you mean 'full_scale'?)\n");
  r = RunDob({.more = {"--lowpass-hz", "3000"}, .out = out});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST_F(DobCli, CompareRefusesBadInput) {
  auto r = RunVibid(
      {"dob", "compare", dir_ + "/rec.csv", "--estimate", "missing", "--measured", "push_n"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("missing"), std::string::npos) << r.err;
  r = RunVibid({"dob", "compare", dir_ + "/rec.csv", "--estimate", "push_n", "--measured", "push_n",
                "--skip-s", "10"});
  EXPECT_EQ(r.exit_code, 1);
  r = RunVibid({"dob", "compare", dir_ + "/nofile.csv", "--estimate", "a", "--measured", "b"});
  EXPECT_EQ(r.exit_code, 1);
  r = RunVibid(
      {"dob", "compare", dir_ + "/rec.csv", "--estimate", "push_n", "--measured", "push_n"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("fit 100.000 %"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace vibid::testing
