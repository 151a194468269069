// The identification commands run as the real binary: results on synthetic hammer tests (truth
// known) and the ECP records, and a clear one-line error with a nonzero exit for bad input.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "run_cli.hpp"
#include "vibid/common/atomic_file.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/testing/real_data.hpp"
#include "vibid/device/log_table.hpp"
#include "vibid/ident/recording_columns.hpp"
#include "vibid/ident/testing/hammer_test.hpp"
#include "vibid/model/modal.hpp"
#include "vibid/model/model.hpp"

namespace vibid::testing {
namespace {

using nlohmann::json;

std::string Write(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = dir + "/" + name;
  WriteFileAtomic(path, text);
  return path;
}

// Truth: chain m = (1.2, 0.8) kg, k = (3000, 2000) N/m, c = (0.9, 0.8) N*s/m. The columns are
// named as `vibid acquire` writes them (force1_n, acc1_m_s2, ...). Each record is
// simulated the first time a case asks for it (ctest runs every case in its own process).
class Rig {
 public:
  static constexpr double kFsHz = 500;
  const std::string dir = MakeTempDir("ident_cli");

  /// Modal tests: hammer on mass 2, both accelerations (seeds 7 and 8).
  const std::string& modal1() const {
    return Made(modal1_, [&] { return Modal("modal1.csv", 7); });
  }
  const std::string& modal2() const {
    return Made(modal2_, [&] { return Modal("modal2.csv", 8); });
  }
  /// Mass tests: each mass alone on its nominal spring (+10 %), ζ = 2 %.
  const std::string& mass1() const {
    return Made(mass1_, [&] { return Mass(0); });
  }
  const std::string& mass2() const {
    return Made(mass2_, [&] { return Mass(1); });
  }
  /// Nominal: masses +8 %, springs +10 % (the mass tests' springs are these nominal ones).
  const std::string& nominal() const {
    return Made(nominal_, [&] {
      return Write(dir, "nominal.json",
                   R"({"topology": "chain", "masses": [1.296, 0.864], "springs": [3300, 2200]})");
    });
  }

 private:
  template <typename Make>
  static const std::string& Made(std::string& path, Make make) {
    if (path.empty()) path = make();
    return path;
  }
  std::string Modal(const std::string& name, std::uint64_t seed) const {
    const model::Model truth = model::MakeChain(
        Eigen::Vector2d(1.2, 0.8), Eigen::Vector2d(3000, 2000), Eigen::Vector2d(0.9, 0.8));
    return Write(dir, name,
                 ident::FormatHammerTestCsv(
                     ident::SimulateHammerTest(truth, ident::ModalTestSpec(kFsHz, seed)),
                     {"acc1_m_s2", "acc2_m_s2"}, "force1_n"));
  }
  std::string Mass(int i) const {
    const double ms[2] = {1.2, 0.8}, ks[2] = {3300, 2200};
    const model::Model one =
        model::MakeChain(Eigen::VectorXd::Constant(1, ms[i]), Eigen::VectorXd::Constant(1, ks[i]),
                         Eigen::VectorXd::Constant(1, 2 * 0.02 * std::sqrt(ks[i] * ms[i])));
    const ident::HammerTestSpec spec = ident::MassTestSpec(kFsHz, 100u + static_cast<unsigned>(i));
    return Write(
        dir, "mass" + std::to_string(i + 1) + ".csv",
        ident::FormatHammerTestCsv(ident::SimulateHammerTest(one, spec),
                                   {ident::AccelerationColumn(static_cast<std::size_t>(i) + 1)},
                                   ident::ForceColumn()));
  }

