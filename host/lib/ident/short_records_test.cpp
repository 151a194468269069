// Hammer tests whose hits come faster than the structure rings down (records of about one second,
// lines 1 Hz apart): the diagram's orders follow the band's lines, the modal model leaves out what
// the lines cannot determine, and no interval is ever reported with a width of 0. Truth: the
// chain's undamped modes in closed form (test_support.hpp) and its state-matrix eigenvalues.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "test_support.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/testing/real_data.hpp"
#include "vibid/ident/impact.hpp"
#include "vibid/ident/modal_model.hpp"
#include "vibid/ident/modes.hpp"
#include "vibid/ident/stabilization.hpp"
#include "vibid/ident/testing/hammer_test.hpp"
#include "vibid/model/modal.hpp"

namespace vibid::ident {
namespace {

// An interval is either not there (NaN) or has a positive width: never a point.
void ExpectNoPointInterval(const std::array<double, 2>& ci, const char* what, double freq_hz) {
  if (std::isnan(ci[0]) && std::isnan(ci[1])) return;
  EXPECT_TRUE(std::isfinite(ci[0]) && std::isfinite(ci[1]) && ci[1] > ci[0])
      << what << " interval [" << ci[0] << ", " << ci[1] << "] of the mode at " << freq_hz << " Hz";
}

void ExpectNoPointIntervals(const std::vector<ModeEstimate>& modes) {
  for (const ModeEstimate& m : modes) {
    ExpectNoPointInterval(m.omega_ci95_rad_s, "omega", m.freq_hz);
    ExpectNoPointInterval(m.zeta_ci95, "zeta", m.freq_hz);
    ExpectNoPointInterval(m.ratio_ci95, "a1/a2", m.freq_hz);
  }
}

// The emulated rig's chain (m 1.82, 1.53 kg, k 3520, 2760 N/m) with stiffness-proportional
// dampers (c = beta k, beta = 1.43e-3: zeta about 2 % and 4.8 %), so its modes are real and the
// undamped closed-form a1/a2 is exact; hit on mass 2 every 1.05 to 1.95 s (the emulator's hammer
// spacing before it followed the rig): records of about one second, lines about 1 Hz apart.
struct ShortRecordCase {
  model::Model truth;
  testing::ChainModes undamped;
  model::ComplexModes damped;
  Frf receptance;
};

const ShortRecordCase& ShortRecords() {
  static const ShortRecordCase c = [] {
    const double m1 = 1.82, m2 = 1.53, k1 = 3520, k2 = 2760, beta = 1.43e-3, fs = 500;
    ShortRecordCase out;
    out.truth = model::MakeChain(Eigen::Vector2d(m1, m2), Eigen::Vector2d(k1, k2),
                                 Eigen::Vector2d(beta * k1, beta * k2));
    out.undamped = testing::ChainModesOf(m1, m2, k1, k2);
    out.damped = model::ComplexModalDamping(out.truth);
    HammerTestSpec spec{.hammer_dof = 1,
                        .fs_hz = fs,
                        .hits = 26,
                        .hit_peak_n = 100,
                        .spacing_min_s = 1.05,
                        .spacing_max_s = 1.95,
                        .force_noise = 0.002,
                        .response_noise = 0.002,
                        .seed = 7};
    const HammerTestRecord rec = SimulateHammerTest(out.truth, spec);
    const ImpactResult r = EstimateImpactFrf(rec.force_n, rec.response, fs, {}, Estimator::kH1,
                                             Quantity::kAcceleration);
    out.receptance = ConvertFrf(r.frf, Quantity::kDisplacement);
    return out;
  }();
  return c;
}

double Pct(double v, double ref) { return 100.0 * (v - ref) / ref; }

void ExpectTheChainModes(const ModeIdentification& r, const ShortRecordCase& c, const char* how) {
  ASSERT_EQ(r.modes.size(), 2u) << how;
  for (std::size_t i = 0; i < 2; ++i) {
    const ModeEstimate& m = r.modes[i];
    std::printf(
        "%s mode %zu: omega %+.4f %%, zeta %+.2f %%, a1/a2 %.5f (closed form %.5f, %+.3f %%)"
        " +- %.3g\n",
        how, i + 1, Pct(m.omega_rad_s, c.damped.omega_rad_s[static_cast<Eigen::Index>(i)]),
        Pct(m.zeta, c.damped.zeta[static_cast<Eigen::Index>(i)]), m.ratio, c.undamped.ratio[i],
        Pct(m.ratio, c.undamped.ratio[i]), 0.5 * (m.ratio_ci95[1] - m.ratio_ci95[0]));
    EXPECT_NEAR(m.omega_rad_s, c.damped.omega_rad_s[static_cast<Eigen::Index>(i)],
                0.002 * c.damped.omega_rad_s[static_cast<Eigen::Index>(i)])
        << how;
    EXPECT_NEAR(m.zeta, c.damped.zeta[static_cast<Eigen::Index>(i)],
                0.1 * c.damped.zeta[static_cast<Eigen::Index>(i)])
        << how;
    // Before: both modes came out with one and the same a1/a2 (the ringing terms' undetermined
    // direction carried every residue), with an interval of 0.
    EXPECT_NEAR(m.ratio, c.undamped.ratio[i], 0.02 * std::abs(c.undamped.ratio[i])) << how;
  }
  ExpectNoPointIntervals(r.modes);
}

// `vibid modes FRF.csv --fmax-hz 30 --orders 4:12:2`, the command of the report.
TEST(ShortRecords, GivenOrdersGiveTheChainModes) {
  const ShortRecordCase& c = ShortRecords();
  ModeIdentificationOptions o;
  o.peaks.freq_max_hz = 30;
  ParseOrders("4:12:2", o.stabilization);
  const ModeIdentification r = IdentifyModes(c.receptance, 1, o);
  ExpectTheChainModes(r, c, "--fmax-hz 30 --orders 4:12:2");
  ASSERT_TRUE(r.has_model);
  EXPECT_FALSE(r.model.ringing_terms);
  EXPECT_TRUE(r.model.ringing_terms_dropped);
  EXPECT_FALSE(r.model.note.empty());
  // Values, but no intervals: the previous hits' ringing is in neither the model nor its noise
  // (a1/a2 of mode 2 is 1.1 % off, its interval was +- 1 %).
  for (const ModeEstimate& m : r.modes) EXPECT_FALSE(m.HasIntervals());
}

// Every default: the band around the peaks, widened to the lines its orders need, orders from
// the band's lines; and --fmax-hz alone (it used to need --orders below 30).
TEST(ShortRecords, DefaultsGiveTheChainModes) {
  const ShortRecordCase& c = ShortRecords();
  const ModeIdentification r = IdentifyModes(c.receptance, 1, {});
  ExpectTheChainModes(r, c, "defaults");
  ASSERT_TRUE(r.has_diagram);
  EXPECT_EQ(r.diagram.orders.front(), 4);
  EXPECT_EQ(r.diagram.orders.back(), 16);  // AutomaticMaxOrder of the widened band's 32 lines
  ModeIdentificationOptions o;
  o.peaks.freq_max_hz = 30;
  const ModeIdentification f = IdentifyModes(c.receptance, 1, o);
  ExpectTheChainModes(f, c, "--fmax-hz 30");
  EXPECT_EQ(f.diagram.orders.back(), 14);  // 29-30 lines: half of them, on the even grid
}

// A band too narrow for any diagram: lscf says so, LSCE too, and the curve fit gives the modes
// with both reasons in the first warning; with the fallback off, the refusal names the lines.
TEST(ShortRecords, TooFewLinesFallBackThenRefuse) {
  const ShortRecordCase& c = ShortRecords();
  ModeIdentificationOptions o;
  o.peaks.freq_max_hz = 12;
  const ModeIdentification r = IdentifyModes(c.receptance, 1, o);
  EXPECT_FALSE(r.has_diagram);
  ASSERT_FALSE(r.warnings.empty());
  EXPECT_NE(r.warnings.front().find("lscf: the band"), std::string::npos) << r.warnings.front();
  EXPECT_NE(r.warnings.front().find("modes from the curve fit"), std::string::npos);
  ASSERT_EQ(r.modes.size(), 2u);
  o.stabilization_fallback_off = true;
  try {
    (void)IdentifyModes(c.receptance, 1, o);
    ADD_FAILURE() << "no refusal";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("frequency lines"), std::string::npos) << what;
    EXPECT_NE(what.find("--record-s"), std::string::npos) << what;
  }
}

// The orders left open, by hand: a quarter of the lines, or up to 4 + 6 x 2 = 16 where half the
// lines (pLSCF; a quarter for LSCE) allow it, at most 48, and nothing below 4 + 3 x 2 = 10.
TEST(ShortRecords, AutomaticOrdersFollowTheLines) {
  StabilizationOptions o;
  EXPECT_EQ(AutomaticMaxOrder(17, o), 0);    // quarter 4, half 8 < 10
  EXPECT_EQ(AutomaticMaxOrder(20, o), 10);   // half 10
  EXPECT_EQ(AutomaticMaxOrder(30, o), 14);   // half 15, on the even grid
  EXPECT_EQ(AutomaticMaxOrder(40, o), 16);   // half 20, capped at 16
  EXPECT_EQ(AutomaticMaxOrder(128, o), 32);  // quarter 32
  EXPECT_EQ(AutomaticMaxOrder(400, o), 48);  // quarter 100, at most 48
  EXPECT_EQ(LinesNeeded(o), 20);
  o.method = PoleMethod::kLsce;
  EXPECT_EQ(AutomaticMaxOrder(40, o), 10);
  EXPECT_EQ(AutomaticMaxOrder(39, o), 0);
  EXPECT_EQ(LinesNeeded(o), 40);
  o.method = PoleMethod::kLscf;
  ParseOrders("4:12:2", o);
  EXPECT_EQ(LinesNeeded(o), 24);
}

// A closed-form FRF in coarse lines with the ringing terms asked for (a pretrigger) that it does
// not hold and that 16 lines 0.8 Hz apart cannot tell from the residues: the fit drops them, says
// so, and gives every quantity a positive interval; omega, zeta and a1/a2 as the closed form.
TEST(ShortRecords, UndeterminedRingingTermsAreLeftOut) {
  const double m1 = 1.82, m2 = 1.53, k1 = 3520, k2 = 2760, beta = 1.43e-3;
  Frf frf = testing::ChainFrf(m1, m2, k1, k2, beta * k1, beta * k2, 1, 0.8, 50);
  frf.pretrigger_s = 0.0166;
  const model::ComplexModes cm = model::ComplexModalDamping(model::MakeChain(
      Eigen::Vector2d(m1, m2), Eigen::Vector2d(k1, k2), Eigen::Vector2d(beta * k1, beta * k2)));
  const testing::ChainModes um = testing::ChainModesOf(m1, m2, k1, k2);
  std::vector<std::complex<double>> start;
  for (Eigen::Index i = 0; i < 2; ++i) {
    const double w = cm.omega_rad_s[i] * 1.001, z = cm.zeta[i] * 1.05;
    start.emplace_back(-z * w, w * std::sqrt(1 - z * z));
  }
  const ModalModelFit fit = FitModalModel(frf, start, {});
  EXPECT_FALSE(fit.ringing_terms);
  EXPECT_NE(fit.note.find("ringing terms"), std::string::npos) << fit.note;
  EXPECT_EQ(fit.undetermined.cols(), 0);
  for (Eigen::Index i = 0; i < 2; ++i) {
    EXPECT_NEAR(fit.omega_rad_s[i], cm.omega_rad_s[i], 1e-6 * cm.omega_rad_s[i]);
    EXPECT_NEAR(fit.zeta[i], cm.zeta[i], 1e-5 * cm.zeta[i]);
    EXPECT_NEAR(fit.ShapeRatio(i, 0, 1), um.ratio[static_cast<std::size_t>(i)],
                1e-5 * std::abs(um.ratio[static_cast<std::size_t>(i)]));
    for (const double sd : {fit.omega_sd_rad_s[i], fit.zeta_sd[i], fit.ShapeRatioSd(i, 0, 1)}) {
      EXPECT_TRUE(std::isfinite(sd) && sd > 0.0) << sd;
    }
  }
}

TEST(ShortRecords, AnIntervalOfZeroWidthIsNoInterval) {
  EXPECT_TRUE(std::isnan(NormalInterval95(1.0, 0.0)[0]));
  EXPECT_TRUE(std::isnan(NormalInterval95(1.0, -1e-9)[1]));
  EXPECT_TRUE(std::isnan(NormalInterval95(1.0, std::nan(""))[0]));
  const std::array<double, 2> ci = NormalInterval95(1.0, 0.5);
  EXPECT_DOUBLE_EQ(ci[0], 1.0 - kZ95 * 0.5);
  EXPECT_DOUBLE_EQ(ci[1], 1.0 + kZ95 * 0.5);
}

// The LADISK beam with every default: modes, none with an interval of 0, none whose damping
// interval reaches 0.
TEST(ShortRecords, LadiskDefaultsGiveNoPointInterval) {
  const Recording rec =
      LoadRecording(vibid::testing::TestData("ladisk_impact_hammer/impact_acceleration_force.csv"));
  const ImpactResult r = EstimateImpactFrf(rec.Signal(ParseColumnSpec("force_N")),
                                           rec.Signal(ParseColumnSpec("acceleration_g:g")),
                                           rec.fs_hz, {}, Estimator::kH1, Quantity::kAcceleration);
  const ModeIdentification m = IdentifyModes(ConvertFrf(r.frf, Quantity::kDisplacement), 0, {});
  EXPECT_GE(m.modes.size(), 4u);
  ExpectNoPointIntervals(m.modes);
  for (const ModeEstimate& e : m.modes) EXPECT_FALSE(e.zeta_ci95[0] <= 0.0) << e.freq_hz;
  // The 18 Hz pole (a peak of |X / F| too, scripts/golden/ladisk_peaks.py) was dropped while the
  // FRF ran to 25 kHz; stopped at the hammer's band (8.4 kHz) the diagram's bands change and it
  // is resolved: either way, never with a damping interval that reaches 0 (checked above).
}

}  // namespace
}  // namespace vibid::ident
