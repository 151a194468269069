// A force channel that is a sine (a rotating unbalance at the motor's speed, a shaker's tone): no
// hammer test. Its FRF holds the rig at that one frequency only; elsewhere H1 is noise over noise,
// and the peak at the force's own frequency is the force's, not a mode of the rig.
#pragma once

#include <string>

#include <Eigen/Core>

namespace vibid::ident {

struct HarmonicForce {
  /// At least kHarmonicShare of the force's power (about its mean, DC aside) lies within
  /// kHarmonicHalfWidthLines lines of its largest line, in a Hann-windowed Welch spectrum.
  bool harmonic = false;
  double freq_hz = 0.0;  ///< The largest line's frequency.
  double share = 0.0;    ///< The share of the power near it.
  std::string description;
};

inline constexpr double kHarmonicShare = 0.8;
inline constexpr int kHarmonicHalfWidthLines = 3;

HarmonicForce CheckHarmonicForce(const Eigen::Ref<const Eigen::VectorXd>& force, double fs_hz);

}  // namespace vibid::ident
