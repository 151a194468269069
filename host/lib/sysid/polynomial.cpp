#include "vibid/sysid/polynomial.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "vibid/common/error.hpp"

namespace vibid::sysid {

Eigen::VectorXd Filter(Eigen::Ref<const Eigen::VectorXd> num, Eigen::Ref<const Eigen::VectorXd> den,
                       Eigen::Ref<const Eigen::VectorXd> x) {
  Require(den.size() >= 1 && den[0] != 0.0, "Filter: leading denominator coefficient must be nonzero");
  const Eigen::Index nb = num.size();
  const Eigen::Index na = den.size();
  const Eigen::Index n = x.size();
  const double a0 = den[0];
  Eigen::VectorXd y(n);
  // Direct form: y(t) = (sum b_k x(t-k) - sum_{k>=1} a_k y(t-k)) / a0.
  const Eigen::Index warm = std::min(n, std::max(nb, na) - 1);
  for (Eigen::Index t = 0; t < warm; ++t) {
    double acc = 0.0;
    const Eigen::Index kb = std::min(nb - 1, t);
    for (Eigen::Index k = 0; k <= kb; ++k) acc += num[k] * x[t - k];
    const Eigen::Index ka = std::min(na - 1, t);
    for (Eigen::Index k = 1; k <= ka; ++k) acc -= den[k] * y[t - k];
    y[t] = acc / a0;
  }
  // Past the first max(nb, na) - 1 samples every tap is there: the same sums in the same order
  // without the bounds, and no division when a0 = 1 (x / 1 is x exactly). The recursion makes
  // the division's latency part of every sample's, and the filters here are mostly monic.
  const double* const b = num.data();
  const double* const a = den.data();
  const double* const in = x.data();
  double* const out = y.data();
  const auto steady = [&](auto divide) {
    for (Eigen::Index t = warm; t < n; ++t) {
      double acc = 0.0;
      for (Eigen::Index k = 0; k < nb; ++k) acc += b[k] * in[t - k];
      for (Eigen::Index k = 1; k < na; ++k) acc -= a[k] * out[t - k];
      out[t] = divide(acc);
    }
  };
  if (a0 == 1.0) {
    steady([](double acc) { return acc; });
  } else {
    steady([a0](double acc) { return acc / a0; });
  }
  return y;
}

Eigen::VectorXd PolyMul(Eigen::Ref<const Eigen::VectorXd> a, Eigen::Ref<const Eigen::VectorXd> b) {
  if (a.size() == 0 || b.size() == 0) return Eigen::VectorXd();
  Eigen::VectorXd c = Eigen::VectorXd::Zero(a.size() + b.size() - 1);
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    for (Eigen::Index j = 0; j < b.size(); ++j) c[i + j] += a[i] * b[j];
  }
  return c;
}

Eigen::VectorXcd Roots(Eigen::Ref<const Eigen::VectorXd> p) {
  Eigen::Index first = 0;
  while (first < p.size() && p[first] == 0.0) ++first;
  const Eigen::Index n = p.size() - first - 1;
  if (n <= 0) return Eigen::VectorXcd();
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index j = 0; j < n; ++j) companion(0, j) = -p[first + 1 + j] / p[first];
  for (Eigen::Index i = 1; i < n; ++i) companion(i, i - 1) = 1.0;
  return Eigen::EigenSolver<Eigen::MatrixXd>(companion, false).eigenvalues();
}

Eigen::VectorXd PolyFromRoots(Eigen::Ref<const Eigen::VectorXcd> roots) {
  Eigen::VectorXcd c = Eigen::VectorXcd::Zero(roots.size() + 1);
  c[0] = 1.0;
  for (Eigen::Index k = 0; k < roots.size(); ++k) {
    for (Eigen::Index i = k + 1; i >= 1; --i) c[i] -= roots[k] * c[i - 1];
  }
  return c.real();
}

double SpectralRadius(Eigen::Ref<const Eigen::VectorXd> p) {
  const Eigen::VectorXcd r = Roots(p);
  return r.size() == 0 ? 0.0 : r.cwiseAbs().maxCoeff();
}

Eigen::VectorXd StabilizeDiscrete(Eigen::Ref<const Eigen::VectorXd> p, double max_radius) {
  Eigen::VectorXcd r = Roots(p);
  bool changed = false;
  for (Eigen::Index i = 0; i < r.size(); ++i) {
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
  return changed ? PolyFromRoots(r) : Eigen::VectorXd(p);
}

Eigen::VectorXd StabilizeContinuous(Eigen::Ref<const Eigen::VectorXd> p) {
  Eigen::VectorXcd r = Roots(p);
  bool changed = false;
  for (Eigen::Index i = 0; i < r.size(); ++i) {
    if (r[i].real() >= 0.0) {
      const double re = r[i].real() > 0.0 ? -r[i].real() : -1e-6 * std::max(1.0, std::abs(r[i]));
      r[i] = {re, r[i].imag()};
      changed = true;
    }
  }
  return changed ? Eigen::VectorXd(PolyFromRoots(r) * p[0]) : Eigen::VectorXd(p);
}

std::complex<double> PolyVal(Eigen::Ref<const Eigen::VectorXd> p, std::complex<double> x) {
  std::complex<double> acc = 0.0;
  for (Eigen::Index i = 0; i < p.size(); ++i) acc = acc * x + p[i];
  return acc;
}

}  // namespace vibid::sysid
