// `vibid report` on hand-made inputs whose numbers are known: the fit of an estimate offset by a
// constant from a sine, and the error of an update against a given truth.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <regex>

#include <nlohmann/json.hpp>

#include "run_cli.hpp"
#include "vibid/common/atomic_file.hpp"
#include "vibid/common/csv.hpp"

namespace vibid::testing {
namespace {

class ReportCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (std::filesystem::temp_directory_path() / ("vibid_report_" + std::to_string(::getpid())))
               .string();
    std::filesystem::create_directories(dir_ + "/ident");
    // Validation as `vibid identify --report` writes it: one mode, one position.
    const nlohmann::json triple = {{"nominal", 29.37},
                                   {"updated", 27.99},
                                   {"test", 27.92},
                                   {"nominal_dev_percent", 5.18},
                                   {"updated_dev_percent", 0.24}};
    nlohmann::json report = {
        {"validation",
         {{"modes", {{{"omega_rad_s", triple}}}},
          {"positions",
           {{{"m_kg", {{"nominal", 2.0}, {"updated", 1.8155}, {"change_percent", -9.225}}},
             {"k_n_per_m",
              {{"nominal", 4000.0}, {"updated", 3517.9}, {"change_percent", -12.0525}}}}}}}},
        {"warnings", {"mass test 1: a <warning>"}}};
    // The first modal test's stabilization diagram: two orders, one chosen pole near 3 Hz.
    report["modal_tests"] = nlohmann::json::parse(
        R"([{"stabilization": {"method": "lscf", "band_hz": [1, 4], "orders": [4, 6],
      "poles": [{"order": 4, "freq_hz": 3.0, "zeta": 0.01, "stable_freq": false, "stable_damping": false, "stable_shape": false, "cluster": -1},
                {"order": 6, "freq_hz": 3.01, "zeta": 0.01, "stable_freq": true, "stable_damping": true, "stable_shape": true, "cluster": 0}],
      "selected": [{"freq_hz": 3.01, "zeta": 0.01, "orders": 1}]}}])");
    WriteFileAtomic(dir_ + "/ident/report.json", report.dump());
    WriteFileAtomic(dir_ + "/ident/frf_overlay.csv",
                    "freq_hz,h12_test,h12_nominal,h12_updated,h22_test,h22_nominal,h22_updated\n"
                    "1,1e-4,1.1e-4,1e-4,2e-4,2.1e-4,2e-4\n2,2e-4,1.5e-4,2e-4,3e-4,3.1e-4,3e-4\n"
                    "4,1e-3,5e-4,1e-3,1e-3,6e-4,1e-3\n");
    // A 1-DOF truth: m 1.82 kg, k 3520 N/m.
    WriteFileAtomic(dir_ + "/truth.json",
                    R"({"topology":"chain","masses":[1.82],"springs":[3520],"dampers":[5]})");
    // Push: 2 N sine at 0.5 Hz over 10 whole periods at 100 Hz; the estimate is 0.1 N above it.
    // Fit = 100 (1 - 0.1 sqrt(n) / (2 sqrt(n / 2))) = 100 (1 - 0.05 sqrt 2) = 92.929 %.
    const Eigen::Index n = 2000;
    Eigen::VectorXd t(n), push(n), est(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      t[i] = static_cast<double>(i) / 100.0;
      push[i] = 2.0 * std::sin(2 * std::numbers::pi * 0.5 * t[i]);
      est[i] = push[i] + 0.1;
    }
    WriteFileAtomic(dir_ + "/dob.csv",
                    FormatCsv({"t_s", "force2_n", "est_n", "same_n"}, {t, push, est, push}));
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string dir_;
};

TEST_F(ReportCli, TablesFiguresAndFitsAreThere) {
  const std::string out = dir_ + "/report.html";
  const auto r =
      RunVibid({"report", "--identify", dir_ + "/ident", "--truth", dir_ + "/truth.json", "--dob",
                dir_ + "/dob.csv", "--measured", "force2_n", "--estimate", "est_n=offset",
                "--estimate", "same_n", "--note", "board d_hat bit-exact", "-o", out});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string html = ReadFileText(out);
  // Two FRF figures (h12, h22), the stabilization diagram and the observer figure.
  const std::regex svg("<svg ");
  EXPECT_EQ(
      std::distance(std::sregex_iterator(html.begin(), html.end(), svg), std::sregex_iterator()),
      4);
  EXPECT_NE(html.find("Stabilization diagram (lscf)"), std::string::npos);
  EXPECT_NE(html.find("class=\"chosen\""), std::string::npos);
  EXPECT_NE(html.find("<td>offset</td><td>est_n</td><td class=\"num\">92.93</td>"),
            std::string::npos);
  EXPECT_NE(html.find("<td>same_n</td><td>same_n</td><td class=\"num\">100.00</td>"),
            std::string::npos);
  // m: (1.8155 - 1.82) / 1.82 = -0.247 %; k: (3517.9 - 3520) / 3520 = -0.060 %.
  EXPECT_NE(html.find("<td class=\"num\">1.82</td><td class=\"num\">-0.25</td>"),
            std::string::npos);
  EXPECT_NE(html.find("<td class=\"num\">3520</td><td class=\"num\">-0.06</td>"),
            std::string::npos);
  EXPECT_NE(html.find("<li>board d_hat bit-exact</li>"), std::string::npos);
  EXPECT_NE(html.find("a &lt;warning&gt;"), std::string::npos);
  EXPECT_EQ(html.find("<script"), std::string::npos);
}

TEST_F(ReportCli, BadInputIsNamedAndNothingIsWritten) {
  const std::string out = dir_ + "/bad.html";
  auto r = RunVibid({"report", "-o", out});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--identify"), std::string::npos) << r.err;
  r = RunVibid({"report", "--dob", dir_ + "/dob.csv", "--measured", "force2_n", "-o", out});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--estimate"), std::string::npos) << r.err;
  r = RunVibid({"report", "--dob", dir_ + "/dob.csv", "--measured", "force2_n", "--estimate",
                "nope", "-o", out});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("nope"), std::string::npos) << r.err;
  r = RunVibid({"report", "--identify", dir_ + "/missing", "-o", out});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("report.json"), std::string::npos) << r.err;
  r = RunVibid({"report", "--dob", dir_ + "/dob.csv", "--measured", "force2_n", "--estimate",
                "est_n", "--skip-s", "11", "-o", out});
  EXPECT_EQ(r.exit_code, 1);
  // A misspelt key in report.json is refused, not read as "no warnings".
  std::filesystem::create_directories(dir_ + "/misspelt");
  std::filesystem::copy_file(dir_ + "/ident/frf_overlay.csv", dir_ + "/misspelt/frf_overlay.csv");
  nlohmann::json report = nlohmann::json::parse(ReadFileText(dir_ + "/ident/report.json"));
  report["warning"] = report["warnings"];
  report.erase("warnings");
  WriteFileAtomic(dir_ + "/misspelt/report.json", report.dump());
  r = RunVibid({"report", "--identify", dir_ + "/misspelt", "-o", out});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err, "vibid: error: unknown key 'warning' in identification report " + dir_ +
                       "/misspelt/report.json (did you mean 'warnings'?)\n");
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace vibid::testing
