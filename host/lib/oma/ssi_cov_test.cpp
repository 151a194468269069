// SSI-cov against the modes of the simulated model (the truth of the simulation, from the model
// library's eigenproblem): the demo rig's two-mass chain, a three-mass chain with encoder-like
// position outputs, and pyOMA2's published 5-DOF example.
#include "vibid/oma/ssi_cov.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <vector>
#include <numbers>

#include "vibid/common/error.hpp"
#include "vibid/model/modal.hpp"
#include "vibid/model/model.hpp"
#include "vibid/oma/testing/ambient.hpp"
#include "vibid/oma/testing/textbook_intervals.hpp"

namespace vibid::oma {
namespace {

// Every mode of the model found, ω within `omega_tol` and ζ within `zeta_tol` (relative), and
// the shape's MAC with the model's above 0.99.
void ExpectModes(const SsiCovResult& r, const model::Model& truth, double omega_tol,
                 double zeta_tol, const Eigen::MatrixXd* truth_shapes = nullptr) {
  const model::ComplexModes modes = model::ComplexModalDamping(truth);
  ASSERT_EQ(static_cast<Eigen::Index>(r.modes.size()), modes.omega_rad_s.size()) << r.message;
  const model::ModalResult modal = model::Modal(truth);
  for (Eigen::Index m = 0; m < modes.omega_rad_s.size(); ++m) {
    const OmaMode& found = r.modes[static_cast<std::size_t>(m)];
    const double w = modes.omega_rad_s(m);
    EXPECT_NEAR(found.omega_rad_s / w - 1.0, 0.0, omega_tol) << "mode " << m + 1;
    EXPECT_NEAR(found.zeta / modes.zeta(m) - 1.0, 0.0, zeta_tol) << "mode " << m + 1;
    const Eigen::VectorXd shape =
        truth_shapes != nullptr ? Eigen::VectorXd(truth_shapes->col(m)) : modal.shapes.col(m);
    EXPECT_GT(Mac(found.shape.cast<std::complex<double>>(), shape.cast<std::complex<double>>()),
              0.99)
        << "mode " << m + 1;
    EXPECT_TRUE(std::isfinite(found.omega_ci95_rad_s) && found.omega_ci95_rad_s > 0.0);
    EXPECT_TRUE(std::isfinite(found.zeta_ci95) && found.zeta_ci95 > 0.0);
    EXPECT_GT(found.mpc, 0.95);
  }
}

model::Model DemoRig() {
  // The emulator's default rig truth (host/emulator/rigs/default.json).
  return model::MakeChain(Eigen::Vector2d(1.82, 1.53), Eigen::Vector2d(3520.0, 2760.0),
                          Eigen::Vector2d(5.0, 3.5));
}

TEST(SsiCov, TwoMassChainUnderOperatingForces) {
  const model::Model rig = DemoRig();
  testing::AmbientOptions sim;
  sim.fs_hz = 1000.0;
  sim.seconds = 600.0;
  sim.seed = 11;
  const Eigen::MatrixXd y = testing::SimulateAmbient(rig, sim);
  SsiCovOptions o;
  o.fs_hz = 1000.0;
  o.fmax_hz = 25.0;
  const SsiCovResult r = SsiCov(y, o);
  EXPECT_EQ(r.decimation, 16);
  // Targets of the watch: ω within 0.5 %, ζ within 15 % of the rig's modes.
  ExpectModes(r, rig, 0.005, 0.15);
}

TEST(SsiCov, ThreeMassChainFromPositions) {
  const model::Model rig =
      model::MakeChain(Eigen::Vector3d(1.2, 0.9, 0.7), Eigen::Vector3d(3000.0, 2200.0, 1500.0),
                       Eigen::Vector3d(3.0, 2.0, 1.5));
  testing::AmbientOptions sim;
  sim.fs_hz = 500.0;
  sim.seconds = 600.0;
  sim.accelerations = false;
  sim.excited = {2};  // one shaker on the last mass
  sim.seed = 4;
  const Eigen::MatrixXd y = testing::SimulateAmbient(rig, sim);
  SsiCovOptions o;
  o.fs_hz = 500.0;
  o.fmax_hz = 20.0;
  const SsiCovResult r = SsiCov(y, o);
  ExpectModes(r, rig, 0.005, 0.15);
}

TEST(SsiCov, PyOma2FiveDofExample) {
  // pyOMA2's published example (pyoma2.functions.gen.example_data), the same record: written by
  // scripts/golden/oma_pyoma2_example.py with numpy's generator and seed as pyOMA2 draws them.
  // A 5-storey shear frame, modal damping 0.02, accelerations at 100 Hz, 30 001 samples, 10 %
  // measurement noise. Published frequencies 0.89, 2.598, 4.095, 5.261, 6.0 Hz.
  std::ifstream file(VIBID_SOURCE_DIR "/host/lib/oma/testdata/pyoma2_example.f32",
                     std::ios::binary);
  ASSERT_TRUE(file.good());
  std::vector<float> raw(30001 * 5);
  file.read(reinterpret_cast<char*>(raw.data()),
            static_cast<std::streamsize>(raw.size() * sizeof(float)));
  ASSERT_TRUE(file.good());
  const Eigen::MatrixXd y =
      Eigen::Map<const Eigen::Matrix<float, Eigen::Dynamic, 5, Eigen::RowMajor>>(raw.data(), 30001,
                                                                                 5)
          .cast<double>();
  // The frame's undamped frequencies from its matrices (the model library's eigenproblem).
  const int n = 5;
  model::Model frame;
  frame.m_kg = Eigen::MatrixXd::Identity(n, n) * 25.91;
  frame.k_n_per_m = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n - 1; ++i) {
    frame.k_n_per_m.block(i, i, 2, 2) += 10000.0 * Eigen::Matrix2d{{1.0, -1.0}, {-1.0, 1.0}};
  }
  frame.k_n_per_m(n - 1, n - 1) += 10000.0;
  frame.c_ns_per_m = Eigen::MatrixXd::Zero(n, n);
  const model::ModalResult undamped = model::Modal(frame);
  const Eigen::VectorXd published_hz{{0.89, 2.598, 4.095, 5.261, 6.0}};
  for (int i = 0; i < n; ++i) EXPECT_NEAR(undamped.freq_hz(i), published_hz(i), 1e-3);

