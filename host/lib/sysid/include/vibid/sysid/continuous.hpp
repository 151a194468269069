// Continuous-time transfer functions: exact sampled simulation, the course's Euler and RK4
// simulations, and conversion between continuous and discrete time (ZOH c2d and its inverse d2c).
//
// A TransferFunction is num(s)/den(s), coefficients in descending powers of s (as MATLAB's tf and
// scipy.signal). Simulations take the input as samples u_k at t_k = k dt_s and return y(t_k).
#pragma once

#include <Eigen/Core>

namespace vibid::sysid {

struct TransferFunction {
  Eigen::VectorXd num;  ///< Descending powers of s.
  Eigen::VectorXd den;  ///< Descending powers of s, den[0] != 0.

  /// Degree of the denominator (number of poles).
  Eigen::Index Order() const { return den.size() - 1; }
};

/// Checks that den[0] != 0, the TF is proper (deg num ≤ deg den) and all coefficients are finite;
/// InputError otherwise.
void ValidateTf(const TransferFunction& tf);

/// Same TF with den monic and leading zeros of num dropped.
TransferFunction Normalized(const TransferFunction& tf);

/// Controllable canonical state space of a proper TF: x = [z^(n-1), ..., z', z] with z = u/den,
/// y = C x + D u.
struct StateSpaceSiso {
  Eigen::MatrixXd a;
  Eigen::VectorXd b;
  Eigen::RowVectorXd c;
  double d = 0.0;
};
StateSpaceSiso ControllableCanonical(const TransferFunction& tf);

/// How the input behaves between samples.
enum class Hold {
  kZero,   ///< Piecewise constant (the DAC's zero-order hold): exact for a stepped input.
  kFirst,  ///< Piecewise linear between samples (first-order hold, non-causal triangle).
};

/// State trajectory x(t_k), k = 0..N−1, of ẋ = A x + B u from x(0) = x0, exact for the hold.
Eigen::MatrixXd SimulateStates(Eigen::Ref<const Eigen::MatrixXd> a,
                               Eigen::Ref<const Eigen::VectorXd> b,
                               Eigen::Ref<const Eigen::VectorXd> u, double dt_s, Hold hold,
                               Eigen::Ref<const Eigen::VectorXd> x0);
/// The same into `states` (resized to N x n; its storage is reused when the size matches, so an
/// iterative caller allocates nothing per pass). With `reversed`, column j holds state n − 1 − j.
void SimulateStatesInto(Eigen::Ref<const Eigen::MatrixXd> a, Eigen::Ref<const Eigen::VectorXd> b,
                        Eigen::Ref<const Eigen::VectorXd> u, double dt_s, Hold hold,
                        Eigen::Ref<const Eigen::VectorXd> x0, bool reversed,
                        Eigen::MatrixXd& states);

/// y(t_k) of the TF driven by u from rest, exact for the given hold.
Eigen::VectorXd Simulate(const TransferFunction& tf, Eigen::Ref<const Eigen::VectorXd> u,
                         double dt_s, Hold hold = Hold::kZero);

/// Course methods: the TF's canonical ODE integrated with one explicit Euler step, or one classical
/// 4th-order Runge–Kutta step, per sample, the input held at u_k over [t_k, t_{k+1}). `substeps`
/// splits each sample interval into that many integration steps.
Eigen::VectorXd SimulateEuler(const TransferFunction& tf, Eigen::Ref<const Eigen::VectorXd> u,
                              double dt_s, int substeps = 1);
Eigen::VectorXd SimulateRk4(const TransferFunction& tf, Eigen::Ref<const Eigen::VectorXd> u,
                            double dt_s, int substeps = 1);

/// Exact ZOH discretization as a q⁻¹ transfer function: num = [b0, b1, ..., bn] (b0 = D), den =
/// [1, a1, ..., an] with n = Order().
struct DiscreteTf {
  Eigen::VectorXd num;
  Eigen::VectorXd den;
};
DiscreteTf C2dZoh(const TransferFunction& tf, double dt_s);

/// Inverse of C2dZoh: the continuous TF whose ZOH discretization is num/den (q⁻¹, den monic,
/// num no longer than den). Throws InputError when a discrete pole lies on the closed negative real
/// axis (no real continuous equivalent) — that includes pure delays beyond one sample.
TransferFunction D2cZoh(Eigen::Ref<const Eigen::VectorXd> num,
                        Eigen::Ref<const Eigen::VectorXd> den, double dt_s);

}  // namespace vibid::sysid
