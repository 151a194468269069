#include "vibid/dob/lowpass.hpp"

#include <cmath>
#include <numbers>
#include <string>

#include "vibid/common/error.hpp"

namespace vibid::dob {

std::vector<SosSection> ButterworthLowpass(int order, double cutoff_hz, double fs_hz) {
  Require(order >= 1, "low-pass order must be >= 1, got " + std::to_string(order));
  Require(std::isfinite(fs_hz) && fs_hz > 0.0, "sample rate must be > 0");
  Require(std::isfinite(cutoff_hz) && cutoff_hz > 0.0 && cutoff_hz < fs_hz / 2.0,
          "low-pass cut-off must lie between 0 and fs/2 = " + std::to_string(fs_hz / 2.0) +
              " Hz, got " + std::to_string(cutoff_hz));
  const double wc = 2.0 * std::numbers::pi * cutoff_hz;
  Zpk analog;
  for (int k = 1; k <= order; ++k) {
    const double angle = std::numbers::pi * (2.0 * k + order - 1.0) / (2.0 * order);
    analog.poles.push_back(wc * Complex(std::cos(angle), std::sin(angle)));
  }
  analog.gain = std::pow(wc, order);
  return ZpkToSos(TustinZpk(analog, fs_hz, wc));
}

Eigen::VectorXd FiltFilt(const std::vector<SosSection>& sos,
                         const Eigen::Ref<const Eigen::VectorXd>& x) {
  Eigen::Index taps = 2 * static_cast<Eigen::Index>(sos.size()) + 1;
  // scipy drops one tap per section whose b2 and a2 are both zero (first-order sections).
  Eigen::Index b2_zero = 0, a2_zero = 0;
  for (const SosSection& s : sos) {
    b2_zero += s.b2 == 0.0;
    a2_zero += s.a2 == 0.0;
  }
  taps -= std::min(b2_zero, a2_zero);
  const Eigen::Index pad = 3 * taps;
  const Eigen::Index n = x.size();
  Require(n > pad, "zero-phase filtering needs more than " + std::to_string(pad) +
                       " samples, got " + std::to_string(n));
  Eigen::VectorXd ext(n + 2 * pad);
  for (Eigen::Index i = 0; i < pad; ++i) {
    ext[i] = 2.0 * x[0] - x[pad - i];
    ext[n + pad + i] = 2.0 * x[n - 1] - x[n - 2 - i];
  }
  ext.segment(pad, n) = x;
  Eigen::VectorXd forward = FilterSos(sos, ext, SosStart::kSteadyState);
  Eigen::VectorXd reversed = forward.reverse();
  Eigen::VectorXd backward = FilterSos(sos, reversed, SosStart::kSteadyState).reverse();
  return backward.segment(pad, n);
}

}  // namespace vibid::dob
