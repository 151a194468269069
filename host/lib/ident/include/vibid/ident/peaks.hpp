// Peak picking on an FRF magnitude (methods §5): local maxima above a threshold, refined by a
// cubic through the neighbouring lines, half-power points by interpolation and
// zeta = (omega_b - omega_a) / (2 omega_i). (One source writes the damping without the 2; this is
// the standard half-power form, exact for an isolated mode as zeta -> 0.)
#pragma once

#include <complex>
#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "vibid/ident/spectral.hpp"

namespace vibid::ident {

struct PeakOptions {
  /// Peaks below this fraction of the largest magnitude in the band are ignored.
  double threshold_fraction = 0.01;
  /// Band searched (Hz); max 0 means up to the last line.
  double freq_min_hz = 0.0;
  double freq_max_hz = 0.0;
  /// Keep at most this many peaks, the largest ones (0: all). Returned in frequency order.
  std::size_t max_peaks = 0;
  /// Warn when the half-power band spans fewer frequency lines than this.
  double min_lines_in_band = 3.0;

  void Validate() const;
};

struct Peak {
  std::size_t line = 0;  ///< Index of the largest sample.
  double freq_hz = 0.0;  ///< Refined by the cubic.
  double omega_rad_s = 0.0;
  double magnitude = 0.0;      ///< |H| at the refined peak.
  double omega_a_rad_s = 0.0;  ///< Half-power points.
  double omega_b_rad_s = 0.0;
  double zeta = 0.0;           ///< Half-power damping, exponential-window correction applied.
  double zeta_measured = 0.0;  ///< Before that correction.
  double lines_in_band = 0.0;  ///< (omega_b - omega_a) / line spacing.
  bool resolution_warning = false;
};

struct PeakResult {
  std::vector<Peak> peaks;
  std::vector<std::string> warnings;
};

/// Picks resonances from |H| sampled at uniform `freq_hz`. A local maximum counts as a resonance
/// only when |H| falls below its half-power level on both sides before rising above the peak;
/// so noise ripples and shoulders of other modes are not taken. `exp_window_tau_s` > 0 corrects
/// zeta for an exponential window.
PeakResult PickPeaks(const Eigen::Ref<const Eigen::VectorXd>& freq_hz,
                     const Eigen::Ref<const Eigen::VectorXd>& magnitude, const PeakOptions& options,
                     double exp_window_tau_s = 0.0);

/// Magnitude used for picking resonances in an FRF of any kind: the mobility magnitude (|H| times
/// or divided by omega as needed; for a viscously damped mode its peak sits at omega_n and its
/// half-power band is 2 zeta omega_n exactly) weighted by the coherence, so that lines dominated
/// by noise (low coherence, or amplified by the conversion from accelerance) do not pose as
/// resonances. `column` >= 0 picks one response; -1 sums all responses, so every mode any
/// response sees shows.
Eigen::VectorXd PickingMagnitude(const Frf& frf, int column);

/// Value of a uniformly sampled complex function at `freq_hz` by a cubic through the four nearest
/// lines (real and imaginary parts separately).
std::complex<double> InterpolateAt(const Eigen::Ref<const Eigen::VectorXd>& freq_hz,
                                   const Eigen::Ref<const Eigen::VectorXcd>& values, double at_hz);

}  // namespace vibid::ident
