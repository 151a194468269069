// Coverage of the one-test chain fit's intervals on m, k and c by simulation: identify without
// mass tests on seeded synthetic hammer tests of a three-mass chain (the model core's simulation,
// half-sine hits, noise on force and responses), the truth being the simulated rig's own
// parameters. Each parameter on its own: the count of seeds whose interval holds the truth, the
// misses below and above it separately, and the interval's mean half-width against the scatter
// of the estimates over the seeds (an interval of any width must not pass). Records cut short
// and friction, which bias the residues, must withhold what they spoil, with the reason.
// VIBID_STUDY_VERBOSE=1 prints every seed's m1, c1 and warnings.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "vibid/common/error.hpp"
#include "vibid/ident/identify.hpp"
#include "vibid/ident/impact.hpp"
#include "vibid/ident/ringdown.hpp"
#include "vibid/ident/testing/hammer_test.hpp"
#include "vibid/model/simulate.hpp"

namespace vibid::ident {
namespace {

constexpr double kFs = 500.0;
// 4.9, 11.4 and 16.4 Hz; zeta 0.5 to 1.6 %.
const Eigen::Vector3d kM(1.0, 0.8, 0.6), kK(4000.0, 3000.0, 2000.0), kC(3.0, 2.0, 1.5);

model::Model Rig() { return model::MakeChain(kM, kK, kC); }

// The nominal model: masses 7 % off, springs 10 % off, no dampers.
model::Model Nominal() {
  return model::MakeChain(Eigen::Vector3d(1.07, 0.744, 0.642),
                          Eigen::Vector3d(4400.0, 2700.0, 2200.0));
}

struct Scenario {
  const char* name;
  int hits;
  double spacing_min_s, spacing_max_s;
  double noise;
  /// Coulomb friction per mass (N); 0: none (then the exact zero-order-hold simulation).
  double friction_n = 0.0;
};

// A hammer test on mass 3 with Coulomb friction: the same hits as SimulateHammerTest (half-sine
// pulses on sample instants, random heights and spacings), simulated by Runge-Kutta at 16 times
// the sample rate with friction (the exact discretisation is linear only), boxcar-averaged and
// decimated, with white noise on every channel.
HammerTestRecord SimulateWithFriction(const model::Model& rig, const HammerTestSpec& spec,
                                      double friction_n) {
  std::mt19937_64 rng(spec.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  model::ForceInput input;
  HammerTestRecord rec;
  double t = spec.lead_s;
  for (int h = 0; h < spec.hits; ++h) {
    model::ForceShape s;
    s.kind = model::ShapeKind::kHalfSine;
    s.dof = spec.hammer_dof;
    s.amp_n = spec.hit_peak_n * (1.0 + spec.hit_peak_spread * (2.0 * unit(rng) - 1.0));
    s.t0_s = std::round(t * spec.fs_hz) / spec.fs_hz;
    s.width_s = spec.pulse_width_s;
    input.shapes.push_back(s);
    rec.hit_times_s.push_back(s.t0_s);
    t += spec.spacing_min_s + (spec.spacing_max_s - spec.spacing_min_s) * unit(rng);
  }
  const int r = spec.oversample;
  model::SimulationOptions opt;
  opt.method = model::Method::kRk4;
  opt.dt_s = 1.0 / (spec.fs_hz * r);
  opt.t_end_s = t;
  // mu g m = friction_n on every mass.
  for (Eigen::Index i = 0; i < rig.dofs(); ++i) {
    const double mu = friction_n / (rig.m_kg(i, i) * model::kStandardGravity_m_s2);
    opt.friction.push_back({mu, mu});
  }
  const model::SimulationResult sim = model::Simulate(rig, input, opt);
  const Eigen::Index samples = sim.t_s.size() / r;
  const auto decimate = [&](const Eigen::VectorXd& fine) {
    Eigen::VectorXd out(samples);
    for (Eigen::Index k = 0; k < samples; ++k) out[k] = fine.segment(k * r, r).mean();
    return out;
  };
  rec.t_s = Eigen::VectorXd::LinSpaced(samples, 0.0, static_cast<double>(samples - 1) / spec.fs_hz);
  rec.force_n = decimate(sim.force_n.col(spec.hammer_dof));
  rec.response.resize(samples, rig.dofs());
  for (Eigen::Index j = 0; j < rig.dofs(); ++j) rec.response.col(j) = decimate(sim.a_m_s2.col(j));
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double fsd = spec.force_noise * rec.force_n.cwiseAbs().maxCoeff();
  for (Eigen::Index i = 0; i < rec.force_n.size(); ++i) rec.force_n[i] += fsd * gauss(rng);
  for (Eigen::Index j = 0; j < rec.response.cols(); ++j) {
    const double rsd = spec.response_noise * rec.response.col(j).cwiseAbs().maxCoeff();
    for (Eigen::Index i = 0; i < rec.response.rows(); ++i) rec.response(i, j) += rsd * gauss(rng);
  }
  return rec;
}

struct Tally {
  int inside = 0, below = 0, above = 0, withheld = 0;
  double sum = 0.0, sum2 = 0.0, half_width = 0.0;
  std::string why;
};

// Runs identify on `seeds` seeded tests of the scenario; per parameter (m1..m3, k1..k3, c1..c3)
// the tally of its intervals against the truth.
std::vector<Tally> Study(const Scenario& sc, int seeds) {
  const model::Model rig = Rig();
  const double truth[9] = {kM[0], kM[1], kM[2], kK[0], kK[1], kK[2], kC[0], kC[1], kC[2]};
  std::vector<Tally> t(9);
  for (int s = 1; s <= seeds; ++s) {
    const HammerTestSpec spec{.hammer_dof = 2,
                              .fs_hz = kFs,
                              .hits = sc.hits,
                              .pulse_width_s = 0.004,
                              .spacing_min_s = sc.spacing_min_s,
                              .spacing_max_s = sc.spacing_max_s,
                              .lead_s = 0.2,
                              .force_noise = sc.noise,
                              .response_noise = sc.noise,
                              .seed = 7000 + static_cast<std::uint64_t>(s)};
    const HammerTestRecord rec = sc.friction_n > 0.0
                                     ? SimulateWithFriction(rig, spec, sc.friction_n)
                                     : SimulateHammerTest(rig, spec);
    const ImpactResult fr = EstimateImpactFrf(rec.force_n, rec.response, kFs, {}, Estimator::kH1,
                                              Quantity::kAcceleration);
    IdentifyOptions o;
    o.driving_point = 2;
    // As `vibid identify` runs: the modes take the amplitude check on the test's own hits.
    o.modal_ringdowns = {RingDownsOf(fr, rec.force_n, rec.response, kFs, Quantity::kAcceleration)};
    const IdentifyResult r =
        Identify(Nominal(), {}, {ConvertFrf(fr.frf, Quantity::kDisplacement)}, o);
    if (std::getenv("VIBID_STUDY_VERBOSE")) {
      const PositionComparison& p0 = r.table.positions[0];
      std::printf("seed %d m1 %+.2f%% [%+.2f, %+.2f] c1 %+.1f%%", s,
                  100 * (p0.m_updated / kM[0] - 1), 100 * (p0.m_ci95.lo / kM[0] - 1),
                  100 * (p0.m_ci95.hi / kM[0] - 1), 100 * (p0.c_updated / kC[0] - 1));
      for (const auto& w : r.warnings) std::printf(" | %s", w.c_str());
      for (const auto& w : fr.warnings) std::printf(" | frf: %.60s", w.c_str());
      std::printf("\n");
    }
    for (std::size_t p = 0; p < 3; ++p) {
      const PositionComparison& pc = r.table.positions[p];
      const std::pair<const Interval95*, double> q[3] = {
          {&pc.m_ci95, pc.m_updated}, {&pc.k_ci95, pc.k_updated}, {&pc.c_ci95, pc.c_updated}};
      for (std::size_t k = 0; k < 3; ++k) {
        Tally& y = t[3 * k + p];
        const double v = truth[3 * k + p];
        const double est = q[k].second / v;  // relative to the truth
        y.sum += est;
        y.sum2 += est * est;
        const Interval95& ci = *q[k].first;
        if (!ci.Known()) {
          ++y.withheld;
          y.why = ci.missing;
          continue;
        }
        y.half_width += ci.HalfWidth() / v;
        if (v < ci.lo) {
          ++y.below;
        } else if (v > ci.hi) {
          ++y.above;
        } else {
          ++y.inside;
        }
      }
    }
  }
  return t;
}

constexpr const char* kNames[9] = {"m1", "m2", "m3", "k1", "k2", "k3", "c1", "c2", "c3"};

// Bounds for 40 seeds at a true 95 % rate: inside ~ Binomial(40, 0.95), mean 38, sd 1.38; at
// least 34 passes (below that a true 95 % rate fails 1 time in 60); a miss on one side ~
// Binomial(40, 0.025): more than 4 on one side happens 1 time in 130. The width: the mean
// half-width over 1.96 times the estimates' standard deviation over the seeds is 1 for an
// interval of the right size; the sample standard deviation of 40 values is within 25 % of the
// truth at 95 %, and the Birge widening adds up to about 20 %: 0.7 to 1.6.
// What a scenario's intervals must do: hold the truth (the bounds above, the width's upper bound
// `max_width` times 1.96 sd), or be withheld in every seed with a reason naming `withheld_why`.
struct Expect {
  bool mk_withheld = false;
  bool c_withheld = false;
  const char* withheld_why = "";
  double max_width = 1.6;
  /// The dampers' bound, where it differs (the ringing floor on zeta: see ThreeMassChain).
  double c_max_width = 1.6;
  /// Seeds allowed to withhold m and k with a friction reason on a rig without friction (false
  /// alarms of the ring-down check).
  int false_friction = 0;
};

void ExpectCoverage(const Scenario& sc, const std::vector<Tally>& t, int seeds, const Expect& e) {
  for (std::size_t i = 0; i < 9; ++i) {
    const Tally& y = t[i];
    const double mean = y.sum / seeds;
    const double sd = std::sqrt(std::max(0.0, (y.sum2 - seeds * mean * mean) / (seeds - 1)));
    const int known = seeds - y.withheld;
    const double hw = known > 0 ? y.half_width / known : 0.0;
    std::printf(
        "%s %s: %d/%d inside, %d below, %d above, %d withheld; bias %+.3f %%, sd %.3f %%, "
        "mean half-width %.3f %%, half-width / (1.96 sd) %.2f%s%s\n",
        sc.name, kNames[i], y.inside, known, y.below, y.above, y.withheld, 100 * (mean - 1.0),
        100 * sd, 100 * hw, hw / (1.96 * sd), y.withheld ? "; withheld: " : "", y.why.c_str());
    if (i < 6 ? e.mk_withheld : e.c_withheld) {
      EXPECT_EQ(y.withheld, seeds) << sc.name << " " << kNames[i];
      EXPECT_NE(y.why.find(e.withheld_why), std::string::npos)
          << sc.name << " " << kNames[i] << ": " << y.why;
      continue;
    }
    if (y.withheld > 0 && y.why.find("friction") != std::string::npos)
      EXPECT_LE(y.withheld, e.false_friction) << sc.name << " " << kNames[i] << ": " << y.why;
    else
      EXPECT_EQ(y.withheld, 0) << sc.name << " " << kNames[i] << ": " << y.why;
    EXPECT_GE(y.inside, 34) << sc.name << " " << kNames[i];
    EXPECT_LE(y.below, 4) << sc.name << " " << kNames[i];
    EXPECT_LE(y.above, 4) << sc.name << " " << kNames[i];
    EXPECT_GT(hw, 0.7 * 1.96 * sd) << sc.name << " " << kNames[i];
    EXPECT_LT(hw, (i < 6 ? e.max_width : e.c_max_width) * 1.96 * sd) << sc.name << " " << kNames[i];
  }
}

constexpr int kSeeds = 40;

// Mode 1 keeps 7 % of its amplitude at the records' end, which the chain fit takes as an error of
// 7 % in its zeta and shape (ChainFitOptions::ringing_error_per_left, measured on an independent
// simulator at 0.01 % noise): c1 and c3, which mode 1's zeta sets, come out with intervals 9 to
// 12 times the scatter here (conservative, and the docs say so); m, k and c2 within 1.6. The
// ring-down check, read down to the noise floor, takes mode 1's damping for amplitude-dependent
// in 1 of the 40 seeds (m and k withheld there, with the friction reason): at most 1 allowed.
TEST(ChainFitCoverage, ThreeMassChain) {
  const Scenario sc{"3-mass", 5, 8.0, 9.0, 0.01};
  ExpectCoverage(sc, Study(sc, kSeeds), kSeeds, {.c_max_width = 14.0, .false_friction = 1});
}

// Three hits 5-5.5 s apart: mode 1 (tau = 3.0 s) keeps about 19 % of its amplitude at the record's
// end; every interval is withheld with the reason.
TEST(ChainFitCoverage, ShortRecordsThreeHits) {
  const Scenario sc{"short", 3, 5.0, 5.5, 0.01};
  ExpectCoverage(sc, Study(sc, kSeeds), kSeeds,
                 {.mk_withheld = true, .c_withheld = true, .withheld_why = "records cut short"});
}

// Coulomb friction of 5 mN on every mass: the ring-downs flag it, m and k are withheld with the
// reason, the dampers stand on the viscous part and hold. Their intervals are wide (the viscous
// part's interval is Student's t over five hits' scatter, and it enters the fit uncorrelated
// with the rest): up to 3 times 1.96 sd is allowed here, 3.5 for the dampers (read down to the
// noise floor, the viscous part scatters less: c1 by 6.2 % over the seeds, its interval 3.2
// times that).
TEST(ChainFitCoverage, CoulombFriction) {
  const Scenario sc{"friction", 5, 8.0, 9.0, 0.01, 0.005};
  ExpectCoverage(
      sc, Study(sc, kSeeds), kSeeds,
      {.mk_withheld = true, .withheld_why = "friction: ", .max_width = 3.0, .c_max_width = 3.5});
}

}  // namespace
}  // namespace vibid::ident
