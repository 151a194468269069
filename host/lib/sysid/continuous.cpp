#include "vibid/sysid/continuous.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <string>
#include <type_traits>
#include <unsupported/Eigen/MatrixFunctions>

#include "vibid/common/error.hpp"
#include "vibid/model/state_space.hpp"
#include "vibid/numerics/polynomial.hpp"

namespace vibid::sysid {

void ValidateTf(const TransferFunction& tf) {
  Require(tf.den.size() >= 1 && tf.den[0] != 0.0,
          "transfer function: leading denominator coefficient must be nonzero");
  Require(tf.num.size() >= 1, "transfer function: empty numerator");
  Require(tf.num.allFinite() && tf.den.allFinite(),
          "transfer function: coefficients must be finite");
  Eigen::Index first = 0;
  while (first < tf.num.size() - 1 && tf.num[first] == 0.0) ++first;
  Require(tf.num.size() - first <= tf.den.size(),
          "transfer function is improper (numerator degree above denominator degree)");
}

TransferFunction Normalized(const TransferFunction& tf) {
  ValidateTf(tf);
  Eigen::Index first = 0;
  while (first < tf.num.size() - 1 && tf.num[first] == 0.0) ++first;
  return TransferFunction{tf.num.tail(tf.num.size() - first) / tf.den[0], tf.den / tf.den[0]};
}

StateSpaceSiso ControllableCanonical(const TransferFunction& tf) {
  const TransferFunction t = Normalized(tf);
  const Eigen::Index n = t.Order();
  StateSpaceSiso ss;
  ss.a = Eigen::MatrixXd::Zero(n, n);
  ss.b = Eigen::VectorXd::Zero(n);
  ss.c = Eigen::RowVectorXd::Zero(n);
  Eigen::VectorXd num = Eigen::VectorXd::Zero(n + 1);
  num.tail(t.num.size()) = t.num;
  ss.d = num[0];
  if (n == 0) return ss;
  ss.a.row(0) = -t.den.tail(n).transpose();
  for (Eigen::Index i = 1; i < n; ++i) ss.a(i, i - 1) = 1.0;
  ss.b[0] = 1.0;
  ss.c = (num.tail(n) - ss.d * t.den.tail(n)).transpose();
  return ss;
}

Eigen::MatrixXd SimulateStates(Eigen::Ref<const Eigen::MatrixXd> a,
                               Eigen::Ref<const Eigen::VectorXd> b,
                               Eigen::Ref<const Eigen::VectorXd> u, double dt_s, Hold hold,
                               Eigen::Ref<const Eigen::VectorXd> x0) {
  Eigen::MatrixXd states;
  SimulateStatesInto(a, b, u, dt_s, hold, x0, false, states);
  return states;
}

namespace {

// x_{k+1} = phi x_k + g0 u_k + g1 (u_{k+1} - u_k) (g1 only with a first-order hold).
struct HoldDiscretization {
  Eigen::MatrixXd phi;
  Eigen::VectorXd g0;
  Eigen::VectorXd g1;
};

// The input as an extra state u' = w/dt (w = u_{k+1} − u_k, the slope of a first-order hold):
// the ZOH discretization of [[A, B], [0, 0]] driven by w gives Φ, the ZOH input integral Γ0 (next
// to Φ) and the first-order-hold one Γ1 (Franklin, Powell & Workman, Digital Control, §6.3.2).
HoldDiscretization DiscretizeWithHold(const Eigen::Ref<const Eigen::MatrixXd>& a,
                                      const Eigen::Ref<const Eigen::VectorXd>& b, double dt_s) {
  const Eigen::Index n = a.rows();
  model::StateSpace ct;
  ct.A = Eigen::MatrixXd::Zero(n + 1, n + 1);
  ct.A.topLeftCorner(n, n) = a;
  ct.A.topRightCorner(n, 1) = b;
  ct.B = Eigen::MatrixXd::Zero(n + 1, 1);
  ct.B(n, 0) = 1.0 / dt_s;
  const model::StateSpace d = model::Discretize(ct, dt_s);
  return {d.A.topLeftCorner(n, n), d.A.topRightCorner(n, 1), d.B.topRows(n)};
}

// This runs for every sample of every filtered regressor in SRIVC and tfest: the state update is
// compiled for each order up to 8 (the loops unrolled, the state in registers), larger orders
// take the general loop. Both sum in the order phi * x, then + g0 u, then + g1 du, as the matrix
// expression they replace, so every order gives the same bits either way.
template <std::size_t N, bool kFirstOrder, bool kReversed>
void SimulateFixedOrder(const HoldDiscretization& h, const Eigen::Ref<const Eigen::VectorXd>& u,
                        const Eigen::Ref<const Eigen::VectorXd>& x0, Eigen::MatrixXd& states) {
  const Eigen::Index samples = u.size();
  const double* const in = u.data();
  double* col[N];
  double ph[N][N];
  double b0[N];
  double b1[N];
  double x[N];
  for (std::size_t i = 0; i < N; ++i) {
    for (std::size_t j = 0; j < N; ++j)
      ph[i][j] = h.phi(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
    b0[i] = h.g0[static_cast<Eigen::Index>(i)];
    b1[i] = h.g1[static_cast<Eigen::Index>(i)];
    x[i] = x0[static_cast<Eigen::Index>(i)];
    col[i] = states.col(static_cast<Eigen::Index>(kReversed ? N - 1 - i : i)).data();
  }
  for (Eigen::Index k = 0;; ++k) {
#pragma GCC unroll 8
    for (std::size_t i = 0; i < N; ++i) col[i][k] = x[i];
    if (k + 1 == samples) break;
    const double uk = in[k];
    const double du = kFirstOrder ? in[k + 1] - uk : 0.0;
    double next[N];
#pragma GCC unroll 8
    for (std::size_t i = 0; i < N; ++i) {
      double acc = 0.0;
#pragma GCC unroll 8
      for (std::size_t j = 0; j < N; ++j) acc += ph[i][j] * x[j];
      acc += b0[i] * uk;
      if constexpr (kFirstOrder) acc += b1[i] * du;
      next[i] = acc;
    }
#pragma GCC unroll 8
    for (std::size_t i = 0; i < N; ++i) x[i] = next[i];
  }
}

// The hold and the column order as template arguments: no test of either per sample.
template <std::size_t N>
void SimulateFixedOrder(const HoldDiscretization& h, const Eigen::Ref<const Eigen::VectorXd>& u,
                        bool first_order, const Eigen::Ref<const Eigen::VectorXd>& x0,
                        bool reversed, Eigen::MatrixXd& states) {
  if (first_order) {
    return reversed ? SimulateFixedOrder<N, true, true>(h, u, x0, states)
                    : SimulateFixedOrder<N, true, false>(h, u, x0, states);
  }
  return reversed ? SimulateFixedOrder<N, false, true>(h, u, x0, states)
                  : SimulateFixedOrder<N, false, false>(h, u, x0, states);
}

void SimulateAnyOrder(const HoldDiscretization& h, const Eigen::Ref<const Eigen::VectorXd>& u,
                      bool first_order, const Eigen::Ref<const Eigen::VectorXd>& x0, bool reversed,
                      Eigen::MatrixXd& states) {
  const Eigen::Index n = h.phi.rows();
  const Eigen::Index samples = u.size();
  Eigen::VectorXd x = x0;
  Eigen::VectorXd next(n);
  for (Eigen::Index k = 0; k < samples; ++k) {
    for (Eigen::Index i = 0; i < n; ++i) states(k, reversed ? n - 1 - i : i) = x[i];
    if (k + 1 == samples) break;
    const double du = first_order ? u[k + 1] - u[k] : 0.0;
    for (Eigen::Index i = 0; i < n; ++i) {
      double acc = 0.0;
      for (Eigen::Index j = 0; j < n; ++j) acc += h.phi(i, j) * x[j];
      acc += h.g0[i] * u[k];
      if (first_order) acc += h.g1[i] * du;
      next[i] = acc;
    }
    x.swap(next);
  }
}

}  // namespace

void SimulateStatesInto(Eigen::Ref<const Eigen::MatrixXd> a, Eigen::Ref<const Eigen::VectorXd> b,
                        Eigen::Ref<const Eigen::VectorXd> u, double dt_s, Hold hold,
                        Eigen::Ref<const Eigen::VectorXd> x0, bool reversed,
                        Eigen::MatrixXd& states) {
  const Eigen::Index n = a.rows();
  const Eigen::Index samples = u.size();
  states.resize(samples, n);
  if (samples == 0) return;
  const HoldDiscretization h = DiscretizeWithHold(a, b, dt_s);
  const bool first_order = hold == Hold::kFirst;
  switch (n) {
    case 1: return SimulateFixedOrder<1>(h, u, first_order, x0, reversed, states);
    case 2: return SimulateFixedOrder<2>(h, u, first_order, x0, reversed, states);
    case 3: return SimulateFixedOrder<3>(h, u, first_order, x0, reversed, states);
    case 4: return SimulateFixedOrder<4>(h, u, first_order, x0, reversed, states);
    case 5: return SimulateFixedOrder<5>(h, u, first_order, x0, reversed, states);
    case 6: return SimulateFixedOrder<6>(h, u, first_order, x0, reversed, states);
    case 7: return SimulateFixedOrder<7>(h, u, first_order, x0, reversed, states);
    case 8: return SimulateFixedOrder<8>(h, u, first_order, x0, reversed, states);
    default: return SimulateAnyOrder(h, u, first_order, x0, reversed, states);
  }
}

Eigen::VectorXd Simulate(const TransferFunction& tf, Eigen::Ref<const Eigen::VectorXd> u,
                         double dt_s, Hold hold) {
  const StateSpaceSiso ss = ControllableCanonical(tf);
  if (ss.a.rows() == 0) return ss.d * u;
  const Eigen::MatrixXd x =
      SimulateStates(ss.a, ss.b, u, dt_s, hold, Eigen::VectorXd::Zero(ss.a.rows()));
  return x * ss.c.transpose() + ss.d * u;
}

namespace {

template <typename Step>
Eigen::VectorXd Integrate(const TransferFunction& tf, Eigen::Ref<const Eigen::VectorXd> u,
                          double dt_s, int substeps, Step step) {
  Require(substeps >= 1, "substeps must be at least 1");
  Require(dt_s > 0.0, "sample period must be > 0");
  const StateSpaceSiso ss = ControllableCanonical(tf);
  const Eigen::Index n = ss.a.rows();
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd y(u.size());
  const double h = dt_s / substeps;
  for (Eigen::Index k = 0; k < u.size(); ++k) {
    y[k] = (n > 0 ? (ss.c * x)(0) : 0.0) + ss.d * u[k];
    for (int s = 0; s < substeps && n > 0; ++s) x = step(ss, x, u[k], h);
  }
  return y;
}

}  // namespace

Eigen::VectorXd SimulateEuler(const TransferFunction& tf, Eigen::Ref<const Eigen::VectorXd> u,
                              double dt_s, int substeps) {
  return Integrate(tf, u, dt_s, substeps,
                   [](const StateSpaceSiso& ss, const Eigen::VectorXd& x, double uk,
                      double h) -> Eigen::VectorXd { return x + h * (ss.a * x + ss.b * uk); });
}

Eigen::VectorXd SimulateRk4(const TransferFunction& tf, Eigen::Ref<const Eigen::VectorXd> u,
                            double dt_s, int substeps) {
  return Integrate(tf, u, dt_s, substeps,
                   [](const StateSpaceSiso& ss, const Eigen::VectorXd& x, double uk,
                      double h) -> Eigen::VectorXd {
                     auto f = [&](const Eigen::VectorXd& s) -> Eigen::VectorXd {
                       return ss.a * s + ss.b * uk;
                     };
                     const Eigen::VectorXd k1 = f(x);
                     const Eigen::VectorXd k2 = f(x + 0.5 * h * k1);
                     const Eigen::VectorXd k3 = f(x + 0.5 * h * k2);
                     const Eigen::VectorXd k4 = f(x + h * k3);
                     return x + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
                   });
}

namespace {

/// Transfer function C (sI − A)⁻¹ B + D of a SISO state space, from characteristic polynomials:
/// det(sI − A + BC) = det(sI − A)(1 + C (sI − A)⁻¹ B).
TransferFunction TfFromStateSpace(const Eigen::MatrixXd& a, const Eigen::VectorXd& b,
                                  const Eigen::RowVectorXd& c, double d) {
  const Eigen::VectorXd den =
      numerics::PolynomialFromRoots(Eigen::EigenSolver<Eigen::MatrixXd>(a, false).eigenvalues());
  const Eigen::MatrixXd closed = a - b * c;
  const Eigen::VectorXd both = numerics::PolynomialFromRoots(
      Eigen::EigenSolver<Eigen::MatrixXd>(closed, false).eigenvalues());
  Eigen::VectorXd num = both - den + d * den;
  return TransferFunction{num, den};
}

}  // namespace

DiscreteTf C2dZoh(const TransferFunction& tf, double dt_s) {
  Require(dt_s > 0.0, "sample period must be > 0");
  const StateSpaceSiso ss = ControllableCanonical(tf);
  const Eigen::Index n = ss.a.rows();
  if (n == 0) return DiscreteTf{Eigen::VectorXd::Constant(1, ss.d), Eigen::VectorXd::Ones(1)};
  model::StateSpace ct;
  ct.A = ss.a;
  ct.B = ss.b;
  const model::StateSpace d = model::Discretize(ct, dt_s);
  // A z-domain TF read with descending powers of z is the same vector in ascending powers of q⁻¹.
  const TransferFunction z = TfFromStateSpace(d.A, d.B.col(0), ss.c, ss.d);
  return DiscreteTf{z.num, z.den};
}

TransferFunction D2cZoh(Eigen::Ref<const Eigen::VectorXd> num,
                        Eigen::Ref<const Eigen::VectorXd> den, double dt_s) {
  Require(dt_s > 0.0, "sample period must be > 0");
  Require(den.size() >= 1 && den[0] != 0.0, "d2c: leading denominator coefficient must be nonzero");
  Require(num.size() <= den.size(),
          "d2c: numerator longer than denominator (more than one sample of delay "
          "or a non-causal model): no continuous equivalent");
  const Eigen::Index n = den.size() - 1;
  Eigen::VectorXd padded = Eigen::VectorXd::Zero(n + 1);
  padded.head(num.size()) = num;
  const std::vector<numerics::Complex> poles = numerics::PolynomialRoots(den);
  for (std::size_t i = 0; i < poles.size(); ++i) {
    Require(
        !(std::abs(poles[i].imag()) <= 1e-12 * std::max(1.0, std::abs(poles[i])) &&
          poles[i].real() <= 1e-12),
        "d2c: discrete pole at z = " + std::to_string(poles[i].real()) +
            " on the negative real axis (or at 0, a pure delay) has no continuous-time equivalent");
  }
  // Discrete state space in the same canonical form, then the matrix logarithm of the ZOH block.
  const StateSpaceSiso zs = ControllableCanonical(TransferFunction{padded, den});
  Eigen::MatrixXd m = Eigen::MatrixXd::Identity(n + 1, n + 1);
  m.topLeftCorner(n, n) = zs.a;
  m.topRightCorner(n, 1) = zs.b;
  const Eigen::MatrixXd l = m.log() / dt_s;
  return TfFromStateSpace(l.topLeftCorner(n, n), l.topRightCorner(n, 1), zs.c, zs.d);
}

}  // namespace vibid::sysid
