// The observer on chains of three and four masses (the board's calibration record holds up to
// four): the workflow's experiment simulated by the model core (exact ZOH at its 1 kHz push
// rate), shaker at 16 Hz and a slow hand push on the last mass, that mass's displacement
// measured. The SISO design must be stable, recover the push, and its fixed-point run must track
// the double design as the two-mass one does (acceptance_test.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "vibid/common/error.hpp"
#include "vibid/dob/compare.hpp"
#include "vibid/dob/design.hpp"
#include "vibid/dob/lowpass.hpp"
#include "vibid/dob/model_plant.hpp"
#include "vibid/model/model.hpp"
#include "vibid/model/simulate.hpp"

namespace vibid::dob {
namespace {

constexpr double kFs = 1000.0;
constexpr double kTwo31 = 2147483648.0;

// The emulator's rigs host/emulator/rigs/chain3.json (effective masses: m1 1.6 kg less its 5 %
// effective-mass loss) and chain4.json.
model::Model Chain(int n) {
  if (n == 3) {
    return model::MakeChain(Eigen::Vector3d(1.52, 1.2, 0.9), Eigen::Vector3d(3200, 2600, 2100),
                            Eigen::Vector3d(3.0, 2.0, 1.5));
  }
  return model::MakeChain(Eigen::Vector4d(1.4, 1.2, 1.0, 0.8),
                          Eigen::Vector4d(4200, 3600, 3000, 2400),
                          Eigen::Vector4d(3.0, 2.5, 2.0, 1.5));
}

struct ChainRun {
  DobDesign design;
  Eigen::VectorXd x_m, force_n, push_n;
};

ChainRun Experiment(int n) {
  const std::string dof = "dof=" + std::to_string(n);
  model::ForceInput force;
  force.shapes.push_back(model::ParseForceShape("sine:" + dof + ",amp=10,freq_hz=16"));
  model::ForceInput push;
  push.shapes.push_back(model::ParseForceShape("chirp:" + dof + ",amp=10,f0_hz=0.2,f1_hz=2,t1=12"));
  model::SimulationOptions o;
  o.method = model::Method::kExact;
  o.dt_s = 1.0 / kFs;
  o.t_end_s = 12.0;
  const model::SimulationResult sim = model::Simulate(Chain(n), force, push, o);
  ChainRun r;
  r.x_m = sim.x_m.col(n - 1);
  r.force_n = sim.force_n.col(n - 1);
  r.push_n = sim.disturbance_n.col(n - 1);
  DobOptions d;
  d.fs_hz = kFs;
  d.input_dof = n - 1;
  d.output_dof = n - 1;
  d.force_full_scale_n = 500.0;  // examples/sensors.json's load cell and encoder
  d.sensor_full_scale = 0.05;
  r.design = DesignObserver(PlantFromModel(Chain(n), n - 1, n - 1), d);
  return r;
}

Eigen::VectorXd Tail(const Eigen::VectorXd& v, double skip_s) {
  const auto skip = static_cast<Eigen::Index>(skip_s * kFs);
  return v.segment(skip, v.size() - 2 * skip);
}

class ChainObserver : public ::testing::TestWithParam<int> {};

TEST_P(ChainObserver, RecoversThePushAndTheFixedPointTracksTheDouble) {
  const int n = GetParam();
  const ChainRun r = Experiment(n);
  ASSERT_TRUE(r.design.stable) << r.design.message;
  // G_A of the last mass: 2n poles, 2n - 2 zeros, so relative degree 2 for displacement.
  EXPECT_EQ(r.design.plant_relative_degree, 2);
  const fixed::FilterDescription& d = r.design.fixed.description;
  EXPECT_EQ(d.output_dof, n - 1);
  ASSERT_EQ(d.input_count, 2);
  EXPECT_EQ(d.input_dof[0], n - 1);
  EXPECT_EQ(d.input_kind[0], fixed::InputKind::kDisplacement);
  EXPECT_EQ(d.input_kind[1], fixed::InputKind::kForce);

  const Eigen::VectorXd ref = RunFloat(r.design.paths, {r.x_m, r.force_n});
  const FixedRun fixed_run = RunFixed(d, {r.x_m, r.force_n});
  EXPECT_EQ(fixed_run.saturations, 0u);
  const auto out_fs = static_cast<double>(fixed::FullScaleValue(d.output_full_scale_bits));
  double signal = 0.0, noise = 0.0, max_lsb = 0.0;
  for (Eigen::Index k = 0; k < ref.size(); ++k) {
    const double err_lsb =
        fixed_run.d_hat_q31[static_cast<std::size_t>(k)] - ref[k] / out_fs * kTwo31;
    signal += ref[k] * ref[k];
    noise += err_lsb * err_lsb;
    max_lsb = std::max(max_lsb, std::abs(err_lsb));
  }
  const double snr_db = 10.0 * std::log10(signal / (noise * (out_fs / kTwo31) * (out_fs / kTwo31)));
  // The two-mass observer at 5 kHz holds 90 dB (acceptance_test.cpp); at 1 kHz the resonances'
  // poles sit farther from z = 1 and the coefficient rounding costs less. Measured 111.3 dB and
  // 154 LSB (3 masses), 112.0 dB and 144 LSB (4 masses).
  EXPECT_GE(snr_db, 105.0);
  EXPECT_LT(max_lsb, 500.0);
  RecordProperty("snr_db", std::to_string(snr_db));

  // The fixed-point estimate, low-passed at 4 Hz as the workflow does, against the true push.
  Eigen::VectorXd d_fixed(ref.size());
  for (Eigen::Index k = 0; k < ref.size(); ++k)
    d_fixed[k] = fixed_run.d_hat_q31[static_cast<std::size_t>(k)] / kTwo31 * out_fs;
  const Eigen::VectorXd d_lp = FiltFilt(ButterworthLowpass(4, 4.0, kFs), d_fixed);
  const Agreement a = CompareSignals(Tail(d_lp, 1.0), Tail(r.push_n, 1.0), kFs);
  EXPECT_GE(a.fit_percent, 98.0);  // measured 99.20 % (3 masses), 99.09 % (4 masses)
  std::printf("%d masses: %zu + %zu sections, SNR %.1f dB, max error %.0f LSB, push fit %.2f %%\n",
              n, r.design.paths[0].sos.size(), r.design.paths[1].sos.size(), snr_db, max_lsb,
              a.fit_percent);
}

INSTANTIATE_TEST_SUITE_P(ThreeAndFourMasses, ChainObserver, ::testing::Values(3, 4));

// The MIMO form takes every sensor of the input mass's row: a middle mass couples to two
// neighbours, so with its force that is four inputs, one more than the board's filter holds. The
// design names the count and the limit; an end mass (two sensors and the force) fits.
TEST(ChainObserverMimo, AMiddleMassNeedsMoreInputsThanTheBoardHolds) {
  DobOptions o;
  o.form = ObserverForm::kMimo;
  o.fs_hz = kFs;
  o.input_dof = 1;
  try {
    static_cast<void>(DesignObserver(PlantFromModel(Chain(3), 1, 1), o));
    FAIL() << "a four-input observer accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("needs 4 inputs"), std::string::npos) << e.what();
  }
  o.input_dof = 2;
  const DobDesign end = DesignObserver(PlantFromModel(Chain(3), 2, 2), o);
  EXPECT_TRUE(end.stable) << end.message;
  ASSERT_EQ(end.paths.size(), 3u);
  EXPECT_EQ(end.paths[0].dof, 1);
  EXPECT_EQ(end.paths[1].dof, 2);
}

}  // namespace
}  // namespace vibid::dob
