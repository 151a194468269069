// Free decay of the ECP Model 210 cart (data/ecp_cart_free_decay/, Politecnico di Milano 2016).
// Reference values: the lab's table in that folder's README (omega_d from one period at 200 Hz,
// zeta from the first two peaks; k and m_c from the loaded/unloaded pair).
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "vibid/common/csv.hpp"
#include "vibid/common/testing/real_data.hpp"
#include "vibid/ident/decay.hpp"

namespace vibid::ident {
namespace {

struct Lab {
  const char* spring;
  const char* loaded[3];
  const char* unloaded[3];
  double wd_loaded, wd_unloaded, zeta_loaded, zeta_loaded_std, zeta_unloaded, zeta_unloaded_std, k,
      mc;
};

// Published values, ecp_cart_free_decay/README.md.
const Lab kLabs[] = {
    {"Khigh",
     {"Khigh_load-0.986kg_Khigh_hand_2mass.csv", "Khigh_load-0.986kg_Khigh_hand_2mass2.csv",
      "Khigh_load-0.986kg_Khigh_hand_2mass3.csv"},
     {"Khigh_load-none_Khigh_hand_Nomass.csv", "Khigh_load-none_Khigh_hand_Nomass2.csv",
      "Khigh_load-none_Khigh_hand_Nomass3.csv"},
     21.2989,
     34.9066,
     0.0128,
     0.0007,
     0.0179,
     0.0025,
     712.60,
     0.5848},
    {"Klow",
     {"Klow_load-0.986kg_Klow_Hand_2mass.csv", "Klow_load-0.986kg_Klow_hand_2mass2.csv",
      "Klow_load-0.986kg_Klow_hand_2mass3.csv"},
     {"Klow_load-none_Klow_Hand_Nomass.csv", "Klow_load-none_Klow_Hand_Nomass2.csv",
      "Klow_load-none_Klow_hand_Nomass3.csv"},
     10.6495,
     17.6991,
     0.0346,
     0.0036,
     0.0379,
     0.0040,
     175.28,
     0.5595},
};

// The lab's damping is a first-peaks log decrement; guide friction makes the decay
// amplitude-dependent, so the comparable fit covers the first two cycles after the release.
DecayResult Analyze(const std::string& dir, const std::string& file) {
  const Recording rec = LoadRecording(dir + "/" + file);
  return AnalyzeDecay(rec.Signal(ParseColumnSpec("X_cm:cm")), rec.fs_hz, {.cycles = 2});
}

struct Stats {
  double mean = 0.0;
  double std = 0.0;
};

Stats MeanStd(const std::vector<double>& v) {
  Stats s;
  for (double x : v) s.mean += x;
  s.mean /= static_cast<double>(v.size());
  for (double x : v) s.std += (x - s.mean) * (x - s.mean);
  s.std = std::sqrt(s.std / static_cast<double>(v.size() - 1));
  return s;
}

TEST(DecayEcp, MatchesThePublishedValues) {
  VIBID_SHARED_DATA_OR_SKIP(dir, "ecp_cart_free_decay");
  for (const Lab& lab : kLabs) {
    std::vector<double> wd_l, wd_u, z_l, z_u, wn_l, wn_u;
    for (int i = 0; i < 3; ++i) {
      const DecayResult l = Analyze(dir, lab.loaded[i]);
      const DecayResult u = Analyze(dir, lab.unloaded[i]);
      EXPECT_TRUE(l.summary.Converged()) << lab.loaded[i] << ": " << l.summary.message;
      EXPECT_TRUE(u.summary.Converged()) << lab.unloaded[i] << ": " << u.summary.message;
      wd_l.push_back(l.omega_d_rad_s);
      wd_u.push_back(u.omega_d_rad_s);
      z_l.push_back(l.zeta);
      z_u.push_back(u.zeta);
      wn_l.push_back(l.omega_n_rad_s);
      wn_u.push_back(u.omega_n_rad_s);
      std::printf(
          "%s %s: wd %.4f zeta %.4f (logdec %.4f) release %.3f s, %zu samples | %s: wd %.4f zeta "
          "%.4f (logdec %.4f)\n",
          lab.spring, lab.loaded[i], l.omega_d_rad_s, l.zeta, l.zeta_log_decrement, l.t_release_s,
          l.fit_samples, lab.unloaded[i], u.omega_d_rad_s, u.zeta, u.zeta_log_decrement);
    }
    const Stats swl = MeanStd(wd_l), swu = MeanStd(wd_u), szl = MeanStd(z_l), szu = MeanStd(z_u);
    const AddedMassSolution pair = SolveAddedMass(MeanStd(wn_u).mean, MeanStd(wn_l).mean, 0.986);
    std::printf("%s: wd loaded %.4f (sd %.4f) lab %.4f; wd unloaded %.4f (sd %.4f) lab %.4f\n",
                lab.spring, swl.mean, swl.std, lab.wd_loaded, swu.mean, swu.std, lab.wd_unloaded);
    std::printf(
        "%s: zeta loaded %.4f (sd %.4f) lab %.4f+-%.4f; unloaded %.4f (sd %.4f) lab %.4f+-%.4f\n",
        lab.spring, szl.mean, szl.std, lab.zeta_loaded, lab.zeta_loaded_std, szu.mean, szu.std,
        lab.zeta_unloaded, lab.zeta_unloaded_std);
    std::printf("%s: k %.2f N/m (lab %.2f), m_c %.4f kg (lab %.4f)\n", lab.spring, pair.k_n_per_m,
                lab.k, pair.base_mass_kg, lab.mc);
    // Their omega_d is one period counted in whole samples at 200 Hz: its spread is one sample.
    const auto quantum = [](double wd) { return wd / (200.0 * 2.0 * std::numbers::pi / wd); };
    EXPECT_NEAR(swl.mean, lab.wd_loaded, quantum(lab.wd_loaded)) << lab.spring;
    EXPECT_NEAR(swu.mean, lab.wd_unloaded, quantum(lab.wd_unloaded)) << lab.spring;
    EXPECT_NEAR(szl.mean, lab.zeta_loaded, 2.0 * lab.zeta_loaded_std) << lab.spring;
    EXPECT_NEAR(szu.mean, lab.zeta_unloaded, 2.0 * lab.zeta_unloaded_std) << lab.spring;
    EXPECT_NEAR(pair.k_n_per_m, lab.k, 0.02 * lab.k) << lab.spring;
    EXPECT_NEAR(pair.base_mass_kg, lab.mc, 0.03 * lab.mc) << lab.spring;
  }
}

}  // namespace
}  // namespace vibid::ident
