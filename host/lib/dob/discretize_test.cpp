#include "vibid/dob/discretize.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "test_support.hpp"
#include "vibid/dob/q_filter.hpp"

namespace vibid::dob {
namespace {

Zpk FromPolys(const Eigen::VectorXd& num, const Eigen::VectorXd& den) {
  Zpk z;
  z.zeros = numerics::PolynomialRoots(num);
  z.poles = numerics::PolynomialRoots(den);
  z.gain = numerics::TrimLeadingZeros(num)[0] / numerics::TrimLeadingZeros(den)[0];
  return z;
}

void ExpectResponse(const std::vector<SosSection>& sos, const nlohmann::json& freqs,
                    const nlohmann::json& ref, double fs_hz, double rel_tol) {
  for (std::size_t i = 0; i < freqs.size(); ++i) {
    const double f = freqs[i].get<double>();
    const Complex z = std::exp(Complex(0.0, 2.0 * std::numbers::pi * f / fs_hz));
    const Complex want = test::AsComplex(ref[i]);
    EXPECT_LE(std::abs(EvaluateSos(sos, z) - want), rel_tol * std::abs(want)) << f;
  }
}

// scipy.signal.bilinear_zpk with the pre-warped constant (scripts/golden/dob_golden.py).
TEST(Discretize, TustinPrewarpedQMatchesScipy) {
  const auto& ref = test::Golden()["q_n5_r4"];
  const QFilter q = MakeQFilter(5, 4, 0.002);
  const auto sos = ZpkToSos(TustinZpk(FromPolys(q.num, q.den), 5000.0, 500.0));
  EXPECT_EQ(sos.size(), 3u);
  ExpectResponse(sos, ref["freqs_hz"], ref["tustin_response"], 5000.0, 1e-9);
}

TEST(Discretize, PrewarpingPinsTheResponseAtTheWarpFrequency) {
  Zpk analog;
  analog.poles = {Complex(-100.0, 400.0), Complex(-100.0, -400.0)};
  analog.gain = 170000.0;
  const double w = 400.0;
  const auto sos = ZpkToSos(TustinZpk(analog, 1000.0, w));
  const Complex hz = EvaluateSos(sos, std::exp(Complex(0.0, w / 1000.0)));
  const Complex hs = EvaluateZpk(analog, Complex(0.0, w));
  EXPECT_NEAR(std::abs(hz - hs), 0.0, 1e-12 * std::abs(hs));
}

// scipy.signal.cont2discrete(method='zoh').
TEST(Discretize, ZeroOrderHoldMatchesScipy) {
  const auto& ref = test::Golden()["zoh"];
  const Eigen::VectorXd num =
      Eigen::Map<const Eigen::VectorXd>(ref["num"].get<std::vector<double>>().data(), 2);
  const Eigen::VectorXd den =
      Eigen::Map<const Eigen::VectorXd>(ref["den"].get<std::vector<double>>().data(), 3);
  const auto sos = ZpkToSos(ZeroOrderHoldZpk(FromPolys(num, den), 5000.0));
  ExpectResponse(sos, ref["freqs_hz"], ref["response"], 5000.0, 1e-8);
}

TEST(Discretize, ZeroOrderHoldOfQMatchesScipy) {
  const auto& ref = test::Golden()["q_n5_r4"];
  const QFilter q = MakeQFilter(5, 4, 0.002);
  const auto sos = ZpkToSos(ZeroOrderHoldZpk(FromPolys(q.num, q.den), 5000.0));
  ExpectResponse(sos, ref["freqs_hz"], ref["zoh_response"], 5000.0, 1e-7);
}

TEST(Discretize, ZeroOrderHoldOfAnIntegratorChainIsStepInvariant) {
  // 1/(s+a): step response 1/a (1 - e^{-a t}) sampled exactly by ZOH.
  Zpk analog;
  analog.poles = {Complex(-50.0, 0.0)};
  const auto sos = ZpkToSos(ZeroOrderHoldZpk(analog, 1000.0));
  const Eigen::VectorXd y = FilterSos(sos, Eigen::VectorXd::Ones(20));
  for (int k = 0; k < 20; ++k) {
    // Output at sample k responds to the held step from t=0 up to t=k T (one-sample delay of ZOH).
    EXPECT_NEAR(y[k], (1.0 - std::exp(-50.0 * k / 1000.0)) / 50.0, 1e-14);
  }
}

TEST(Discretize, SosOrdersPolesTowardsTheUnitCircleLast) {
  Zpk d;
  d.poles = {Complex(0.3, 0.0), Complex(0.9, 0.1), Complex(0.9, -0.1), Complex(0.5, 0.0),
             Complex(-0.2, 0.0)};
  d.zeros = {Complex(-1.0, 0.0), Complex(-1.0, 0.0), Complex(0.2, 0.0)};
  d.gain = 0.25;
  const auto sos = ZpkToSos(d);
  ASSERT_EQ(sos.size(), 3u);
  EXPECT_NEAR(MaxPoleRadius({sos.back()}), std::abs(Complex(0.9, 0.1)), 1e-12);
  for (const double f : {0.01, 0.1, 0.3}) {
    const Complex z = std::exp(Complex(0.0, 2.0 * std::numbers::pi * f));
    EXPECT_NEAR(std::abs(EvaluateSos(sos, z) - EvaluateZpk(d, z)), 0.0, 1e-12);
  }
}

}  // namespace
}  // namespace vibid::dob
