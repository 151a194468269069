// The front ends' estimation: the same numbers from a recording file and from the same signals in
// memory, the impact/Welch decision, the Welch default segment, and options refused up front.
#include "vibid/workflow/estimate.hpp"

#include <complex>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/ident/testing/hammer_test.hpp"
#include "vibid/model/model.hpp"
#include "vibid/workflow/modes_request.hpp"

namespace vibid::workflow {
namespace {

std::string WriteTemp(const std::string& name, const std::string& text) {
  const std::filesystem::path p = std::filesystem::temp_directory_path() / name;
  std::ofstream(p) << text;
  return p.string();
}

// A hammer test of the 2-DOF chain (the identification scenario's modal test).
struct ModalRecording {
  std::string path;
  Recording rec;
};

ModalRecording MakeModalRecording() {
  const model::Model truth = model::MakeChain(
      Eigen::Vector2d(1.8, 1.5), Eigen::Vector2d(3500.0, 2750.0), Eigen::Vector2d(2.0, 1.5));
  const ident::HammerTestRecord r =
      ident::SimulateHammerTest(truth, ident::ModalTestSpec(500.0, 3));
  ModalRecording out;
  out.path = WriteTemp("workflow_modal.csv",
                       ident::FormatHammerTestCsv(r, {"acc1_m_s2", "acc2_m_s2"}, "force1_n"));
  out.rec = LoadRecording(out.path);
  return out;
}

TEST(Estimate, ARecordingAndTheSameSignalsInMemoryGiveTheSameFrf) {
  const ModalRecording m = MakeModalRecording();
  EstimationOptions o;
  o.force = "force1_n";
  o.responses = "acc1_m_s2,acc2_m_s2";
  const Estimated file = EstimateFromRecording(m.path, o);
  Eigen::MatrixXd resp(static_cast<Eigen::Index>(m.rec.samples()), 2);
  resp.col(0) = m.rec.table.Column("acc1_m_s2");
  resp.col(1) = m.rec.table.Column("acc2_m_s2");
  const Estimated mem = EstimateFromSignals(m.rec.table.Column("force1_n"), resp, m.rec.fs_hz,
                                            "force1_n", {"acc1_m_s2", "acc2_m_s2"}, o);
  // The automatic decision: ten hits (ModalTestSpec), processed as an impact test.
  EXPECT_TRUE(file.impact);
  EXPECT_TRUE(mem.impact);
  EXPECT_EQ(file.hits.size(), 10u);
  EXPECT_NE(file.note.find("processed as an impact test"), std::string::npos) << file.note;
  ASSERT_EQ(file.frf.h.rows(), mem.frf.h.rows());
  // Bit for bit: the same samples through the same code.
  EXPECT_EQ((file.frf.h - mem.frf.h).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((file.frf.coherence - mem.frf.coherence).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(mem.frf.response_names, file.frf.response_names);
  EXPECT_EQ(DescribeHits(file.hits), DescribeHits(mem.hits));
  // The modes request by name gives two modes near the chain's (closed-form undamped 4.66 and
  // 9.62 Hz for these masses and springs: eigenvalues of M^-1 K).
  ModeRequest req;
  req.driving_point = "acc2_m_s2";
  const ident::ModeIdentification modes = IdentifyModes(file.frf, req);
  ASSERT_EQ(modes.modes.size(), 2u);
  const double m1 = 1.8, m2 = 1.5, k1 = 3500.0, k2 = 2750.0;
  const double b = (k1 + k2) / m1 + k2 / m2, c = k1 * k2 / (m1 * m2);
  const double l1 = 0.5 * (b - std::sqrt(b * b - 4 * c)), l2 = 0.5 * (b + std::sqrt(b * b - 4 * c));
  EXPECT_NEAR(modes.modes[0].omega_rad_s, std::sqrt(l1), 0.01 * std::sqrt(l1));
  EXPECT_NEAR(modes.modes[1].omega_rad_s, std::sqrt(l2), 0.01 * std::sqrt(l2));
  std::filesystem::remove(m.path);
}

TEST(Estimate, RandomForceIsWelchAveragedToTheClosedFormFir) {
  // y[n] = 0.5 x[n] + 0.25 x[n-1]: H(f) = 0.5 + 0.25 exp(-j 2 pi f / fs), coherence 1.
  const double fs = 1000.0;
  const Eigen::Index n = 40000;
  std::mt19937_64 gen(5);
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::VectorXd x(n);
  for (Eigen::Index i = 0; i < n; ++i) x[i] = g(gen);
  Eigen::MatrixXd y(n, 1);
  y(0, 0) = 0.5 * x[0];
  for (Eigen::Index i = 1; i < n; ++i) y(i, 0) = 0.5 * x[i] + 0.25 * x[i - 1];
  EstimationOptions o;
  o.sensor = "disp";
  o.kind = "receptance";
  const Estimated e = EstimateFromSignals(x, y, fs, "x", {"y"}, o);
  EXPECT_FALSE(e.impact);
  EXPECT_NE(e.note.find("Welch averaging"), std::string::npos) << e.note;
  EXPECT_EQ(e.record_samples, DefaultSegment(static_cast<std::size_t>(n)));
  EXPECT_EQ(e.record_samples, 4096u);
  double worst = 0.0;
  for (Eigen::Index i = 1; i < e.frf.freq_hz.size(); ++i) {
    const std::complex<double> h =
        0.5 +
        0.25 * std::exp(std::complex<double>(0.0, -2.0 * std::numbers::pi * e.frf.freq_hz[i] / fs));
    worst = std::max(worst, std::abs(e.frf.h(i, 0) - h));
  }
  // The only error: the FIR's one sample of memory across a segment edge (x[-1] is not in the
  // segment), which the Hann window's zero at the edges all but removes.
  EXPECT_LT(worst, 5e-4);  // measured 2e-4; a wrong delay sign gives 0.35
}

// Accelerometers and encoders in one test: each response is estimated as what it measures and
// brought to the FRF kind asked for. Two responses hold the same samples, y = FIR(x) with the
// closed-form response h(f) = 0.5 + 0.25 exp(-j 2 pi f / fs); named as a displacement (d_m) and
// as an acceleration (a_m_s2), the accelerance is -omega^2 h for the first (a displacement's
// FRF, differentiated twice) and h itself for the second.
TEST(Estimate, AccelerationsAndDisplacementsShareOneTest) {
  const double fs = 1000.0;
  const Eigen::Index n = 40000;
  std::mt19937_64 gen(5);
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::VectorXd x(n);
  for (Eigen::Index i = 0; i < n; ++i) x[i] = g(gen);
  Eigen::MatrixXd y(n, 2);
  y(0, 0) = 0.5 * x[0];
  for (Eigen::Index i = 1; i < n; ++i) y(i, 0) = 0.5 * x[i] + 0.25 * x[i - 1];
  y.col(1) = y.col(0);
  EstimationOptions o;
  o.kind = "accelerance";
  const Estimated e = EstimateFromSignals(x, y, fs, "x", {"d_m", "a_m_s2"}, o);
  ASSERT_EQ(e.frf.quantity, ident::Quantity::kAcceleration);
  double worst_d = 0.0, worst_a = 0.0;
  for (Eigen::Index i = 1; i < e.frf.freq_hz.size(); ++i) {
    const double w = 2.0 * std::numbers::pi * e.frf.freq_hz[i];
    const std::complex<double> h = 0.5 + 0.25 * std::exp(std::complex<double>(0.0, -w / fs));
    worst_d = std::max(worst_d, std::abs(e.frf.h(i, 0) / (-w * w) - h));
    worst_a = std::max(worst_a, std::abs(e.frf.h(i, 1) - h));
  }
  EXPECT_LT(worst_d, 5e-4);  // the Welch error of the test above; unaligned, it would be ~1
  EXPECT_LT(worst_a, 5e-4);
  // Said per response, the same; the column names need no units then.
  o.sensor = "disp,acc";
  const Estimated listed = EstimateFromSignals(x, y, fs, "x", {"d", "a"}, o);
  EXPECT_TRUE(listed.frf.h.isApprox(e.frf.h, 1e-15));

  // A sensor that contradicts a unit, or a list of another length, is refused.
  const auto refusal = [&](const std::string& sensor, const std::vector<std::string>& names) {
    EstimationOptions bad;
    bad.sensor = sensor;
    try {
      (void)EstimateFromSignals(x, y, fs, "x", names, bad);
    } catch (const InputError& err) {
      return std::string(err.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(refusal("acc", {"d_m", "a_m_s2"}),
            "--sensor says response 'd_m' measures an acceleration, but its unit makes it a "
            "displacement: drop --sensor (each response then measures what its unit says) or give "
            "it per response (--sensor acc,disp,...)");
  EXPECT_NE(refusal("acc,acc,disp", {"d", "a"}).find("--sensor names 3 quantities for 2"),
            std::string::npos);
  EXPECT_NE(refusal("acc,dsp", {"d", "a"}).find("dsp"), std::string::npos);
}

TEST(Estimate, DefaultSegmentIsAPowerOfTwoUpToAQuarterOfTheRecord) {
  EXPECT_EQ(DefaultSegment(100000), 4096u);
  EXPECT_EQ(DefaultSegment(1000), 128u);  // 4096 halved while above 250
  EXPECT_EQ(DefaultSegment(10), 16u);     // never below 16
}

TEST(Estimate, OptionsAreRefusedBeforeAnyWork) {
  EstimationOptions o;
  o.window = "hann1";
  try {
    o.Validate();
    FAIL() << "a window typo passed";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("hann1"), std::string::npos) << e.what();
  }
  o = EstimationOptions{};
  o.impact = o.welch = true;
  EXPECT_THROW(o.Validate(), InputError);
  o = EstimationOptions{};
  o.detrend = "linear";
  EXPECT_THROW(o.Validate(), InputError);
  const Eigen::VectorXd f = Eigen::VectorXd::Ones(100);
  Eigen::MatrixXd r = Eigen::MatrixXd::Ones(99, 1);
  EXPECT_THROW((void)EstimateFromSignals(f, r, 100.0, "f", {"r"}, EstimationOptions{}), InputError);
  r = Eigen::MatrixXd::Ones(100, 1);
  r(3, 0) = std::nan("");
  EXPECT_THROW((void)EstimateFromSignals(f, r, 100.0, "f", {"r"}, EstimationOptions{}), InputError);
}

}  // namespace
}  // namespace vibid::workflow
