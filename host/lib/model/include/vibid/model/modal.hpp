// Modal analysis (methods §2): K φ = ω² M φ, φᵀ M φ = 1, modes sorted by ω.
#pragma once

#include <Eigen/Core>

#include "vibid/model/model.hpp"

namespace vibid::model {

enum class DampingKind {
  kNone,          ///< C = 0.
  kProportional,  ///< Φᵀ C Φ diagonal: ζ_i = φᵢᵀ C φᵢ / (2 ω_i).
  kGeneral,       ///< Non-classical C: ζ_i from the complex eigenvalues of the state matrix.
};

/// "none", "proportional", "general": the name `vibid modal` prints and its JSON holds.
const char* DampingKindName(DampingKind kind);

/// Mode i is column/entry i of every member, in ascending ω.
struct ModalResult {
  Eigen::VectorXd omega_rad_s;  ///< Undamped natural frequencies, rad/s (0 for rigid-body modes).
  Eigen::VectorXd freq_hz;      ///< omega_rad_s / 2π.
  Eigen::VectorXd zeta;         ///< Damping ratios (0 for rigid-body modes and undamped models).
  /// Modal damping φᵢᵀ C φᵢ in 1/s (= 2 ζ ω for a flexible mode); used by the modal FRF so that
  /// rigid-body modes with damping are represented too.
  Eigen::VectorXd modal_damping_per_s;
  Eigen::MatrixXd
      shapes;  ///< Mass-normalised shapes, n×n, one per column; first nonzero entry > 0.
  Eigen::VectorXd ratio;  ///< a1/a2 = shapes(0,i)/shapes(1,i) (sign kept); NaN when n < 2.
  DampingKind damping = DampingKind::kNone;

  int size() const { return static_cast<int>(omega_rad_s.size()); }
};

/// Validates the model, then solves the symmetric-definite eigenproblem. Damping kind is
/// detected (off-diagonal Φᵀ C Φ below 1e-9 of its largest entry → proportional).
ModalResult Modal(const Model& model);

/// Natural frequencies (rad/s) and damping ratios from the eigenvalues of the first-order state
/// matrix [[0, I], [−M⁻¹K, −M⁻¹C]], ascending in frequency. A complex pair λ gives ω = |λ|,
/// ζ = −Re λ/|λ|; overdamped real pairs (taken in order) give ω = √(λ₁λ₂), ζ = −(λ₁+λ₂)/(2ω).
/// Holds for any C; for proportional C it equals Modal's ω and ζ.
struct ComplexModes {
  Eigen::VectorXd omega_rad_s;
  Eigen::VectorXd zeta;
};
ComplexModes ComplexModalDamping(const Model& model);

}  // namespace vibid::model