  SsiCovOptions o;
  o.fs_hz = 100.0;
  o.fmax_hz = 8.0;
  o.fmin_hz = 0.8;
  const SsiCovResult r = SsiCov(y, o);
  ASSERT_EQ(r.modes.size(), 5u) << r.message;
  for (int i = 0; i < n; ++i) {
    const OmaMode& found = r.modes[static_cast<std::size_t>(i)];
    std::printf("mode %d: %.4f Hz (error %+.3f %%, 95 %% +- %.3f %%), zeta %.4f +- %.4f\n", i + 1,
                found.omega_rad_s / (2.0 * std::numbers::pi),
                100.0 * (found.omega_rad_s / undamped.omega_rad_s(i) - 1.0),
                100.0 * found.omega_ci95_rad_s / found.omega_rad_s, found.zeta, found.zeta_ci95);
    // The errors on this record (+0.28, -0.15, +0.25, -0.02, -0.03 %) are the record's own: every
    // lag count and band tried gives them within 0.05 %. Each lies inside its 95 % interval.
    EXPECT_NEAR(found.omega_rad_s / undamped.omega_rad_s(i), 1.0, 0.003) << "mode " << i + 1;
    EXPECT_NEAR(found.omega_rad_s, undamped.omega_rad_s(i), found.omega_ci95_rad_s)
        << "mode " << i + 1;
    EXPECT_NEAR(found.zeta / 0.02, 1.0, 0.3) << "mode " << i + 1;
  }
}

TEST(SsiCov, WhiteNoiseAloneGivesNoMode) {
  testing::AmbientOptions sim;
  Eigen::MatrixXd y = Eigen::MatrixXd::Random(120000, 2);  // uniform white noise, no dynamics
  SsiCovOptions o;
  o.fs_hz = 1000.0;
  o.fmax_hz = 25.0;
  const SsiCovResult r = SsiCov(y, o);
  EXPECT_TRUE(r.modes.empty());
  EXPECT_NE(r.message.find("no mode"), std::string::npos);
}

TEST(SsiCov, AClusterScatteredOverMoreThanTheShareAskedIsNoMode) {
  // The rig's two modes, then the same data with the frequency share set between their two
  // relative half-widths: the wider one is withheld and named, the other kept with the same
  // figures.
  testing::AmbientOptions sim;
  sim.fs_hz = 1000.0;
  sim.seconds = 300.0;
  sim.seed = 12;
  const Eigen::MatrixXd y = testing::SimulateAmbient(DemoRig(), sim);
  SsiCovOptions o;
  o.fs_hz = 1000.0;
  o.fmax_hz = 25.0;
  const SsiCovResult all = SsiCov(y, o);
  ASSERT_EQ(all.modes.size(), 2u) << all.message;
  double share[2];
  for (int m = 0; m < 2; ++m) {
    share[m] = all.modes[static_cast<std::size_t>(m)].omega_ci95_rad_s /
               all.modes[static_cast<std::size_t>(m)].omega_rad_s;
    EXPECT_LT(share[m], o.max_omega_ci95_share) << m;  // a real mode: well inside 3 %
  }
  ASSERT_NE(share[0], share[1]);
  const int wide = share[0] > share[1] ? 0 : 1;
  o.max_omega_ci95_share = std::sqrt(share[0] * share[1]);
  const SsiCovResult some = SsiCov(y, o);
  ASSERT_EQ(some.modes.size(), 1u) << some.message;
  const OmaMode& kept = all.modes[static_cast<std::size_t>(1 - wide)];
  EXPECT_EQ(some.modes[0].omega_rad_s, kept.omega_rad_s);
  EXPECT_EQ(some.modes[0].omega_ci95_rad_s, kept.omega_ci95_rad_s);
  EXPECT_NE(some.message.find("scatter by ±"), std::string::npos) << some.message;
  EXPECT_NE(some.message.find("not reported as a mode"), std::string::npos) << some.message;
  int clustered = 0;  // the diagram's poles of the withheld cluster are no longer a mode's
  for (const Pole& p : some.diagram) clustered += p.cluster > 0;
  EXPECT_EQ(clustered, 0);
  o.max_omega_ci95_share = 0.0;
  EXPECT_THROW(SsiCov(y, o), InputError);
}

// The intervals' samples take shortcuts (the eigensolver of h hᵀ for the singular basis, the
// eigenvalues without the Schur form, the state matrix by an l × l solve, shapes by inverse
// iteration): on the watch's block (120 s of two accelerations at 1 kHz, band 25 Hz) and a
// three-mass chain's positions, the half-widths equal those of the textbook propagation (an SVD
// and the full eigensolver per sample) to 1e-6 relative, and each mode is found again in the
// same samples. (h hᵀ squares the singular values, so its basis is good to about 1e-7 where
// they span many decades, as positions' do; a different sample or match would move a half-width
// by percents: their Monte Carlo error over 200 samples is about 5 %.)
TEST(SsiCov, IntervalsEqualTheTextbookPropagation) {
  struct Case {
    model::Model rig;
    testing::AmbientOptions sim;
    SsiCovOptions options;
  };
  std::vector<Case> cases;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    Case c{model::MakeChain(Eigen::Vector2d(1.82, 1.53), Eigen::Vector2d(3520.0, 2760.0),
                            Eigen::Vector2d(5.0, 3.5)),
           {},
           {}};
    c.sim.fs_hz = 1000.0;
    c.sim.seconds = 120.0;
    c.sim.seed = seed;
    c.options.fs_hz = 1000.0;
    c.options.fmax_hz = 25.0;
    cases.push_back(c);
  }
  Case three{
      model::MakeChain(Eigen::Vector3d(1.2, 0.9, 0.7), Eigen::Vector3d(3000.0, 2200.0, 1500.0),
                       Eigen::Vector3d(3.0, 2.0, 1.5)),
      {},
      {}};
  three.sim.fs_hz = 500.0;
  three.sim.seconds = 300.0;
  three.sim.accelerations = false;
  three.options.fs_hz = 500.0;
  three.options.fmax_hz = 20.0;
  cases.push_back(three);
  constexpr double kRelTol = 1e-6;
  for (const Case& c : cases) {
    const Eigen::MatrixXd y = testing::SimulateAmbient(c.rig, c.sim);
    const SsiCovResult r = SsiCov(y, c.options);
    ASSERT_EQ(r.modes.size(), static_cast<std::size_t>(c.rig.dofs())) << r.message;
    const std::vector<testing::TextbookInterval> reference =
        testing::TextbookIntervals(y, c.options, r);
    for (std::size_t m = 0; m < r.modes.size(); ++m) {
      const OmaMode& mode = r.modes[m];
      SCOPED_TRACE("seed " + std::to_string(c.sim.seed) + " masses " +
                   std::to_string(c.rig.dofs()) + " mode " + std::to_string(m + 1));
      EXPECT_EQ(mode.found_share, reference[m].found_share);
      EXPECT_NEAR(mode.omega_ci95_rad_s, reference[m].omega_ci95_rad_s,
                  kRelTol * reference[m].omega_ci95_rad_s);
      EXPECT_NEAR(mode.zeta_ci95, reference[m].zeta_ci95, kRelTol * reference[m].zeta_ci95);
      for (Eigen::Index k = 0; k < mode.shape_ci95.size(); ++k) {
        EXPECT_NEAR(mode.shape_ci95(k), reference[m].shape_ci95(k),
                    kRelTol * reference[m].shape_ci95(k));
      }
    }
  }
}

TEST(SsiCov, RefusesBadOptionsAndShortRecords) {
  const Eigen::MatrixXd y = Eigen::MatrixXd::Random(20000, 2);
  SsiCovOptions o;
  EXPECT_THROW(SsiCov(y, o), InputError);  // fs_hz missing
  o.fs_hz = 1000.0;
  o.fmax_hz = 600.0;
  EXPECT_THROW(SsiCov(y, o), InputError);
  o.fmax_hz = 25.0;
  o.blocks = 3;
  EXPECT_THROW(SsiCov(y, o), InputError);
  o.blocks = 20;
  try {
    SsiCov(y.topRows(5000), o);
    FAIL() << "a 5 s record cannot hold 20 blocks of the Hankel matrix";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("too short"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace vibid::oma