  mutable std::string modal1_, modal2_, mass1_, mass2_, nominal_;
};

const Rig& SyntheticRig() {
  static const Rig rig;
  return rig;
}

// Files that one command makes and later cases read, made on first use so that every case also
// runs alone (ctest runs each in its own process).
std::string MadeOnce(const std::string& path, const std::vector<std::string>& args) {
  if (!std::filesystem::exists(path)) {
    std::vector<std::string> with_output = args;
    with_output.insert(with_output.end(), {"-o", path});
    const CliResult r = RunVibid(with_output);
    EXPECT_EQ(r.exit_code, 0) << r.err;
  }
  return path;
}

/// The H1 estimate of the first modal test (as FrfEstimateCli.ImpactCsvAndUff makes it).
std::string ImpactFrfCsv() {
  const Rig& rig = SyntheticRig();
  return MadeOnce(rig.dir + "/impact_frf.csv", {"frf-estimate", rig.modal1(), "--force", "force1_n",
                                                "--response", "acc1_m_s2,acc2_m_s2", "--impact"});
}

/// The modes of the first modal test (as ModesCli.JsonSchemaAndTruth makes them).
std::string Modes1Json() {
  const Rig& rig = SyntheticRig();
  return MadeOnce(
      rig.dir + "/modes_of_test1.json",
      {"modes", rig.modal1(), "--force", "force1_n", "--response", "acc1_m_s2,acc2_m_s2",
       "--impact", "--exp-window", "0.01", "--max-modes", "2", "--json"});
}

void ExpectInputError(const CliResult& r, const std::string& fragment) {
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

TEST(FrfEstimateCli, ImpactCsvAndUff) {
  const Rig& rig = SyntheticRig();
  const auto r = RunVibid({"frf-estimate", rig.modal1(), "--force", "force1_n", "--response",
                           "acc1_m_s2,acc2_m_s2", "--impact", "-o", rig.dir + "/frf.csv"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("10 average(s)"), std::string::npos) << r.out;
  const std::string csv = ReadFileText(rig.dir + "/frf.csv");
  // A plain header row, the metadata in the sidecar beside it.
  EXPECT_EQ(csv.rfind("freq_hz,acc1_m_s2_re,acc1_m_s2_im,acc1_m_s2_coh,", 0), 0u)
      << csv.substr(0, 80);
  const std::string meta = ReadFileText(rig.dir + "/frf.csv.json");
  EXPECT_NE(meta.find("\"kind\": \"receptance\""), std::string::npos) << meta;
  EXPECT_NE(meta.find("\"averages\": 10"), std::string::npos) << meta;
  const auto u =
      RunVibid({"frf-estimate", rig.modal1(), "--force", "force1_n", "--response", "acc2_m_s2",
                "--impact", "--kind", "accelerance", "-o", rig.dir + "/frf.uff"});
  ASSERT_EQ(u.exit_code, 0) << u.err;
  EXPECT_EQ(ReadFileText(rig.dir + "/frf.uff").substr(0, 13), "    -1\n    58");
  // Welch on the same record to stdout.
  const auto w =
      RunVibid({"frf-estimate", rig.modal1(), "--force", "force1_n", "--response", "acc2_m_s2",
                "--segment", "2048", "--window", "hann", "--estimator", "h2"});
  ASSERT_EQ(w.exit_code, 0) << w.err;
  // To stdout: the plain CSV alone (no sidecar); to a file, its metadata beside it.
  EXPECT_EQ(w.out.rfind("freq_hz,acc2_m_s2_re,acc2_m_s2_im,acc2_m_s2_coh\n", 0), 0u)
      << w.out.substr(0, 80);
  const auto wf = RunVibid({"frf-estimate", rig.modal1(), "--force", "force1_n", "--response",
                            "acc2_m_s2", "--segment", "2048", "--window", "hann", "--estimator",
                            "h2", "-o", rig.dir + "/welch.csv"});
  ASSERT_EQ(wf.exit_code, 0) << wf.err;
  EXPECT_NE(ReadFileText(rig.dir + "/welch.csv.json").find("\"estimator\": \"h2\""),
            std::string::npos);
}

// A tone on two channels sampled 3.238 us apart (the board's force2 after acc1: one 68-clock
// conversion at 21 MHz), as a board recording states them in its header line.
std::string ToneRecording(const std::string& dir, const std::string& name,
                          const std::string& header) {
  const double fs = 10000.0, f = 2437.0, force_us = 5.905, response_us = 2.667;
  std::string text = header;
  text += "t_s,force2_n,acc1_m_s2\n";
  char line[128];
  for (int i = 0; i < 10000; ++i) {
    const double t = i / fs;
    std::snprintf(line, sizeof(line), "%.17g,%.17g,%.17g\n", t,
                  std::sin(2.0 * M_PI * f * (t + force_us * 1e-6)),
                  std::sin(2.0 * M_PI * f * (t + response_us * 1e-6)));
    text += line;
  }
  return Write(dir, name, text);
}

/// Phase of the FRF file's response at `freq_hz` (one of its lines).
double FrfPhaseAt(const std::string& path, double freq_hz) {
  const CsvTable t = ParseCsv(ReadFileText(path), path);
  const Eigen::VectorXd& f = t.Column("freq_hz");
  for (Eigen::Index k = 0; k < f.size(); ++k) {
    if (f(k) == freq_hz)
      return std::atan2(t.Column("acc1_m_s2_im")(k), t.Column("acc1_m_s2_re")(k));
  }
  ADD_FAILURE() << "no line at " << freq_hz << " Hz in " << path;
  return std::numeric_limits<double>::quiet_NaN();
}

TEST(FrfEstimateCli, SampleInstantsInTheHeaderAreCompensatedAndStated) {
  const Rig& rig = SyntheticRig();
  const std::vector<std::string> welch = {
      "--force",   "force2_n", "--response", "acc1_m_s2", "--welch", "--window",   "rect",
      "--segment", "10000",    "--overlap",  "0",         "--kind",  "accelerance"};
  const auto run = [&](const std::string& recording, const std::string& out) {
    std::vector<std::string> args = {"frf-estimate", recording};
    args.insert(args.end(), welch.begin(), welch.end());
    args.insert(args.end(), {"-o", out});
    return RunVibid(args);
  };
  // Without instants: the response, sampled 3.238 us before the force, shows
  // exp(-j 2 pi 2437 Hz 3.238 us) = -0.049581 rad.
  const std::string plain = ToneRecording(rig.dir, "tone_plain.csv", "");
  const auto p = run(plain, rig.dir + "/plain.csv");
  ASSERT_EQ(p.exit_code, 0) << p.err;
  EXPECT_EQ(p.out.find("sampling instants"), std::string::npos) << p.out;
  EXPECT_NEAR(FrfPhaseAt(rig.dir + "/plain.csv", 2437.0), -2.0 * M_PI * 2437.0 * 3.238e-6, 1e-9);
  // With the board's header line: moved to the force's instant, and said.
  const std::string stated =
      ToneRecording(rig.dir, "tone_stated.csv",
                    "# vibid-recording sample_instants_us=force2_n:5.905,acc1_m_s2:2.667\n");
  const auto s = run(stated, rig.dir + "/stated.csv");
  ASSERT_EQ(s.exit_code, 0) << s.err;
  EXPECT_NE(s.out.find("sampling instants compensated"), std::string::npos) << s.out;
  EXPECT_NE(s.out.find("acc1_m_s2 -3.238 us"), std::string::npos) << s.out;
  EXPECT_NEAR(FrfPhaseAt(rig.dir + "/stated.csv", 2437.0), 0.0, 1e-9);
  // A header that leaves out a column used is refused, naming it.
  const std::string partial = ToneRecording(
      rig.dir, "tone_partial.csv", "# vibid-recording sample_instants_us=force2_n:5.905\n");
  ExpectInputError(run(partial, rig.dir + "/partial.csv"), "acc1_m_s2");
}

TEST(FrfEstimateCli, BadInput) {
  const Rig& rig = SyntheticRig();
  ExpectInputError(
      RunVibid({"frf-estimate", rig.dir + "/missing.csv", "--force", "f", "--response", "x"}),
      "missing.csv");
  ExpectInputError(
      RunVibid({"frf-estimate", rig.modal1(), "--force", "force1_n", "--response", "nope"}),
      "nope");
  ExpectInputError(RunVibid({"frf-estimate", rig.modal1(), "--force", "force1_n", "--response",
                             "acc1_m_s2", "--estimator", "h3"}),
                   "h3");
  ExpectInputError(RunVibid({"frf-estimate", rig.modal1(), "--force", "force1_n", "--response",
                             "acc1_m_s2", "--segment", "64", "--overlap", "64"}),
                   "overlap");
  ExpectInputError(RunVibid({"frf-estimate", rig.modal1(), "--force", "force1_n", "--response",
                             "acc1_m_s2", "--window", "kaiser"}),
                   "kaiser");
  const std::string nan = Write(rig.dir, "nan.csv", "t_s,f,x\n0,1,2\n0.1,nan,2\n0.2,1,2\n");
  ExpectInputError(RunVibid({"frf-estimate", nan, "--force", "f", "--response", "x"}), "nan.csv:3");
  const std::string jumpy = Write(
      rig.dir, "jumpy.csv",
      "t_s,f,x\n0,1,2\n0.1,1,2\n0.5,1,2\n0.6,1,2\n0.7,1,2\n0.8,1,2\n0.9,1,2\n1.0,1,2\n1.1,1,2\n");
  const auto j = RunVibid({"frf-estimate", jumpy, "--force", "f", "--response", "x"});
  EXPECT_EQ(j.exit_code, 1) << j.err;
  // A recording without any hit in impact mode.
  const std::string flat =
      Write(rig.dir, "flat.csv",
            "t_s,f,x\n0,0,0\n0.1,0,0\n0.2,0,0\n0.3,0,0\n0.4,0,0\n0.5,0,0\n0.6,0,0\n0.7,0,0\n0.8,0,"
            "0\n0.9,0,0\n1.0,0,0\n1.1,0,0\n1.2,0,0\n1.3,0,0\n1.4,0,0\n1.5,0,0\n1.6,0,0\n");
  ExpectInputError(RunVibid({"frf-estimate", flat, "--force", "f", "--response", "x", "--impact"}),
                   "no hit");
  EXPECT_EQ(RunVibid({"frf-estimate", rig.modal1(), "--response", "acc1_m_s2"}).exit_code,
            2);  // --force missing
  // Nothing is written on failure.
  RunVibid({"frf-estimate", rig.modal1(), "--force", "force1_n", "--response", "nope", "-o",
            rig.dir + "/never.csv"});
  EXPECT_FALSE(std::filesystem::exists(rig.dir + "/never.csv"));
}

TEST(ModesCli, JsonSchemaAndTruth) {
  const Rig& rig = SyntheticRig();
  const auto r = RunVibid({"modes", rig.modal1(), "--force", "force1_n", "--response",
                           "acc1_m_s2,acc2_m_s2", "--impact", "--exp-window", "0.01", "--max-modes",
                           "2", "--json", "-o", rig.dir + "/modes1.json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(ReadFileText(rig.dir + "/modes1.json"));
  ASSERT_EQ(j["modes"].size(), 2u);
  for (const char* key : {"omega_rad_s", "freq_hz", "zeta", "ratio", "shape"})
    EXPECT_TRUE(j["modes"][0].contains(key)) << key;
  // Truth (model core's modal analysis of the chain): omega 33.594 and 74.418 rad/s, a1/a2 0.5486
  // and -1.2153.
  EXPECT_NEAR(j["modes"][0]["omega_rad_s"].get<double>(), 33.594, 0.002 * 33.594);
  EXPECT_NEAR(j["modes"][1]["omega_rad_s"].get<double>(), 74.418, 0.002 * 74.418);
  EXPECT_NEAR(j["modes"][0]["ratio"].get<double>(), 0.5486, 0.03 * 0.5486);
  EXPECT_EQ(j["summary"]["termination"].get<std::string>().find("tolerance") != std::string::npos,
            true);
  // The default method gives 95 % intervals around each value.
  for (const auto& m : j["modes"]) {
    ASSERT_TRUE(m.contains("ci95")) << m.dump();
    for (const char* key : {"omega_rad_s", "zeta", "ratio"}) {
      const auto& ci = m["ci95"][key];
      ASSERT_TRUE(ci.is_array() && ci.size() == 2) << key;
      EXPECT_LT(ci[0].get<double>(), m[key].get<double>()) << key;
      EXPECT_GT(ci[1].get<double>(), m[key].get<double>()) << key;
    }
  }
  // From an FRF file, peak picking: no intervals.
  const auto p =
      RunVibid({"modes", ImpactFrfCsv(), "--method", "peaks", "--max-modes", "2", "--json"});
  ASSERT_EQ(p.exit_code, 0) << p.err;
  EXPECT_EQ(json::parse(p.out)["modes"].size(), 2u);
  EXPECT_FALSE(json::parse(p.out)["modes"][0].contains("ci95"));
}

// Acceptance: the default path recognises a hammer record (no --impact), says so in one line,
// and gets the modes right; --welch forces Welch averaging. Truth: the rig's state-matrix modes
// (model core) and the closed-form a1/a2 of the chain.
TEST(ModesCli, DefaultPathRecognisesAnImpactTest) {
  const Rig& rig = SyntheticRig();
  const auto r = RunVibid({"modes", rig.modal1(), "--force", "force1_n", "--response",
                           "acc1_m_s2,acc2_m_s2", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("processed as an impact test"), std::string::npos) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["method"], "lscf");
  ASSERT_TRUE(j.contains("stabilization"));
  EXPECT_FALSE(j["stabilization"]["poles"].empty());
  ASSERT_EQ(j["modes"].size(), 2u);
  const model::Model truth = model::MakeChain(
      Eigen::Vector2d(1.2, 0.8), Eigen::Vector2d(3000, 2000), Eigen::Vector2d(0.9, 0.8));
  const model::ComplexModes cm = model::ComplexModalDamping(truth);
  for (Eigen::Index i = 0; i < 2; ++i) {
    const json& mode = j["modes"][static_cast<std::size_t>(i)];
    const double omega = mode["omega_rad_s"].get<double>();
    const double zeta = mode["zeta"].get<double>();
    std::printf("modes default path mode %ld: omega %+.4f %%, zeta %+.2f %%\n",
                static_cast<long>(i) + 1, 100 * (omega / cm.omega_rad_s[i] - 1),
                100 * (zeta / cm.zeta[i] - 1));
    EXPECT_NEAR(omega, cm.omega_rad_s[i], 0.0005 * cm.omega_rad_s[i]);
    EXPECT_NEAR(zeta, cm.zeta[i], 0.03 * cm.zeta[i]);
  }
  const auto w = RunVibid({"modes", rig.modal1(), "--force", "force1_n", "--response",
                           "acc1_m_s2,acc2_m_s2", "--welch", "--method", "fit"});
  EXPECT_EQ(w.err.find("processed as an impact test"), std::string::npos) << w.err;
  EXPECT_EQ(RunVibid({"modes", rig.modal1(), "--force", "force1_n", "--response", "acc1_m_s2",
                      "--welch", "--impact"})
                .exit_code,
            2);
  const auto bad = RunVibid(
      {"modes", rig.modal1(), "--force", "force1_n", "--response", "acc1_m_s2", "--orders", "9:3"});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("--orders '9:3'"), std::string::npos) << bad.err;
}

// The DaISy robot arm (a periodic sweep, 1024 samples, Welch): pLSCF finds no stable pole on so
// few lines and the default falls back to LSCE, saying so. Reference: the data set's own statement
// that a 4th-order model is good enough, i.e. two modes.
TEST(ModesCli, DefaultFallsBackWhenLscfFindsNoStablePole) {
  const auto r =
      RunVibid({"modes", vibid::testing::TestData("daisy_robot_arm/robot_arm.csv"), "--force",
                "u_reaction_torque", "--response", "y_arm_acceleration", "--fs-hz", "1", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("Welch averaging"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("modes from LSCE"), std::string::npos) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["modes"].size(), 2u);
  EXPECT_EQ(j["stabilization"]["method"], "lsce");
}

// Hits faster than the chain rings down (every 1.05 to 1.95 s: records of about a second, lines
// about 1 Hz apart), the emulated rig's chain with c = 1.43e-3 k. `vibid modes` with its defaults
// and with the orders of the report give both modes, a1/a2 of opposite signs as the closed form
// (0.5678, -1.4806), and no interval printed as +- 0 (text) or of zero width (JSON).
TEST(ModesCli, ShortRecordsGiveTheModesAndNoPointInterval) {
  const Rig& rig = SyntheticRig();
  const std::string rec = rig.dir + "/short_hits.csv";
  if (!std::filesystem::exists(rec)) {
    const model::Model truth =
        model::MakeChain(Eigen::Vector2d(1.82, 1.53), Eigen::Vector2d(3520, 2760),
                         Eigen::Vector2d(1.43e-3 * 3520, 1.43e-3 * 2760));
    const ident::HammerTestSpec spec{.hammer_dof = 1,
                                     .fs_hz = Rig::kFsHz,
                                     .hits = 26,
                                     .hit_peak_n = 100,
                                     .spacing_min_s = 1.05,
                                     .spacing_max_s = 1.95,
                                     .seed = 7};
    Write(rig.dir, "short_hits.csv",
          ident::FormatHammerTestCsv(ident::SimulateHammerTest(truth, spec),
                                     {"acc1_m_s2", "acc2_m_s2"}));
  }
  const std::string frf =
      MadeOnce(rig.dir + "/short_frf.csv",
               {"frf-estimate", rec, "--force", "force_n", "--response", "acc1_m_s2,acc2_m_s2"});
  const std::vector<std::vector<std::string>> runs = {
      {"modes", frf}, {"modes", frf, "--fmax-hz", "30", "--orders", "4:12:2"}};
  for (const auto& args : runs) {
    const auto t = RunVibid(args);
    ASSERT_EQ(t.exit_code, 0) << t.err;
    EXPECT_EQ(t.out.find("+- 0 "), std::string::npos) << t.out;
    std::vector<std::string> with_json = args;
    with_json.push_back("--json");
    const auto r = RunVibid(with_json);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const json j = json::parse(r.out);
    ASSERT_EQ(j["modes"].size(), 2u) << r.out;
    EXPECT_NEAR(j["modes"][0]["ratio"].get<double>(), 0.5678, 0.02 * 0.5678);
    EXPECT_NEAR(j["modes"][1]["ratio"].get<double>(), -1.4806, 0.02 * 1.4806);
    for (const auto& m : j["modes"]) {
      if (!m.contains("ci95")) continue;
      for (const auto& [key, ci] : m["ci95"].items()) {
        if (!ci.is_null()) {
          EXPECT_LT(ci[0].get<double>(), ci[1].get<double>()) << key;
        }
      }
    }
  }
}

TEST(ModesCli, BadInput) {
  const Rig& rig = SyntheticRig();
  ExpectInputError(RunVibid({"modes", rig.dir + "/none.csv", "--json"}), "none.csv");
  ExpectInputError(RunVibid({"modes", rig.modal1(), "--json"}), "--force");
  const std::string half = Write(rig.dir, "half.csv", "freq_hz,h_re\n1,2\n2,2\n3,2\n4,2\n");
  ExpectInputError(RunVibid({"modes", half, "--json"}), "h_im");
  ExpectInputError(RunVibid({"modes", ImpactFrfCsv(), "--method", "guess"}), "guess");
  ExpectInputError(RunVibid({"modes", ImpactFrfCsv(), "--driving-point", "7"}), "--driving-point");
}

TEST(UpdateCli, MassAndStiffness) {
  const Rig& rig = SyntheticRig();
  const auto m =
      RunVibid({"update", "mass", rig.mass1(), "--force", "force1_n", "--response", "acc1_m_s2",
                "--impact", "--stiffness-n-per-m", "3300", "--nominal-kg", "1.296", "--json"});
  ASSERT_EQ(m.exit_code, 0) << m.err;
  const json mj = json::parse(m.out);
  for (const char* key : {"mass_kg", "nominal_kg", "change_percent", "zeta", "summary"})
    EXPECT_TRUE(mj.contains(key)) << key;
  EXPECT_NEAR(mj["mass_kg"].get<double>(), 1.2, 0.01 * 1.2);
  EXPECT_NEAR(mj["change_percent"].get<double>(),
              100 * (mj["mass_kg"].get<double>() - 1.296) / 1.296, 1e-9);
  EXPECT_NEAR(mj["zeta"].get<double>(), 0.02, 0.002);
  // 95 % intervals: m and c from the fit, none for the given k (and the reason).
  ASSERT_TRUE(mj["mass_kg_ci95"].is_array()) << mj.dump();
  EXPECT_LT(mj["mass_kg_ci95"][0].get<double>(), mj["mass_kg"].get<double>());
  EXPECT_GT(mj["mass_kg_ci95"][1].get<double>(), mj["mass_kg"].get<double>());
  EXPECT_TRUE(mj["c_ns_per_m_ci95"].is_array());
  EXPECT_TRUE(mj["k_n_per_m_ci95"].is_null());
  EXPECT_EQ(mj["k_n_per_m_ci95_missing"], "given, not fitted");

  const auto m2 = RunVibid({"modes", rig.modal2(), "--force", "force1_n", "--response",
                            "acc1_m_s2,acc2_m_s2", "--impact", "--exp-window", "0.01",
                            "--max-modes", "2", "--json", "-o", rig.dir + "/modes2.json"});
  ASSERT_EQ(m2.exit_code, 0) << m2.err;
  const auto s = RunVibid({"update", "stiffness", "--masses", "1.2,0.8", "--modes", Modes1Json(),
                           rig.dir + "/modes2.json", "--json"});
  ASSERT_EQ(s.exit_code, 0) << s.err;
  const json sj = json::parse(s.out);
  for (const char* key : {"springs", "K", "springs_lsq", "offdiag_mismatch_percent", "spread"})
    EXPECT_TRUE(sj.contains(key)) << key;
  EXPECT_NEAR(sj["springs"][0].get<double>(), 3000, 30);
  EXPECT_NEAR(sj["springs"][1].get<double>(), 2000, 20);
  EXPECT_EQ(sj["K"].size(), 2u);
  // Intervals per position, the masses taken as exact unless their half-widths are given.
  ASSERT_EQ(sj["intervals"].size(), 2u);
  const json& k1 = sj["intervals"][0];
  ASSERT_TRUE(k1["k_n_per_m_ci95"].is_array()) << sj.dump();
  EXPECT_NE(k1["k_n_per_m_ci95_basis"].get<std::string>().find("masses taken as exact"),
            std::string::npos);
  const auto one = RunVibid({"update", "stiffness", "--masses", "1.2,0.8", "--modes", Modes1Json(),
                             "--mass-ci95", "0.002,0.001"});
  ASSERT_EQ(one.exit_code, 0) << one.err;
  EXPECT_NE(one.out.find("95 % intervals: k1 +- "), std::string::npos) << one.out;
  EXPECT_EQ(one.out.find("+- 0 "), std::string::npos) << one.out;
}

TEST(UpdateCli, BadInput) {
  const Rig& rig = SyntheticRig();
  ExpectInputError(RunVibid({"update", "mass", rig.modal1(), "--force", "force1_n", "--response",
                             "acc1_m_s2,acc2_m_s2", "--impact"}),
                   "exactly one response");
  ExpectInputError(RunVibid({"update", "mass", rig.mass1(), "--force", "force1_n", "--response",
                             "acc1_m_s2", "--nominal-kg", "-1"}),
                   "--nominal-kg");
  ExpectInputError(RunVibid({"update", "stiffness", "--masses", "1,abc", "--modes", Modes1Json()}),
                   "abc");
  ExpectInputError(RunVibid({"update", "stiffness", "--masses", "1,1,1", "--modes", Modes1Json()}),
                   "2 modes for 3 masses");
  const std::string broken = Write(rig.dir, "broken.json", "{\"modes\": [");
  ExpectInputError(RunVibid({"update", "stiffness", "--masses", "1,1", "--modes", broken}),
                   "broken.json");
  const std::string empty = Write(rig.dir, "empty.json", "{\"modes\": []}");
  ExpectInputError(RunVibid({"update", "stiffness", "--masses", "1,1", "--modes", empty}), "empty");
  // A misspelt key is refused: "zetta" would otherwise load as a mode without damping.
  const std::string misspelt =
      Write(rig.dir, "misspelt.json", R"({"modes": [{"omega_rad_s": 40, "zetta": 0.01}]})");
  ExpectInputError(
      RunVibid({"update", "stiffness", "--masses", "1", "--modes", misspelt}),
      "unknown key 'zetta' in modes file " + misspelt + " mode 1 (did you mean 'zeta'?)");
  EXPECT_EQ(RunVibid({"update"}).exit_code, 2);
}

TEST(DecayCli, EcpPair) {
  VIBID_SHARED_DATA_OR_SKIP(dir, "ecp_cart_free_decay");
  const std::string d = dir + "/";
  const auto r = RunVibid(
      {"decay", d + "Khigh_load-none_Khigh_hand_Nomass.csv",
       d + "Khigh_load-none_Khigh_hand_Nomass2.csv", d + "Khigh_load-none_Khigh_hand_Nomass3.csv",
       "--position", "X_cm:cm", "--loaded", d + "Khigh_load-0.986kg_Khigh_hand_2mass.csv",
       d + "Khigh_load-0.986kg_Khigh_hand_2mass2.csv",
       d + "Khigh_load-0.986kg_Khigh_hand_2mass3.csv", "--added-kg", "0.986", "--json"});
  // The guide's friction is named on every record (the lab noted it): the result is written,
  // with its cautions, and exits 0 (a caution is no refusal), the cautions named on stderr.
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("caution"), std::string::npos) << r.err;
  const json j = json::parse(r.out);
  for (const json* set : {&j, &j["loaded"]}) {
    for (const json& rec : (*set)["records"])
      EXPECT_TRUE(rec["friction"]["detected"].get<bool>()) << rec["file"];
  }
  EXPECT_GE(j["cautions"].size(), 6u) << j["cautions"].dump();
  for (const char* key : {"omega_d_rad_s", "zeta", "omega_n_rad_s", "k_n_per_m", "base_mass_kg"})
    EXPECT_TRUE(j.contains(key)) << key;
  // The lab's values (data README): omega_d 34.9066 rad/s (one 200 Hz sample = 2.8 %), k 712.60
  // N/m, m_c 0.5848 kg.
  EXPECT_NEAR(j["omega_d_rad_s"].get<double>(), 34.9066, 0.028 * 34.9066);
  EXPECT_NEAR(j["k_n_per_m"].get<double>(), 712.60, 0.02 * 712.60);
  EXPECT_NEAR(j["base_mass_kg"].get<double>(), 0.5848, 0.03 * 0.5848);
}

// One record in centimetres, negated, halved and in metres: the same omega_n, zeta, cautions and
// exit code (the verdict once depended on the sign and unit).
TEST(DecayCli, SignAndUnitDoNotChangeTheVerdict) {
  VIBID_SHARED_DATA_OR_SKIP(dir, "ecp_cart_free_decay");
  const std::string rec = dir + "/Klow_load-none_Klow_Hand_Nomass.csv";
  const auto ref = RunVibid({"decay", rec, "--position", "X_cm", "--json"});
  ASSERT_EQ(ref.exit_code, 0) << ref.err;
  ASSERT_NE(ref.err.find("caution"), std::string::npos) << ref.err;
  const json a = json::parse(ref.out);
  for (const char* position : {"X_cm*-1", "X_cm*0.5", "X_cm:cm", "X_cm*-0.01"}) {
    const auto r = RunVibid({"decay", rec, "--position", position, "--json"});
    EXPECT_EQ(r.exit_code, ref.exit_code) << position << ": " << r.err;
    const json b = json::parse(r.out);
    EXPECT_NEAR(b["omega_n_rad_s"].get<double>(), a["omega_n_rad_s"].get<double>(),
                1e-9 * a["omega_n_rad_s"].get<double>())
        << position;
    EXPECT_NEAR(b["zeta"].get<double>(), a["zeta"].get<double>(), 1e-7 * a["zeta"].get<double>())
        << position;
    EXPECT_EQ(b["cautions"].size(), a["cautions"].size()) << position;
  }
  // The text names the friction on a CAUTION line.
  const auto text = RunVibid({"decay", rec, "--position", "X_cm*-1"});
  EXPECT_NE(text.out.find("CAUTION: " + rec + ": friction"), std::string::npos) << text.out;
}

// The ECP cart driven by its motor's voltage (a step record): every command of the FRF route
// refuses it, --impact too, naming the time-domain methods; tfest takes it, and says that its
// residual tests fail (a caution: exit 0, the cautions named).
TEST(NotHammerCli, MotorStepRecordTakesTheTimeDomainRoute) {
  VIBID_SHARED_DATA_OR_SKIP(dir, "ecp_cart_motor_driven");
  const std::string rec = dir + "/steps_kmed_nomass_data0000.csv";
  const std::vector<std::string> io = {
      "--force", "V_volt", "--response", "X_encoder_counts*1.7857e-5", "--sensor", "disp"};
  const auto with = [&](std::vector<std::string> args) {
    args.insert(args.end(), io.begin(), io.end());
    return args;
  };
  const std::string out = MakeTempDir("not_hammer") + "/frf.csv";
  for (const auto& args :
       {with({"frf-estimate", rec, "-o", out}), with({"frf-estimate", rec, "--impact", "-o", out}),
        with({"modes", rec}), with({"update", "mass", rec})}) {
    const auto r = RunVibid(args);
    EXPECT_EQ(r.exit_code, 1) << args[0] << ": " << r.err;
    EXPECT_NE(r.err.find("not a hammer test"), std::string::npos) << args[0] << ": " << r.err;
    EXPECT_NE(r.err.find("vibid tfest"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(std::filesystem::exists(out));
  const auto tf = RunVibid({"tfest", rec, "--input", "I_amp*-178.57", "--output",
                            "X_encoder_counts*1.7857e-5", "--np", "2"});
  EXPECT_EQ(tf.exit_code, 0) << tf.err;
  EXPECT_NE(tf.out.find("CAUTION: the residuals are not white"), std::string::npos) << tf.out;
}

TEST(DecayCli, BadInput) {
  const Rig& rig = SyntheticRig();
  const std::string flat =
      Write(rig.dir, "still.csv",
            "t_s,X\n0,1\n0.1,1\n0.2,1\n0.3,1\n0.4,1\n0.5,1\n0.6,1\n0.7,1\n0.8,1\n0.9,1\n1.0,1\n1.1,"
            "1\n1.2,1\n1.3,1\n1.4,1\n1.5,1\n1.6,1\n1.7,1\n1.8,1\n1.9,1\n2.0,1\n2.1,1\n2.2,1\n2.3,"
            "1\n2.4,1\n2.5,1\n2.6,1\n2.7,1\n2.8,1\n2.9,1\n3.0,1\n3.1,1\n");
  ExpectInputError(RunVibid({"decay", flat, "--position", "Y"}), "Y");
  ExpectInputError(RunVibid({"decay", flat, "--position", "X", "--loaded", flat}), "--added-kg");
  ExpectInputError(RunVibid({"decay", flat, "--position", "X"}), "no motion");
  EXPECT_EQ(RunVibid({"decay", flat}).exit_code, 2);  // --position missing
}

TEST(IdentifyCli, WholeChainOnSyntheticTruth) {
  const Rig& rig = SyntheticRig();
  const std::string out = rig.dir + "/updated.json";
  const auto r =
      RunVibid({"identify", "--nominal", rig.nominal(), "--mass-test", "1=" + rig.mass1(),
                "--mass-test", "2=" + rig.mass2(), "--modal-test", rig.modal1(), "--modal-test",
                rig.modal2(), "--exp-window", "0.01", "-o", out, "--report", rig.dir + "/report"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("Modes (deviation of each model from the test)"), std::string::npos)
      << r.out;
  const json m = json::parse(ReadFileText(out));
  EXPECT_EQ(m["topology"], "chain");
  EXPECT_NEAR(m["masses"][0].get<double>(), 1.2, 0.012);
  EXPECT_NEAR(m["masses"][1].get<double>(), 0.8, 0.008);
  EXPECT_NEAR(m["springs"][0].get<double>(), 3000, 30);
  EXPECT_NEAR(m["springs"][1].get<double>(), 2000, 20);
  for (const char* f : {"validation.txt", "report.json", "frf_overlay.csv"}) {
    EXPECT_TRUE(std::filesystem::exists(rig.dir + "/report/" + f)) << f;
  }
  // m, k and c with their 95 % intervals, in the table and the report (truth: 1.2, 0.8 kg,
  // 3000, 2000 N/m).
  EXPECT_NE(r.out.find("95 % interval"), std::string::npos) << r.out;
  const json rep = json::parse(ReadFileText(rig.dir + "/report/report.json"));
  ASSERT_EQ(rep["parameters"].size(), 2u);
  const double truth[2][2] = {{1.2, 3000}, {0.8, 2000}};
  for (std::size_t p = 0; p < 2; ++p) {
    const json& q = rep["parameters"][p];
    for (const char* key : {"m_kg_ci95", "k_n_per_m_ci95", "c_ns_per_m_ci95"})
      ASSERT_TRUE(q[key].is_array()) << key << " " << q.dump();
    EXPECT_LE(q["k_n_per_m_ci95"][0].get<double>(), truth[p][1]) << q.dump();
    EXPECT_GE(q["k_n_per_m_ci95"][1].get<double>(), truth[p][1]) << q.dump();
  }
  EXPECT_TRUE(rep["validation"]["positions"][0]["m_kg"]["updated_ci95"].is_array());
  // The mass tests' springs are the nominal ones: nothing to warn of.
  EXPECT_EQ(r.err.find("its FRF's level says"), std::string::npos) << r.err;
}

// Three masses, the hammer on mass 3: the validation has a1/a3 and a2/a3 for each mode, and
// `vibid report` reads them (a report of more than two responses used to be refused).
TEST(IdentifyCli, ThreeMassReportHasEveryShapeRatio) {
  const Rig& rig = SyntheticRig();
  const model::Model truth =
      model::MakeChain(Eigen::Vector3d(1.0, 0.8, 0.6), Eigen::Vector3d(4000, 3000, 2000),
                       Eigen::Vector3d(3.0, 2.0, 1.5));
  ident::HammerTestSpec spec = ident::ModalTestSpec(Rig::kFsHz, 31);
  spec.hammer_dof = 2;
  const std::string rec =
      Write(rig.dir, "chain3.csv",
            ident::FormatHammerTestCsv(ident::SimulateHammerTest(truth, spec),
                                       {"acc1_m_s2", "acc2_m_s2", "acc3_m_s2"}, "force1_n"));
  const std::string nominal = Write(
      rig.dir, "nominal3.json",
      R"({"topology": "chain", "masses": [1.07, 0.856, 0.642], "springs": [4000, 3000, 2000]})");
  const std::string dir = rig.dir + "/report3";
  const auto r = RunVibid({"identify", "--nominal", nominal, "--modal-test", rec,
                           "--modal-responses", "acc1_m_s2,acc2_m_s2,acc3_m_s2", "-o",
                           rig.dir + "/updated3.json", "--report", dir});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json rep = json::parse(ReadFileText(dir + "/report.json"));
  const json& modes = rep["validation"]["modes"];
  ASSERT_EQ(modes.size(), 3u) << modes.dump();
  // Reference: the truth's mass-normalised shapes (model::Modal), each entry over mass 3's.
  const model::ModalResult exact = model::Modal(truth);
  for (std::size_t i = 0; i < 3; ++i) {
    const json& m = modes[i];
    EXPECT_FALSE(m.contains("ratio")) << m.dump();  // a1/a2 is a two-response quantity
    ASSERT_TRUE(m.contains("shape_ratios")) << m.dump();
    ASSERT_EQ(m["shape_ratios"].size(), 2u) << m.dump();
    const auto col = static_cast<Eigen::Index>(m["mode"].get<int>() - 1);
    for (std::size_t j = 0; j < 2; ++j) {
      const json& x = m["shape_ratios"][j];
      EXPECT_EQ(x["name"], "a" + std::to_string(j + 1) + "/a3");
      const double want = exact.shapes(static_cast<Eigen::Index>(j), col) / exact.shapes(2, col);
      EXPECT_NEAR(x["test"].get<double>(), want, 0.03 * std::abs(want)) << x.dump();
      EXPECT_NEAR(x["test"].get<double>(), m["shape"]["test"][j].get<double>(), 1e-12);
    }
  }
  const std::string page = rig.dir + "/report3.html";
  const auto p = RunVibid({"report", "--identify", dir, "-o", page});
  ASSERT_EQ(p.exit_code, 0) << p.err;
  const std::string html = ReadFileText(page);
  EXPECT_NE(html.find("a1/a3"), std::string::npos);
  EXPECT_NE(html.find("a2/a3"), std::string::npos);
  EXPECT_EQ(html.find("a1/a2"), std::string::npos);
}

// A wrong given spring moves the mass by as much; the test's own level says so.
TEST(IdentifyCli, AWrongSpringIsNamed) {
  const Rig& rig = SyntheticRig();
  const auto r = RunVibid({"identify", "--nominal", rig.nominal(), "--mass-test",
                           "1=" + rig.mass1(), "--mass-spring", "1=3600", "--modal-test",
                           rig.modal1(), "-o", rig.dir + "/updated_wrong_spring.json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("mass test 1: its FRF's level says the spring is"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("--mass-spring 1=fit"), std::string::npos) << r.err;
}

// identify's default columns are the names the board's log table gives the load cell and the
// accelerometers (host/device/log_table.cpp), so a recording off the board needs no option.
TEST(IdentifyCli, DefaultColumnsAreTheBoardsNames) {
  const auto name = [](wire::Channel c, wire::Unit u) {
    return std::string(device::ChannelStem(c)) + "_" + device::UnitSuffix(u);
  };
  EXPECT_EQ(ident::ForceColumn(), name(wire::Channel::kForce1, wire::Unit::kNewton));
  EXPECT_EQ(ident::AccelerationColumn(1),
            name(wire::Channel::kAccel1, wire::Unit::kMeterPerSecond2));
  EXPECT_EQ(ident::AccelerationColumn(2),
            name(wire::Channel::kAccel2, wire::Unit::kMeterPerSecond2));
  EXPECT_EQ(ident::AccelerationColumns(2), "acc1_m_s2,acc2_m_s2");
}

// A modal test with a text column nobody asked for loads; asking for that column is refused
// with the line and the column.
TEST(IdentifyCli, TextColumnsThatAreNotAskedForLoad) {
  const Rig& rig = SyntheticRig();
  std::string text = ReadFileText(rig.modal1());
  std::string noted;
  std::size_t line = 0;
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t end = text.find('\n', at);
    noted += text.substr(at, end - at) + (line == 0 ? ",note\n" : line == 1 ? ",hit A\n" : ",\n");
    at = end + 1;
    ++line;
  }
  const std::string path = Write(rig.dir, "modal1_noted.csv", noted);
  const std::string out = rig.dir + "/updated_noted.json";
  const auto r = RunVibid({"identify", "--nominal", rig.nominal(), "--mass-test",
                           "1=" + rig.mass1(), "--mass-test", "2=" + rig.mass2(), "--modal-test",
                           path, "--exp-window", "0.01", "-o", out});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json m = json::parse(ReadFileText(out));
  EXPECT_NEAR(m["springs"][1].get<double>(), 2000, 20);
  ExpectInputError(RunVibid({"modes", path, "--force", "force1_n", "--response", "acc2_m_s2,note"}),
                   "modal1_noted.csv:2: column 5 'note': 'hit A' is not a number");
}

TEST(IdentifyCli, BadInput) {
  const Rig& rig = SyntheticRig();
  const std::string out = rig.dir + "/not_written.json";
  ExpectInputError(RunVibid({"identify", "--nominal", rig.nominal(), "--mass-test",
                             "one=" + rig.mass1(), "--modal-test", rig.modal1(), "-o", out}),
                   "--mass-test");
  ExpectInputError(RunVibid({"identify", "--nominal", rig.nominal(), "--mass-test",
                             "3=" + rig.mass1(), "--modal-test", rig.modal1(), "-o", out}),
                   "beyond");
  ExpectInputError(RunVibid({"identify", "--nominal", rig.dir + "/nope.json", "--modal-test",
                             rig.modal1(), "-o", out}),
                   "nope.json");
  ExpectInputError(
      RunVibid({"identify", "--nominal", rig.nominal(), "--modal-test", rig.mass1(), "-o", out}),
      "no column 'acc2_m_s2'");
  EXPECT_EQ(RunVibid({"identify", "--nominal", rig.nominal(), "-o", out}).exit_code,
            2);  // no --modal-test
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace vibid::testing
