// Coverage of every interval `vibid modes` prints on an impact recording (omega, zeta and each
// shape ratio phi_j / phi_p), by simulation: seeded synthetic hammer tests through the product's
// path (impact FRF, lscf with the modal model, the ring-down check of the damping), per mode and
// per quantity on its own. Each must hold the truth in at least 90 % of the seeds where it is
// given, miss it on each side in at most 7.5 %, and have a mean half-width of at least 0.5 times
// 1.96 standard deviations of its estimates over the seeds (at most 3 times; 8 times with friction,
// where the FRF model's misfit raises its noise level: an interval of any width must not pass). An
// interval that is not given must come with its reason (the mode's caution or a warning naming the
// mode).
//
// Truth: the simulated model's modal parameters: omega and zeta from its state matrix's
// eigenvalues (model::ComplexModalDamping), shapes from the undamped generalised eigenproblem
// K phi = omega^2 M phi (stiffness-proportional damping: the damped modes are real and equal to
// them). The Coulomb-friction study's truth is its viscous model's (friction adds no damping
// ratio: it takes a fixed amplitude per cycle, ringdown.hpp).
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "vibid/ident/impact.hpp"
#include "vibid/ident/modes.hpp"
#include "vibid/ident/ringdown.hpp"
#include "vibid/ident/testing/hammer_test.hpp"
#include "vibid/model/modal.hpp"
#include "vibid/model/model.hpp"

namespace vibid::ident {
namespace {

struct Truth {
  Eigen::VectorXd omega, zeta;
  Eigen::MatrixXd ratio;  // responses x modes: phi_j / phi_p
};

Truth TruthOf(const model::Model& rig, int driving) {
  Truth t;
  const model::ComplexModes cm = model::ComplexModalDamping(rig);
  t.omega = cm.omega_rad_s;
  t.zeta = cm.zeta;
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(rig.k_n_per_m, rig.m_kg);
  const Eigen::MatrixXd phi = es.eigenvectors();  // ascending eigenvalues
  t.ratio.resize(phi.rows(), phi.cols());
  for (Eigen::Index i = 0; i < phi.cols(); ++i) t.ratio.col(i) = phi.col(i) / phi(driving, i);
  return t;
}

// One quantity of one mode over the seeds.
struct Tally {
  std::string name;
  double truth = 0.0;
  int seeds = 0, given = 0, in = 0, below = 0, above = 0, withheld_with_reason = 0;
  std::vector<double> estimates, half_widths;

