// State-space form of a model and its exact zero-order-hold discretisation.
#pragma once

#include <Eigen/Core>

#include "vibid/model/model.hpp"

namespace vibid::model {

/// ẋ = A x + B u, y = C x + D u (continuous), or x[k+1] = A x[k] + B u[k] (discrete, dt_s > 0).
/// For a model: state x = [positions (n); velocities (n)], input u = forces on each DOF (n) — the
/// disturbance d enters through the same channels, u = F + d — and output
/// y = [positions (n); velocities (n); accelerations (n)].
struct StateSpace {
  Eigen::MatrixXd A;  ///< 2n×2n
  Eigen::MatrixXd B;  ///< 2n×n
  Eigen::MatrixXd C;  ///< 3n×2n
  Eigen::MatrixXd D;  ///< 3n×n
  double dt_s = 0.0;  ///< 0: continuous time; > 0: sample period of a discrete system.
};

/// A = [[0, I], [−M⁻¹K, −M⁻¹C]], B = [[0], [M⁻¹]], C = [[I, 0], [0, I], [−M⁻¹K, −M⁻¹C]],
/// D = [[0], [0], [M⁻¹]]. Validates the model.
StateSpace ModelStateSpace(const Model& model);

/// Exact ZOH: expm([[A, B], [0, 0]] dt) = [[Ad, Bd], [0, I]]; C, D unchanged. InputError unless
/// `continuous` is continuous time and dt_s is finite and > 0.
StateSpace Discretize(const StateSpace& continuous, double dt_s);

}  // namespace vibid::model
