#include "vibid/model/state_space.hpp"

#include <cmath>

#include <Eigen/LU>
#include <unsupported/Eigen/MatrixFunctions>

#include "vibid/common/error.hpp"

namespace vibid::model {

StateSpace ModelStateSpace(const Model& model) {
  Validate(model);
  const Eigen::Index n = model.m_kg.rows();
  const Eigen::PartialPivLU<Eigen::MatrixXd> m_lu(model.m_kg);
  const Eigen::MatrixXd m_inv = m_lu.inverse();
  const Eigen::MatrixXd minus_m_inv_k = -(m_inv * model.k_n_per_m);
  const Eigen::MatrixXd minus_m_inv_c = -(m_inv * model.c_ns_per_m);

  StateSpace ss;
  ss.A = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  ss.A.topRightCorner(n, n).setIdentity();
  ss.A.bottomLeftCorner(n, n) = minus_m_inv_k;
  ss.A.bottomRightCorner(n, n) = minus_m_inv_c;
  ss.B = Eigen::MatrixXd::Zero(2 * n, n);
  ss.B.bottomRows(n) = m_inv;
  ss.C = Eigen::MatrixXd::Zero(3 * n, 2 * n);
  ss.C.topRows(2 * n).setIdentity();
  ss.C.bottomRows(n) = ss.A.bottomRows(n);
  ss.D = Eigen::MatrixXd::Zero(3 * n, n);
  ss.D.bottomRows(n) = m_inv;
  ss.dt_s = 0.0;
  return ss;
}

StateSpace Discretize(const StateSpace& continuous, double dt_s) {
  Require(continuous.dt_s == 0.0, "Discretize needs a continuous-time system");
  Require(std::isfinite(dt_s) && dt_s > 0.0, "dt_s must be finite and > 0");
  const Eigen::Index ns = continuous.A.rows();
  const Eigen::Index ni = continuous.B.cols();
  Require(continuous.A.cols() == ns && continuous.B.rows() == ns,
          "state-space A and B sizes do not match");
  // Van Loan: the exponential of the augmented matrix carries both ∫e^{Aτ}dτ B and e^{A dt}.
  Eigen::MatrixXd augmented = Eigen::MatrixXd::Zero(ns + ni, ns + ni);
  augmented.topLeftCorner(ns, ns) = continuous.A * dt_s;
  augmented.topRightCorner(ns, ni) = continuous.B * dt_s;
  const Eigen::MatrixXd e = augmented.exp();
  StateSpace d = continuous;
  d.A = e.topLeftCorner(ns, ns);
  d.B = e.topRightCorner(ns, ni);
  d.dt_s = dt_s;
  return d;
}

}  // namespace vibid::model
