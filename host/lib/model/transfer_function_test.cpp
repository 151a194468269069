// Transfer functions: closed forms, scipy.signal.ss2tf, the matrix FRF, and the cart-track models.
#include "vibid/model/transfer_function.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "test_support.hpp"
#include "vibid/common/error.hpp"

namespace vibid::model {
namespace {

using testing::Golden;
using testing::JsonVector;
using testing::MaxRelativeError;

void ExpectCoefficientsNear(const Eigen::VectorXd& actual, const Eigen::VectorXd& expected,
                            double rel) {
  ASSERT_EQ(actual.size(), expected.size())
      << "actual " << actual.transpose() << " expected " << expected.transpose();
  for (Eigen::Index i = 0; i < expected.size(); ++i) {
    EXPECT_NEAR(actual[i], expected[i], rel * std::abs(expected[i])) << "coefficient " << i;
  }
}

TEST(TransferFunction, OneDofIsOneOverMsSquaredPlusCsPlusK) {
  const Model m = MakeChain(Eigen::VectorXd::Constant(1, 2.0), Eigen::VectorXd::Constant(1, 5000.0),
                            Eigen::VectorXd::Constant(1, 4.0));
  const TransferFunction tf = ModelTransferFunction(m, 0, 0, FrfKind::kReceptance);
  ExpectCoefficientsNear(tf.num, Eigen::VectorXd::Constant(1, 0.5), 1e-14);
  ExpectCoefficientsNear(tf.den, Eigen::Vector3d(1.0, 2.0, 2500.0), 1e-14);
  const TransferFunction acc = ModelTransferFunction(m, 0, 0, FrfKind::kAccelerance);
  ExpectCoefficientsNear(acc.num, Eigen::Vector3d(0.5, 0.0, 0.0), 1e-14);
}

TEST(TransferFunction, TwoDofCrossTermMatchesClosedFormAndScipySs2tf) {
  // X2/F1 of the chain: (c2 s + k2) / det(Ms² + Cs + K), normalised by m1 m2.
  const auto& g = Golden().at("ss2tf");  // scipy.signal.ss2tf, scripts/golden/model_golden.py
  const Model m = testing::JsonModel(g);
  const TransferFunction tf = ModelTransferFunction(m, 0, 1, FrfKind::kReceptance);
  const double m1 = 2.0, m2 = 1.5, c1 = 2.0, c2 = 1.0, k1 = 4000.0, k2 = 3000.0;
  ExpectCoefficientsNear(tf.num, Eigen::Vector2d(c2 / (m1 * m2), k2 / (m1 * m2)), 1e-12);
  Eigen::VectorXd den(5);
  // (m1 s² + (c1+c2) s + k1+k2)(m2 s² + c2 s + k2) − (c2 s + k2)², divided by m1 m2.
  den << m1 * m2, m1 * c2 + m2 * (c1 + c2), m1 * k2 + m2 * (k1 + k2) + (c1 + c2) * c2 - c2 * c2,
      (c1 + c2) * k2 + (k1 + k2) * c2 - 2.0 * c2 * k2, (k1 + k2) * k2 - k2 * k2;
  ExpectCoefficientsNear(tf.den, den / (m1 * m2), 1e-12);
  ExpectCoefficientsNear(tf.num, JsonVector(g.at("num")), 1e-9);  // ss2tf carries ~1e-11 rounding
  ExpectCoefficientsNear(tf.den, JsonVector(g.at("den")), 1e-12);
}

TEST(TransferFunction, AgreesWithMatrixFrfOverRandomSystems) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 30; ++trial) {
    const Eigen::Index n = 1 + trial % 4;
    const Model m = testing::RandomModel(rng, n, trial % 3 == 0);
    const Eigen::VectorXd omega = Eigen::VectorXd::LinSpaced(60, 1.0, 400.0);
    const int in = trial % static_cast<int>(n);
    const int out = (trial + 1) % static_cast<int>(n);
    for (const FrfKind kind : {FrfKind::kReceptance, FrfKind::kMobility, FrfKind::kAccelerance}) {
      const TransferFunction tf = ModelTransferFunction(m, in, out, kind);
      EXPECT_EQ(tf.den.size(), 2 * n + 1);
      EXPECT_EQ(tf.den[0], 1.0);
      EXPECT_LE(tf.num.size(), 2 * n - 1 +
                                   (kind == FrfKind::kMobility      ? 1
                                    : kind == FrfKind::kAccelerance ? 2
                                                                    : 0));
      EXPECT_LT(MaxRelativeError(EvaluateTfAt(tf, omega), Frf(m, in, out, kind, omega)), 1e-8)
          << "trial " << trial;
    }
  }
}

