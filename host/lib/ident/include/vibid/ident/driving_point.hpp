// Which response is the driving point (the hammer's mass), from the modes' modal constants
// (methods §14): a passive structure's driving-point receptance has a positive constant
// A_ppr = phi_pr^2 in every mode, while a cross point's phi_ir phi_pr change sign from mode to mode
// (with every mode of an n-mass structure, sum_r phi_ir phi_pr = (M^-1)_ip = 0 for a diagonal M).
// Of the responses whose constants are all positive, the one whose scaled shapes give a mass
// matrix (Phi Phi^T)^-1 closest to diagonal is it.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "vibid/ident/modes.hpp"
#include "vibid/ident/spectral.hpp"

namespace vibid::ident {

/// The modes' real modal constants: column r holds mode r's A_jr (response j over the force), as
/// a receptance residue H_j = A_jr / (omega_r^2 - omega^2 + 2 i zeta_r omega_r omega).
struct ModalConstants {
  Eigen::MatrixXd a;               ///< responses x modes.
  std::vector<double> freq_hz;     ///< One per mode.
  std::vector<std::string> names;  ///< One per response.
};

/// A mode whose largest receptance peak |A| / (2 zeta omega^2) is under this fraction of the
/// strongest mode's is left out of ModalConstantsOf.
inline constexpr double kWeakModeFraction = 1e-3;

/// The reported modes' constants (not the dropped ones, nor those marked unreliable, nor those
/// under kWeakModeFraction): the residue fit's when the identification has one (matched to each
/// mode by frequency), else the FRF's quadrature part at the mode's line (A ~ -2 zeta omega^2
/// Im H at resonance).
ModalConstants ModalConstantsOf(const Frf& receptance, const ModeIdentification& modes);

/// What the constants say of one response as the driving point.
struct DrivingPointEvidence {
  /// Modes whose constant here is large enough to have a sign (kSignFraction of the mode's
  /// largest), and of those the ones that are negative.
  std::size_t signed_modes = 0;
  std::vector<std::size_t> negative_modes;  ///< 0-based, into ModalConstants' modes.
  /// Every constant positive where it has a sign: the response can be the driving point.
  bool one_sign = false;
  /// With at least as many modes as responses: the largest off-diagonal |M_ij| / sqrt(M_ii M_jj)
  /// of (Phi Phi^T)^-1 with the shapes scaled from this response (0 for a diagonal matrix); NaN
  /// when it cannot be formed (too few modes, or a constant here not positive).
  double mass_coupling = 0.0;
};

struct DrivingPointFinding {
  std::vector<DrivingPointEvidence> responses;
  /// The response the data make the driving point, or none when they do not single one out
  /// (`why` says which could be and why no one of them is chosen).
  std::optional<std::size_t> fits;
  std::string why;
};

/// A constant smaller than this fraction of its mode's largest has no sign worth counting: at a
/// node of the mode (phi_p ~ 0) noise sets it.
inline constexpr double kSignFraction = 0.05;
/// The candidate with the most nearly diagonal mass matrix is chosen when the next one's coupling
/// is at least this many times larger and at least kCouplingFloor.
inline constexpr double kCouplingRatio = 3.0;
inline constexpr double kCouplingFloor = 0.1;

DrivingPointFinding FindDrivingPoint(const ModalConstants& constants);

/// Where a named driving point came from, for messages: "--driving-point acc2_m_s2", "the
/// board's record (load cell 1 on mass 3)".
struct NamedDrivingPoint {
  std::size_t index = 0;
  std::string source;
};

/// The decision, with the lines it leaves for the user.
struct DrivingPointChoice {
  std::size_t index = 0;
  /// "named" (kept: the data agree or cannot tell), "found" (from the data alone).
  std::string how;
  std::string note;  ///< One line: which response and why.
  /// Modes with a node near the driving point (|phi_p| under kNodeFraction of the shape's largest
  /// entry): each named with the mass to hit to scale it.
  std::vector<std::string> warnings;
};

inline constexpr double kNodeFraction = 0.1;

/// Keeps a named driving point the data do not contradict, finds one from the data when none is
/// named, and refuses (InputError) a named point the data contradict (naming the one that fits,
/// or saying none does) and a record whose data single out none (naming the candidates and
/// --driving-point). A single response is its own driving point.
DrivingPointChoice ChooseDrivingPoint(const ModalConstants& constants,
                                      const std::optional<NamedDrivingPoint>& named);

}  // namespace vibid::ident
