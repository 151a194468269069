#include "vibid/numerics/polynomial.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>

#include "vibid/common/error.hpp"

namespace vibid::numerics {

Complex EvaluatePolynomial(Eigen::Ref<const Eigen::VectorXd> p, Complex x) {
  Complex acc = 0.0;
  for (Eigen::Index i = 0; i < p.size(); ++i) acc = acc * x + p[i];
  return acc;
}

Eigen::VectorXd MultiplyPolynomials(Eigen::Ref<const Eigen::VectorXd> a,
                                    Eigen::Ref<const Eigen::VectorXd> b) {
  if (a.size() == 0 || b.size() == 0) return Eigen::VectorXd();
  Eigen::VectorXd out = Eigen::VectorXd::Zero(a.size() + b.size() - 1);
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    for (Eigen::Index j = 0; j < b.size(); ++j) out[i + j] += a[i] * b[j];
  }
  return out;
}

Eigen::VectorXd TrimLeadingZeros(Eigen::Ref<const Eigen::VectorXd> p, double rel_tol) {
  const double scale = p.size() == 0 ? 0.0 : p.cwiseAbs().maxCoeff();
  Eigen::Index first = 0;
  while (first + 1 < p.size() && std::abs(p[first]) <= rel_tol * scale) ++first;
  return p.tail(p.size() - first);
}

namespace {

// Parlett-Reinsch balancing by powers of two (the similarity LAPACK's gebal applies before an
// eigenvalue solve): companion matrices of polynomials whose coefficients span many decades lose
// most of their accuracy without it.
void Balance(Eigen::MatrixXd& a) {
  const Eigen::Index n = a.rows();
  bool converged = false;
  for (int sweep = 0; sweep < 100 && !converged; ++sweep) {
    converged = true;
    for (Eigen::Index i = 0; i < n; ++i) {
      const double c = a.col(i).cwiseAbs().sum() - std::abs(a(i, i));
      const double r = a.row(i).cwiseAbs().sum() - std::abs(a(i, i));
      if (c == 0.0 || r == 0.0) continue;
      double f = 1.0;
      double cc = c;
      while (cc < r / 2.0) {
        cc *= 2.0;
        f *= 2.0;
      }
      while (cc >= r * 2.0) {
        cc /= 2.0;
        f /= 2.0;
      }
      if ((c * f + r / f) < 0.95 * (c + r)) {
        converged = false;
        a.row(i) /= f;
        a.col(i) *= f;
      }
    }
  }
}

}  // namespace

std::vector<Complex> PolynomialRoots(Eigen::Ref<const Eigen::VectorXd> coeffs) {
  Eigen::VectorXd p = TrimLeadingZeros(coeffs);
  const Eigen::Index n = p.size() - 1;
  std::vector<Complex> roots;
  if (n <= 0) return roots;
  // Zero roots exactly, then scale the variable (s = sigma x) so the coefficients are O(1).
  Eigen::Index zeros_at_origin = 0;
  while (p.size() > 1 && p[p.size() - 1] == 0.0) {
    p.conservativeResize(p.size() - 1);
    ++zeros_at_origin;
  }
  const Eigen::Index m = p.size() - 1;
  for (Eigen::Index i = 0; i < zeros_at_origin; ++i) roots.emplace_back(0.0, 0.0);
  if (m > 0) {
    const double sigma = std::pow(std::abs(p[m] / p[0]), 1.0 / static_cast<double>(m));
    Eigen::VectorXd q(m + 1);
    for (Eigen::Index k = 0; k <= m; ++k) {
      q[k] = p[k] / p[0] * std::pow(sigma, -static_cast<double>(k));
    }
    Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(m, m);
    for (Eigen::Index j = 0; j < m; ++j) companion(0, j) = -q[j + 1];
    for (Eigen::Index i = 1; i < m; ++i) companion(i, i - 1) = 1.0;
    Balance(companion);
    const Eigen::EigenSolver<Eigen::MatrixXd> solver(companion, false);
    for (Eigen::Index i = 0; i < m; ++i) roots.push_back(solver.eigenvalues()[i] * sigma);
  }
  std::sort(roots.begin(), roots.end(), [](const Complex& a, const Complex& b) {
    return a.real() != b.real() ? a.real() < b.real() : a.imag() < b.imag();
  });
  return roots;
}

Eigen::VectorXd PolynomialFromRoots(const std::vector<Complex>& roots) {
  std::vector<Complex> c = {1.0};
  for (const Complex& r : roots) {
    std::vector<Complex> next(c.size() + 1, 0.0);
    for (std::size_t i = 0; i < c.size(); ++i) {
      next[i] += c[i];
      next[i + 1] -= c[i] * r;
    }
    c = std::move(next);
  }
  Eigen::VectorXd out(static_cast<Eigen::Index>(c.size()));
  for (std::size_t i = 0; i < c.size(); ++i) out[static_cast<Eigen::Index>(i)] = c[i].real();
  return out;
}

