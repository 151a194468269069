// `vibid modal|frf|simulate`: real runs of the binary, outputs checked against closed forms, and
// every documented error path.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "run_cli.hpp"
#include "vibid/common/atomic_file.hpp"
#include "vibid/common/csv.hpp"

namespace vibid::testing {
namespace {

class ModelCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = MakeTempDir("model_cli");
    rig_ = Write(
        "rig.json",
        R"({"topology": "chain", "masses": [2.0, 1.5], "springs": [4000, 3000], "dampers": [2, 1]})");
    one_ = Write("one.json", R"({"M": [[2]], "K": [[5000]], "C": [[4]]})");
  }
  std::string Write(const std::string& name, const std::string& text) {
    const std::string path = dir_ + "/" + name;
    WriteFileAtomic(path, text);
    return path;
  }
  // Runs a command expected to fail with exit 1 and a one-line message containing `fragment`.
  void ExpectInputError(const std::vector<std::string>& args, const std::string& fragment) {
    const CliResult r = RunVibid(args);
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_NE(r.err.find(fragment), std::string::npos) << "stderr: " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_TRUE(r.out.empty());
  }
  std::string dir_, rig_, one_;
};

TEST_F(ModelCli, ModalJsonMatchesTheTwoDofClosedForm) {
  const CliResult r = RunVibid({"modal", rig_, "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("modes").size(), 2u);
  // ω² roots of m1 m2 λ² − (m1 k2 + m2 (k1 + k2)) λ + k1 k2 with 2, 1.5, 4000, 3000.
  const double b = 2.0 * 3000.0 + 1.5 * 7000.0, disc = std::sqrt(b * b - 4.0 * 3.0 * 12e6);
  const double w1 = std::sqrt((b - disc) / 6.0), w2 = std::sqrt((b + disc) / 6.0);
  EXPECT_NEAR(j["modes"][0]["omega_rad_s"].get<double>(), w1, 1e-9);
  EXPECT_NEAR(j["modes"][1]["omega_rad_s"].get<double>(), w2, 1e-9);
  EXPECT_NEAR(j["modes"][0]["freq_hz"].get<double>(), w1 / (2.0 * M_PI), 1e-9);
  EXPECT_NEAR(j["modes"][0]["ratio"].get<double>(), 3000.0 / (7000.0 - 2.0 * w1 * w1), 1e-9);
  EXPECT_EQ(j["modes"][1]["shape"].size(), 2u);
  EXPECT_GT(j["modes"][0]["zeta"].get<double>(), 0.0);
  EXPECT_EQ(j["damping"], "general");  // dampers only in parallel with springs of different ratio
}

TEST_F(ModelCli, ModalTableAndOneDofJson) {
  const CliResult table = RunVibid({"modal", one_});
  ASSERT_EQ(table.exit_code, 0) << table.err;
  EXPECT_NE(table.out.find("7.95775"), std::string::npos) << table.out;  // 50 rad/s = 7.957747 Hz
  EXPECT_NE(table.out.find("0.02"), std::string::npos) << table.out;     // ζ = 4/(2√(2·5000))
  const nlohmann::json j = nlohmann::json::parse(RunVibid({"modal", one_, "--json"}).out);
  EXPECT_TRUE(j["modes"][0]["ratio"].is_null());
  EXPECT_NEAR(j["modes"][0]["omega_rad_s"].get<double>(), 50.0, 1e-12);
  EXPECT_NEAR(j["modes"][0]["zeta"].get<double>(), 0.02, 1e-15);
}

TEST_F(ModelCli, FrfCsvHoldsTheOneDofReceptance) {
  const std::string out = dir_ + "/frf.csv";
  const CliResult r =
      RunVibid({"frf", one_, "--input", "1", "--output", "1", "--kind", "receptance", "--f-min-hz",
                "0", "--f-max-hz", "20", "--points", "5", "-o", out});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const CsvTable t = ReadCsv(out);
  ASSERT_EQ(t.names,
            (std::vector<std::string>{"freq_hz", "re_receptance_1_1", "im_receptance_1_1"}));
  ASSERT_EQ(t.rows(), 5u);
  for (std::size_t i = 0; i < 5; ++i) {
    const double w = 2.0 * M_PI * t.columns[0][static_cast<Eigen::Index>(i)];
    const std::complex<double> h =
        1.0 / std::complex<double>(5000.0 - 2.0 * w * w, 4.0 * w);  // 1/(k − mω² + jωc)
    EXPECT_NEAR(t.columns[1][static_cast<Eigen::Index>(i)], h.real(), 1e-15);
    EXPECT_NEAR(t.columns[2][static_cast<Eigen::Index>(i)], h.imag(), 1e-15);
  }
}

TEST_F(ModelCli, FrfPolarLogAndTwoOutputs) {
  const CliResult r =
      RunVibid({"frf", rig_, "--input", "1", "--output", "1,2", "--kind", "accelerance",
                "--f-min-hz", "1", "--f-max-hz", "100", "--points", "3", "--log", "--polar"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const CsvTable t = ParseCsv(r.out, "stdout");
  EXPECT_EQ(t.names,
            (std::vector<std::string>{"freq_hz", "mag_accelerance_1_1", "phase_deg_accelerance_1_1",
                                      "mag_accelerance_1_2", "phase_deg_accelerance_1_2"}));
  EXPECT_EQ(t.columns[0], Eigen::Vector3d(1.0, 10.0, 100.0));
  // Far above both resonances the accelerance tends to the mass line 1/m1 at the driving point.
  EXPECT_NEAR(t.columns[1][2], 1.0 / 2.0, 0.05);
}

TEST_F(ModelCli, SimulateExactStepSettlesAtFOverK) {
  const std::string out = dir_ + "/sim.csv";
  const CliResult r = RunVibid({"simulate", one_, "--method", "exact", "--dt-s", "0.001",
                                "--t-end-s", "5", "--force", "step:dof=1,amp=5", "-o", out});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const CsvTable t = ReadCsv(out);
  EXPECT_EQ(t.names, (std::vector<std::string>{"t_s", "x1_m", "v1_m_s", "a1_m_s2", "f1_n"}));
  EXPECT_EQ(t.rows(), 5001u);
  // After 5 s the transient has decayed by e^{−ζω·5} = e^{−5}: within 1 % of F/k = 1 mm.
  EXPECT_NEAR(t.Column("x1_m")[5000], 1e-3, 1e-5);
  EXPECT_EQ(t.Column("f1_n")[0], 5.0);
}

TEST_F(ModelCli, SimulateWithFrictionHoldsTheBlock) {
  const CliResult r = RunVibid({"simulate", one_, "--method", "rk4", "--dt-s", "0.001", "--t-end-s",
                                "0.1", "--force", "step:dof=1,amp=5", "--friction", "0.3,0.2"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const CsvTable t = ParseCsv(r.out, "stdout");
  EXPECT_TRUE(t.Column("x1_m").isZero(0.0));  // μs m g = 5.88 N > 5 N
}

TEST_F(ModelCli, RepeatedForcesAddUpAndNeverSwallowTheModelPath) {
  const CliResult r = RunVibid({"simulate", "--force", "step:dof=1,amp=5", "--force",
                                "pulse:dof=2,amp=1,width=0.02", rig_, "--method", "exact", "--dt-s",
                                "0.01", "--t-end-s", "0.03"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const CsvTable t = ParseCsv(r.out, "stdout");
  EXPECT_EQ(t.Column("f1_n"), Eigen::Vector4d(5.0, 5.0, 5.0, 5.0));
  EXPECT_EQ(t.Column("f2_n"), Eigen::Vector4d(1.0, 1.0, 0.0, 0.0));
}

TEST_F(ModelCli, HelpListsUnits) {
  for (const char* cmd : {"modal", "frf", "simulate"}) {
    const CliResult r = RunVibid({cmd, "--help"});
    EXPECT_EQ(r.exit_code, 0);
    EXPECT_NE(r.out.find(std::string(cmd) == "frf"     ? "Hz"
                         : std::string(cmd) == "modal" ? "rad/s"
                                                       : ", s"),
              std::string::npos)
        << r.out;
  }
}

TEST_F(ModelCli, BadModelFilesAreOneLineInputErrors) {
  ExpectInputError({"modal", dir_ + "/absent.json"}, "absent.json");
  ExpectInputError({"modal", Write("bad.json", "{\n \"M\": [[1]],\n \"K\": [[1]\n}")},
                   "bad.json:4: malformed JSON");
  ExpectInputError({"modal", Write("sizes.json", R"({"M": [[1, 0], [0, 1]], "K": [[1]]})")},
                   "K must be 2x2 like M, got 1x1");
  ExpectInputError(
      {"modal", Write("indef.json", R"({"M": [[1, 2], [2, 1]], "K": [[1, 0], [0, 1]]})")},
      "M is not positive definite");
  ExpectInputError(
      {"frf", Write("chain.json", R"({"topology": "chain", "masses": [1, 2], "springs": [1]})"),
       "--input", "1", "--output", "1", "--f-min-hz", "1", "--f-max-hz", "2"},
      "chain has 2 masses but 1 springs");
  ExpectInputError(
      {"simulate",
       Write("field.json", R"({"topology": "chain", "masses": [1, "x"], "springs": [1, 1]})"),
       "--dt-s", "0.001", "--t-end-s", "1", "--force", "step:dof=1,amp=1"},
      "field \"masses\"[2] must be a number");
}

TEST_F(ModelCli, BadOptionsAreOneLineInputErrors) {
  const std::vector<std::string> sim{"simulate", rig_,      "--t-end-s",
                                     "1",        "--force", "step:dof=1,amp=1"};
  auto with = [&sim](std::vector<std::string> extra) {
    std::vector<std::string> args = sim;
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  };
  ExpectInputError(with({"--dt-s", "-0.001"}), "dt_s must be finite and > 0, got -0.001");
  ExpectInputError(with({"--dt-s", "0.001", "--method", "verlet"}),
                   "unknown simulation method 'verlet'");
  ExpectInputError(
      {"simulate", rig_, "--dt-s", "0.1", "--t-end-s", "0.05", "--force", "step:dof=1,amp=1"},
      "t_end_s must be finite and greater than dt_s");
  ExpectInputError({"simulate", rig_, "--dt-s", "0.001", "--t-end-s", "1", "--force", "kick:dof=1"},
                   "unknown kind 'kick'");
  ExpectInputError(
      {"simulate", rig_, "--dt-s", "0.001", "--t-end-s", "1", "--force", "pulse:dof=1,amp=1"},
      "missing key 'width'");
  ExpectInputError(
      {"simulate", rig_, "--dt-s", "0.001", "--t-end-s", "1", "--force", "step:dof=3,amp=1"},
      "force dof 3 is out of range 1..2");
  ExpectInputError(with({"--dt-s", "0.001", "--method", "exact", "--friction", "0.1,0.1"}),
                   "cannot simulate Coulomb friction");
  ExpectInputError(with({"--dt-s", "0.001", "--friction", "0.1"}), "expected mu_static,mu_dynamic");
  ExpectInputError({"simulate", rig_, "--dt-s", "0.001", "--t-end-s", "1"},
                   "nothing excites the model");
  ExpectInputError(with({"--dt-s", "0.001", "--x0-m", "0.1"}),
                   "--x0-m has 1 values, the model has 2 DOFs");

  const std::vector<std::string> frf{"frf", rig_, "--f-min-hz", "1", "--f-max-hz", "50"};
  auto frf_with = [&frf](std::vector<std::string> extra) {
    std::vector<std::string> args = frf;
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  };
  ExpectInputError(frf_with({"--input", "3", "--output", "1"}), "--input 3 is out of range 1..2");
  ExpectInputError(frf_with({"--input", "1", "--output", "1,5"}),
                   "--output 5 is out of range 1..2");
  ExpectInputError(frf_with({"--input", "1", "--output", "0"}), "must be an integer >= 1");
  ExpectInputError(frf_with({"--input", "1", "--output", "1", "--kind", "inertance"}),
                   "unknown FRF kind 'inertance'");
  ExpectInputError(
      {"frf", rig_, "--input", "1", "--output", "1", "--f-min-hz", "10", "--f-max-hz", "5"},
      "--f-max-hz must be greater than --f-min-hz");
  ExpectInputError(
      {"frf", rig_, "--input", "1", "--output", "1", "--f-min-hz", "0", "--f-max-hz", "5", "--log"},
      "--log needs --f-min-hz > 0");
  ExpectInputError(frf_with({"--input", "1", "--output", "1", "--points", "1"}),
                   "--points must be between 2");
}

TEST_F(ModelCli, UnwritableOutputLeavesNothing) {
  const std::string out = dir_ + "/missing_dir/sim.csv";
  const CliResult r = RunVibid({"simulate", one_, "--dt-s", "0.001", "--t-end-s", "0.1", "--force",
                                "step:dof=1,amp=1", "-o", out});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST_F(ModelCli, MissingRequiredOptionIsAUsageError) {
  EXPECT_EQ(RunVibid({"simulate", one_, "--t-end-s", "1"}).exit_code, 2);
  EXPECT_EQ(RunVibid({"frf", one_, "--output", "1"}).exit_code, 2);
}

}  // namespace
}  // namespace vibid::testing
