// The instrumental-variable step of the refined IV (SRIVC) and Steiglitz–McBride style starts.
#pragma once

#include <Eigen/Core>

namespace vibid::sysid {

/// Instrumental-variable solution θ of Zᵀ Φ θ = Zᵀ y, with Φ's columns scaled to unit norm first
/// (regressors of y and u can differ by many orders of magnitude, which would otherwise look like
/// rank deficiency). Returns false when ZᵀΦ is singular or the solution is not finite.
bool SolveInstrumental(Eigen::Ref<const Eigen::MatrixXd> zeta,
                       Eigen::Ref<const Eigen::MatrixXd> phi,
                       Eigen::Ref<const Eigen::VectorXd> target, Eigen::VectorXd& theta);

}  // namespace vibid::sysid
