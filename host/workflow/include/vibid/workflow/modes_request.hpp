// Modal identification as the front ends ask for it: a method by name, model orders as text, the
// driving point by column name or 1-based index.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "vibid/ident/driving_point.hpp"
#include "vibid/ident/modes.hpp"
#include "vibid/ident/ringdown.hpp"
#include "vibid/workflow/estimate.hpp"

namespace vibid::workflow {

struct ModeRequest {
  std::string method = "lscf";  ///< lscf, lsce, fit, peaks.
  std::string orders;           ///< "MIN:MAX[:STEP]" for lscf/lsce; empty: the defaults.
  /// Column name or 1-based index; empty: found from the data (ident::ChooseDrivingPoint).
  std::string driving_point;
  /// Where `driving_point` came from, for messages; empty: "--driving-point NAME".
  std::string driving_point_source;
  ident::ModeIdentificationOptions options;
};

/// Index of the driving-point response named by `spec` (non-empty); refuses a name or index the
/// FRF does not have.
std::size_t ResolveDrivingPoint(const ident::Frf& frf, const std::string& spec);

/// The request's driving point as ident::ChooseDrivingPoint takes it: none when not named.
std::optional<ident::NamedDrivingPoint> NamedDrivingPointOf(const ident::Frf& frf,
                                                            const ModeRequest& request);

/// ident::ChooseDrivingPoint on `provisional` (modes found with any driving point: the modal
/// constants do not depend on it). A refusal for data that single out no point says, where the
/// ring-downs of the FRF's hits (same responses, same order) show dry friction, that friction is
/// the likely cause: it hides modes, and with fewer modes than responses no point can be found.
ident::DrivingPointChoice ChooseDrivingPointOf(const ident::Frf& frf,
                                               const ident::ModeIdentification& provisional,
                                               const std::optional<ident::NamedDrivingPoint>& named,
                                               const ident::RingDowns* ringdowns);

/// Modes of a receptance FRF as `vibid modes` computes them, with the hammer at the driving point
/// ident::ChooseDrivingPoint keeps or finds from the modes' constants (InputError when it refuses:
/// a named point the data contradict, or none named and none singled out); `choice` receives it,
/// and its warnings (modes with a node there) join the identification's. With the ring-downs of
/// the hits the FRF was estimated from (an impact recording's, same responses in the same order),
/// each mode's damping is checked for amplitude dependence (ident::ApplyAmplitudeCheck).
ident::ModeIdentification IdentifyModes(const ident::Frf& receptance, const ModeRequest& request,
                                        const ident::RingDowns* ringdowns = nullptr,
                                        ident::DrivingPointChoice* choice = nullptr);

/// `vibid modes` on its inputs: each an FRF file or a recording (estimated with `estimation`),
/// joined as responses, then IdentifyModes; the ring-down check only with a single recording (it
/// reads that recording's hits, not columns joined from several).
struct ModesOfInputs {
  ident::Frf frf;  ///< The joined receptance the modes come from.
  ident::ModeIdentification identification;
  ident::DrivingPointChoice driving_point;
  /// Each input's estimation notes (EstimationNotes), for the JSON's "notes".
  std::vector<std::string> notes;
  /// Per input, in order: its estimation note (may be empty) and its warnings, for the front end
  /// to show as it shows them.
  std::vector<std::string> estimation_notes;
  std::vector<std::vector<std::string>> estimation_warnings;
};
ModesOfInputs IdentifyModesOf(const std::vector<std::string>& inputs,
                              const EstimationOptions& estimation, const ModeRequest& request);

}  // namespace vibid::workflow
