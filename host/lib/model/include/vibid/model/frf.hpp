// Frequency response functions of a model (methods §3).
#pragma once

#include <string_view>

#include <Eigen/Core>

#include "vibid/model/modal.hpp"
#include "vibid/model/model.hpp"

namespace vibid::model {

enum class FrfKind {
  kReceptance,   ///< displacement / force, m/N
  kMobility,     ///< velocity / force, m/(N·s) = jω · receptance
  kAccelerance,  ///< acceleration / force, m/(N·s²) = −ω² · receptance
};

/// "receptance" | "mobility" | "accelerance"; InputError otherwise.
FrfKind ParseFrfKind(std::string_view name);
std::string_view FrfKindName(FrfKind kind);

/// H_out,in(ω) from the matrices: (K − ω²M + jωC)⁻¹, times jω or −ω² for mobility/accelerance.
/// DOFs 0-based; InputError when out of range or the model is invalid. A frequency at which the
/// dynamic stiffness is singular (undamped resonance hit exactly) gives a non-finite entry.
Eigen::VectorXcd Frf(const Model& model, int input_dof, int output_dof, FrfKind kind,
                     Eigen::Ref<const Eigen::VectorXd> omega_rad_s);

/// The same from the modal form Σ_i φ_out,i φ_in,i / (ω_i² − ω² + jω φᵢᵀCφᵢ). Exact for undamped
/// and proportionally damped models; for general damping it neglects the modal coupling terms.
Eigen::VectorXcd FrfModal(const ModalResult& modes, int input_dof, int output_dof, FrfKind kind,
                          Eigen::Ref<const Eigen::VectorXd> omega_rad_s);

}  // namespace vibid::model