Eigen::VectorXd PolynomialFromRoots(Eigen::Ref<const Eigen::VectorXcd> roots) {
  return PolynomialFromRoots(std::vector<Complex>(roots.data(), roots.data() + roots.size()));
}

double SpectralRadius(Eigen::Ref<const Eigen::VectorXd> p) {
  double radius = 0.0;
  for (const Complex& r : PolynomialRoots(p)) radius = std::max(radius, std::abs(r));
  return radius;
}

Eigen::VectorXd StabilizeDiscrete(Eigen::Ref<const Eigen::VectorXd> p, double max_radius) {
  std::vector<Complex> r = PolynomialRoots(p);
  bool changed = false;
  for (std::size_t i = 0; i < r.size(); ++i) {
    double mag = std::abs(r[i]);
    if (mag > 1.0) {
      r[i] = 1.0 / std::conj(r[i]);
      mag = std::abs(r[i]);
      changed = true;
    }
    if (mag > max_radius) {
      r[i] *= max_radius / mag;
      changed = true;
    }
  }
  return changed ? PolynomialFromRoots(r) : Eigen::VectorXd(p);
}

Eigen::VectorXd StabilizeContinuous(Eigen::Ref<const Eigen::VectorXd> p) {
  std::vector<Complex> r = PolynomialRoots(p);
  bool changed = false;
  for (std::size_t i = 0; i < r.size(); ++i) {
    if (r[i].real() >= 0.0) {
      const double re = r[i].real() > 0.0 ? -r[i].real() : -1e-6 * std::max(1.0, std::abs(r[i]));
      r[i] = {re, r[i].imag()};
      changed = true;
    }
  }
  return changed ? Eigen::VectorXd(PolynomialFromRoots(r) * p[0]) : Eigen::VectorXd(p);
}

namespace {

// The direct-form recursion past the warm-up. The feedback terms are subtracted oldest first, so
// that the newest output y(t−1) enters the last operation only: the recursion's critical path per
// sample is one multiply and one subtraction rather than one per tap (IIR filters are latency
// bound, and the estimators run them dozens of times per fit). Orders up to kFixedTaps are
// compiled with the tap counts as constants, the past outputs kept in registers.
constexpr Eigen::Index kFixedTaps = 9;

template <std::size_t NB, std::size_t NA, std::size_t M, typename Divide>
void FilterFixed(const double* b_in, const double* a_in, const double* const* in, Eigen::Index warm,
                 Eigen::Index n, double* const* out, Divide divide) {
  if (warm >= n) return;  // else warm = max(nb, na) − 1: every past output below is there
  double b[NB];
  double a[NA];
  double past[M][NA];  // past[m][k] = y_m(t − k), k ≥ 1
  for (std::size_t k = 0; k < NB; ++k) b[k] = b_in[k];
  for (std::size_t k = 0; k < NA; ++k) a[k] = a_in[k];
  for (std::size_t m = 0; m < M; ++m) {
    for (std::size_t k = 1; k < NA; ++k) past[m][k] = out[m][warm - static_cast<Eigen::Index>(k)];
  }
  for (Eigen::Index t = warm; t < n; ++t) {
    for (std::size_t m = 0; m < M; ++m) {  // M independent recursions, interleaved
      double acc = 0.0;
      for (std::size_t k = 0; k < NB; ++k) acc += b[k] * in[m][t - static_cast<Eigen::Index>(k)];
      for (std::size_t k = NA - 1; k >= 1; --k) acc -= a[k] * past[m][k];
      const double y = divide(acc);
      out[m][t] = y;
      for (std::size_t k = NA - 1; k >= 2; --k) past[m][k] = past[m][k - 1];
      if constexpr (NA > 1) past[m][1] = y;
    }
  }
}

template <typename Divide>
void FilterAny(const double* b, Eigen::Index nb, const double* a, Eigen::Index na, const double* in,
               Eigen::Index warm, Eigen::Index n, double* out, Divide divide) {
  for (Eigen::Index t = warm; t < n; ++t) {
    double acc = 0.0;
    for (Eigen::Index k = 0; k < nb; ++k) acc += b[k] * in[t - k];
    for (Eigen::Index k = na - 1; k >= 1; --k) acc -= a[k] * out[t - k];
    out[t] = divide(acc);
  }
}

/// Entry (nb − 1) · kFixedTaps + (na − 1) filters M signals with nb and na taps.
template <std::size_t M, typename Divide, std::size_t... I>
void FilterDispatch(std::index_sequence<I...>, const double* b, Eigen::Index nb, const double* a,
                    Eigen::Index na, const double* const* in, Eigen::Index warm, Eigen::Index n,
                    double* const* out, Divide divide) {
  using Kernel = void (*)(const double*, const double*, const double* const*, Eigen::Index,
                          Eigen::Index, double* const*, Divide);
  constexpr std::size_t kTaps = kFixedTaps;
  static constexpr Kernel kTable[] = {&FilterFixed<I / kTaps + 1, I % kTaps + 1, M, Divide>...};
  kTable[static_cast<std::size_t>((nb - 1) * kFixedTaps + (na - 1))](b, a, in, warm, n, out,
                                                                     divide);
}

/// Filters M signals (M = 2 only for monic filters with a fixed-size kernel, see FilterPair).
template <std::size_t M, typename Divide>
void FilterSteady(const double* b, Eigen::Index nb, const double* a, Eigen::Index na,
                  const double* const* in, Eigen::Index warm, Eigen::Index n, double* const* out,
                  Divide divide) {
  if (nb >= 1 && nb <= kFixedTaps && na >= 1 && na <= kFixedTaps) {
    FilterDispatch<M>(std::make_index_sequence<kFixedTaps * kFixedTaps>{}, b, nb, a, na, in, warm,
                      n, out, divide);
  } else {
    for (std::size_t m = 0; m < M; ++m) FilterAny(b, nb, a, na, in[m], warm, n, out[m], divide);
  }
}

/// The first max(nb, na) − 1 samples, where not every tap is there yet; returns that count.
Eigen::Index FilterWarmUp(Eigen::Ref<const Eigen::VectorXd> num,
                          Eigen::Ref<const Eigen::VectorXd> den,
                          Eigen::Ref<const Eigen::VectorXd> x, Eigen::VectorXd& y) {
  const Eigen::Index nb = num.size();
  const Eigen::Index na = den.size();
  const Eigen::Index n = x.size();
  y.resize(n);
  // Direct form: y(t) = (sum b_k x(t-k) - sum_{k>=1} a_k y(t-k)) / a0.
  const Eigen::Index warm = std::min(n, std::max(nb, na) - 1);
  for (Eigen::Index t = 0; t < warm; ++t) {
    double acc = 0.0;
    const Eigen::Index kb = std::min(nb - 1, t);
    for (Eigen::Index k = 0; k <= kb; ++k) acc += num[k] * x[t - k];
    const Eigen::Index ka = std::min(na - 1, t);
    for (Eigen::Index k = ka; k >= 1; --k) acc -= den[k] * y[t - k];
    y[t] = acc / den[0];
  }
  return warm;
}

}  // namespace

