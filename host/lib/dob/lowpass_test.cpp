#include "vibid/dob/lowpass.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "test_support.hpp"
#include "vibid/common/error.hpp"

namespace vibid::dob {
namespace {

Eigen::VectorXd Vector(const nlohmann::json& j) {
  const auto v = j.get<std::vector<double>>();
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

// scipy.signal.butter(4, 2, fs=5000, output='sos'), sosfilt and sosfiltfilt of the same signal.
TEST(Lowpass, MatchesScipyButterSosfiltAndSosfiltfilt) {
  const auto& ref = test::Golden()["lowpass"];
  const auto sos = ButterworthLowpass(4, 2.0, 5000.0);
  const Eigen::VectorXd x = Vector(ref["input"]);
  const Eigen::VectorXd y = FilterSos(sos, x);
  const Eigen::VectorXd want = Vector(ref["sosfilt"]);
  EXPECT_LT((y - want).cwiseAbs().maxCoeff(), 1e-9);
  const Eigen::VectorXd yy = FiltFilt(sos, x);
  const Eigen::VectorXd want2 = Vector(ref["sosfiltfilt"]);
  EXPECT_LT((yy - want2).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(Lowpass, AnyOrderIsMinus3dBAtTheCutoff) {
  for (int order = 1; order <= 9; ++order) {
    const auto sos = ButterworthLowpass(order, 20.0, 1000.0);
    const Complex z = std::exp(Complex(0.0, 2.0 * std::numbers::pi * 20.0 / 1000.0));
    EXPECT_NEAR(std::abs(EvaluateSos(sos, z)), 1.0 / std::sqrt(2.0), 1e-10) << order;
    EXPECT_NEAR(std::abs(EvaluateSos(sos, 1.0)), 1.0, 1e-12);
  }
}

TEST(Lowpass, RefusesCutoffsOutsideTheBand) {
  EXPECT_THROW(ButterworthLowpass(4, 0.0, 100.0), InputError);
  EXPECT_THROW(ButterworthLowpass(4, 50.0, 100.0), InputError);
  EXPECT_THROW(ButterworthLowpass(0, 5.0, 100.0), InputError);
  EXPECT_THROW(FiltFilt(ButterworthLowpass(4, 5.0, 100.0), Eigen::VectorXd::Ones(10)), InputError);
}

}  // namespace
}  // namespace vibid::dob
