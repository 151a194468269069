#include "vibid/model/transfer_function.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <string>

#include "vibid/common/error.hpp"
#include "vibid/model/state_space.hpp"
#include "vibid/numerics/polynomial.hpp"

namespace vibid::model {
namespace {

// Drops leading coefficients that are rounding noise. "Small" is judged after substituting the
// model's frequency scale for s, so that coefficients of different powers are comparable.
Eigen::VectorXd TrimLeading(const Eigen::VectorXd& poly, double omega_scale) {
  const Eigen::Index degree = poly.size() - 1;
  Eigen::VectorXd weighted(poly.size());
  for (Eigen::Index i = 0; i < poly.size(); ++i) {
    weighted[i] = std::abs(poly[i]) * std::pow(omega_scale, static_cast<double>(degree - i));
  }
  const double largest = weighted.maxCoeff();
  Eigen::Index first = 0;
  while (first + 1 < poly.size() && weighted[first] <= 1e-12 * largest) ++first;
  return poly.tail(poly.size() - first);
}

}  // namespace

std::complex<double> EvaluateTf(const TransferFunction& tf, std::complex<double> s) {
  const auto horner = [s](const Eigen::VectorXd& p) {
    std::complex<double> acc = 0.0;
    for (Eigen::Index i = 0; i < p.size(); ++i) acc = acc * s + p[i];
    return acc;
  };
  return horner(tf.num) / horner(tf.den);
}

Eigen::VectorXcd EvaluateTfAt(const TransferFunction& tf,
                              Eigen::Ref<const Eigen::VectorXd> omega_rad_s) {
  Eigen::VectorXcd out(omega_rad_s.size());
  for (Eigen::Index i = 0; i < omega_rad_s.size(); ++i)
    out[i] = EvaluateTf(tf, {0.0, omega_rad_s[i]});
  return out;
}

TransferFunction Multiply(const TransferFunction& a, const TransferFunction& b) {
  return {numerics::MultiplyPolynomials(a.num, b.num), numerics::MultiplyPolynomials(a.den, b.den)};
}

TransferFunction ModelTransferFunction(const Model& model, int input_dof, int output_dof,
                                       FrfKind kind) {
  const StateSpace ss = ModelStateSpace(model);
  const Eigen::Index n = model.m_kg.rows();
  Require(input_dof >= 0 && input_dof < n, "input DOF " + std::to_string(input_dof + 1) +
                                               " is out of range 1.." + std::to_string(n));
  Require(output_dof >= 0 && output_dof < n, "output DOF " + std::to_string(output_dof + 1) +
                                                 " is out of range 1.." + std::to_string(n));
  const Eigen::Index order = 2 * n;

  // Faddeev–LeVerrier on A/w: det(zI − Ã) and adj(zI − Ã) = Σ_k M_k z^(N−k). The scaling keeps the
  // coefficients of a lightly damped rig within a few decades of each other.
  const double trace_k = (model.m_kg.llt().solve(model.k_n_per_m)).trace();
  const double w = trace_k > 0.0 ? std::sqrt(trace_k / static_cast<double>(n)) : 1.0;
  const Eigen::MatrixXd a = ss.A / w;
  const Eigen::VectorXd b = ss.B.col(input_dof);
  const Eigen::RowVectorXd c = ss.C.row(output_dof);

  Eigen::VectorXd den(order + 1);  // descending powers of z
  Eigen::VectorXd num(order);      // coefficient k−1 multiplies z^(N−k)
  den[0] = 1.0;
  Eigen::MatrixXd mk(order, order);
  Eigen::MatrixXd amk = Eigen::MatrixXd::Zero(order, order);  // Ã M_(k−1)
  for (Eigen::Index k = 1; k <= order; ++k) {
    mk = amk;
    mk.diagonal().array() += den[k - 1];
    num[k - 1] = c * mk * b;
    amk.noalias() = a * mk;
    den[k] = -amk.trace() / static_cast<double>(k);
  }
  // Back to s = w z, multiplying through by w^N: den_j ← den_j w^j, num_(k−1) ← num_(k−1) w^(k−1).
  TransferFunction tf;
  tf.den.resize(order + 1);
  for (Eigen::Index j = 0; j <= order; ++j)
    tf.den[j] = den[j] * std::pow(w, static_cast<double>(j));
  Eigen::VectorXd receptance(order - 1);  // the s^(N−1) term is zero by structure: drop it
  for (Eigen::Index k = 2; k <= order; ++k)
    receptance[k - 2] = num[k - 1] * std::pow(w, static_cast<double>(k - 1));
  receptance = TrimLeading(receptance, w);

  switch (kind) {
    case FrfKind::kReceptance: tf.num = receptance; break;
    case FrfKind::kMobility:
      tf.num = numerics::MultiplyPolynomials(receptance, Eigen::Vector2d(1.0, 0.0));
      break;
    case FrfKind::kAccelerance:
      tf.num = numerics::MultiplyPolynomials(receptance, Eigen::Vector3d(1.0, 0.0, 0.0));
      break;
  }
  return tf;
}

TransferFunction CartTrackTf(Eigen::Ref<const Eigen::VectorXd> masses_kg, double k_n_per_m,
                             Eigen::Ref<const Eigen::VectorXd> frictions_ns_per_m, CartInput input,
                             double bi_ns_per_m) {
  const Eigen::Index n = masses_kg.size();
  Require(n == 1 || n == 2,
          "the cart-track first-principle model has 1 or 2 carts, got " + std::to_string(n));
  Require(frictions_ns_per_m.size() == n, "cart track needs one friction per cart");
  Require(masses_kg.minCoeff() > 0.0 && masses_kg.allFinite(),
          "cart masses must be finite and > 0");
  Require(std::isfinite(k_n_per_m) && k_n_per_m >= 0.0, "cart spring must be finite and >= 0");
  Require(frictions_ns_per_m.allFinite() && frictions_ns_per_m.minCoeff() >= 0.0,
          "cart frictions must be finite and >= 0");
  Require(std::isfinite(bi_ns_per_m) && bi_ns_per_m >= 0.0,
          "input friction Bi must be finite and >= 0");
  const double k = k_n_per_m;
  const double bi = bi_ns_per_m;
  TransferFunction tf;
  if (n == 1) {
    // Methods §10, one cart (cart 2 pinned).
    const double m = masses_kg[0];
    const double b = frictions_ns_per_m[0];
    tf.den = Eigen::Vector3d(1.0, b / m, 2.0 * k / m);
    tf.num = input == CartInput::kForce ? Eigen::VectorXd::Constant(1, 1.0 / m)
                                        : Eigen::VectorXd(Eigen::Vector2d(bi / m, 2.0 * k / m));
    return tf;
  }
  // Methods §10, two carts, output X1.
  const double m1 = masses_kg[0];
  const double m2 = masses_kg[1];
  const double b1 = frictions_ns_per_m[0];
  const double b2 = frictions_ns_per_m[1];
  const double mm = m1 * m2;
  tf.den.resize(5);
  tf.den << 1.0, (m1 * b2 + m2 * b1) / mm, (2.0 * k * m1 + 2.0 * k * m2 + b1 * b2) / mm,
      (2.0 * k * b1 + 2.0 * k * b2) / mm, 3.0 * k * k / mm;
  if (input == CartInput::kForce) {
    tf.num = Eigen::Vector3d(m2 / mm, b2 / mm, 2.0 * k / mm);
  } else {
    tf.num.resize(4);
    tf.num << bi * m2 / mm, (2.0 * k * m2 + b2 * bi) / mm, (2.0 * k * b2 + 2.0 * k * bi) / mm,
        4.0 * k * k / mm;
  }
  return tf;
}

}  // namespace vibid::model