TEST(CartTrack, OneCartForceAndPositionTfsMatchTheMatrixModel) {
  // Methods §10, one cart: X1/F = (1/M)/(s² + (B/M)s + 2k/M); X1/Xi = ((Bi/M)s + 2k/M)/(same).
  const double mass = 0.57, k = 15.0, b = 0.8, bi = 0.3;
  const Eigen::VectorXd masses = Eigen::VectorXd::Constant(1, mass);
  const Eigen::VectorXd frictions = Eigen::VectorXd::Constant(1, b);
  const Model model = MakeCartTrack(masses, k, frictions);
  const TransferFunction force = CartTrackTf(masses, k, frictions, CartInput::kForce);
  ExpectCoefficientsNear(force.den, ModelTransferFunction(model, 0, 0, FrfKind::kReceptance).den,
                         1e-13);
  ExpectCoefficientsNear(force.num, ModelTransferFunction(model, 0, 0, FrfKind::kReceptance).num,
                         1e-13);
  ExpectCoefficientsNear(force.den, Eigen::Vector3d(1.0, b / mass, 2.0 * k / mass), 1e-15);

  const Eigen::VectorXd omega = Eigen::VectorXd::LinSpaced(40, 0.5, 50.0);
  Eigen::VectorXcd expected = Frf(model, 0, 0, FrfKind::kReceptance, omega);
  for (Eigen::Index i = 0; i < omega.size(); ++i)
    expected[i] *= std::complex<double>(2.0 * k, bi * omega[i]);
  const TransferFunction position = CartTrackTf(masses, k, frictions, CartInput::kPosition, bi);
  EXPECT_LT(MaxRelativeError(EvaluateTfAt(position, omega), expected), 1e-12);
}

TEST(CartTrack, TwoCartCoefficientsMatchTheMatrixModel) {
  const Eigen::Vector2d masses(0.57, 0.56);
  const Eigen::Vector2d frictions(0.8, 0.6);
  const double k = 15.0, bi = 0.3;
  const Model model = MakeCartTrack(masses, k, frictions);

  // X1/F: the matrix model's exact polynomials against methods §10's den (a3..a0) and numerator.
  const TransferFunction from_matrix = ModelTransferFunction(model, 0, 0, FrfKind::kReceptance);
  const TransferFunction force = CartTrackTf(masses, k, frictions, CartInput::kForce);
  ExpectCoefficientsNear(from_matrix.den, force.den, 1e-12);
  ExpectCoefficientsNear(from_matrix.num, force.num, 1e-12);

  // X1/Xi = (Bi s + 2k) · X1/F: b3..b0 of methods §10.
  const TransferFunction input_map{Eigen::Vector2d(bi, 2.0 * k), Eigen::VectorXd::Ones(1)};
  const TransferFunction position = CartTrackTf(masses, k, frictions, CartInput::kPosition, bi);
  const TransferFunction composed = Multiply(input_map, from_matrix);
  ExpectCoefficientsNear(composed.num, position.num, 1e-12);
  ExpectCoefficientsNear(composed.den, position.den, 1e-12);

  const Eigen::VectorXd omega = Eigen::VectorXd::LinSpaced(40, 0.5, 50.0);
  Eigen::VectorXcd expected = Frf(model, 0, 0, FrfKind::kReceptance, omega);
  for (Eigen::Index i = 0; i < omega.size(); ++i)
    expected[i] *= std::complex<double>(2.0 * k, bi * omega[i]);
  EXPECT_LT(MaxRelativeError(EvaluateTfAt(position, omega), expected), 1e-12);
  // a0 = 3k²/(M1M2): the det of [[2k, −k], [−k, 2k]] over the masses.
  EXPECT_NEAR(position.den[4], 3.0 * k * k / (masses[0] * masses[1]), 1e-12);
}

TEST(CartTrack, RejectsMoreThanTwoCarts) {
  EXPECT_THROW(
      CartTrackTf(Eigen::Vector3d(1, 1, 1), 1.0, Eigen::Vector3d(0, 0, 0), CartInput::kForce),
      InputError);
  EXPECT_THROW(CartTrackTf(Eigen::Vector2d(1, 1), 1.0, Eigen::VectorXd::Zero(1), CartInput::kForce),
               InputError);
}

}  // namespace
}  // namespace vibid::model
