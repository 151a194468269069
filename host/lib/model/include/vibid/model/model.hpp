// Lumped-parameter models of vibration rigs: M ẍ + C ẋ + K x = F + d (methods §1).
//
// DOF indices are 0-based in C++ (the CLI and model files count from 1). Units are SI: kg, N/m,
// N·s/m.
#pragma once

#include <Eigen/Core>

namespace vibid::model {

struct Model {
  Eigen::MatrixXd m_kg;        ///< Mass matrix, n×n, symmetric positive definite.
  Eigen::MatrixXd c_ns_per_m;  ///< Viscous damping matrix, n×n, symmetric; all zeros when undamped.
  Eigen::MatrixXd k_n_per_m;   ///< Stiffness matrix, n×n, symmetric positive semidefinite.

  int dofs() const { return static_cast<int>(m_kg.rows()); }
};

/// Throws InputError naming the problem unless: n ≥ 1; M, C, K are n×n and finite; M and K
/// symmetric (C too); M positive definite; K positive semidefinite.
void Validate(const Model& model);

/// Series chain ground –k1– m1 –k2– m2 – … (rig A). `dampers_ns_per_m` is empty (undamped) or has
/// one dashpot per spring, in parallel with it. Validates the result.
Model MakeChain(Eigen::Ref<const Eigen::VectorXd> masses_kg,
                Eigen::Ref<const Eigen::VectorXd> springs_n_per_m,
                Eigen::Ref<const Eigen::VectorXd> dampers_ns_per_m = Eigen::VectorXd());

/// Cart track ground –k– M1 –k– M2 – … –k– ground (rig B): n carts, n+1 springs of equal k, and a
/// viscous friction per cart to ground (empty: none). Validates the result.
Model MakeCartTrack(Eigen::Ref<const Eigen::VectorXd> masses_kg, double k_n_per_m,
                    Eigen::Ref<const Eigen::VectorXd> frictions_ns_per_m = Eigen::VectorXd());

/// Mass-weighted position input of the cart track: a position Xi imposed through the first
/// spring acts on cart 1 as the force F(s) = (Bi s + 2k) Xi(s) (methods §1), `bi_ns_per_m` being
/// the initial-friction term Bi. Returns F in N for a given Xi (m) and dXi/dt (m/s).
double CartPositionInputForce(double k_n_per_m, double bi_ns_per_m, double xi_m, double dxi_m_s);

}  // namespace vibid::model
