#include "vibid/dob/polynomial.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

namespace vibid::dob {

Complex EvaluatePolynomial(const Eigen::Ref<const Eigen::VectorXd>& coeffs, Complex x) {
  Complex acc = 0.0;
  for (Eigen::Index i = 0; i < coeffs.size(); ++i) acc = acc * x + coeffs[i];
  return acc;
}

Eigen::VectorXd MultiplyPolynomials(const Eigen::Ref<const Eigen::VectorXd>& a,
                                    const Eigen::Ref<const Eigen::VectorXd>& b) {
  if (a.size() == 0 || b.size() == 0) return Eigen::VectorXd();
  Eigen::VectorXd out = Eigen::VectorXd::Zero(a.size() + b.size() - 1);
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    for (Eigen::Index j = 0; j < b.size(); ++j) out[i + j] += a[i] * b[j];
  }
  return out;
}

Eigen::VectorXd TrimLeadingZeros(const Eigen::Ref<const Eigen::VectorXd>& coeffs, double rel_tol) {
  const double scale = coeffs.size() == 0 ? 0.0 : coeffs.cwiseAbs().maxCoeff();
  Eigen::Index first = 0;
  while (first + 1 < coeffs.size() && std::abs(coeffs[first]) <= rel_tol * scale) ++first;
  return coeffs.tail(coeffs.size() - first);
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

std::vector<Complex> PolynomialRoots(const Eigen::Ref<const Eigen::VectorXd>& coeffs) {
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
    for (Eigen::Index k = 0; k <= m; ++k) q[k] = p[k] / p[0] * std::pow(sigma, -static_cast<double>(k));
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

}  // namespace vibid::dob
