#include "vibid/ident/decay.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/QR>

#include "vibid/common/error.hpp"

namespace vibid::ident {

void DecayOptions::Validate() const {
  Require(end_fraction >= 0.0 && end_fraction < 1.0, "decay: end fraction must be in [0, 1)");
  Require(cycles >= 0, "decay: number of cycles must be >= 0");
  solver.Validate();
}

namespace {

// Linear part of the damped-sinusoid model for given (sigma, omega_d): columns
// exp(-sigma t) cos(omega_d t), exp(-sigma t) sin(omega_d t), 1.
Eigen::MatrixXd DecayBasis(const Eigen::VectorXd& t, double sigma, double omega_d) {
  Eigen::MatrixXd a(t.size(), 3);
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    const double e = std::exp(-sigma * t[i]);
    a(i, 0) = e * std::cos(omega_d * t[i]);
    a(i, 1) = e * std::sin(omega_d * t[i]);
    a(i, 2) = 1.0;
  }
  return a;
}

// The release ends the hold before the first crossing of the equilibrium. Its sample is found by
// walking back from that crossing while the record keeps rising away from the equilibrium (the
// first half cycle of a free decay is monotone) and is still more than 1 % of the pull below the
// largest excursion. Taking the largest sample of the hold instead puts the start anywhere on a
// noisy plateau, and a fit that includes part of the hold is no damped sinusoid (it read a growing
// one on a record held for a second). Stopping within 1 % of the pull may start the fit a sample
// after the true release: harmless, the model's amplitude and phase are free.
Eigen::Index FindRelease(const Eigen::VectorXd& dev, double max_dev) {
  const Eigen::Index n = dev.size();
  Eigen::Index big = 0;
  while (big < n && std::abs(dev[big]) < 0.5 * max_dev) ++big;
  const double side = dev[big] > 0.0 ? 1.0 : -1.0;
  Eigen::Index cross = big;
  while (cross < n && side * dev[cross] > 0.0) ++cross;
  Require(cross < n, "decay: the record never crosses its final position; no release found");
  double pull = 0.0;
  for (Eigen::Index i = big; i < cross; ++i) pull = std::max(pull, side * dev[i]);
  constexpr double kHoldFraction = 0.01;
  Eigen::Index release = cross - 1;
  while (release > big && side * dev[release - 1] > side * dev[release] &&
         side * dev[release] < (1.0 - kHoldFraction) * pull) {
    --release;
  }
  return release;
}

// Crossings after the release (they give the start period) and the peak of each half cycle (the
// envelope).
struct HalfCycles {
  std::vector<Eigen::Index> crossings;
  std::vector<double> peak_amp;
  std::vector<Eigen::Index> peak_idx;
};

HalfCycles FindHalfCycles(const Eigen::VectorXd& dev, Eigen::Index release) {
  HalfCycles hc;
  for (Eigen::Index i = release + 1; i < dev.size(); ++i) {
    if ((dev[i - 1] > 0.0) != (dev[i] > 0.0)) hc.crossings.push_back(i);
  }
  Require(hc.crossings.size() >= 4, "decay: fewer than two oscillation cycles after the release");
  Eigen::Index from = release;
  for (Eigen::Index c : hc.crossings) {
    Eigen::Index best = from;
    for (Eigen::Index i = from; i < c; ++i) {
      if (std::abs(dev[i]) > std::abs(dev[best])) best = i;
    }
    hc.peak_amp.push_back(std::abs(dev[best]));
    hc.peak_idx.push_back(best);
    from = c;
  }
  return hc;
}

// End of the fitted part: after the requested cycles, else where the envelope falls below
// end_fraction of the first peak, else the record's end.
Eigen::Index FitEnd(const HalfCycles& hc, Eigen::Index n, const DecayOptions& options) {
  if (options.cycles > 0) {
    const auto c = static_cast<std::size_t>(2 * options.cycles);
    Require(c < hc.crossings.size(), "decay: the record holds fewer than " +
                                         std::to_string(options.cycles) +
                                         " cycles after the release");
    return hc.crossings[c];
  }
  if (options.end_fraction > 0.0) {
    for (std::size_t k = 1; k < hc.peak_amp.size(); ++k) {
      if (hc.peak_amp[k] < options.end_fraction * hc.peak_amp[0]) return hc.peak_idx[k];
    }
  }
  return n;
}

// Start values for the fit over [release, end): omega_d from the crossings, sigma from the log
// decrement between same-sign peaks (two half cycles apart).
struct DecayStart {
  double omega_d0 = 0.0;
  double sigma0 = 0.0;
};

DecayStart StartFromCycles(const HalfCycles& hc, Eigen::Index end, double fs_hz, DecayResult& res) {
  std::vector<Eigen::Index> used_cross;
  for (Eigen::Index c : hc.crossings) {
    if (c < end) used_cross.push_back(c);
  }
  Require(used_cross.size() >= 2, "decay: fewer than one oscillation cycles in the fitted part");
  DecayStart start;
  const double half_periods = static_cast<double>(used_cross.size() - 1);
  start.omega_d0 = std::numbers::pi * half_periods * fs_hz /
                   static_cast<double>(used_cross.back() - used_cross.front());
  std::size_t last_peak = 0;
  for (std::size_t k = 0; k < hc.peak_idx.size(); ++k) {
    if (hc.peak_idx[k] < end) last_peak = k;
  }
  const std::size_t pairs = last_peak / 2;
  if (pairs >= 1 && hc.peak_amp[2 * pairs] > 0.0) {
    const double delta =
        std::log(hc.peak_amp[0] / hc.peak_amp[2 * pairs]) / static_cast<double>(pairs);
    res.zeta_log_decrement =
        delta / std::sqrt(4.0 * std::numbers::pi * std::numbers::pi + delta * delta);
    start.sigma0 = delta * start.omega_d0 / (2.0 * std::numbers::pi);
  }
  res.cycles = static_cast<int>(pairs);
  return start;
}

// Variable projection: the amplitude, phase and offset are linear once sigma and omega_d are
// fixed; LM moves p = [omega_d / omega_d0, sigma / omega_d0].
void FitDecay(const Eigen::VectorXd& y, double fs_hz, const DecayStart& start,
              const DecayOptions& options, DecayResult& res) {
  const Eigen::Index m = y.size();
  Eigen::VectorXd t(m);
  for (Eigen::Index i = 0; i < m; ++i) t[i] = static_cast<double>(i) / fs_hz;
  const double omega_d0 = start.omega_d0;
  const numerics::ResidualOnlyFunction f = [&](const Eigen::VectorXd& p, Eigen::VectorXd& r) {
    const double wd = p[0] * omega_d0;
    const double sg = p[1] * omega_d0;
    if (wd <= 0.0) return false;
    const Eigen::MatrixXd a = DecayBasis(t, sg, wd);
    const Eigen::VectorXd x = a.colPivHouseholderQr().solve(y);
    r = a * x - y;
    return true;
  };
  Eigen::VectorXd p(2);
  p << 1.0, std::max(start.sigma0, 0.0) / omega_d0;
  res.summary = numerics::LevenbergMarquardt(numerics::NumericDiff(f), p, options.solver);
  res.omega_d_rad_s = p[0] * omega_d0;
  res.sigma_per_s = p[1] * omega_d0;
  res.omega_n_rad_s = std::hypot(res.omega_d_rad_s, res.sigma_per_s);
  res.zeta = res.sigma_per_s / res.omega_n_rad_s;
  const Eigen::MatrixXd a = DecayBasis(t, res.sigma_per_s, res.omega_d_rad_s);
  const Eigen::VectorXd x = a.colPivHouseholderQr().solve(y);
  res.amplitude = std::hypot(x[0], x[1]);
  res.phase_rad = std::atan2(-x[1], x[0]);
  res.offset = x[2];
  res.rms_residual = std::sqrt((a * x - y).squaredNorm() / static_cast<double>(m));
}

}  // namespace