  void Add(double value, const std::array<double, 2>& ci, bool reason) {
    ++seeds;
    if (!(std::isfinite(ci[0]) && std::isfinite(ci[1]))) {
      withheld_with_reason += reason;
      return;
    }
    ++given;
    estimates.push_back(value);
    half_widths.push_back(0.5 * (ci[1] - ci[0]));
    if (truth < ci[0]) {
      ++below;
    } else if (truth > ci[1]) {
      ++above;
    } else {
      ++in;
    }
  }
  double Mean() const {
    double mean = 0.0;
    for (double e : estimates) mean += e;
    return estimates.empty() ? 0.0 : mean / static_cast<double>(estimates.size());
  }
  // Standard deviation of the estimates over the seeds, robustly: 1.4826 times their median
  // absolute deviation (one seed's outlier must not widen the yardstick of every interval).
  double Scatter() const {
    if (estimates.size() < 2) return 0.0;
    const auto median = [](std::vector<double> v) {
      std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
      return v[v.size() / 2];
    };
    const double mid = median(estimates);
    std::vector<double> dev;
    for (double e : estimates) dev.push_back(std::abs(e - mid));
    return 1.4826 * median(dev);
  }
  double WidthRatio() const {
    double hw = 0.0;
    for (double h : half_widths) hw += h;
    hw /= std::max<double>(1.0, static_cast<double>(half_widths.size()));
    const double s = Scatter();
    return s > 0.0 ? hw / (1.959963984540054 * s) : 0.0;
  }
};

struct Study {
  const char* name;
  model::Model rig;
  HammerTestSpec spec;
  int seeds;
  /// Largest mean half-width over 1.96 robust standard deviations of the estimates.
  double max_width_ratio = 3.0;
};

// Runs the study and checks every tally; prints one table row per tally (docs/identification.md).
void RunStudy(const Study& study) {
  const int p = study.spec.hammer_dof;
  const Truth truth = TruthOf(study.rig, p);
  const Eigen::Index modes = truth.omega.size();
  const Eigen::Index responses = study.rig.dofs();
  std::vector<Tally> tallies;
  for (Eigen::Index i = 0; i < modes; ++i) {
    tallies.push_back({"mode " + std::to_string(i + 1) + " omega", truth.omega[i]});
    tallies.push_back({"mode " + std::to_string(i + 1) + " zeta", truth.zeta[i]});
    for (Eigen::Index j = 0; j < responses; ++j) {
      if (j == p) continue;
      tallies.push_back({"mode " + std::to_string(i + 1) + " phi" + std::to_string(j + 1) + "/phi" +
                             std::to_string(p + 1),
                         truth.ratio(j, i)});
    }
  }
  const std::size_t per_mode = tallies.size() / static_cast<std::size_t>(modes);
  int amplitude_flagged = 0;
  int not_found = 0;
  std::vector<int> silent(static_cast<std::size_t>(modes), 0);
  for (int seed = 1; seed <= study.seeds; ++seed) {
    HammerTestSpec spec = study.spec;
    spec.seed = static_cast<std::uint64_t>(9000 + seed);
    const HammerTestRecord rec = SimulateHammerTest(study.rig, spec);
    const ImpactResult r = EstimateImpactFrf(rec.force_n, rec.response, spec.fs_hz, {},
                                             Estimator::kH1, Quantity::kAcceleration);
    ModeIdentification id =
        IdentifyModes(ConvertFrf(r.frf, Quantity::kDisplacement), static_cast<std::size_t>(p), {});
    ApplyAmplitudeCheck(
        RingDownsOf(r, rec.force_n, rec.response, spec.fs_hz, Quantity::kAcceleration), id);
    for (Eigen::Index i = 0; i < modes; ++i) {
      // The reported mode nearest the truth, within 5 %; none: every interval of it is missing.
      const ModeEstimate* m = nullptr;
      for (const ModeEstimate& e : id.modes) {
        if (std::abs(e.omega_rad_s - truth.omega[i]) < 0.05 * truth.omega[i] &&
            (m == nullptr ||
             std::abs(e.omega_rad_s - truth.omega[i]) < std::abs(m->omega_rad_s - truth.omega[i])))
          m = &e;
      }
      Tally* t = &tallies[static_cast<std::size_t>(i) * per_mode];
      const std::array<double, 2> none{ModeEstimate::kNoInterval, ModeEstimate::kNoInterval};
      if (m == nullptr) {
        // Not reported: the peak must be named (a peak with no mode) for the seed to count as a
        // value withheld with its reason.
        const auto near = [&](double f_hz) {
          return std::abs(2.0 * std::numbers::pi * f_hz - truth.omega[i]) < 0.05 * truth.omega[i];
        };
        bool named =
            std::any_of(id.peaks_without_mode_hz.begin(), id.peaks_without_mode_hz.end(), near);
        for (const ModeEstimate& d : id.dropped) named = named || near(d.freq_hz);
        ++not_found;
        if (!named) {
          // A mode the diagram did not choose and the peak check did not name: counted on its own
          // (at most 10 % of the seeds), not as an interval withheld.
          ++silent[static_cast<std::size_t>(i)];
          std::printf("%s seed %d: mode %d (%.4g Hz) neither reported nor named\n", study.name,
                      seed, static_cast<int>(i) + 1, truth.omega[i] / (2.0 * std::numbers::pi));
          continue;
        }
        for (std::size_t k = 0; k < per_mode; ++k) t[k].Add(0.0, none, named);
        continue;
      }
      amplitude_flagged += m->amplitude.amplitude_dependent;
      char at[32];
      std::snprintf(at, sizeof at, "%.5g Hz", m->freq_hz);
      bool warned = false;
      for (const std::string& w : id.warnings) warned = warned || w.find(at) != std::string::npos;
      const bool reason = !m->caution.empty() || warned;
      t[0].Add(m->omega_rad_s, m->omega_ci95_rad_s, reason);
      t[1].Add(m->zeta, m->zeta_ci95, reason);
      std::size_t k = 2;
      for (Eigen::Index j = 0; j < responses; ++j) {
        if (j == p) continue;
        const bool have = m->shape_ratio.size() == responses &&
                          m->shape_ratio_ci95.size() == static_cast<std::size_t>(responses);
        t[k++].Add(have ? m->shape_ratio[j] : 0.0,
                   have ? m->shape_ratio_ci95[static_cast<std::size_t>(j)] : none, reason);
      }
    }
  }
  std::printf("%s: %d seeds, %d mode results flagged amplitude-dependent, %d modes not reported\n",
              study.name, study.seeds, amplitude_flagged, not_found);
  std::printf(
      "| study | quantity | truth | mean estimate | given | covered | below | above | "
      "withheld (reason) | half-width / 1.96 sd |\n");
  for (std::size_t i = 0; i < silent.size(); ++i) {
    EXPECT_LE(silent[i], 0.1 * study.seeds)
        << study.name << " mode " << i + 1 << " missing without a word";
  }
  for (const Tally& t : tallies) {
    const double rate = t.given > 0 ? static_cast<double>(t.in) / t.given : 0.0;
    std::printf("| %s | %s | %.6g | %.6g | %d/%d | %.1f %% | %d | %d | %d (%d) | %.2f |\n",
                study.name, t.name.c_str(), t.truth, t.Mean(), t.given, t.seeds, 100.0 * rate,
                t.below, t.above, t.seeds - t.given, t.withheld_with_reason, t.WidthRatio());
    // Every interval not given has its reason.
    EXPECT_EQ(t.withheld_with_reason, t.seeds - t.given) << study.name << " " << t.name;
    if (t.given == 0) continue;
    EXPECT_GE(rate, 0.90) << study.name << " " << t.name;
    EXPECT_LE(t.below, 0.075 * t.given) << study.name << " " << t.name << " truth below";
    EXPECT_LE(t.above, 0.075 * t.given) << study.name << " " << t.name << " truth above";
    if (t.given >= 10) {
      EXPECT_GE(t.WidthRatio(), 0.5) << study.name << " " << t.name;
      EXPECT_LE(t.WidthRatio(), study.max_width_ratio) << study.name << " " << t.name;
    }
  }
}

// Three masses, hammer on the last, every mass measured: 5 hits 5 to 5.5 s apart at 200 Hz,
// 0.5 % noise on force and responses.
TEST(ModeCoverage, ThreeMassChain) {
  const Eigen::Vector3d k(4000.0, 3000.0, 2000.0);
  const model::Model rig =
      model::MakeChain(Eigen::Vector3d(1.0, 0.8, 0.6), k, Eigen::Vector3d(1e-3 * k));
  RunStudy({"three-mass chain", rig,
            HammerTestSpec{.hammer_dof = 2,
                           .fs_hz = 200.0,
                           .hits = 5,
                           .pulse_width_s = 0.004,
                           .spacing_min_s = 5.0,
                           .spacing_max_s = 5.5,
                           .lead_s = 0.2,
                           .force_noise = 0.005,
                           .response_noise = 0.005},
            40});
}

// Short records, few hits: three hits 3 to 3.2 s apart (the records end while mode 1 still
// rings at a fifth of its start), two masses, hammer on mass 2.
TEST(ModeCoverage, ShortRecordsThreeHits) {
  const Eigen::Vector2d k(3520.0, 2760.0);
  const model::Model rig =
      model::MakeChain(Eigen::Vector2d(1.82, 1.53), k, Eigen::Vector2d(1.3e-3 * k));
  RunStudy({"short records, 3 hits", rig,
            HammerTestSpec{.hammer_dof = 1,
                           .fs_hz = 200.0,
                           .hits = 3,
                           .pulse_width_s = 0.004,
                           .spacing_min_s = 3.0,
                           .spacing_max_s = 3.2,
                           .lead_s = 0.2,
                           .force_noise = 0.005,
                           .response_noise = 0.005},
            40});
}

// The emulator's default rig in proportional form (m 1.82 and 1.53 kg, k 3520 and 2760 N/m,
// zeta about 1.9 % and 3.7 %) with its Coulomb friction of 5 mN on each mass: the FRF alone gives
// zeta1 some 15 % high with an interval that excludes the truth; the ring-down check must flag it
// and give the viscous part with an interval that holds. Mode 2's own ring-downs are too short to
// show the friction: its zeta interval reaches down by the bound the friction found on mode 1 puts
// on it (5 relay terms, ringdown.cpp), 12.8 times the scatter over these seeds (conservative by
// that much, docs/identification.md), hence the limit of 14 here; the other quantities stay
// below 8.
TEST(ModeCoverage, CoulombFriction) {
  const Eigen::Vector2d m(1.82, 1.53);
  const Eigen::Vector2d k(3520.0, 2760.0);
  const model::Model rig = model::MakeChain(m, k, Eigen::Vector2d(1.3e-3 * k));
  std::vector<model::CoulombFriction> friction;
  for (int i = 0; i < 2; ++i) {
    const double mu = 0.005 / (m[i] * model::kStandardGravity_m_s2);
    friction.push_back({mu, mu});
  }
  RunStudy({"Coulomb friction 5 mN", rig,
            HammerTestSpec{.hammer_dof = 1,
                           .fs_hz = 200.0,
                           .hits = 5,
                           .hit_peak_n = 100.0,
                           .pulse_width_s = 0.004,
                           .spacing_min_s = 8.0,
                           .spacing_max_s = 9.0,
                           .lead_s = 0.2,
                           .friction = friction,
                           .force_noise = 0.002,
                           .response_noise = 0.002},
            40, 14.0});
}

}  // namespace
}  // namespace vibid::ident
