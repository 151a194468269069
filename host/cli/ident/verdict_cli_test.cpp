// The verdict contract through the real binary: a flagged identification exits 6 and writes no
// model; --accept-flagged writes it with its verdict; dob design and report refuse the flagged
// file unless given --accept-flagged; a caution exits 0 and is carried in the file; a model file
// without a verdict (written before files carried one) still reads everywhere.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "run_cli.hpp"
#include "vibid/common/atomic_file.hpp"
#include "vibid/ident/recording_columns.hpp"
#include "vibid/ident/testing/hammer_test.hpp"
#include "vibid/model/model.hpp"

namespace vibid::testing {
namespace {

using nlohmann::json;

constexpr int kExitFlagged = 6;  // host/cli/exit_codes.hpp
constexpr double kFsHz = 500;

std::string Write(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = dir + "/" + name;
  WriteFileAtomic(path, text);
  return path;
}

// The rig: chain m = (1.2, 0.8) kg, k = (3000, 2000) N/m, c = (0.9, 0.8) N*s/m; each mass test
// on its own spring of 3300 and 2200 N/m, the nominal model's chain springs (masses +8 %, springs
// +10 %), as `identify` assumes without --mass-spring.
struct Files {
  std::string dir = MakeTempDir("verdict_cli");
  std::string nominal, modal, mass1, mass2;

  Files() {
    nominal = Write(dir, "nominal.json",
                    R"({"topology": "chain", "masses": [1.296, 0.864], "springs": [3300, 2200]})");
    const model::Model truth = model::MakeChain(
        Eigen::Vector2d(1.2, 0.8), Eigen::Vector2d(3000, 2000), Eigen::Vector2d(0.9, 0.8));
    modal = Write(
        dir, "modal.csv",
        ident::FormatHammerTestCsv(ident::SimulateHammerTest(truth, ident::ModalTestSpec(kFsHz, 7)),
                                   {"acc1_m_s2", "acc2_m_s2"}, "force1_n"));
    mass1 = Mass(0);
    mass2 = Mass(1);
  }
  std::string Mass(int i) const {
    const double ms[2] = {1.2, 0.8}, ks[2] = {3300, 2200};
    const model::Model one =
        model::MakeChain(Eigen::VectorXd::Constant(1, ms[i]), Eigen::VectorXd::Constant(1, ks[i]),
                         Eigen::VectorXd::Constant(1, 2 * 0.02 * std::sqrt(ks[i] * ms[i])));
    return Write(
        dir, "mass" + std::to_string(i + 1) + ".csv",
        ident::FormatHammerTestCsv(
            ident::SimulateHammerTest(one,
                                      ident::MassTestSpec(kFsHz, 100u + static_cast<unsigned>(i))),
            {ident::AccelerationColumn(static_cast<std::size_t>(i) + 1)}, ident::ForceColumn()));
  }
  /// identify with mass 1's test taken on a spring of `k1` N/m (--mass-spring 1=K): a spring
  /// misread from the drawing moves m1 by as much, and the chain built on it misses the modes.
  std::vector<std::string> Identify(const std::string& k1, const std::string& out) const {
    return {"identify",    "--nominal",    nominal,         "--mass-test", "1=" + mass1,
            "--mass-test", "2=" + mass2,   "--mass-spring", "1=" + k1,     "--modal-test",
            modal,         "--exp-window", "0.01",          "-o",          out};
  }
};

const Files& Rig() {
  static const Files files;
  return files;
}

bool Has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// A mass test on a spring the user states wrongly (4400 N/m for the 3300 it stood on: 33 % stiff,
// so m1 comes out 33 % heavy) gives a chain that fits its own test worse than the nominal model.
TEST(VerdictCli, FlaggedIdentificationWritesNothingAndExitsSix) {
  const Files& rig = Rig();
  const std::string out = rig.dir + "/flagged.json";
  const std::string report = rig.dir + "/flagged_report";
  std::vector<std::string> args = rig.Identify("4400", out);
  args.insert(args.end(), {"--report", report});
  const CliResult r = RunVibid(args);
  EXPECT_EQ(r.exit_code, kExitFlagged) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out)) << "a flagged model must not be written";
  EXPECT_TRUE(Has(r.out, "Verdict: FLAGGED: the updated model fits its own test worse")) << r.out;
  EXPECT_TRUE(Has(r.err, "was not written; --accept-flagged writes it anyway")) << r.err;
  // The report is written, so that it says why: its verdict, reasons with their codes.
  const json rep = json::parse(ReadFileText(report + "/report.json"));
  EXPECT_EQ(rep["verdict"]["level"], "flagged");
  EXPECT_EQ(rep["verdict"]["reasons"][0]["code"], "worse_than_nominal");
  EXPECT_TRUE(rep["validation"]["modal_deviation"]["worse_than_nominal"].get<bool>());
  // vibid report refuses it unless told, naming the option; with it, red at the top.
  const std::string page = rig.dir + "/flagged.html";
  const CliResult p = RunVibid({"report", "--identify", report, "-o", page});
  EXPECT_EQ(p.exit_code, kExitFlagged) << p.err;
  EXPECT_TRUE(Has(p.err, "--accept-flagged")) << p.err;
  EXPECT_FALSE(std::filesystem::exists(page));
  const CliResult pa = RunVibid({"report", "--identify", report, "-o", page, "--accept-flagged"});
  ASSERT_EQ(pa.exit_code, 0) << pa.err;
  const std::string html = ReadFileText(page);
  const std::size_t box = html.find("<div class=\"notice notice-flagged\" id=\"verdict\">");
  ASSERT_NE(box, std::string::npos) << html.substr(0, 2000);
  EXPECT_LT(box, html.find("<h2>Identification</h2>")) << "the verdict comes first";
}

