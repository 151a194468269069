// The nonlinear searches of sysid on the shared solver, reporting the prediction-error criterion
// V(θ) = (1/N) Σ r_t(θ)² (the System Identification Toolbox's loss) as the summary's cost rather
// than the solver's ½ ‖r‖², so that costs read the same as the closed-form ARX loss.
#pragma once

#include <Eigen/Core>

#include "vibid/numerics/least_squares.hpp"

namespace vibid::sysid {

/// Runs numerics::LevenbergMarquardt; `solution` receives r, J and J's R factor at the returned θ.
/// The search stops on the cost decrease and the step only: an absolute gradient bound means
/// nothing for a loss whose scale is the data's, so gradient_tolerance is not applied here.
inline numerics::SolverSummary MinimizePredictionError(const numerics::ResidualFunction& fn,
                                                       Eigen::VectorXd& theta,
                                                       const numerics::SolverOptions& options,
                                                       numerics::Solution& solution) {
  options.Validate();
  numerics::SolverOptions scale_free = options;
  scale_free.gradient_tolerance = 0.0;
  numerics::SolverSummary summary = numerics::LevenbergMarquardt(fn, theta, scale_free, &solution);
  if (solution.residuals.size() > 0) {
    const double to_mean_square = 2.0 / static_cast<double>(solution.residuals.size());
    summary.initial_cost *= to_mean_square;
    summary.final_cost *= to_mean_square;
  }
  return summary;
}

}  // namespace vibid::sysid
