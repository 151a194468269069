#include "vibid/ident/peaks.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "vibid/common/error.hpp"

namespace vibid::ident {

void PeakOptions::Validate() const {
  Require(threshold_fraction >= 0.0 && threshold_fraction < 1.0,
          "peaks: threshold fraction must be in [0, 1)");
  Require(freq_min_hz >= 0.0 && freq_max_hz >= 0.0, "peaks: band limits must be >= 0");
  Require(freq_max_hz == 0.0 || freq_max_hz > freq_min_hz,
          "peaks: band maximum must exceed the minimum");
  Require(min_lines_in_band >= 0.0, "peaks: minimum lines in the half-power band must be >= 0");
}

namespace {

// Least-squares cubic through (x_k, y_k); returns the abscissa of its maximum within [lo, hi] and
// the value there, or false when the cubic has no interior maximum.
bool CubicMaximum(const double* x, const double* y, int count, double lo, double hi, double& x_max,
                  double& y_max) {
  // Normal equations of a 4-coefficient polynomial; count is 4 or 5 and x is O(1), so this is
  // well conditioned.
  double ata[4][4] = {};
  double aty[4] = {};
  for (int k = 0; k < count; ++k) {
    const double p[4] = {1.0, x[k], x[k] * x[k], x[k] * x[k] * x[k]};
    for (int r = 0; r < 4; ++r) {
      aty[r] += p[r] * y[k];
      for (int c = 0; c < 4; ++c) ata[r][c] += p[r] * p[c];
    }
  }
  // Gaussian elimination with partial pivoting.
  int order[4] = {0, 1, 2, 3};
  for (int col = 0; col < 4; ++col) {
    int piv = col;
    for (int r = col + 1; r < 4; ++r) {
      if (std::abs(ata[order[r]][col]) > std::abs(ata[order[piv]][col])) piv = r;
    }
    std::swap(order[col], order[piv]);
    const double d = ata[order[col]][col];
    if (std::abs(d) < 1e-14) return false;
    for (int r = col + 1; r < 4; ++r) {
      const double f = ata[order[r]][col] / d;
      for (int c = col; c < 4; ++c) ata[order[r]][c] -= f * ata[order[col]][c];
      aty[order[r]] -= f * aty[order[col]];
    }
  }
  double coef[4];
  for (int col = 3; col >= 0; --col) {
    double s = aty[order[col]];
    for (int c = col + 1; c < 4; ++c) s -= ata[order[col]][c] * coef[c];
    coef[col] = s / ata[order[col]][col];
  }
  const auto value = [&](double t) {
    return coef[0] + t * (coef[1] + t * (coef[2] + t * coef[3]));
  };
  // Stationary points: 3 c3 t^2 + 2 c2 t + c1 = 0, maximum where 6 c3 t + 2 c2 < 0.
  const double qa = 3.0 * coef[3];
  const double qb = 2.0 * coef[2];
  const double qc = coef[1];
  double roots[2];
  int nroots = 0;
  if (std::abs(qa) < 1e-14 * (std::abs(qb) + std::abs(qc))) {
    if (qb != 0.0) roots[nroots++] = -qc / qb;
  } else {
    const double disc = qb * qb - 4.0 * qa * qc;
    if (disc >= 0.0) {
      const double sq = std::sqrt(disc);
      roots[nroots++] = (-qb + sq) / (2.0 * qa);
      roots[nroots++] = (-qb - sq) / (2.0 * qa);
    }
  }
  bool found = false;
  for (int k = 0; k < nroots; ++k) {
    const double t = roots[k];
    if (t < lo || t > hi || 6.0 * coef[3] * t + 2.0 * coef[2] >= 0.0) continue;
    if (!found || value(t) > y_max) {
      x_max = t;
      y_max = value(t);
      found = true;
    }
  }
  return found;
}

using VectorRef = Eigen::Ref<const Eigen::VectorXd>;

// Maximum near line i from a cubic in units of lines around it: offset in lines and magnitude,
// or the sample itself when the cubic has no maximum above it within one line.
void RefineMaximum(const VectorRef& magnitude, Eigen::Index i0, Eigen::Index i1, Eigen::Index i,
                   double& x_peak, double& m_peak) {
  const double m = magnitude[i];
  const Eigen::Index lo = std::max(i0, i - 2);
  const Eigen::Index hi = std::min(i1, i + 2);
  double xs[5];
  double ys[5];
  int count = 0;
  for (Eigen::Index k = lo; k <= hi; ++k, ++count) {
    xs[count] = static_cast<double>(k - i);
    ys[count] = magnitude[k];
  }
  x_peak = 0.0;
  m_peak = m;
  if (count < 4 || !CubicMaximum(xs, ys, count, -1.0, 1.0, x_peak, m_peak) || m_peak < m) {
    x_peak = 0.0;
    m_peak = m;
  }
}

// Walks outwards from line i to the half-power crossings fa < fb; false when a higher sample (or
// the band edge) comes first, so that this is not an isolated resonance (a ripple on another
// mode's flank).
bool HalfPowerCrossings(const VectorRef& freq_hz, const VectorRef& magnitude, Eigen::Index i0,
                        Eigen::Index i1, Eigen::Index i, double half, double df, double& fa,
                        double& fb) {
  const double m = magnitude[i];
  fa = 0.0;
  Eigen::Index k = i - 1;
  while (true) {
    if (k < i0 || magnitude[k] > m) return false;
    if (magnitude[k] < half) {
      fa = freq_hz[k] + (half - magnitude[k]) / (magnitude[k + 1] - magnitude[k]) * df;
      break;
    }
    --k;
  }
  fb = 0.0;
  k = i + 1;
  while (true) {
    if (k > i1 || magnitude[k] > m) return false;
    if (magnitude[k] < half) {
      fb = freq_hz[k] - (half - magnitude[k]) / (magnitude[k - 1] - magnitude[k]) * df;
      return true;
    }
    ++k;
  }
}

// The `max_peaks` largest (0: all), in frequency order.
void KeepLargest(std::size_t max_peaks, std::vector<Peak>& found) {
  if (max_peaks > 0 && found.size() > max_peaks) {
    std::sort(found.begin(), found.end(),
              [](const Peak& a, const Peak& b) { return a.magnitude > b.magnitude; });
    found.resize(max_peaks);
    std::sort(found.begin(), found.end(),
              [](const Peak& a, const Peak& b) { return a.freq_hz < b.freq_hz; });
  }
}

std::vector<std::string> PeakWarnings(const std::vector<Peak>& found, double exp_window_tau_s) {
  std::vector<std::string> warnings;
  for (const Peak& p : found) {
    if (p.resolution_warning) {
      std::ostringstream w;
      w << "peak at " << p.freq_hz << " Hz: half-power band spans only " << p.lines_in_band
        << " lines; damping is unreliable (use longer records or a curve fit)";
      warnings.push_back(w.str());
    }
    if (exp_window_tau_s > 0.0 && p.zeta <= 0.0) {
      std::ostringstream w;
      w << "peak at " << p.freq_hz
        << " Hz: the exponential window's damping exceeds the measured one";
      warnings.push_back(w.str());
    }
  }
  return warnings;
}

}  // namespace

PeakResult PickPeaks(const Eigen::Ref<const Eigen::VectorXd>& freq_hz,
                     const Eigen::Ref<const Eigen::VectorXd>& magnitude, const PeakOptions& options,
                     double exp_window_tau_s) {
  options.Validate();
  Require(freq_hz.size() == magnitude.size(), "peaks: frequency and magnitude differ in length");
  Require(freq_hz.size() >= 5, "peaks: at least 5 frequency lines are needed");
  Require(magnitude.allFinite(), "peaks: magnitude has non-finite values");
  const Eigen::Index n = freq_hz.size();
  const double df = (freq_hz[n - 1] - freq_hz[0]) / static_cast<double>(n - 1);
  Eigen::Index i0 = 0;
  while (i0 < n && freq_hz[i0] < options.freq_min_hz) ++i0;
  Eigen::Index i1 = n - 1;
  if (options.freq_max_hz > 0.0) {
    while (i1 > 0 && freq_hz[i1] > options.freq_max_hz) --i1;
  }
  Require(i1 - i0 >= 4, "peaks: the band holds fewer than 5 frequency lines");
  const double band_max = magnitude.segment(i0, i1 - i0 + 1).maxCoeff();
  const double threshold = options.threshold_fraction * band_max;

  PeakResult result;
  std::vector<Peak> found;
  for (Eigen::Index i = i0 + 1; i < i1; ++i) {
    const double m = magnitude[i];
    if (!(m > magnitude[i - 1] && m >= magnitude[i + 1] && m >= threshold && m > 0.0)) continue;
    double x_peak = 0.0;
    double m_peak = m;
    RefineMaximum(magnitude, i0, i1, i, x_peak, m_peak);
    const double half = m_peak / std::numbers::sqrt2;
    double fa = 0.0;
    double fb = 0.0;
    if (!HalfPowerCrossings(freq_hz, magnitude, i0, i1, i, half, df, fa, fb)) continue;
    Peak p;
    p.line = static_cast<std::size_t>(i);
    p.freq_hz = freq_hz[i] + x_peak * df;
    p.omega_rad_s = 2.0 * std::numbers::pi * p.freq_hz;
    p.magnitude = m_peak;
    p.omega_a_rad_s = 2.0 * std::numbers::pi * fa;
    p.omega_b_rad_s = 2.0 * std::numbers::pi * fb;
    p.zeta_measured = (p.omega_b_rad_s - p.omega_a_rad_s) / (2.0 * p.omega_rad_s);
    p.zeta = CorrectExponentialWindowDamping(p.zeta_measured, p.omega_rad_s, exp_window_tau_s);
    p.lines_in_band = (fb - fa) / df;
    p.resolution_warning = p.lines_in_band < options.min_lines_in_band;
    found.push_back(p);
  }
  KeepLargest(options.max_peaks, found);
  result.warnings = PeakWarnings(found, exp_window_tau_s);
  result.peaks = std::move(found);
  return result;
}

Eigen::VectorXd PickingMagnitude(const Frf& frf, int column) {
  Require(column < 0 || static_cast<std::size_t>(column) < frf.responses(),
          "response column out of range");
  const int power = frf.quantity == Quantity::kDisplacement ? 1
                    : frf.quantity == Quantity::kVelocity   ? 0
                                                            : -1;
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(frf.h.rows());
  for (Eigen::Index j = 0; j < frf.h.cols(); ++j) {
    if (column >= 0 && j != column) continue;
    for (Eigen::Index i = 0; i < frf.h.rows(); ++i) {
      const double w = 2.0 * std::numbers::pi * frf.freq_hz[i];
      const double scale = power == 1 ? w : power == -1 ? (w > 0.0 ? 1.0 / w : 0.0) : 1.0;
      sum[i] += std::abs(frf.h(i, j)) * scale * std::clamp(frf.coherence(i, j), 0.0, 1.0);
    }
  }
  return sum;
}

std::complex<double> InterpolateAt(const Eigen::Ref<const Eigen::VectorXd>& freq_hz,
                                   const Eigen::Ref<const Eigen::VectorXcd>& values, double at_hz) {
  const Eigen::Index n = freq_hz.size();
  Require(n >= 4 && values.size() == n, "interpolation needs at least 4 lines");
  const double df = (freq_hz[n - 1] - freq_hz[0]) / static_cast<double>(n - 1);
  const double pos = (at_hz - freq_hz[0]) / df;
  auto base = static_cast<Eigen::Index>(std::floor(pos)) - 1;
  base = std::clamp<Eigen::Index>(base, 0, n - 4);
  std::complex<double> sum(0.0, 0.0);
  for (Eigen::Index a = 0; a < 4; ++a) {
    double w = 1.0;
    for (Eigen::Index b = 0; b < 4; ++b) {
      if (b != a) w *= (pos - static_cast<double>(base + b)) / static_cast<double>(a - b);
    }
    sum += w * values[base + a];
  }
  return sum;
}

}  // namespace vibid::ident
