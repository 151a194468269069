// State space and exact ZOH discretisation against closed-form matrix exponentials.
#include "vibid/model/state_space.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "vibid/common/error.hpp"

namespace vibid::model {
namespace {

TEST(StateSpace, OneDofMatrices) {
  const Model m = MakeChain(Eigen::VectorXd::Constant(1, 2.0), Eigen::VectorXd::Constant(1, 5000.0),
                            Eigen::VectorXd::Constant(1, 4.0));
  const StateSpace ss = ModelStateSpace(m);
  EXPECT_EQ(ss.A, (Eigen::Matrix2d() << 0.0, 1.0, -2500.0, -2.0).finished());
  EXPECT_EQ(ss.B, Eigen::Vector2d(0.0, 0.5));
  EXPECT_EQ(ss.C.rows(), 3);
  EXPECT_EQ(ss.C.row(2), Eigen::RowVector2d(-2500.0, -2.0));
  EXPECT_EQ(ss.D(2, 0), 0.5);
  EXPECT_EQ(ss.dt_s, 0.0);
}

TEST(Discretize, FreeMassIsTheExactDoubleIntegrator) {
  // ẍ = F/m: Ad = [[1, dt], [0, 1]], Bd = [dt²/(2m), dt/m].
  Model m;
  m.m_kg = Eigen::MatrixXd::Constant(1, 1, 4.0);
  m.k_n_per_m = Eigen::MatrixXd::Zero(1, 1);
  m.c_ns_per_m = Eigen::MatrixXd::Zero(1, 1);
  const double dt = 0.01;
  const StateSpace d = Discretize(ModelStateSpace(m), dt);
  EXPECT_TRUE(d.A.isApprox((Eigen::Matrix2d() << 1.0, dt, 0.0, 1.0).finished(), 1e-15));
  EXPECT_NEAR(d.B(0, 0), dt * dt / 8.0, 1e-18);
  EXPECT_NEAR(d.B(1, 0), dt / 4.0, 1e-17);
  EXPECT_EQ(d.dt_s, dt);
}

TEST(Discretize, UndampedOscillatorIsARotation) {
  // ω = 50: Ad = [[cos ωT, sin ωT/ω], [−ω sin ωT, cos ωT]], Bd = [(1 − cos ωT)/k, sin ωT/(mω)].
  const double mass = 2.0, k = 5000.0, w = 50.0, dt = 2e-3;
  const Model m = MakeChain(Eigen::VectorXd::Constant(1, mass), Eigen::VectorXd::Constant(1, k));
  const StateSpace d = Discretize(ModelStateSpace(m), dt);
  const double c = std::cos(w * dt), s = std::sin(w * dt);
  // Relative 2e-13: the closed form's own 1 − cos ωT loses three digits to cancellation.
  const auto near = [](double actual, double expected) {
    EXPECT_NEAR(actual, expected, 2e-13 * std::abs(expected));
  };
  near(d.A(0, 0), c);
  near(d.A(0, 1), s / w);
  near(d.A(1, 0), -w * s);
  near(d.A(1, 1), c);
  near(d.B(0, 0), (1.0 - c) / k);
  near(d.B(1, 0), s / (mass * w));
}

TEST(Discretize, RejectsBadStepAndDiscreteInput) {
  const Model m =
      MakeChain(Eigen::VectorXd::Constant(1, 2.0), Eigen::VectorXd::Constant(1, 5000.0));
  const StateSpace ss = ModelStateSpace(m);
  EXPECT_THROW(Discretize(ss, 0.0), InputError);
  EXPECT_THROW(Discretize(ss, -1e-3), InputError);
  EXPECT_THROW(Discretize(ss, std::nan("")), InputError);
  EXPECT_THROW(Discretize(Discretize(ss, 1e-3), 1e-3), InputError);
}

}  // namespace
}  // namespace vibid::model
