#include "vibid/sysid/least_squares.hpp"

#include <cmath>
#include <limits>

#include <Eigen/QR>
#include <Eigen/SVD>

#include "vibid/common/error.hpp"

namespace vibid::sysid {

const char* TerminationName(Termination t) {
  switch (t) {
    case Termination::kConvergedCost: return "converged-cost";
    case Termination::kConvergedStep: return "converged-step";
    case Termination::kMaxIterations: return "max-iterations";
    case Termination::kNumericalFailure: return "numerical-failure";
  }
  return "numerical-failure";
}

void SolverOptions::Validate() const {
  Require(max_iterations >= 1, "solver: max_iterations must be at least 1");
  Require(std::isfinite(cost_tolerance) && cost_tolerance >= 0.0, "solver: cost_tolerance must be >= 0");
  Require(std::isfinite(step_tolerance) && step_tolerance >= 0.0, "solver: step_tolerance must be >= 0");
  Require(std::isfinite(initial_damping) && initial_damping > 0.0, "solver: initial_damping must be > 0");
}

namespace {

double Cost(const Eigen::VectorXd& r) { return r.squaredNorm() / static_cast<double>(r.size()); }

bool Finite(const Eigen::VectorXd& r) { return r.allFinite(); }

}  // namespace

SolverSummary MinimizeLeastSquares(const ResidualFunction& fn, Eigen::VectorXd& theta, const SolverOptions& options,
                                   Eigen::MatrixXd* jacobian_out) {
  options.Validate();
  SolverSummary s;
  const Eigen::Index p = theta.size();
  Eigen::VectorXd r;
  Eigen::MatrixXd jac;
  if (!fn(theta, r, &jac) || !Finite(r) || !jac.allFinite()) {
    s.message = "the initial parameters give no finite prediction error";
    return s;
  }
  double cost = Cost(r);
  s.initial_cost = cost;
  s.final_cost = cost;
  double lambda = options.initial_damping;
  Eigen::VectorXd trial_r;
  Eigen::MatrixXd trial_jac;
  bool done = false;
  while (!done) {
    if (s.iterations >= options.max_iterations) {
      s.termination = Termination::kMaxIterations;
      s.message = "stopped after " + std::to_string(s.iterations) + " iterations without meeting the tolerances";
      break;
    }
    if (cost == 0.0) {
      s.termination = Termination::kConvergedCost;
      s.message = "the prediction error is exactly zero";
      break;
    }
    ++s.iterations;
    Eigen::VectorXd scale = jac.colwise().norm().transpose();
    for (Eigen::Index j = 0; j < p; ++j) {
      if (!(scale[j] > 0.0)) scale[j] = 1.0;
    }
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(jac);
    const Eigen::MatrixXd rfac = qr.matrixQR().topRows(p).triangularView<Eigen::Upper>();
    const Eigen::VectorXd qtr = (qr.householderQ().transpose() * r).head(p);
    bool accepted = false;
    // Raise the damping until a step lowers the cost; 1e16 × the scale means a step of nothing.
    while (lambda < 1e16) {
      Eigen::MatrixXd aug(2 * p, p);
      aug.topRows(p) = rfac;
      aug.bottomRows(p) = (std::sqrt(lambda) * scale).asDiagonal();
      Eigen::VectorXd rhs = Eigen::VectorXd::Zero(2 * p);
      rhs.head(p) = -qtr;
      const Eigen::VectorXd step = aug.householderQr().solve(rhs);
      const Eigen::VectorXd candidate = theta + step;
      const double step_norm = step.norm();
      if (step_norm <= options.step_tolerance * (theta.norm() + options.step_tolerance)) {
        s.termination = Termination::kConvergedStep;
        s.message = "parameter step below tolerance";
        done = true;
        break;
      }
      if (fn(candidate, trial_r, &trial_jac) && Finite(trial_r) && trial_jac.allFinite()) {
        const double trial_cost = Cost(trial_r);
        if (trial_cost <= cost) {
          const double decrease = cost - trial_cost;
          theta = candidate;
          r.swap(trial_r);
          jac.swap(trial_jac);
          cost = trial_cost;
          lambda = std::max(lambda / 10.0, 1e-12);
          accepted = true;
          if (decrease <= options.cost_tolerance * (cost + decrease)) {
            s.termination = Termination::kConvergedCost;
            s.message = "relative cost decrease below tolerance";
            done = true;
          }
          break;
        }
      }
      lambda *= 10.0;
    }
    if (!accepted && !done) {
      // No damping gives a decrease: the current point is a minimum to working precision when the
      // gradient vanishes, otherwise the model cannot move (unstable in every direction tried).
      const double gradient = (jac.transpose() * r).cwiseQuotient(scale).norm() / std::max(r.norm(), 1e-300);
      if (gradient < 1e-6) {
        s.termination = Termination::kConvergedCost;
        s.message = "no further decrease possible: at a minimum to working precision";
      } else {
        s.termination = Termination::kNumericalFailure;
        s.message = "no admissible step lowers the cost (the model stays at the edge of stability)";
      }
      done = true;
    }
  }
  s.final_cost = cost;
  if (jacobian_out != nullptr) *jacobian_out = jac;
  return s;
}

Eigen::MatrixXd CovarianceFromJacobian(Eigen::Ref<const Eigen::MatrixXd> jacobian,
                                       Eigen::Ref<const Eigen::VectorXd> residual) {
  const Eigen::Index n = jacobian.rows();
  const Eigen::Index p = jacobian.cols();
  const double dof = static_cast<double>(std::max<Eigen::Index>(n - p, 1));
  const double sigma2 = residual.squaredNorm() / dof;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(jacobian, Eigen::ComputeThinV);
  const Eigen::VectorXd sv = svd.singularValues();
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(p, p);
  const double tol = sv.size() > 0 ? sv[0] * 1e-12 * static_cast<double>(std::max(n, p)) : 0.0;
  for (Eigen::Index i = 0; i < sv.size(); ++i) {
    if (sv[i] > tol) {
      cov += svd.matrixV().col(i) * svd.matrixV().col(i).transpose() / (sv[i] * sv[i]);
    } else {
      for (Eigen::Index j = 0; j < p; ++j) {
        if (svd.matrixV()(j, i) != 0.0) cov(j, j) = std::numeric_limits<double>::infinity();
      }
    }
  }
  return sigma2 * cov;
}

bool SolveInstrumental(Eigen::Ref<const Eigen::MatrixXd> zeta, Eigen::Ref<const Eigen::MatrixXd> phi,
                       Eigen::Ref<const Eigen::VectorXd> target, Eigen::VectorXd& theta) {
  const Eigen::Index p = phi.cols();
  Eigen::VectorXd phi_scale = phi.colwise().norm().transpose();
  Eigen::VectorXd zeta_scale = zeta.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < p; ++j) {
    if (!(phi_scale[j] > 0.0) || !(zeta_scale[j] > 0.0)) return false;
  }
  const Eigen::MatrixXd zp = zeta_scale.cwiseInverse().asDiagonal() * (zeta.transpose() * phi) *
                             phi_scale.cwiseInverse().asDiagonal();
  const Eigen::VectorXd zy = zeta_scale.cwiseInverse().asDiagonal() * (zeta.transpose() * target);
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(zp);
  qr.setThreshold(1e-13);
  if (qr.rank() < p) return false;
  theta = phi_scale.cwiseInverse().asDiagonal() * qr.solve(zy);
  return theta.allFinite();
}

}  // namespace vibid::sysid
