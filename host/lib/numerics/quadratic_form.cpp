// Lugannani–Rice for Q = Σ wᵢ (zᵢ + δᵢ)²: cumulant generating function
// K(s) = Σ [−½ log(1 − 2 s wᵢ) + wᵢ δᵢ² s / (1 − 2 s wᵢ)], s < 1/(2 max w).
#include "vibid/numerics/quadratic_form.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "vibid/common/error.hpp"
#include "vibid/numerics/distributions.hpp"

namespace vibid::numerics {

namespace {

struct Cumulants {
  double k0 = 0.0;  // K(s)
  double k1 = 0.0;  // K'(s)
  double k2 = 0.0;  // K''(s)
};

Cumulants At(const Eigen::VectorXd& w, const Eigen::VectorXd& d2, double s) {
  Cumulants c;
  for (Eigen::Index i = 0; i < w.size(); ++i) {
    const double a = 1.0 - 2.0 * s * w(i);
    c.k0 += -0.5 * std::log(a) + w(i) * d2(i) * s / a;
    c.k1 += w(i) / a + w(i) * d2(i) / (a * a);
    c.k2 += 2.0 * w(i) * w(i) / (a * a) + 4.0 * w(i) * w(i) * d2(i) / (a * a * a);
  }
  return c;
}

}  // namespace

double QuadraticFormTail(const Eigen::VectorXd& weights, const Eigen::VectorXd& noncentrality,
                         double h) {
  Require(weights.size() >= 1 && weights.size() == noncentrality.size() && weights.minCoeff() > 0.0,
          "quadratic form: positive weights, one noncentrality each");
  Require(std::isfinite(h) && h > 0.0, "quadratic form: the threshold must be positive");
  const Eigen::VectorXd d2 = noncentrality.array().square();
  const double mean = (weights.array() * (1.0 + d2.array())).sum();
  // The saddlepoint ŝ solves K'(ŝ) = h; K' increases from 0 (s → −∞) to ∞ (s → 1/(2 max w)).
  const double s_max = 0.5 / weights.maxCoeff();
  double lo = 0.0;
  double hi = 0.0;
  if (h > mean) {
    hi = s_max;
  } else {
    lo = -s_max;
    while (At(weights, d2, lo).k1 > h) lo *= 2.0;
  }
  // Newton from the bracket's middle, kept inside the bracket (K' is increasing and convex).
  double s = 0.5 * (lo + hi);
  for (int it = 0; it < 200; ++it) {
    const Cumulants c = At(weights, d2, s);
    (c.k1 > h ? hi : lo) = s;
    double next = s - (c.k1 - h) / c.k2;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - s) <= 1e-14 * std::max(std::abs(s), 1e-300) || hi - lo <= 1e-15 * s_max) {
      s = next;
      break;
    }
    s = next;
  }
  const Cumulants c = At(weights, d2, s);
  const double w2 = 2.0 * (s * h - c.k0);
  // Near the mean (ŝ → 0) the formula's two terms cancel: the normal approximation there.
  if (std::abs(s) * std::sqrt(c.k2) < 1e-4 || w2 <= 0.0) {
    const Cumulants c0 = At(weights, d2, 0.0);
    return 1.0 - NormalCdf((h - c0.k1) / std::sqrt(c0.k2));
  }
  const double w = std::copysign(std::sqrt(w2), s);
  const double u = s * std::sqrt(c.k2);
  const double phi = std::exp(-0.5 * w * w) / std::sqrt(2.0 * std::numbers::pi);
  const double tail = (w > 0.0 ? NormalCdf(-w) : 1.0 - NormalCdf(w)) + phi * (1.0 / u - 1.0 / w);
  return std::clamp(tail, 0.0, 1.0);
}

}  // namespace vibid::numerics
