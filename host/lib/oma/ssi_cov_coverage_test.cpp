// Coverage of SSI-cov's 95 % intervals over seeded records: per mode and per quantity (ω, ζ), on
// both sides of the truth, and the interval's width against the scatter of the estimates over the
// seeds (an interval of any width cannot pass). The truth is the simulated model's own modes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "vibid/model/modal.hpp"
#include "vibid/model/model.hpp"
#include "vibid/oma/ssi_cov.hpp"
#include "vibid/oma/testing/ambient.hpp"

namespace vibid::oma {
namespace {

struct Tally {
  int inside = 0, below = 0, above = 0;  // truth inside, below the interval, above it
  std::vector<double> estimates, half_widths;
  void Add(double estimate, double half_width, double truth) {
    estimates.push_back(estimate);
    half_widths.push_back(half_width);
    if (truth < estimate - half_width) {
      ++below;
    } else if (truth > estimate + half_width) {
      ++above;
    } else {
      ++inside;
    }
  }
  double Coverage() const { return inside / static_cast<double>(estimates.size()); }
  // Mean half-width over 1.96 × the standard deviation of the estimates across seeds.
  double WidthRatio() const {
    double mean = 0.0, mean_hw = 0.0;
    for (std::size_t k = 0; k < estimates.size(); ++k) {
      mean += estimates[k];
      mean_hw += half_widths[k];
    }
    const auto count = static_cast<double>(estimates.size());
    mean /= count;
    mean_hw /= count;
    double ss = 0.0;
    for (double e : estimates) ss += (e - mean) * (e - mean);
    return mean_hw / (1.96 * std::sqrt(ss / (count - 1.0)));
  }
};

// The width over the scatter docs/watch.md states per mode, ω and ζ. An interval that covers
// at its rate with a width near 1.96 standard deviations of the estimates is right; one much
// wider covers by its width. Where the docs state 1.5 or less the test holds 0.75 … 1.5; where
// they state an interval conservative, by the stated factor, it holds within 15 % of it (the
// seeds are fixed: a wider interval than stated fails, as does one narrower than the scatter).
struct StatedWidth {
  double omega = 0.0;
  double zeta = 0.0;
};

void CheckWidth(const char* name, std::size_t mode, const char* quantity, double measured,
                double stated) {
  const double low = stated <= 1.5 ? 0.75 : stated / 1.15;
  const double high = stated <= 1.5 ? 1.5 : stated * 1.15;
  EXPECT_GE(measured, low) << name << " mode " << mode + 1 << " " << quantity;
  EXPECT_LE(measured, high) << name << " mode " << mode + 1 << " " << quantity << " (stated "
                            << stated << ")";
}

void RunStudy(const char* name, const model::Model& rig, testing::AmbientOptions sim,
              const SsiCovOptions& options, int seeds, const std::vector<StatedWidth>& stated) {
  const model::ComplexModes truth = model::ComplexModalDamping(rig);
  const std::size_t modes = static_cast<std::size_t>(truth.omega_rad_s.size());
  std::vector<Tally> omega(modes), zeta(modes);
  for (int seed = 1; seed <= seeds; ++seed) {
    sim.seed = static_cast<std::uint64_t>(seed);
    const SsiCovResult r = SsiCov(testing::SimulateAmbient(rig, sim), options);
    ASSERT_EQ(r.modes.size(), modes) << name << " seed " << seed << r.message;
    for (std::size_t m = 0; m < modes; ++m) {
      const OmaMode& found = r.modes[m];
      const auto k = static_cast<Eigen::Index>(m);
      ASSERT_TRUE(std::isfinite(found.omega_ci95_rad_s)) << r.message;
      omega[m].Add(found.omega_rad_s, found.omega_ci95_rad_s, truth.omega_rad_s(k));
      zeta[m].Add(found.zeta, found.zeta_ci95, truth.zeta(k));
    }
  }
  for (std::size_t m = 0; m < modes; ++m) {
    for (auto [quantity, tally] : {std::pair{"omega", &omega[m]}, std::pair{"zeta", &zeta[m]}}) {
      std::printf("%s mode %zu %-5s coverage %.3f (below %d, above %d) width/scatter %.2f\n", name,
                  m + 1, quantity, tally->Coverage(), tally->below, tally->above,
                  tally->WidthRatio());
      EXPECT_GE(tally->Coverage(), 0.9) << name << " mode " << m + 1 << " " << quantity;
      // Misses split between both sides: neither side takes more than 4 of 40.
      EXPECT_LE(tally->below, seeds / 10) << name << " mode " << m + 1 << " " << quantity;
      EXPECT_LE(tally->above, seeds / 10) << name << " mode " << m + 1 << " " << quantity;
      // Neither too narrow nor so wide that it covers by width alone.
      ASSERT_EQ(stated.size(), modes) << name;
      CheckWidth(name, m, quantity, tally->WidthRatio(),
                 tally == &omega[m] ? stated[m].omega : stated[m].zeta);
    }
  }
}

TEST(SsiCovCoverage, TwoMassChainFortySeeds) {
  testing::AmbientOptions sim;
  sim.fs_hz = 1000.0;
  sim.seconds = 300.0;
  SsiCovOptions o;
  o.fs_hz = 1000.0;
  o.fmax_hz = 25.0;
  RunStudy("chain2",
           model::MakeChain(Eigen::Vector2d(1.82, 1.53), Eigen::Vector2d(3520.0, 2760.0),
                            Eigen::Vector2d(5.0, 3.5)),
           sim, o, 40, {{1.13, 1.18}, {1.59, 1.89}});
}

TEST(SsiCovCoverage, ThreeMassChainPositionsFortySeeds) {
  testing::AmbientOptions sim;
  sim.fs_hz = 500.0;
  sim.seconds = 300.0;
  sim.accelerations = false;
  SsiCovOptions o;
  o.fs_hz = 500.0;
  o.fmax_hz = 20.0;
  RunStudy("chain3",
           model::MakeChain(Eigen::Vector3d(1.2, 0.9, 0.7), Eigen::Vector3d(3000.0, 2200.0, 1500.0),
                            Eigen::Vector3d(3.0, 2.0, 1.5)),
           sim, o, 40, {{1.12, 2.07}, {1.86, 1.88}, {1.40, 1.35}});
}

}  // namespace
}  // namespace vibid::oma
