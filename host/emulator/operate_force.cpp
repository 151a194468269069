#include "operate_force.hpp"

#include <algorithm>
#include <cmath>

#include "vibid/dob/lowpass.hpp"

namespace vibid::emu {

void BandLimitedNoise::Start(double rms, double band_hz, double fs_hz) {
  band_hz_ = std::min(band_hz, kMaxBandFraction * fs_hz);
  sos_ = dob::ButterworthLowpass(4, band_hz_, fs_hz);
  delays_.assign(sos_.size(), {0.0, 0.0});
  // Noise gain: the sum of the squared impulse response. The slowest pole pair (damping
  // sin(pi/8) = 0.38 of the edge) decays by e^-1 in about 0.4 edge periods, so 200 edge
  // periods leave far less than 1e-12 of it.
  const auto samples = static_cast<long>(std::ceil(200.0 * fs_hz / band_hz_));
  double energy = 0.0;
  for (long i = 0; i < samples; ++i) {
    const double h = Filter(i == 0 ? 1.0 : 0.0);
    energy += h * h;
  }
  gain_ = energy > 0.0 ? rms / std::sqrt(energy) : 0.0;
  delays_.assign(sos_.size(), {0.0, 0.0});
}

double BandLimitedNoise::Next(double white) { return gain_ * Filter(white); }

double BandLimitedNoise::Filter(double white) {
  double x = white;
  for (std::size_t i = 0; i < sos_.size(); ++i) {
    const dob::SosSection& s = sos_[i];
    auto& z = delays_[i];
    const double y = s.b0 * x + z[0];
    z[0] = s.b1 * x - s.a1 * y + z[1];
    z[1] = s.b2 * x - s.a2 * y;
    x = y;
  }
  return x;
}

}  // namespace vibid::emu
