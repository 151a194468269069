// FRF synthesis: 1-DOF closed forms, numpy golden values, matrix vs modal form.
#include "vibid/model/frf.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <random>

#include "test_support.hpp"
#include "vibid/common/error.hpp"

namespace vibid::model {
namespace {

using testing::Golden;
using testing::JsonVector;
using testing::MaxRelativeError;

TEST(Frf, OneDofPeakReceptanceClosedForm) {
  // m = 2, k = 5000, c = 4 → ωn = 50, ζ = 0.02. |H| peaks at ωn√(1−2ζ²) with 1/(2kζ√(1−ζ²));
  // at ωn, H = 1/(jωn c) = −j/(2kζ).
  const double k = 5000.0, zeta = 0.02, wn = 50.0;
  const Model m = MakeChain(Eigen::VectorXd::Constant(1, 2.0), Eigen::VectorXd::Constant(1, k),
                            Eigen::VectorXd::Constant(1, 4.0));
  const double w_peak = wn * std::sqrt(1.0 - 2.0 * zeta * zeta);
  const Eigen::Vector3d omega(w_peak * (1.0 - 1e-4), w_peak, w_peak * (1.0 + 1e-4));
  const Eigen::VectorXcd h = Frf(m, 0, 0, FrfKind::kReceptance, omega);
  const double peak = 1.0 / (2.0 * k * zeta * std::sqrt(1.0 - zeta * zeta));
  EXPECT_NEAR(std::abs(h[1]), peak, 1e-12 * peak);
  EXPECT_LT(std::abs(h[0]), std::abs(h[1]));
  EXPECT_LT(std::abs(h[2]), std::abs(h[1]));
  const Eigen::VectorXcd at_wn =
      Frf(m, 0, 0, FrfKind::kReceptance, Eigen::VectorXd::Constant(1, wn));
  EXPECT_NEAR(at_wn[0].real(), 0.0, 1e-15);
  EXPECT_NEAR(at_wn[0].imag(), -1.0 / (2.0 * k * zeta), 1e-13);
  // Static: 1/k.
  EXPECT_NEAR(Frf(m, 0, 0, FrfKind::kReceptance, Eigen::VectorXd::Zero(1))[0].real(), 1.0 / k,
              1e-18);
}

TEST(Frf, MobilityAndAccelerationAreJOmegaAndMinusOmegaSquaredTimesReceptance) {
  const Model m = MakeChain(Eigen::Vector2d(2.0, 1.5), Eigen::Vector2d(4000.0, 3000.0),
                            Eigen::Vector2d(2.0, 1.0));
  const Eigen::VectorXd omega = Eigen::VectorXd::LinSpaced(50, 1.0, 200.0);
  const Eigen::VectorXcd h = Frf(m, 0, 1, FrfKind::kReceptance, omega);
  const Eigen::VectorXcd y = Frf(m, 0, 1, FrfKind::kMobility, omega);
  const Eigen::VectorXcd a = Frf(m, 0, 1, FrfKind::kAccelerance, omega);
  for (Eigen::Index i = 0; i < omega.size(); ++i) {
    EXPECT_EQ(y[i], h[i] * std::complex<double>(0.0, omega[i]));
    EXPECT_EQ(a[i], h[i] * (-omega[i] * omega[i]));
  }
  // Reciprocity: H12 = H21.
  EXPECT_LT(MaxRelativeError(Frf(m, 1, 0, FrfKind::kReceptance, omega), h), 1e-12);
}

TEST(Frf, MatchesNumpySolveForNonProportionalDamping) {
  const auto& g = Golden().at("frf");  // numpy.linalg.solve(K − ω²M + jωC, I), model_golden.py
  const Model m = testing::JsonModel(g);
  const Eigen::VectorXd omega = JsonVector(g.at("omega_rad_s"));
  Eigen::VectorXcd expected(omega.size());
  expected.real() = JsonVector(g.at("re"));
  expected.imag() = JsonVector(g.at("im"));
  const Eigen::VectorXcd h = Frf(m, g.at("input_dof").get<int>() - 1,
                                 g.at("output_dof").get<int>() - 1, FrfKind::kReceptance, omega);
  EXPECT_LT(MaxRelativeError(h, expected), 1e-11);
}

TEST(Frf, MatrixAndModalFormsAgreeToOneInABillionForProportionalDamping) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 40; ++trial) {
    const Eigen::Index n = 1 + trial % 5;
    const Model m = testing::RandomModel(rng, n, true);
    const ModalResult modes = Modal(m);
    // A grid through every resonance, where cancellation is worst.
    Eigen::VectorXd omega(3 * n + 40);
    omega.head(40) = Eigen::VectorXd::LinSpaced(40, 0.1, 1.5 * modes.omega_rad_s.maxCoeff());
    for (Eigen::Index i = 0; i < n; ++i) {
      omega.segment(40 + 3 * i, 3) << modes.omega_rad_s[i] * 0.999, modes.omega_rad_s[i],
          modes.omega_rad_s[i] * 1.001;
    }
    for (const FrfKind kind : {FrfKind::kReceptance, FrfKind::kMobility, FrfKind::kAccelerance}) {
      const int in = trial % static_cast<int>(n);
      const int out = (trial / 2) % static_cast<int>(n);
      const Eigen::VectorXcd direct = Frf(m, in, out, kind, omega);
      const Eigen::VectorXcd modal = FrfModal(modes, in, out, kind, omega);
      EXPECT_LT(MaxRelativeError(modal, direct), 1e-9) << "trial " << trial << " n " << n;
    }
  }
}

TEST(Frf, ModalFormHandlesRigidBodyModes) {
  Model m;
  m.m_kg = (Eigen::Matrix2d() << 1.0, 0.0, 0.0, 2.0).finished();
  m.k_n_per_m = (Eigen::Matrix2d() << 500.0, -500.0, -500.0, 500.0).finished();
  m.c_ns_per_m = 0.002 * m.k_n_per_m;
  const Eigen::VectorXd omega = Eigen::VectorXd::LinSpaced(30, 1.0, 80.0);
  EXPECT_LT(MaxRelativeError(FrfModal(Modal(m), 0, 1, FrfKind::kAccelerance, omega),
                             Frf(m, 0, 1, FrfKind::kAccelerance, omega)),
            1e-9);
}

TEST(Frf, ParsesKindsAndRejectsBadDofs) {
  EXPECT_EQ(ParseFrfKind("mobility"), FrfKind::kMobility);
  EXPECT_EQ(FrfKindName(FrfKind::kAccelerance), "accelerance");
  EXPECT_THROW(ParseFrfKind("inertance"), InputError);
  const Model m = MakeChain(Eigen::Vector2d(2.0, 1.5), Eigen::Vector2d(4000.0, 3000.0));
  EXPECT_THROW(Frf(m, 2, 0, FrfKind::kReceptance, Eigen::VectorXd::Ones(1)), InputError);
  EXPECT_THROW(FrfModal(Modal(m), 0, -1, FrfKind::kReceptance, Eigen::VectorXd::Ones(1)),
               InputError);
}

}  // namespace
}  // namespace vibid::model
