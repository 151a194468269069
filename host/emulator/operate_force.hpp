// The operate scenario's force: band-limited Gaussian noise, as a rig in operation is driven
// (traffic, a machine's process, wind: broadband up to some frequency, nothing above).
#pragma once

#include <array>
#include <vector>

#include "vibid/dob/discretize.hpp"

namespace vibid::emu {

/// White Gaussian samples through a 4th-order Butterworth low-pass (dob::ButterworthLowpass:
/// flat below the band edge, -3 dB at it, -24 dB at twice it, -80 dB a decade beyond), scaled so
/// that the output's RMS is the one asked for (the filter's noise gain, the sum of its squared
/// impulse response, is divided out).
class BandLimitedNoise {
 public:
  /// The highest band edge, as a fraction of the sample rate: the edge asked for is lowered to
  /// it (the Butterworth's Tustin map needs the edge below half the rate; 0.4 keeps its pass
  /// band as designed).
  static constexpr double kMaxBandFraction = 0.4;

  /// Resets the filter. @p rms in the output's unit, @p band_hz > 0, @p fs_hz the sample rate.
  void Start(double rms, double band_hz, double fs_hz);
  /// The next sample, from one standard normal draw.
  double Next(double white);
  /// The band edge in use (Hz): the one asked for, or kMaxBandFraction of the rate.
  double band_hz() const { return band_hz_; }

 private:
  double Filter(double x);  // the unscaled cascade

  std::vector<dob::SosSection> sos_;
  std::vector<std::array<double, 2>> delays_;  // direct form II transposed, per section
  double gain_ = 0.0;
  double band_hz_ = 0.0;
};

}  // namespace vibid::emu