TEST(VerdictCli, AcceptedFlaggedModelCarriesItsVerdictAndIsRefusedDownstream) {
  const Files& rig = Rig();
  const std::string out = rig.dir + "/accepted.json";
  std::vector<std::string> args = rig.Identify("4400", out);
  args.push_back("--accept-flagged");
  const CliResult r = RunVibid(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json m = json::parse(ReadFileText(out));
  EXPECT_EQ(m["verdict"]["level"], "flagged");
  EXPECT_EQ(m["verdict"]["reasons"][0]["code"], "worse_than_nominal");
  EXPECT_TRUE(Has(r.err, "although flagged")) << r.err;
  // The model reader keeps the verdict: dob design refuses the file unless told.
  const std::string design = rig.dir + "/design_flagged.json";
  const CliResult d = RunVibid({"dob", "design", out, "-o", design});
  EXPECT_EQ(d.exit_code, kExitFlagged) << d.err;
  EXPECT_TRUE(Has(d.err, "model file " + out + " is flagged (the updated model fits")) << d.err;
  EXPECT_TRUE(Has(d.err, "dob design refuses it; --accept-flagged takes it anyway")) << d.err;
  EXPECT_FALSE(std::filesystem::exists(design));
  const CliResult da = RunVibid({"dob", "design", out, "-o", design, "--accept-flagged"});
  EXPECT_EQ(da.exit_code, 0) << da.err;
  EXPECT_TRUE(Has(da.err, "FLAGGED")) << da.err;
  // Tools that only look at a model read it whatever its verdict.
  EXPECT_EQ(RunVibid({"modal", out}).exit_code, 0);
}

// The same tests with the spring as it stood: ok, written, exit 0, the file says so.
TEST(VerdictCli, OkIdentificationIsWrittenWithItsVerdict) {
  const Files& rig = Rig();
  const std::string out = rig.dir + "/ok.json";
  const CliResult r = RunVibid(rig.Identify("3300", out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(Has(r.out, "Verdict: OK\n")) << r.out;
  const json m = json::parse(ReadFileText(out));
  EXPECT_EQ(m["verdict"]["level"], "ok");
  EXPECT_TRUE(m["verdict"]["reasons"].empty());
  EXPECT_NEAR(m["masses"][0].get<double>(), 1.2, 0.012);
}

// The one-test chain fit with a mode whose interval cannot be had (--method fit gives no
// covariance): a caution, exit 0, said and carried in the file; dob design takes it with a note.
TEST(VerdictCli, CautionExitsZeroAndIsCarried) {
  const Files& rig = Rig();
  const std::string out = rig.dir + "/caution.json";
  const CliResult r = RunVibid({"identify", "--nominal", rig.nominal, "--modal-test", rig.modal,
                                "--exp-window", "0.01", "--method", "fit", "-o", out});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(Has(r.out, "Verdict: CAUTION: the one-test chain fit has no intervals")) << r.out;
  const json m = json::parse(ReadFileText(out));
  EXPECT_EQ(m["verdict"]["level"], "caution");
  EXPECT_EQ(m["verdict"]["reasons"][0]["code"], "chain_fit_unchecked");
  const CliResult d = RunVibid({"dob", "design", out, "-o", rig.dir + "/design_caution.json"});
  EXPECT_EQ(d.exit_code, 0) << d.err;
  EXPECT_TRUE(Has(d.err, "note: " + out + ": CAUTION: the one-test chain fit")) << d.err;
}

// A model file written before files carried a verdict reads as before; a malformed verdict is
// refused naming the file and the field.
TEST(VerdictCli, OldModelFilesReadAndBadVerdictsAreRefused) {
  const Files& rig = Rig();
  // The shipped nominal model has no verdict: it designs as before.
  const CliResult old = RunVibid({"dob", "design", VIBID_SOURCE_DIR "/examples/rig_nominal.json",
                                  "-o", rig.dir + "/design_old.json"});
  EXPECT_EQ(old.exit_code, 0) << old.err;
  EXPECT_FALSE(Has(old.err, "flagged")) << old.err;
  const std::string bad = Write(
      rig.dir, "bad_verdict.json",
      R"({"topology": "chain", "masses": [1, 1], "springs": [1, 1], "verdict": {"level": "good"}})");
  const CliResult r = RunVibid({"dob", "design", bad, "-o", rig.dir + "/design_bad.json"});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_TRUE(Has(r.err,
                  "bad_verdict.json: field \"verdict\": \"level\" 'good' is not one of ok, "
                  "caution, flagged, refused"))
      << r.err;
}

}  // namespace
}  // namespace vibid::testing
