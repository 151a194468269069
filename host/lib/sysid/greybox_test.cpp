// Grey-box cart parameters: exact recovery from noise-free records, fixed parameters,
// uncertainties.
#include "vibid/sysid/greybox.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "testing_systems.hpp"
#include "vibid/common/error.hpp"

namespace vibid::sysid {
namespace {

constexpr double kDt = 0.005;

double Value(const GreyboxResult& r, const std::string& name) {
  for (const auto& p : r.parameters) {
    if (p.name == name) return p.value;
  }
  ADD_FAILURE() << "no parameter " << name;
  return 0.0;
}

TEST(Greybox, CartTfMatchesMethodsFormulas) {
  // methods §10, two carts, position input: b3 = Bi M2/(M1 M2), ..., a0 = 3k²/(M1 M2).
  const double m1 = 0.57, m2 = 0.56, b1 = 0.6, b2 = 0.5, k = 15.0, bi = 0.25;
  const TransferFunction tf =
      Normalized(CartTf(CartConfig{2, CartInput::kPosition}, testing::TwoCartValues()));
  const double mm = m1 * m2;
  const Eigen::Vector4d num(bi * m2 / mm, (2 * k * m2 + b2 * bi) / mm,
                            (2 * k * b2 + 2 * k * bi) / mm, 4 * k * k / mm);
  Eigen::VectorXd den(5);
  den << 1.0, (m1 * b2 + m2 * b1) / mm, (2 * k * m1 + 2 * k * m2 + b1 * b2) / mm,
      (2 * k * b1 + 2 * k * b2) / mm, 3 * k * k / mm;
  EXPECT_LT((tf.num - num).cwiseAbs().maxCoeff(), 1e-12 * num.cwiseAbs().maxCoeff());
  EXPECT_LT((tf.den - den).cwiseAbs().maxCoeff(), 1e-12 * den.cwiseAbs().maxCoeff());
}

TEST(Greybox, RecoversOneCartForceModel) {
  const Eigen::Vector3d truth(0.57, 0.6, 15.0);                 // M, B, k
  const Eigen::VectorXd u = testing::Pulse(3000, 20, 20, 5.0);  // 5 N for 0.1 s (methods §10)
  const Eigen::VectorXd y = Simulate(CartTf(CartConfig{1, CartInput::kForce}, truth), u, kDt);
  GreyboxOptions o;
  const GreyboxResult r = EstimateCart(MakeIoData(u, y, kDt), o);
  ASSERT_TRUE(r.summary.Converged()) << r.summary.message;
  EXPECT_NEAR(Value(r, "M"), 0.57, 0.57e-6);
  EXPECT_NEAR(Value(r, "B"), 0.6, 0.6e-6);
  EXPECT_NEAR(Value(r, "k"), 15.0, 15e-6);
  EXPECT_GT(r.fit_percent, 99.999);
}

TEST(Greybox, PositionInputWithFixedMassAndSpring) {
  // The contract's example: --fix M=0.57,k=15 leaves B and Bi.
  const Eigen::VectorXd truth = testing::OneCartValues();  // M, B, k, Bi
  const Eigen::VectorXd u = testing::Step(3000, 20, 0.01);
  const Eigen::VectorXd y0 = Simulate(CartTf(CartConfig{1, CartInput::kPosition}, truth), u, kDt);
  GreyboxOptions o;
  o.config.input = CartInput::kPosition;
  o.fixed = {{"M", 0.57}, {"k", 15.0}};
  const GreyboxResult exact = EstimateCart(MakeIoData(u, y0, kDt), o);
  EXPECT_NEAR(Value(exact, "B"), truth[1], 1e-6 * truth[1]);
  EXPECT_NEAR(Value(exact, "Bi"), truth[3], 1e-6 * truth[3]);
  // With 1 % output noise the estimates stay within 3 of their own standard deviations.
  const Eigen::VectorXd y = y0 + testing::WhiteNoise(y0.size(), 0.01 * testing::Rms(y0), 77);
  const GreyboxResult noisy = EstimateCart(MakeIoData(u, y, kDt), o);
  for (const auto& p : noisy.parameters) {
    if (p.fixed) continue;
    const double t = p.name == "B" ? truth[1] : truth[3];
    EXPECT_LT(std::abs(p.value - t), 3.0 * p.std) << p.name << " " << p.value << " +- " << p.std;
    EXPECT_GT(p.std, 0.0);
  }
}

TEST(Greybox, RecoversTwoCartForceModel) {
  Eigen::VectorXd truth(5);
  truth << 0.57, 0.56, 0.6, 0.5, 15.0;  // M1, M2, B1, B2, k
  const Eigen::VectorXd u = testing::Pulse(4000, 20, 20, 5.0);
  const Eigen::VectorXd y = Simulate(CartTf(CartConfig{2, CartInput::kForce}, truth), u, kDt);
  GreyboxOptions o;
  o.config.carts = 2;
  const GreyboxResult r = EstimateCart(MakeIoData(u, y, kDt), o);
  ASSERT_TRUE(r.summary.Converged()) << r.summary.message;
  const char* names[] = {"M1", "M2", "B1", "B2", "k"};
  for (int i = 0; i < 5; ++i)
    EXPECT_NEAR(Value(r, names[i]), truth[i], 1e-6 * truth[i]) << names[i];
}

TEST(Greybox, RejectsUnidentifiableOrUnknownParameters) {
  GreyboxOptions o;
  o.config.input = CartInput::kPosition;
  EXPECT_THROW(o.Validate(), InputError);  // position input: the scale needs M or k fixed
  o.fixed = {{"Q", 1.0}};
  EXPECT_THROW(o.Validate(), InputError);
  o.fixed = {{"M", 1.0}, {"B", 1.0}, {"k", 1.0}, {"Bi", 1.0}};
  EXPECT_THROW(o.Validate(), InputError);
}

}  // namespace
}  // namespace vibid::sysid
