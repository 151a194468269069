#include "vibid/ident/decay.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/QR>

#include "vibid/common/error.hpp"
#include "vibid/ident/intervals.hpp"

namespace vibid::ident {

void DecayOptions::Validate() const {
  Require(end_fraction >= 0.0 && end_fraction < 1.0, "decay: end fraction must be in [0, 1)");
  Require(cycles >= 0, "decay: number of cycles must be >= 0");
  solver.Validate();
}

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

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

// Samples within this fraction of the largest excursion from the final position count as on it:
// they belong to neither side. A cart held by friction sits exactly on its final position (an
// encoder's count repeated), and a sign test on exact zeros, or on the last bits a unit's factor
// leaves, would count crossings for one sign of the data that the other sign does not.
constexpr double kZeroBand = 1e-9;

int SideOf(double u) { return u > kZeroBand ? 1 : u < -kZeroBand ? -1 : 0; }

// The release ends the hold before the first crossing of the equilibrium. Its sample is found by
// walking back from that crossing while the record keeps rising away from the equilibrium (the
// first half cycle of a free decay is monotone) and is still more than 1 % of the pull below the
// largest excursion. Taking the largest sample of the hold instead puts the start anywhere on a
// noisy plateau, and a fit that includes part of the hold is no damped sinusoid (it read a growing
// one on a record held for a second). Stopping within 1 % of the pull may start the fit a sample
// after the true release: harmless, the model's amplitude and phase are free. `u` is the record's
// deviation from its final position over its largest excursion (so |u| <= 1, whatever the unit).
Eigen::Index FindRelease(const Eigen::VectorXd& u) {
  const Eigen::Index n = u.size();
  Eigen::Index big = 0;
  while (big < n && std::abs(u[big]) < 0.5) ++big;
  const int side = SideOf(u[big]);
  Eigen::Index cross = big;
  while (cross < n && SideOf(u[cross]) != -side) ++cross;
  Require(cross < n, "decay: the record never crosses its final position; no release found");
  double pull = 0.0;
  for (Eigen::Index i = big; i < cross; ++i) pull = std::max(pull, side * u[i]);
  constexpr double kHoldFraction = 0.01;
  Eigen::Index release = cross - 1;
  while (release > big && side * u[release - 1] > side * u[release] &&
         side * u[release] < (1.0 - kHoldFraction) * pull) {
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

// A crossing is the first sample on the other side; samples on the final position itself (within
// kZeroBand) belong to the side the motion came from.
HalfCycles FindHalfCycles(const Eigen::VectorXd& dev, Eigen::Index release) {
  HalfCycles hc;
  int last = SideOf(dev[release]);
  for (Eigen::Index i = release + 1; i < dev.size(); ++i) {
    const int side = SideOf(dev[i]);
    if (side == 0) continue;
    if (last != 0 && side != last) hc.crossings.push_back(i);
    last = side;
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

// Friction from the half cycles. Peak-to-peak spans s_k = |p_k| + |p_{k+1}| of consecutive peaks
// (opposite signs) do not depend on where the record's final position lies, which friction leaves
// anywhere within F / k of the spring's equilibrium; they follow the peaks' recurrence,
// s_{k+1} = rho s_k - 2 d, read by least squares (u: the record over its largest excursion).
DecayFriction ReadFriction(const Eigen::VectorXd& u, const HalfCycles& hc, double fs_hz) {
  DecayFriction f;
  constexpr double kFrictionEndFraction = 0.1;  // below it, the encoder's steps and noise
  std::vector<double> peaks;
  for (std::size_t k = 0; k < hc.peak_idx.size(); ++k) {
    if (hc.peak_amp[k] < kFrictionEndFraction * hc.peak_amp[0]) break;
    peaks.push_back(std::abs(u[hc.peak_idx[k]]));
  }
  std::vector<double> span;
  for (std::size_t k = 0; k + 1 < peaks.size(); ++k) span.push_back(peaks[k] + peaks[k + 1]);
  if (span.size() < 5) {
    f.note = "fewer than 6 half cycles above a tenth of the first: friction not checked";
    return f;
  }
  const auto n = static_cast<Eigen::Index>(span.size() - 1);
  Eigen::VectorXd x(n), y(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    x[k] = span[static_cast<std::size_t>(k)];
    y[k] = span[static_cast<std::size_t>(k) + 1];
  }
  const double xm = x.mean();
  const double ym = y.mean();
  const double sxx = (x.array() - xm).square().sum();
  if (!(sxx > 0.0)) {
    f.note = "the half cycles do not change in amplitude: friction not checked";
    return f;
  }
  const double rho = ((x.array() - xm) * (y.array() - ym)).sum() / sxx;
  const double intercept = ym - rho * xm;
  const double dof = static_cast<double>(n - 2);
  const double s2 = (y.array() - intercept - rho * x.array()).square().sum() / dof;
  const double se_intercept = std::sqrt(s2 * (1.0 / static_cast<double>(n) + xm * xm / sxx));
  f.checked = true;
  f.half_cycles = static_cast<int>(n);
  f.drop_per_half_cycle = -0.5 * intercept;
  f.drop_ci95 = 0.5 * StudentT95(dof) * se_intercept;
  f.friction_over_k = f.drop_per_half_cycle / (1.0 + std::clamp(rho, 0.0, 1.0));
  const auto zeta_of = [](double ratio) {
    const double delta = std::log(ratio);
    return delta / std::sqrt(std::numbers::pi * std::numbers::pi + delta * delta);
  };
  f.zeta_viscous = rho < 1.0 && rho > 0.0 ? zeta_of(1.0 / rho) : kNaN;
  // Half-cycle damping over the first and the last third (at least two half cycles each).
  const std::size_t third = std::max<std::size_t>(2, span.size() / 3);
  double first = 0.0;
  double last = 0.0;
  for (std::size_t k = 0; k < third; ++k) {
    first += zeta_of(span[k] / span[k + 1]) / static_cast<double>(third);
    last +=
        zeta_of(span[span.size() - 2 - k] / span[span.size() - 1 - k]) / static_cast<double>(third);
  }
  f.zeta_first = first;
  f.zeta_last = last;
  // Two cycles' crossings at each end of the read span.
  std::vector<Eigen::Index> cross(hc.crossings.begin(),
                                  hc.crossings.begin() + static_cast<std::ptrdiff_t>(std::min(
                                                             hc.crossings.size(), peaks.size())));
  if (cross.size() >= 5) {
    const auto omega = [&](Eigen::Index a, Eigen::Index b) {
      return 2.0 * std::numbers::pi * fs_hz / static_cast<double>(b - a);
    };
    f.omega_first_rad_s = omega(cross[0], cross[4]) * 2.0;
    f.omega_last_rad_s = omega(cross[cross.size() - 5], cross.back()) * 2.0;
  }
  f.detected = f.drop_per_half_cycle - f.drop_ci95 > 0.0 && f.zeta_last >= kFrictionGrowth * first;
  return f;
}

// What the decay says beside its numbers: friction named, and the two damping estimates when they
// disagree.
std::vector<std::string> Cautions(const DecayResult& r) {
  std::vector<std::string> out;
  char text[900];
  const DecayFriction& f = r.friction;
  if (f.detected) {
    const double drop = f.drop_per_half_cycle;
    int n = std::snprintf(
        text, sizeof text,
        "friction: the damping per half cycle grows from %.3g to %.3g as the amplitude falls, "
        "which a viscous damper cannot do: dry (Coulomb) friction takes %.4g (+- %.2g) of the "
        "position's unit off every half cycle (F/k = %.4g). zeta %.4g is a purely viscous fit's "
        "average over the amplitudes it spans: it depends on the pull and on --cycles and is no "
        "property of the rig",
        f.zeta_first, f.zeta_last, drop, f.drop_ci95, f.friction_over_k, r.zeta);
    if (std::isfinite(f.zeta_viscous)) {
      n += std::snprintf(text + n, sizeof text - static_cast<std::size_t>(n),
                         "; viscous + Coulomb over %d half cycles: viscous part zeta_v %.4g",
                         f.half_cycles, f.zeta_viscous);
    } else {
      n += std::snprintf(text + n, sizeof text - static_cast<std::size_t>(n),
                         "; viscous + Coulomb over %d half cycles: no viscous part resolved "
                         "beside the friction",
                         f.half_cycles);
    }
    if (f.omega_first_rad_s > 0.0 &&
        std::abs(f.omega_last_rad_s - f.omega_first_rad_s) > 0.02 * f.omega_first_rad_s) {
      std::snprintf(text + n, sizeof text - static_cast<std::size_t>(n),
                    "; the frequency moves from %.4g to %.4g rad/s as it slows (the friction "
                    "holds the cart near its turning points)",
                    f.omega_first_rad_s, f.omega_last_rad_s);
    }
    out.emplace_back(text);
  }
  if (r.zeta_log_decrement > 0.0 &&
      std::abs(r.zeta - r.zeta_log_decrement) >
          kDampingEstimatesGap * std::max(r.zeta, r.zeta_log_decrement)) {
    std::snprintf(
        text, sizeof text,
        "the two damping estimates disagree: the fit gives zeta %.4g, the log decrement "
        "of its peaks over %d cycle(s) %.4g (%.0f %% apart): the decay is not the "
        "exponential a viscous damper gives%s",
        r.zeta, r.cycles, r.zeta_log_decrement,
        100.0 * std::abs(r.zeta - r.zeta_log_decrement) / std::min(r.zeta, r.zeta_log_decrement),
        f.detected ? " (friction, above)" : "");
    out.emplace_back(text);
  }
  return out;
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
  // Everything below reads the record over its largest excursion: the same samples in another
  // unit or with the other sign give the same crossings, peaks and fit.
  const double max_dev = (position.array() - eq).abs().maxCoeff();
  Require(max_dev > 0.0, "decay record is constant: no motion");
  const Eigen::VectorXd dev = (position.array() - eq) / max_dev;
  const Eigen::Index release = FindRelease(dev);
  DecayResult res;
  res.release_index = static_cast<std::size_t>(release);
  res.t_release_s = static_cast<double>(release) / fs_hz;

  const HalfCycles half_cycles = FindHalfCycles(dev, release);
  const Eigen::Index end = FitEnd(half_cycles, n, options);
  const DecayStart start = StartFromCycles(half_cycles, end, fs_hz, res);
  res.fit_samples = static_cast<std::size_t>(end - release);
  FitDecay(dev.segment(release, end - release), fs_hz, start, options, res);
  res.amplitude *= max_dev;
  res.offset = eq + res.offset * max_dev;
  res.rms_residual *= max_dev;
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
  res.friction = ReadFriction(dev, half_cycles, fs_hz);
  res.friction.drop_per_half_cycle *= max_dev;
  res.friction.drop_ci95 *= max_dev;
  res.friction.friction_over_k *= max_dev;
  res.cautions = Cautions(res);
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
