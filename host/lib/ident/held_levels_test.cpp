// The held-levels check: a step, a controller's pulse and a held random command hold levels; a
// hammer record on a 12-bit converter, which repeats its resting code as often, and a random force
// do not.
#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "vibid/ident/held_levels.hpp"
#include "vibid/ident/impact.hpp"

namespace vibid::ident {
namespace {

constexpr double kFs = 200.0;
constexpr Eigen::Index kN = 3000;

TEST(HeldLevels, StepPulseAndHeldCommandHoldLevels) {
  Eigen::VectorXd step = Eigen::VectorXd::Zero(kN);
  step.tail(kN / 2).setConstant(3.0);
  Eigen::VectorXd pulse = Eigen::VectorXd::Zero(kN);
  pulse.segment(500, 400).setConstant(-3.0);
  pulse.segment(900, 400).setConstant(3.0);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> level(-1.5, 1.5);
  Eigen::VectorXd held(kN);
  double v = 0.0;
  for (Eigen::Index i = 0; i < kN; ++i) {
    if (i % 20 == 0) v = level(rng);  // a 10 Hz zero-order-hold random command
    held[i] = v;
  }
  for (const Eigen::VectorXd* f : {&step, &pulse, &held}) {
    const HeldLevels c = CheckHeldLevels(*f);
    EXPECT_TRUE(c.held) << c.description;
    EXPECT_FALSE(ClassifyExcitation(*f, kFs).impact) << c.description;
    EXPECT_NE(c.description.find("holds levels"), std::string::npos) << c.description;
  }
}

TEST(HeldLevels, HammerOnAConverterAndRandomForceDoNot) {
  // Half-sine hits of 2 ms every 2 s at 5 kHz on 12-bit codes (resting at 2048, a code of noise).
  const double fs = 5000.0;
  const Eigen::Index n = 50000;
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.6);
  Eigen::VectorXd hammer(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Index k = i % 10000;
    const double hit =
        k >= 100 && k < 110
            ? 1500.0 * std::sin(std::numbers::pi * static_cast<double>(k - 100) / 10.0)
            : 0.0;
    hammer[i] = std::round(2048.0 + hit + noise(rng));
  }
  EXPECT_TRUE(ClassifyExcitation(hammer, fs).impact);
  const HeldLevels h = CheckHeldLevels(hammer);
  EXPECT_GT(h.held_fraction, 0.5) << h.description;  // it does repeat its resting code
  EXPECT_FALSE(h.held) << h.description;
  Eigen::VectorXd random(kN);
  for (Eigen::Index i = 0; i < kN; ++i) random[i] = noise(rng);
  const HeldLevels r = CheckHeldLevels(random);
  EXPECT_FALSE(r.held) << r.description;
}

}  // namespace
}  // namespace vibid::ident
