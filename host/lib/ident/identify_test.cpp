// End to end on synthetic ground truth: hammer tests simulated by the model core on known rigs,
// noise on force and responses, through impact FRF estimation, mass update, modal identification,
// stiffness update and the updated model. References are the truth rigs' own parameters and their
// modal analysis in closed form (test_support.hpp).
#include "vibid/ident/identify.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "test_support.hpp"
#include "vibid/common/error.hpp"
#include "vibid/ident/impact.hpp"
#include "vibid/ident/testing/hammer_test.hpp"
#include "vibid/model/modal.hpp"

namespace vibid::ident {
namespace {

struct Truth {
  const char* name;
  double m1, m2, k1, k2, c1, c2;
};

// Separated modes with light damping (about 1 %), close modes with moderate damping (4-6 %).
const Truth kTruths[] = {
    {"separated_light", 1.2, 0.8, 3000.0, 2000.0, 0.9, 0.8},
    {"close_moderate", 1.0, 0.1, 4000.0, 400.0, 6.0, 0.6},
};

// Lightly damped modes ring longer than the hit spacing: an exponential window (its damping is
// corrected in the fit) as in practice.
Frf Receptance(const HammerTestRecord& rec, double fs_hz) {
  const ImpactResult r =
      EstimateImpactFrf(rec.force_n, rec.response, fs_hz, {.exp_window_end = 0.01}, Estimator::kH1,
                        Quantity::kAcceleration);
  for (const Hit& h : r.hits) EXPECT_TRUE(h.used) << h.note;
  return ConvertFrf(r.frf, Quantity::kDisplacement);
}

class SyntheticChain : public ::testing::TestWithParam<Truth> {};

TEST_P(SyntheticChain, RecoversTheTruth) {
  const Truth t = GetParam();
  const double fs = 500.0;
  // Nominal (datasheet) values off the truth: masses +8 %, springs +10 %.
  const model::Model nominal = model::MakeChain(Eigen::Vector2d(1.08 * t.m1, 1.08 * t.m2),
                                                Eigen::Vector2d(1.1 * t.k1, 1.1 * t.k2));
  // Mass tests: each true mass alone on its (calibrated, nominal) spring, 2 % damping.
  std::vector<MassTestInput> mass_tests;
  const double ms[2] = {t.m1, t.m2};
  for (std::size_t i = 0; i < 2; ++i) {
    const double k = 1.1 * (i == 0 ? t.k1 : t.k2);
    const double c = 2 * 0.02 * std::sqrt(k * ms[i]);
    const model::Model one =
        model::MakeChain(Eigen::VectorXd::Constant(1, ms[i]), Eigen::VectorXd::Constant(1, k),
                         Eigen::VectorXd::Constant(1, c));
    mass_tests.push_back(
        {i, Receptance(SimulateHammerTest(one, MassTestSpec(fs, 100 + i)), fs), 0.0});
  }
  // Two modal tests of the truth chain, hammer on m2, accelerometers on both masses.
  const model::Model truth = model::MakeChain(
      Eigen::Vector2d(t.m1, t.m2), Eigen::Vector2d(t.k1, t.k2), Eigen::Vector2d(t.c1, t.c2));
  std::vector<Frf> modal;
  for (std::uint64_t seed : {7u, 8u}) {
    modal.push_back(Receptance(SimulateHammerTest(truth, ModalTestSpec(fs, seed)), fs));
  }
  const IdentifyResult r = Identify(nominal, mass_tests, modal, {});
  std::printf("%s\n%s", t.name, FormatValidationTable(r.table).c_str());

  // Truth modes: undamped omega and a1/a2 in closed form; zeta from the state matrix (model core).
  const auto tm = testing::ChainModesOf(t.m1, t.m2, t.k1, t.k2);
  const model::ComplexModes cm = model::ComplexModalDamping(truth);
  ASSERT_EQ(r.test_modes.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const ModeEstimate& m = r.test_modes[i];
    const auto ii = static_cast<Eigen::Index>(i);
    std::printf(
        "%s mode %zu: omega %.5f (truth %.5f, %.3f %%), zeta %.5f (truth %.5f, %.2f %%), ratio "
        "%.5f (truth %.5f, %.3f %%)\n",
        t.name, i + 1, m.omega_rad_s, cm.omega_rad_s[ii],
        PercentDeviation(m.omega_rad_s, cm.omega_rad_s[ii]), m.zeta, cm.zeta[ii],
        PercentDeviation(m.zeta, cm.zeta[ii]), m.ratio, tm.ratio[i],
        PercentDeviation(m.ratio, tm.ratio[i]));
    EXPECT_NEAR(m.omega_rad_s, cm.omega_rad_s[ii], 0.002 * cm.omega_rad_s[ii]) << t.name;
    EXPECT_NEAR(m.zeta, cm.zeta[ii], 0.1 * cm.zeta[ii]) << t.name;
    EXPECT_NEAR(m.ratio, tm.ratio[i], 0.02 * std::abs(tm.ratio[i])) << t.name;
  }
  const double truth_m[2] = {t.m1, t.m2};
  const double truth_k[2] = {t.k1, t.k2};
  for (Eigen::Index i = 0; i < 2; ++i) {
    std::printf(
        "%s position %ld: m %.5f (truth %.5f, %.3f %%), k %.3f (truth %.3f, %.3f %%), spread "
        "%.3f\n",
        t.name, static_cast<long>(i) + 1, r.chain.masses_kg[i], truth_m[i],
        PercentDeviation(r.chain.masses_kg[i], truth_m[i]), r.chain.springs_n_per_m[i], truth_k[i],
        PercentDeviation(r.chain.springs_n_per_m[i], truth_k[i]), r.stiffness.spread[i]);
    EXPECT_NEAR(r.chain.masses_kg[i], truth_m[i], 0.01 * truth_m[i]) << t.name;
    EXPECT_NEAR(r.chain.springs_n_per_m[i], truth_k[i], 0.01 * truth_k[i]) << t.name;
  }
  EXPECT_EQ(r.stiffness.tests.size(), 2u);
  // The table carries the numbers it was built from.
  EXPECT_DOUBLE_EQ(r.table.positions[0].m_updated, r.chain.masses_kg[0]);
  EXPECT_DOUBLE_EQ(r.table.modes[1].omega_test, r.test_modes[1].omega_rad_s);
}

INSTANTIATE_TEST_SUITE_P(Truths, SyntheticChain, ::testing::ValuesIn(kTruths),
                         [](const auto& param_info) { return std::string(param_info.param.name); });

TEST(Identify, InconsistentInputsAreInputErrors) {
  const model::Model nominal = model::MakeChain(Eigen::Vector2d(1, 1), Eigen::Vector2d(1000, 1000));
  EXPECT_THROW(Identify(nominal, {}, {}, {}), InputError);
  const Frf one = testing::ChainFrf(1, 1, 1000, 1000, 0.5, 0.5, 1, 0.02, 1000);
  EXPECT_THROW(Identify(nominal, {{5, one, 0.0}}, {one}, {}), InputError);
  const model::Model single =
      model::MakeChain(Eigen::VectorXd::Ones(1), Eigen::VectorXd::Constant(1, 100.0));
  EXPECT_THROW(Identify(single, {}, {one}, {}), InputError);
}

TEST(Validation, PercentDeviationsAndChainOf) {
  EXPECT_DOUBLE_EQ(PercentDeviation(110, 100), 10.0);
  EXPECT_TRUE(std::isnan(PercentDeviation(1, 0)));
  const model::Model m =
      model::MakeChain(Eigen::Vector2d(1, 2), Eigen::Vector2d(300, 200), Eigen::Vector2d(3, 2));
  const ChainParameters c = ChainOf(m);
  EXPECT_DOUBLE_EQ(c.springs_n_per_m[0], 300);
  EXPECT_DOUBLE_EQ(c.springs_n_per_m[1], 200);
  EXPECT_DOUBLE_EQ(c.dampers_ns_per_m[0], 3);
  EXPECT_DOUBLE_EQ(c.masses_kg[1], 2);
}

}  // namespace
}  // namespace vibid::ident
