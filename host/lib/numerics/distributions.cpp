// Incomplete gamma and beta by their power series and continued fractions (the split points are
// the usual ones: the series converges fast for x < a + 1, the fraction elsewhere), quantiles by
// bisection on a bracket that is widened until it holds p.
#include "vibid/numerics/distributions.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include "vibid/common/error.hpp"

namespace vibid::numerics {
namespace {

constexpr double kEps = 1e-15;
constexpr double kTiny = 1e-300;
constexpr int kMaxTerms = 10000;

double GammaSeries(double a, double x) {
  double term = 1.0 / a;
  double sum = term;
  for (int n = 1; n < kMaxTerms; ++n) {
    term *= x / (a + n);
    sum += term;
    if (std::fabs(term) < std::fabs(sum) * kEps) break;
  }
  return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// Q(a, x) = Γ(a, x)/Γ(a) by the modified Lentz method.
double GammaFractionQ(double a, double x) {
  double b = x + 1.0 - a;
  double c = 1.0 / kTiny;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < kMaxTerms; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::fabs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::fabs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::fabs(delta - 1.0) < kEps) break;
  }
  return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

double BetaFraction(double a, double b, double x) {
  const double qab = a + b;
  const double qap = a + 1.0;
  const double qam = a - 1.0;
  double c = 1.0;
  double d = 1.0 - qab * x / qap;
  if (std::fabs(d) < kTiny) d = kTiny;
  d = 1.0 / d;
  double h = d;
  for (int m = 1; m < kMaxTerms; ++m) {
    const int m2 = 2 * m;
    double aa = m * (b - m) * x / ((qam + m2) * (a + m2));
    d = 1.0 + aa * d;
    if (std::fabs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::fabs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    h *= d * c;
    aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
    d = 1.0 + aa * d;
    if (std::fabs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::fabs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::fabs(delta - 1.0) < kEps) break;
  }
  return h;
}

void RequireProbability(double p, const char* what) {
  Require(p > 0.0 && p < 1.0, std::string(what) + ": the probability must lie in (0, 1)");
}

void RequireDof(double dof, const char* what) {
  Require(std::isfinite(dof) && dof > 0.0,
          std::string(what) + ": the degrees of freedom must be positive");
}

// The q with cdf(q) = p, cdf increasing; the bracket [lo, hi] is widened until it holds p, then
// halved until it cannot shrink any further in double precision.
double Invert(const std::function<double(double)>& cdf, double p, double lo, double hi,
              bool lower_bounded) {
  while (cdf(hi) < p) hi = hi > 0.0 ? 2.0 * hi : 1.0;
  if (!lower_bounded) {
    while (cdf(lo) > p) lo = lo < 0.0 ? 2.0 * lo : -1.0;
  }
  for (int i = 0; i < 2200; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    if (cdf(mid) < p) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return 0.5 * (lo + hi);
}

// I_x(a, b) with y = 1 − x given separately: callers that know 1 − x without cancellation (the
// t and F distributions near their centre) keep its precision.
double Beta(double a, double b, double x, double y) {
  if (x <= 0.0) return 0.0;
  if (y <= 0.0) return 1.0;
  const double front = std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) +
                                a * std::log(x) + b * std::log(y));
  // The fraction converges fast for x < (a + 1)/(a + b + 2); use the symmetry elsewhere.
  if (x < (a + 1.0) / (a + b + 2.0)) return front * BetaFraction(a, b, x) / a;
  return 1.0 - front * BetaFraction(b, a, y) / b;
}

}  // namespace

double RegularizedGammaP(double a, double x) {
  Require(a > 0.0 && x >= 0.0, "incomplete gamma: a > 0 and x >= 0");
  if (x == 0.0) return 0.0;
  if (x < a + 1.0) return GammaSeries(a, x);
  return 1.0 - GammaFractionQ(a, x);
}

double RegularizedBeta(double a, double b, double x) {
  Require(a > 0.0 && b > 0.0 && x >= 0.0 && x <= 1.0, "incomplete beta: a, b > 0, 0 <= x <= 1");
  return Beta(a, b, x, 1.0 - x);
}

double NormalCdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

double StudentTCdf(double t, double dof) {
  RequireDof(dof, "Student's t");
  const double tail = 0.5 * Beta(0.5 * dof, 0.5, dof / (dof + t * t), t * t / (dof + t * t));
  return t >= 0.0 ? 1.0 - tail : tail;
}

double ChiSquareCdf(double x, double dof) {
  RequireDof(dof, "chi-square");
  return x <= 0.0 ? 0.0 : RegularizedGammaP(0.5 * dof, 0.5 * x);
}

double FCdf(double x, double dof1, double dof2) {
  RequireDof(dof1, "F");
  RequireDof(dof2, "F");
  const double denom = dof1 * x + dof2;
  return x <= 0.0 ? 0.0 : Beta(0.5 * dof1, 0.5 * dof2, dof1 * x / denom, dof2 / denom);
}

double NormalQuantile(double p) {
  RequireProbability(p, "normal quantile");
  return Invert(NormalCdf, p, -1.0, 1.0, false);
}

double StudentTQuantile(double p, double dof) {
  RequireProbability(p, "t quantile");
  RequireDof(dof, "t quantile");
  return Invert([dof](double t) { return StudentTCdf(t, dof); }, p, -1.0, 1.0, false);
}

double ChiSquareQuantile(double p, double dof) {
  RequireProbability(p, "chi-square quantile");
  RequireDof(dof, "chi-square quantile");
  return Invert([dof](double x) { return ChiSquareCdf(x, dof); }, p, 0.0, dof + 1.0, true);
}

double FQuantile(double p, double dof1, double dof2) {
  RequireProbability(p, "F quantile");
  RequireDof(dof1, "F quantile");
  RequireDof(dof2, "F quantile");
  return Invert([dof1, dof2](double x) { return FCdf(x, dof1, dof2); }, p, 0.0, 2.0, true);
}

}  // namespace vibid::numerics