DecayResult AnalyzeDecay(const Eigen::Ref<const Eigen::VectorXd>& position, double fs_hz,
                         const DecayOptions& options) {
  options.Validate();
  Require(fs_hz > 0.0 && std::isfinite(fs_hz), "sample rate must be > 0");
  const Eigen::Index n = position.size();
  Require(n >= 32, "decay record is too short (" + std::to_string(n) + " samples)");
  Require(position.allFinite(), "decay record has non-finite samples");

  // Equilibrium from the last quarter, where the motion has died down the most.
  const Eigen::Index tail = std::max<Eigen::Index>(n / 4, 8);
  const double eq = position.tail(tail).mean();
  const Eigen::VectorXd dev = position.array() - eq;
  const double max_dev = dev.cwiseAbs().maxCoeff();
  Require(max_dev > 0.0, "decay record is constant: no motion");
  const Eigen::Index release = FindRelease(dev, max_dev);
  DecayResult res;
  res.release_index = static_cast<std::size_t>(release);
  res.t_release_s = static_cast<double>(release) / fs_hz;

  const HalfCycles half_cycles = FindHalfCycles(dev, release);
  const Eigen::Index end = FitEnd(half_cycles, n, options);
  const DecayStart start = StartFromCycles(half_cycles, end, fs_hz, res);
  res.fit_samples = static_cast<std::size_t>(end - release);
  FitDecay(position.segment(release, end - release), fs_hz, start, options, res);
  // A passive spring-mass cannot gain energy: a fit with zeta <= 0 means the fitted part is not a
  // free decay (a hold or a push inside it, or a drift larger than the decay), never a result.
  if (!(res.zeta > 0.0)) {
    std::ostringstream why;
    why << "decay: the fit gives zeta " << res.zeta
        << " <= 0 (a growing oscillation) over t = " << res.t_release_s << " s to "
        << static_cast<double>(end) / fs_hz
        << " s: that part of the record is not a free decay (rms residual " << res.rms_residual
        << ", " << 100.0 * res.rms_residual / res.amplitude
        << " % of the amplitude); check that the record holds still before one release and "
           "fit fewer cycles (--cycles)";
    throw InputError(why.str());
  }
  return res;
}

AddedMassSolution SolveAddedMass(double omega_unloaded_rad_s, double omega_loaded_rad_s,
                                 double added_kg) {
  Require(omega_unloaded_rad_s > 0.0 && omega_loaded_rad_s > 0.0,
          "natural frequencies must be > 0");
  Require(added_kg > 0.0, "added mass must be > 0");
  Require(omega_loaded_rad_s < omega_unloaded_rad_s,
          "the loaded record must oscillate slower than the unloaded one");
  const double wl2 = omega_loaded_rad_s * omega_loaded_rad_s;
  const double wu2 = omega_unloaded_rad_s * omega_unloaded_rad_s;
  AddedMassSolution s;
  s.base_mass_kg = added_kg * wl2 / (wu2 - wl2);
  s.k_n_per_m = s.base_mass_kg * wu2;
  return s;
}

}  // namespace vibid::ident
