// Plausible references given the one in hand, whitened by the true covariance: the reference's
// covariance S ~ Wishart(m − 1, I)/(m − 1) and its mean's error e ~ N(0, I/m), independent. Both
// calibrations (the window test's, the sequential test's) draw them with their own variates
// written out (Box–Muller; Marsaglia & Tsang, ACM TOMS 26 2000), so that a threshold is the same
// on every standard library.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

namespace vibid::oma::detail {

class Variates {
 public:
  explicit Variates(std::uint64_t seed) : rng_(seed) {}
  double Uniform() { return (static_cast<double>(rng_() >> 11) + 0.5) * 0x1.0p-53; }
  double Normal() {
    if (spare_) {
      spare_ = false;
      return next_;
    }
    const double r = std::sqrt(-2.0 * std::log(Uniform()));
    const double a = 2.0 * std::numbers::pi * Uniform();
    next_ = r * std::sin(a);
    spare_ = true;
    return r * std::cos(a);
  }
  // Gamma(shape ≥ 1, 1).
  double Gamma(double shape) {
    const double d = shape - 1.0 / 3.0;
    const double c = 1.0 / std::sqrt(9.0 * d);
    for (;;) {
      const double x = Normal();
      const double v = std::pow(1.0 + c * x, 3);
      if (v <= 0.0) continue;
      if (std::log(Uniform()) < 0.5 * x * x + d - d * v + d * std::log(v)) return d * v;
    }
  }

 private:
  std::mt19937_64 rng_;
  bool spare_ = false;
  double next_ = 0.0;
};

// One reference's error: S's eigenvalues and the mean's error in S's eigenvectors (Vᵀe).
struct ReferenceError {
  Eigen::VectorXd eigenvalues;
  Eigen::VectorXd mean_error;
};

inline ReferenceError DrawReferenceError(Variates& v, int p, int m) {
  // Bartlett: W = A Aᵀ ~ Wishart(m − 1, I), A lower triangular.
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(p, p);
  for (int i = 0; i < p; ++i) {
    a(i, i) = std::sqrt(2.0 * v.Gamma(0.5 * (m - 1 - i)));
    for (int j = 0; j < i; ++j) a(i, j) = v.Normal();
  }
  const Eigen::MatrixXd s = a * a.transpose() / (m - 1.0);
  Eigen::VectorXd e(p);
  for (int i = 0; i < p; ++i) e(i) = v.Normal() / std::sqrt(static_cast<double>(m));
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(s);
  return {eig.eigenvalues(), eig.eigenvectors().transpose() * e};
}

// The q point of the references' figures (nearest rank): where both calibrations read their
// 97.5 % point and their band's ends.
inline double Quantile(std::vector<double> x, double q) {
  std::sort(x.begin(), x.end());
  const auto i = static_cast<std::size_t>(std::lround(q * static_cast<double>(x.size() - 1)));
  return x[i];
}

}  // namespace vibid::oma::detail
