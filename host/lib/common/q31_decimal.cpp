#include "vibid/common/q31_decimal.hpp"

#include <charconv>
#include <cmath>

namespace vibid {

double ShortestQ31Decimal(double value, double full_scale) {
  constexpr double kTwo31 = 2147483648.0;
  if (!(full_scale > 0.0) || !std::isfinite(value)) return value;
  // q x full_scale / 2^31 needs up to 55 bits, so the double in hand is q's value rounded: on the
  // grid within a hair (a decimated value, with fraction bits of its own, is not).
  const double exact = value / full_scale * kTwo31;
  const double q = std::nearbyint(exact);
  if (!(std::abs(exact - q) < 1e-6) || std::abs(q) > kTwo31) return value;
  char buf[64];
  for (int digits = 1; digits <= 17; ++digits) {
    const auto res =
        std::to_chars(buf, buf + sizeof buf, value, std::chars_format::general, digits);
    double back = 0.0;
    std::from_chars(buf, res.ptr, back);
    if (std::nearbyint(back / full_scale * kTwo31) == q) return back;
  }
  return value;
}

double ShortestFloat32Decimal(float value) {
  if (!std::isfinite(value)) return static_cast<double>(value);
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, value);
  double back = 0.0;
  std::from_chars(buf, res.ptr, back);
  return back;
}

}  // namespace vibid