Eigen::VectorXd Filter(Eigen::Ref<const Eigen::VectorXd> num, Eigen::Ref<const Eigen::VectorXd> den,
                       Eigen::Ref<const Eigen::VectorXd> x) {
  Require(den.size() >= 1 && den[0] != 0.0,
          "Filter: leading denominator coefficient must be nonzero");
  Eigen::VectorXd y;
  const Eigen::Index warm = FilterWarmUp(num, den, x, y);
  // Past the warm-up every tap is there: the same sums in the same order without the bounds, and
  // no division when a0 = 1 (x / 1 is x exactly): the division's latency would be part of every
  // sample's, and the filters here are mostly monic.
  const double a0 = den[0];
  const double* in[1] = {x.data()};
  double* out[1] = {y.data()};
  if (a0 == 1.0) {
    FilterSteady<1>(num.data(), num.size(), den.data(), den.size(), in, warm, x.size(), out,
                    [](double acc) { return acc; });
  } else {
    FilterSteady<1>(num.data(), num.size(), den.data(), den.size(), in, warm, x.size(), out,
                    [a0](double acc) { return acc / a0; });
  }
  return y;
}

void FilterPair(Eigen::Ref<const Eigen::VectorXd> num, Eigen::Ref<const Eigen::VectorXd> den,
                Eigen::Ref<const Eigen::VectorXd> x1, Eigen::Ref<const Eigen::VectorXd> x2,
                Eigen::VectorXd& y1, Eigen::VectorXd& y2) {
  Require(x1.size() == x2.size(), "FilterPair: the two signals must have the same length");
  if (!(den.size() >= 1 && den[0] == 1.0)) {
    y1 = Filter(num, den, x1);
    y2 = Filter(num, den, x2);
    return;
  }
  const Eigen::Index warm = FilterWarmUp(num, den, x1, y1);
  FilterWarmUp(num, den, x2, y2);
  const double* in[2] = {x1.data(), x2.data()};
  double* out[2] = {y1.data(), y2.data()};
  FilterSteady<2>(num.data(), num.size(), den.data(), den.size(), in, warm, x1.size(), out,
                  [](double acc) { return acc; });
}

}  // namespace vibid::numerics
