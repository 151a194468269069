// Continuous-time transfer functions as polynomial coefficient vectors.
#pragma once

#include <complex>

#include <Eigen/Core>

#include "vibid/model/frf.hpp"
#include "vibid/model/model.hpp"

namespace vibid::model {

/// num(s)/den(s), coefficients in descending powers of s (highest first), `den` monic.
struct TransferFunction {
  Eigen::VectorXd num;
  Eigen::VectorXd den;
};

/// Value at a complex s.
std::complex<double> EvaluateTf(const TransferFunction& tf, std::complex<double> s);
/// Values at s = jω for each ω (rad/s): directly comparable with Frf().
Eigen::VectorXcd EvaluateTfAt(const TransferFunction& tf,
                              Eigen::Ref<const Eigen::VectorXd> omega_rad_s);

/// Product of two transfer functions (polynomial products).
TransferFunction Multiply(const TransferFunction& a, const TransferFunction& b);

/// Exact polynomial form of H_out,in(s): adj(Ms² + Cs + K)_out,in / det(Ms² + Cs + K), normalised
/// so the denominator (degree 2n) is monic. Computed by Faddeev–LeVerrier on the frequency-scaled
/// state matrix; numerator coefficients that are zero by structure are dropped (receptance
/// degree ≤ 2n−2, mobility one more, accelerance two more).
TransferFunction ModelTransferFunction(const Model& model, int input_dof, int output_dof,
                                       FrfKind kind);

/// Input of the cart-track first-principle models (methods §10).
enum class CartInput {
  kForce,     ///< force F on cart 1, N
  kPosition,  ///< position Xi imposed through the first spring, m: F(s) = (Bi s + 2k) Xi(s)
};

/// First-principle TF from the input to the position X1 of cart 1, for one cart (cart 2 pinned)
/// or two carts, as written in methods §10: X1/F = (1/M)/(s² + (B/M)s + 2k/M),
/// X1/Xi = ((Bi/M)s + 2k/M)/(…), and the 3rd-over-4th-order two-cart form. `masses_kg` and
/// `frictions_ns_per_m` have 1 or 2 entries. InputError otherwise.
TransferFunction CartTrackTf(Eigen::Ref<const Eigen::VectorXd> masses_kg, double k_n_per_m,
                             Eigen::Ref<const Eigen::VectorXd> frictions_ns_per_m, CartInput input,
                             double bi_ns_per_m = 0.0);

}  // namespace vibid::model
