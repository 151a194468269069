// The system-identification commands run as a user runs them: arx, pem, tfest, compare, greybox.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "run_cli.hpp"
#include "vibid/common/atomic_file.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/common/testing/real_data.hpp"
#include "vibid/sysid/continuous.hpp"
#include "vibid/sysid/greybox.hpp"

namespace vibid::testing {
namespace {

const std::string kArxData = VIBID_SOURCE_DIR "/host/lib/sysid/testdata/arx_data.csv";
constexpr double kDt = 0.005;

/// A written model: exit 0, with cautions when its residual tests fail (checked below and in
/// not_hammer_test.cpp; a noise-free record leaves residuals at rounding level, whose tests mean
/// nothing, and the golden ARX data's noise is coloured): stderr names them exactly then.
nlohmann::json Json(const CliResult& r) {
  EXPECT_EQ(r.exit_code, 0) << r.exit_code << ": " << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(r.err.find("vibid: caution:") != std::string::npos,
            j.contains("cautions") && !j["cautions"].empty())
      << r.err;
  return j;
}

/// A model written with cautions (its residual tests fail): exit 0 (a caution is no refusal),
/// the cautions in the JSON and named on stderr.
nlohmann::json CautionedJson(const CliResult& r) {
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("caution"), std::string::npos) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_FALSE(j["cautions"].empty());
  return j;
}

Eigen::VectorXd Vec(const nlohmann::json& j) {
  const auto v = j.get<std::vector<double>>();
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

/// One line on stderr naming the problem, exit code 1.
void ExpectInputError(const CliResult& r, const std::string& needle) {
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

/// A record of a known continuous system: t_s, u, y (ZOH-exact).
std::string WriteRecord(const std::string& dir, const std::string& name,
                        const sysid::TransferFunction& tf, const Eigen::VectorXd& u) {
  const Eigen::VectorXd t =
      Eigen::VectorXd::LinSpaced(u.size(), 0.0, static_cast<double>(u.size() - 1)) * kDt;
  const std::string path = dir + "/" + name;
  WriteFileAtomic(path, FormatCsv({"t_s", "u", "y"}, {t, u, sysid::Simulate(tf, u, kDt)}));
  return path;
}

Eigen::VectorXd Pulse(Eigen::Index n, Eigen::Index start, Eigen::Index width, double amp) {
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
  u.segment(start, width).setConstant(amp);
  return u;
}

/// One cart driven by a force: M = 0.57 kg, B = 0.6 N·s/m, k = 15 N/m (methods §10 rig values).
sysid::TransferFunction OneCartForce() {
  return sysid::CartTf(sysid::CartConfig{1, sysid::CartInput::kForce},
                       Eigen::Vector3d(0.57, 0.6, 15.0));
}

TEST(SysidCli, ArxMatchesOctaveGolden) {
  // Golden: scripts/golden/sysid_arx_octave.m, case na = 2, nb = 2 (octave nk 0 = our nk 1).
  const auto golden =
      ReadJsonFile(VIBID_SOURCE_DIR "/host/lib/sysid/testdata/arx_octave.json")["cases"][0];
  const auto j = Json(RunVibid({"arx", kArxData, "--input", "u", "--output", "y", "--na", "2",
                                "--nb", "2", "--nk", "1", "--json"}));
  EXPECT_LT((Vec(j["A"]) - Vec(golden["A"])).cwiseAbs().maxCoeff(), 1e-8);
  EXPECT_LT((Vec(j["B"]) - Vec(golden["B"])).cwiseAbs().maxCoeff(), 1e-8);
  EXPECT_EQ(j["A"][0], 1.0);
  EXPECT_EQ(j["std"]["A"].size(), 3u);
  EXPECT_EQ(j["std"]["A"][0], 0.0);
  EXPECT_GT(j["std"]["B"][1].get<double>(), 0.0);
  EXPECT_GT(j["fit_percent"].get<double>(), 50.0);
  EXPECT_TRUE(j.contains("residuals"));
}

TEST(SysidCli, ArxEstimateRangeAndOrderSelection) {
  const auto j =
      Json(RunVibid({"arx", kArxData, "--input", "u", "--output", "y", "--na", "2", "--nb", "2",
                     "--estimate-range", "100:400", "--validate-range", "400:", "--json"}));
  EXPECT_EQ(j["samples"], 300);
  EXPECT_EQ(j["validation"]["samples"], 200);
  const auto s = Json(RunVibid({"arx", kArxData, "--input", "u", "--output", "y", "--select", "aic",
                                "--max-order", "5", "--json"}));
  EXPECT_EQ(s["order_selection"].size(), 5u);
  // na = nb, nk = 1: A = [1, a1..an], B = [0, b1..bn]; the chosen n has the smallest AIC.
  EXPECT_EQ(s["A"].size(), s["B"].size());
  double best = 1e300;
  std::size_t best_n = 0;
  for (const auto& c : s["order_selection"]) {
    if (c["aic"].get<double>() < best) {
      best = c["aic"];
      best_n = c["na"];
    }
  }
  EXPECT_EQ(s["A"].size(), best_n + 1);
}

TEST(SysidCli, TfestCompareAndCourseMethods) {
  const std::string dir = MakeTempDir("sysid_cli");
  const std::string rec = WriteRecord(dir, "pulse.csv", OneCartForce(), Pulse(2000, 20, 20, 5.0));
  const std::string tf_path = dir + "/tf.json";
  const auto j = Json(RunVibid({"tfest", rec, "--input", "u", "--output", "y", "--np", "2", "--nz",
                                "0", "--json", "-o", tf_path}));
  // Truth: X1/F = (1/M)/(s² + (B/M) s + 2k/M).
  EXPECT_NEAR(j["den"][1].get<double>(), 0.6 / 0.57, 1e-9);
  EXPECT_NEAR(j["den"][2].get<double>(), 30.0 / 0.57, 1e-8);
  EXPECT_NEAR(j["num"][0].get<double>(), 1.0 / 0.57, 1e-9);
  EXPECT_EQ(j["ic"], "zero");
  EXPECT_GT(j["fit_percent"].get<double>(), 99.999);
  const std::string termination = j["summary"]["termination"];
  EXPECT_TRUE(termination == "function_tolerance" || termination == "parameter_tolerance")
      << termination;
  for (const char* key : {"iterations", "initial_cost", "final_cost", "message"})
    EXPECT_TRUE(j["summary"].contains(key));
  ASSERT_TRUE(std::filesystem::exists(tf_path));

  const std::vector<std::string> base = {"compare", rec,       "--input", "u",     "--output",
                                         "y",       "--model", tf_path,   "--json"};
  const auto exact = Json(RunVibid(base));
  EXPECT_GT(exact["fit_percent"].get<double>(), 99.999);
  EXPECT_EQ(exact["horizon"], "inf");
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = base;
    args.insert(args.end(), extra.begin(), extra.end());
    return Json(RunVibid(args));
  };
  EXPECT_EQ(with({"--horizon", "5"})["horizon"], 5);
  const double rk4 = with({"--method", "rk4"})["fit_percent"];
  const double euler = with({"--method", "euler"})["fit_percent"];
  EXPECT_GT(rk4, 99.9);
  EXPECT_LT(euler, rk4);
  EXPECT_GT(with({"--method", "euler", "--substeps", "50"})["fit_percent"].get<double>(), euler);
}

TEST(SysidCli, PemOeWithD2cRecoversTheContinuousModel) {
  const std::string dir = MakeTempDir("sysid_cli");
  const std::string rec = WriteRecord(dir, "pulse.csv", OneCartForce(), Pulse(2000, 20, 20, 5.0));
  const std::string model_path = dir + "/oe.json";
  const auto j = Json(RunVibid({"pem", rec, "--input", "u", "--output", "y", "--structure", "oe",
                                "--orders", "2,2,1", "--d2c", "--json", "-o", model_path}));
  EXPECT_EQ(j["structure"], "oe");
  EXPECT_NEAR(j["continuous"]["den"][2].get<double>(), 30.0 / 0.57, 1e-5);
  EXPECT_NEAR(j["continuous"]["den"][1].get<double>(), 0.6 / 0.57, 1e-6);
  EXPECT_TRUE(j["summary"].contains("termination"));
  // The written model file is read back by compare (k-step prediction of an OE model = simulation).
  const auto c = Json(RunVibid({"compare", rec, "--input", "u", "--output", "y", "--model",
                                model_path, "--horizon", "3", "--json"}));
  EXPECT_GT(c["fit_percent"].get<double>(), 99.99);
  EXPECT_EQ(c["model_kind"], "polynomial");
  // A misspelt key in the model file is refused, not read as its default (F = 1 here).
  nlohmann::json misspelt = nlohmann::json::parse(ReadFileText(model_path));
  misspelt["f"] = misspelt["F"];
  misspelt.erase("F");
  WriteFileAtomic(dir + "/misspelt.json", misspelt.dump());
  const auto refused = RunVibid(
      {"compare", rec, "--input", "u", "--output", "y", "--model", dir + "/misspelt.json"});
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_EQ(refused.err, "vibid: error: unknown key 'f' in polynomial model file " + dir +
                             "/misspelt.json (did you mean 'F'?)\n");
  WriteFileAtomic(dir + "/tf.json", R"({"num": [1], "dne": [1, 2]})");
  const auto tf_refused =
      RunVibid({"compare", rec, "--input", "u", "--output", "y", "--model", dir + "/tf.json"});
  EXPECT_EQ(tf_refused.exit_code, 1);
  EXPECT_EQ(tf_refused.err, "vibid: error: unknown key 'dne' in transfer-function file " + dir +
                                "/tf.json (did you mean 'den'?)\n");
}

TEST(SysidCli, GreyboxCartWithFixedMassAndSpring) {
  const std::string dir = MakeTempDir("sysid_cli");
  const Eigen::Vector4d truth(0.57, 0.6, 15.0, 0.25);  // M, B, k, Bi
  Eigen::VectorXd u = Eigen::VectorXd::Zero(3000);
  u.tail(2980).setConstant(0.01);  // a 1 cm step of the first spring's end
  const std::string rec = WriteRecord(
      dir, "step.csv", sysid::CartTf(sysid::CartConfig{1, sysid::CartInput::kPosition}, truth), u);
  const auto j = Json(RunVibid({"greybox", "cart", rec, "--input", "u", "--output", "y",
                                "--input-kind", "position", "--fix", "M=0.57,k=15", "--json"}));
  EXPECT_NEAR(j["parameters"]["B"]["value"].get<double>(), 0.6, 1e-6);
  EXPECT_NEAR(j["parameters"]["Bi"]["value"].get<double>(), 0.25, 1e-6);
  EXPECT_TRUE(j["parameters"]["M"]["fixed"].get<bool>());
  EXPECT_GE(j["parameters"]["B"]["std"].get<double>(), 0.0);
  EXPECT_GT(j["fit_percent"].get<double>(), 99.999);
}

TEST(SysidCli, CompareAcceptsModelCoreFiles) {
  const std::string dir = MakeTempDir("sysid_cli");
  const std::string rec = WriteRecord(dir, "pulse.csv", OneCartForce(), Pulse(2000, 20, 20, 5.0));
  WriteFileAtomic(dir + "/cart.json",
                  R"({"topology": "cart", "masses": [0.57], "spring": 15, "frictions": [0.6]})");
  const auto j = Json(RunVibid(
      {"compare", rec, "--input", "u", "--output", "y", "--model", dir + "/cart.json", "--json"}));
  EXPECT_GT(j["fit_percent"].get<double>(), 99.999);
}

TEST(SysidCli, RealRecordWithASampleRate) {
  const std::string arm = vibid::testing::TestData("daisy_robot_arm/robot_arm.csv");
  // No t_s column: the sample rate must be given.
  ExpectInputError(RunVibid({"arx", arm, "--input", "u_reaction_torque", "--output",
                             "y_arm_acceleration", "--na", "4", "--nb", "4"}),
                   "t_s");
  // The arm's OE residuals are not white (Ljung-Box 2908 above 44.3): written, with cautions.
  const auto j = CautionedJson(
      RunVibid({"pem", arm, "--input", "u_reaction_torque", "--output", "y_arm_acceleration",
                "--fs-hz", "1", "--structure", "oe", "--orders", "nb=5,nf=4,nk=0",
                "--estimate-range", "0:512", "--validate-range", "512:", "--json"}));
  EXPECT_GT(j["validation"]["fit_percent"].get<double>(),
            87.0);  // 88.3 % measured (real_data_test)
}

TEST(SysidCli, RealRecordWithColumnSpecs) {
  VIBID_SHARED_DATA_OR_SKIP(dir, "ecp_cart_motor_driven");
  // The cart's dry friction leaves residuals far from white: written, with cautions.
  const auto ecp = CautionedJson(
      RunVibid({"tfest", dir + "/pulse_kmed_2mass_data0000.csv", "--input", "I_amp*-178.57",
                "--output", "X_encoder_counts*1.7857e-3", "--np", "2", "--json"}));
  EXPECT_NEAR(ecp["den"][2].get<double>() / ecp["num"][0].get<double>(), 281.0,
              281.0 * 0.05);  // lab K
}

TEST(SysidCli, BadInputGetsOneClearLine) {
  const std::string dir = MakeTempDir("sysid_cli");
  auto write = [&](const std::string& name, const std::string& text) {
    WriteFileAtomic(dir + "/" + name, text);
    return dir + "/" + name;
  };
  std::string rows = "t_s,u,y\n";
  for (int i = 0; i < 40; ++i)
    rows +=
        std::to_string(i * 0.01) + "," + std::to_string(i % 3) + "," + std::to_string(i % 5) + "\n";
  const std::string good = write("good.csv", rows);
  const std::string out = dir + "/model.json";
  // A row short of a cell: input and output would differ in length.
  ExpectInputError(RunVibid({"arx", write("short.csv", rows + "0.4,1\n"), "--input", "u",
                             "--output", "y", "--na", "1", "--nb", "1", "-o", out}),
                   "expected 3 cells");
  ExpectInputError(RunVibid({"arx", write("nan.csv", rows + "0.4,nan,1\n"), "--input", "u",
                             "--output", "y", "--na", "1", "--nb", "1", "-o", out}),
                   "non-finite");
  std::string constant = "t_s,u,y\n";
  for (int i = 0; i < 40; ++i)
    constant += std::to_string(i * 0.01) + ",2," + std::to_string(i % 5) + "\n";
  ExpectInputError(RunVibid({"tfest", write("const.csv", constant), "--input", "u", "--output", "y",
                             "--np", "2", "-o", out}),
                   "not persistently exciting");
  ExpectInputError(RunVibid({"arx", good, "--input", "u", "--output", "y", "--na", "20", "--nb",
                             "20", "-o", out}),
                   "orders too high");
  ExpectInputError(
      RunVibid({"tfest", good, "--input", "u", "--output", "y", "--np", "6", "-o", out}),
      "orders too high");
  ExpectInputError(
      RunVibid({"tfest", good, "--input", "u", "--output", "y", "--np", "2", "--nz", "2"}), "nz");
  ExpectInputError(RunVibid({"pem", good, "--input", "u", "--output", "y", "--structure", "oe",
                             "--orders", "1,2"}),
                   "takes 3 numbers");
  ExpectInputError(
      RunVibid({"arx", good, "--input", "u", "--output", "nope", "--na", "1", "--nb", "1"}),
      "nope");
  ExpectInputError(RunVibid({"greybox", "cart", good, "--input", "u", "--output", "y",
                             "--input-kind", "position"}),
                   "fix M");
  ExpectInputError(RunVibid({"arx", good, "--input", "u", "--output", "y", "--na", "1", "--nb", "1",
                             "--estimate-range", "10:400"}),
                   "--estimate-range");
  EXPECT_FALSE(std::filesystem::exists(out));  // nothing half-written
  const CliResult bad_structure = RunVibid(
      {"pem", good, "--input", "u", "--output", "y", "--structure", "foo", "--orders", "1"});
  EXPECT_EQ(bad_structure.exit_code, 1);  // a value out of its set is bad input, not a usage error
  EXPECT_NE(bad_structure.err.find("--structure"), std::string::npos) << bad_structure.err;
}

}  // namespace
}  // namespace vibid::testing
