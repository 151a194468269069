// Continuous-time TFs: exact ZOH simulation and c2d against scipy, d2c round trips, the course's
// Euler and RK4 simulations, first-order hold.
#include "vibid/sysid/continuous.hpp"

#include <cmath>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "testing_systems.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/sysid/fit.hpp"

namespace vibid::sysid {
namespace {

Eigen::VectorXd Vec(const nlohmann::json& j) {
  const auto v = j.get<std::vector<double>>();
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

nlohmann::json Golden() {
  return ReadJsonFile(VIBID_SOURCE_DIR "/host/lib/sysid/testdata/zoh_scipy.json");
}

TEST(Continuous, ZohDiscretizationMatchesScipy) {
  const auto g = Golden();  // scripts/golden/sysid_zoh_scipy.py: scipy.signal.cont2discrete(zoh)
  const TransferFunction tf{Vec(g["num"]), Vec(g["den"])};
  const DiscreteTf d = C2dZoh(tf, g["dt_s"].get<double>());
  const Eigen::VectorXd numd = Vec(g["numd"]);
  const Eigen::VectorXd dend = Vec(g["dend"]);
  ASSERT_EQ(d.den.size(), dend.size());
  ASSERT_EQ(d.num.size(), numd.size());
  EXPECT_LT((d.den - dend).cwiseAbs().maxCoeff(), 1e-12);
  // The numerator nearly cancels (the zeros sit close to the poles at 200 Hz): compare to its
  // scale.
  EXPECT_LT((d.num - numd).cwiseAbs().maxCoeff(), 1e-11 * numd.cwiseAbs().maxCoeff());
}

TEST(Continuous, ZohSimulationMatchesScipyDlsim) {
  const auto g = Golden();  // scipy.signal.dlsim of the ZOH model: step and pulse
  const TransferFunction tf{Vec(g["num"]), Vec(g["den"])};
  const double dt = g["dt_s"].get<double>();
  for (const char* which : {"step", "pulse"}) {
    SCOPED_TRACE(which);
    const Eigen::VectorXd u = Vec(g[std::string("u_") + which]);
    const Eigen::VectorXd y = Vec(g[std::string("y_") + which]);
    const Eigen::VectorXd mine = Simulate(tf, u, dt);
    // scipy's dlsim goes through tf2ss of the nearly cancelling discrete numerator: ~1e-10
    // relative.
    EXPECT_LT((mine - y).cwiseAbs().maxCoeff(), 1e-9 * y.cwiseAbs().maxCoeff());
  }
}

TEST(Continuous, D2cInvertsC2d) {
  // A q⁻¹ polynomial with n poles near z = 1 carries its information in the last ~n·log10(1/(ω dt))
  // digits, so the round trip loses accuracy as dt shrinks: the tolerance follows (ω dt)^-4.
  for (const TransferFunction& tf : {testing::OneCartTf(), testing::TwoCartTf()}) {
    for (const auto& [dt, tol] :
         {std::pair{0.001, 1e-5}, std::pair{0.005, 1e-7}, std::pair{0.05, 1e-10}}) {
      const DiscreteTf d = C2dZoh(tf, dt);
      const TransferFunction back = D2cZoh(d.num, d.den, dt);
      EXPECT_LT(testing::MaxRelativeError(Normalized(back), tf), tol) << "dt " << dt;
    }
  }
}

TEST(Continuous, D2cRejectsNegativeRealPoles) {
  // z = −0.5 is the ZOH image of no real continuous system.
  EXPECT_THROW(D2cZoh(Eigen::Vector2d(0.0, 1.0), Eigen::Vector2d(1.0, 0.5), 0.01), InputError);
  // Two samples of delay: a pole at z = 0.
  EXPECT_THROW(D2cZoh(Eigen::Vector3d(0.0, 0.0, 1.0), Eigen::Vector3d(1.0, -0.5, 0.0), 0.01),
               InputError);
}

TEST(Continuous, FirstOrderSystemClosedForm) {
  // 1/(s + 2) driven by a unit step from t = 0: y = (1 − e^{−2t})/2, exact at every sample (ZOH).
  const TransferFunction tf{Eigen::VectorXd::Ones(1), Eigen::Vector2d(1.0, 2.0)};
  const double dt = 0.01;
  const Eigen::VectorXd y = Simulate(tf, Eigen::VectorXd::Ones(300), dt);
  for (Eigen::Index k = 0; k < 300; ++k) {
    EXPECT_NEAR(y[k], 0.5 * (1.0 - std::exp(-2.0 * dt * static_cast<double>(k))), 1e-14);
  }
  // First-order hold is exact for a ramp u = t: y = t/2 − 1/4 + e^{−2t}/4.
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(300, 0.0, 299 * dt);
  const Eigen::VectorXd yr = Simulate(tf, t, dt, Hold::kFirst);
  for (Eigen::Index k = 0; k < 300; ++k)
    EXPECT_NEAR(yr[k], t[k] / 2 - 0.25 + std::exp(-2.0 * t[k]) / 4, 1e-13);
}

TEST(Continuous, EulerAndRk4ConvergeAtTheirOrders) {
  // The course methods hold the input per sample like the ZOH, so with substeps they converge to
  // the exact discretization: error ∝ h for Euler, ∝ h⁴ for RK4.
  const TransferFunction tf = testing::TwoCartTf();
  const double dt = 0.01;
  const Eigen::VectorXd u = testing::Pulse(500, 10, 20, 0.01);
  const Eigen::VectorXd exact = Simulate(tf, u, dt);
  auto err = [&](const Eigen::VectorXd& y) { return (y - exact).cwiseAbs().maxCoeff(); };
  const double e1 = err(SimulateEuler(tf, u, dt, 4));
  const double e2 = err(SimulateEuler(tf, u, dt, 8));
  EXPECT_NEAR(e1 / e2, 2.0, 0.2);
  const double r1 = err(SimulateRk4(tf, u, dt, 1));
  const double r2 = err(SimulateRk4(tf, u, dt, 2));
  EXPECT_NEAR(r1 / r2, 16.0, 2.0);
  EXPECT_GT(FitPercent(exact, SimulateRk4(tf, u, dt)), 99.9);
  EXPECT_LT(FitPercent(exact, SimulateEuler(tf, u, dt)), FitPercent(exact, SimulateRk4(tf, u, dt)));
}

TEST(Continuous, RejectsImproperTf) {
  EXPECT_THROW(Simulate(TransferFunction{Eigen::Vector3d(1, 0, 0), Eigen::Vector2d(1, 1)},
                        Eigen::VectorXd::Ones(4), 0.1),
               InputError);
  EXPECT_THROW(Simulate(TransferFunction{Eigen::VectorXd::Ones(1), Eigen::Vector2d(0, 1)},
                        Eigen::VectorXd::Ones(4), 0.1),
               InputError);
}

}  // namespace
}  // namespace vibid::sysid
