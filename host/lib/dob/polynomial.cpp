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

std::vector<Complex> PolynomialRoots(const Eigen::Ref<const Eigen::VectorXd>& coeffs) {
  const Eigen::VectorXd p = TrimLeadingZeros(coeffs);
  const Eigen::Index n = p.size() - 1;
  std::vector<Complex> roots;
  if (n <= 0) return roots;
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index j = 0; j < n; ++j) companion(0, j) = -p[j + 1] / p[0];
  for (Eigen::Index i = 1; i < n; ++i) companion(i, i - 1) = 1.0;
  const Eigen::EigenSolver<Eigen::MatrixXd> solver(companion, false);
  for (Eigen::Index i = 0; i < n; ++i) roots.push_back(solver.eigenvalues()[i]);
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
