#include "vibid/dob/q_filter.hpp"

#include <cmath>
#include <numbers>
#include <string>

#include "vibid/common/error.hpp"

namespace vibid::dob {

Eigen::VectorXd ButterworthCoefficients(int order) {
  Require(order >= 1, "Butterworth order must be >= 1, got " + std::to_string(order));
  const double gamma = std::numbers::pi / (2.0 * order);
  Eigen::VectorXd a(order + 1);
  a[0] = 1.0;
  for (int k = 1; k <= order; ++k)
    a[k] = a[k - 1] * std::cos((k - 1) * gamma) / std::sin(k * gamma);
  return a;
}

Eigen::VectorXd BinomialCoefficients(int order) {
  Require(order >= 1, "binomial order must be >= 1, got " + std::to_string(order));
  Eigen::VectorXd a(order + 1);
  a[0] = 1.0;
  for (int k = 1; k <= order; ++k) a[k] = a[k - 1] * (order - k + 1) / k;
  return a;
}

QFilter MakeQFilter(int order, int relative_degree, double tau_s, QPrototype prototype) {
  Require(order >= 1, "Q order N must be >= 1, got " + std::to_string(order));
  Require(relative_degree >= 0 && relative_degree <= order,
          "Q relative degree r must satisfy 0 <= r <= N = " + std::to_string(order) + ", got " +
              std::to_string(relative_degree));
  Require(std::isfinite(tau_s) && tau_s > 0.0, "tau_s must be a finite number > 0");
  QFilter q;
  q.order = order;
  q.relative_degree = relative_degree;
  q.tau_s = tau_s;
  q.prototype = prototype == QPrototype::kButterworth ? ButterworthCoefficients(order)
                                                      : BinomialCoefficients(order);
  const int num_degree = order - relative_degree;
  q.den.resize(order + 1);
  q.num.resize(num_degree + 1);
  for (int k = 0; k <= order; ++k) q.den[order - k] = q.prototype[k] * std::pow(tau_s, k);
  for (int k = 0; k <= num_degree; ++k) q.num[num_degree - k] = q.prototype[k] * std::pow(tau_s, k);
  return q;
}

}  // namespace vibid::dob
