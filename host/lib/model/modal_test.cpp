// Modal analysis against closed forms, scipy.linalg.eigh, and properties over random systems.
#include "vibid/model/modal.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include <Eigen/SVD>

#include "test_support.hpp"
#include "vibid/common/error.hpp"

namespace vibid::model {
namespace {

using testing::Golden;
using testing::JsonMatrix;
using testing::JsonVector;

TEST(Modal, OneDofClosedForms) {
  // m = 2 kg, k = 5000 N/m, c = 4 N·s/m: ω = √(k/m) = 50 rad/s, ζ = c/(2√(km)) = 0.02, φ = 1/√m.
  const Model m = MakeChain(Eigen::VectorXd::Constant(1, 2.0), Eigen::VectorXd::Constant(1, 5000.0),
                            Eigen::VectorXd::Constant(1, 4.0));
  const ModalResult r = Modal(m);
  ASSERT_EQ(r.size(), 1);
  EXPECT_NEAR(r.omega_rad_s[0], 50.0, 1e-12);
  EXPECT_NEAR(r.freq_hz[0], 50.0 / (2.0 * std::numbers::pi), 1e-12);
  EXPECT_NEAR(r.zeta[0], 0.02, 1e-15);
  EXPECT_NEAR(r.shapes(0, 0), 1.0 / std::sqrt(2.0), 1e-15);
  EXPECT_TRUE(std::isnan(r.ratio[0]));
  EXPECT_EQ(r.damping, DampingKind::kProportional);
}

TEST(Modal, TwoDofChainEigenvaluesInClosedForm) {
  // det(K − λM) = 0 for the chain: m1 m2 λ² − (m1 k2 + m2 (k1 + k2)) λ + k1 k2 = 0, and the shape
  // ratio from the first row: a1/a2 = k2 / (k1 + k2 − m1 λ).
  const double m1 = 2.0, m2 = 1.5, k1 = 4000.0, k2 = 3000.0;
  const double b = m1 * k2 + m2 * (k1 + k2);
  const double disc = std::sqrt(b * b - 4.0 * m1 * m2 * k1 * k2);
  const double lambda1 = (b - disc) / (2.0 * m1 * m2);
  const double lambda2 = (b + disc) / (2.0 * m1 * m2);
  const ModalResult r = Modal(MakeChain(Eigen::Vector2d(m1, m2), Eigen::Vector2d(k1, k2)));
  EXPECT_NEAR(r.omega_rad_s[0], std::sqrt(lambda1), 1e-12 * std::sqrt(lambda1));
  EXPECT_NEAR(r.omega_rad_s[1], std::sqrt(lambda2), 1e-12 * std::sqrt(lambda2));
  const double ratio1 = k2 / (k1 + k2 - m1 * lambda1);
  const double ratio2 = k2 / (k1 + k2 - m1 * lambda2);
  EXPECT_NEAR(r.ratio[0], ratio1, 1e-10 * std::abs(ratio1));
  EXPECT_NEAR(r.ratio[1], ratio2, 1e-10 * std::abs(ratio2));
  EXPECT_GT(r.ratio[0], 0.0);  // in phase
  EXPECT_LT(r.ratio[1], 0.0);  // out of phase
  // Mass normalisation: m1 a1² + m2 a2² = 1 with a1 = ratio · a2.
  const double a2 = 1.0 / std::sqrt(m1 * ratio1 * ratio1 + m2);
  EXPECT_NEAR(r.shapes(1, 0), a2, 1e-12);
  EXPECT_EQ(r.damping, DampingKind::kNone);
  EXPECT_TRUE(r.zeta.isZero(0.0));
}

TEST(Modal, MatchesScipyEighWithFullMassMatrix) {
  const auto& g = Golden().at("eigh");  // scipy.linalg.eigh(K, M), scripts/golden/model_golden.py
  Model m;
  m.m_kg = JsonMatrix(g.at("M"));
  m.k_n_per_m = JsonMatrix(g.at("K"));
  m.c_ns_per_m = Eigen::MatrixXd::Zero(3, 3);
  const ModalResult r = Modal(m);
  const Eigen::VectorXd omega = JsonVector(g.at("omega_rad_s"));
  const Eigen::MatrixXd shapes = JsonMatrix(g.at("shapes"));
  EXPECT_LT((r.omega_rad_s - omega).cwiseAbs().maxCoeff(), 1e-10 * omega.maxCoeff());
  EXPECT_LT((r.shapes - shapes).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(Modal, ProportionalDampingGivesRayleighZetaInClosedForm) {
  // C = αM + βK: ζ_i = α/(2ω_i) + βω_i/2.
  const double alpha = 1.5, beta = 2e-4;
  Model m = MakeChain(Eigen::Vector3d(2.0, 1.5, 1.0), Eigen::Vector3d(4000.0, 3000.0, 2000.0));
  m.c_ns_per_m = alpha * m.m_kg + beta * m.k_n_per_m;
  const ModalResult r = Modal(m);
  EXPECT_EQ(r.damping, DampingKind::kProportional);
  for (int i = 0; i < 3; ++i) {
    const double expected = alpha / (2.0 * r.omega_rad_s[i]) + beta * r.omega_rad_s[i] / 2.0;
    EXPECT_NEAR(r.zeta[i], expected, 1e-12) << "mode " << i;
  }
  // The complex-eigenvalue route gives the same ω and ζ for classical damping.
  const ComplexModes c = ComplexModalDamping(m);
  ASSERT_EQ(c.zeta.size(), 3);
  EXPECT_LT((c.zeta - r.zeta).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_LT((c.omega_rad_s - r.omega_rad_s).cwiseAbs().maxCoeff(), 1e-9 * r.omega_rad_s.maxCoeff());
}

TEST(Modal, GeneralDampingIsDetectedAndItsEigenvaluesSolveTheQuadraticProblem) {
  // Damper only at the tip of a chain: not of the form ΦᵀCΦ diagonal.
  const Model m = MakeChain(Eigen::Vector2d(2.0, 1.5), Eigen::Vector2d(4000.0, 3000.0),
                            Eigen::Vector2d(0.0, 8.0));
  const ModalResult r = Modal(m);
  EXPECT_EQ(r.damping, DampingKind::kGeneral);
  const ComplexModes c = ComplexModalDamping(m);
  for (int i = 0; i < 2; ++i) {
    EXPECT_GT(r.zeta[i], 0.0);
    EXPECT_EQ(r.zeta[i], c.zeta[i]);
    // λ = −ζω + jω√(1−ζ²) must make M λ² + C λ + K singular.
    const std::complex<double> lambda(-c.zeta[i] * c.omega_rad_s[i],
                                      c.omega_rad_s[i] * std::sqrt(1.0 - c.zeta[i] * c.zeta[i]));
    const Eigen::MatrixXcd q = m.m_kg.cast<std::complex<double>>() * lambda * lambda +
                               m.c_ns_per_m.cast<std::complex<double>>() * lambda +
                               m.k_n_per_m.cast<std::complex<double>>();
    const Eigen::JacobiSVD<Eigen::MatrixXcd> svd(q);
    EXPECT_LT(svd.singularValues()[1], 1e-9 * svd.singularValues()[0]) << "mode " << i;
  }
}

TEST(Modal, OverdampedOneDofUsesTheRealEigenvaluePair) {
  // ζ = c/(2√(km)) = 3 > 1: two real roots; ω = √(λ1 λ2) = √(k/m), ζ = −(λ1+λ2)/(2ω).
  Model m = MakeChain(Eigen::VectorXd::Constant(1, 1.0), Eigen::VectorXd::Constant(1, 100.0),
                      Eigen::VectorXd::Constant(1, 60.0));
  const ComplexModes c = ComplexModalDamping(m);
  ASSERT_EQ(c.zeta.size(), 1);
  EXPECT_NEAR(c.omega_rad_s[0], 10.0, 1e-10);
  EXPECT_NEAR(c.zeta[0], 3.0, 1e-10);
}

TEST(Modal, RigidBodyModeHasZeroFrequencyAndZeroZeta) {
  Model m;
  m.m_kg = Eigen::Matrix2d::Identity();
  m.k_n_per_m = (Eigen::Matrix2d() << 100.0, -100.0, -100.0, 100.0).finished();
  m.c_ns_per_m = 0.01 * m.k_n_per_m;
  const ModalResult r = Modal(m);
  EXPECT_NEAR(r.omega_rad_s[0], 0.0, 1e-6);
  EXPECT_EQ(r.zeta[0], 0.0);
  EXPECT_NEAR(r.omega_rad_s[1], std::sqrt(200.0), 1e-12);
  EXPECT_NEAR(r.zeta[1], 0.01 * std::sqrt(200.0) / 2.0, 1e-12);
}

TEST(Modal, PropertiesOverRandomSystems) {
  std::mt19937 rng(42);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Index n = 1 + trial % 6;
    const Model m = testing::RandomModel(rng, n, trial % 2 == 0);
    const ModalResult r = Modal(m);
    const Eigen::MatrixXd& phi = r.shapes;
    EXPECT_TRUE((phi.transpose() * m.m_kg * phi).isIdentity(1e-10)) << "trial " << trial;
    const Eigen::MatrixXd kk = phi.transpose() * m.k_n_per_m * phi;
    EXPECT_TRUE(kk.isApprox(Eigen::MatrixXd(r.omega_rad_s.cwiseAbs2().asDiagonal()), 1e-10))
        << "trial " << trial;
    for (Eigen::Index i = 1; i < n; ++i) EXPECT_LE(r.omega_rad_s[i - 1], r.omega_rad_s[i]);
    EXPECT_EQ(r.damping, trial % 2 == 0
                             ? DampingKind::kProportional
                             : (n == 1 ? DampingKind::kProportional : DampingKind::kGeneral))
        << "trial " << trial;
  }
}

TEST(Modal, RejectsInvalidModel) {
  Model m = MakeChain(Eigen::Vector2d(2.0, 1.5), Eigen::Vector2d(4000.0, 3000.0));
  m.m_kg(0, 0) = -2.0;
  EXPECT_THROW(Modal(m), InputError);
}

}  // namespace
}  // namespace vibid::model
