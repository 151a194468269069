#include "vibid/model/modal.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

namespace vibid::model {

const char* DampingKindName(DampingKind kind) {
  switch (kind) {
    case DampingKind::kNone: return "none";
    case DampingKind::kProportional: return "proportional";
    case DampingKind::kGeneral: return "general";
  }
  return "none";
}

namespace {

// Relative size of the off-diagonal of ΦᵀCΦ below which C counts as proportional (classical).
constexpr double kProportionalTolerance = 1e-9;

}  // namespace

ModalResult Modal(const Model& model) {
  Validate(model);
  const Eigen::Index n = model.m_kg.rows();
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> solver(model.k_n_per_m,
                                                                         model.m_kg);
  // Eigen returns ascending eigenvalues and M-normalised vectors (φᵀMφ = 1).
  ModalResult r;
  r.omega_rad_s = solver.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  r.freq_hz = r.omega_rad_s / (2.0 * std::numbers::pi);
  r.shapes = solver.eigenvectors();
  for (Eigen::Index i = 0; i < n; ++i) {
    auto phi = r.shapes.col(i);
    const double scale = phi.cwiseAbs().maxCoeff();
    for (Eigen::Index j = 0; j < n; ++j) {
      if (std::abs(phi[j]) > 1e-9 * scale) {
        if (phi[j] < 0.0) phi = -phi;
        break;
      }
    }
  }
  r.ratio = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::quiet_NaN());
  if (n >= 2) r.ratio = r.shapes.row(0).cwiseQuotient(r.shapes.row(1)).transpose();

  const Eigen::MatrixXd modal_c = r.shapes.transpose() * model.c_ns_per_m * r.shapes;
  r.modal_damping_per_s = modal_c.diagonal();
  r.zeta = Eigen::VectorXd::Zero(n);
  const double c_scale = modal_c.cwiseAbs().maxCoeff();
  if (c_scale == 0.0) {
    r.damping = DampingKind::kNone;
    return r;
  }
  const Eigen::MatrixXd off_diagonal = modal_c - Eigen::MatrixXd(modal_c.diagonal().asDiagonal());
  if (off_diagonal.cwiseAbs().maxCoeff() <= kProportionalTolerance * c_scale) {
    r.damping = DampingKind::kProportional;
    for (Eigen::Index i = 0; i < n; ++i) {
      if (r.omega_rad_s[i] > 0.0) r.zeta[i] = modal_c(i, i) / (2.0 * r.omega_rad_s[i]);
    }
    return r;
  }
  r.damping = DampingKind::kGeneral;
  const ComplexModes complex_modes = ComplexModalDamping(model);
  // Rigid-body modes (ω = 0) keep ζ = 0; the flexible ones take the complex modes in order.
  Eigen::Index next = 0;
  for (Eigen::Index i = 0; i < n && next < complex_modes.zeta.size(); ++i) {
    if (r.omega_rad_s[i] > 0.0) r.zeta[i] = complex_modes.zeta[next++];
  }
  return r;
}

ComplexModes ComplexModalDamping(const Model& model) {
  Validate(model);
  const Eigen::Index n = model.m_kg.rows();
  const Eigen::PartialPivLU<Eigen::MatrixXd> m_lu(model.m_kg);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  a.topRightCorner(n, n).setIdentity();
  a.bottomLeftCorner(n, n) = -m_lu.solve(model.k_n_per_m);
  a.bottomRightCorner(n, n) = -m_lu.solve(model.c_ns_per_m);
  const Eigen::EigenSolver<Eigen::MatrixXd> eig(a, false);
  const Eigen::VectorXcd& lambda = eig.eigenvalues();

  std::vector<std::pair<double, double>> modes;  // (ω, ζ)
  std::vector<double> real_roots;
  const double scale = lambda.cwiseAbs().maxCoeff();
  for (Eigen::Index i = 0; i < lambda.size(); ++i) {
    const std::complex<double> l = lambda[i];
    if (std::abs(l.imag()) > 1e-12 * scale) {
      if (l.imag() > 0.0) modes.emplace_back(std::abs(l), -l.real() / std::abs(l));
    } else {
      real_roots.push_back(l.real());
    }
  }
  // Rigid-body roots (λ = 0) are not vibration modes; overdamped pairs are taken in order of size.
  std::sort(real_roots.begin(), real_roots.end(),
            [](double x, double y) { return std::abs(x) < std::abs(y); });
  std::vector<double> flexible;
  for (const double root : real_roots) {
    if (std::abs(root) > 1e-9 * std::max(scale, 1.0)) flexible.push_back(root);
  }
  for (std::size_t i = 0; i + 1 < flexible.size(); i += 2) {
    const double omega = std::sqrt(flexible[i] * flexible[i + 1]);
    modes.emplace_back(omega, -(flexible[i] + flexible[i + 1]) / (2.0 * omega));
  }
  std::sort(modes.begin(), modes.end());
  ComplexModes out;
  out.omega_rad_s.resize(static_cast<Eigen::Index>(modes.size()));
  out.zeta.resize(static_cast<Eigen::Index>(modes.size()));
  for (std::size_t i = 0; i < modes.size(); ++i) {
    out.omega_rad_s[static_cast<Eigen::Index>(i)] = modes[i].first;
    out.zeta[static_cast<Eigen::Index>(i)] = modes[i].second;
  }
  return out;
}

}  // namespace vibid::model
