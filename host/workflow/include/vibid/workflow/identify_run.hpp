// The whole identification from recordings, as `vibid identify` runs it: each mass test and modal
// test estimated (impact or Welch decided per recording), the modes, the mass and stiffness
// updates, the validation table; and the report's data (report.json, validation.txt, the FRF
// overlay) built from the result.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "vibid/ident/identify.hpp"
#include "vibid/model/model.hpp"
#include "vibid/workflow/estimate.hpp"
#include "vibid/workflow/modes_request.hpp"

namespace vibid::workflow {

struct MassTestFile {
  std::size_t position = 0;  ///< 0-based mass position.
  std::string path;
};

/// "POS=REC.csv" (POS counted from 1), as --mass-test takes it.
MassTestFile ParseMassTest(const std::string& text);

struct IdentifyRequest {
  std::vector<MassTestFile> mass_tests;
  /// "POS=K" (N/m) or "POS=fit" per mass test whose spring is not the nominal chain spring.
  std::vector<std::string> mass_springs;
  std::vector<std::string> modal_tests;
  /// Response columns of the mass tests: empty (accP_m_s2 for mass P), one for all, or one per
  /// mass test, comma separated.
  std::string mass_response;
  /// Response columns of the modal tests, one per mass; empty: acc1_m_s2..accN_m_s2.
  std::string modal_responses;
  /// Force column, estimator, sensor, windows, hit options; `responses`, `kind` and `impact` are
  /// set per test. Its force defaults to the board's force1_n.
  EstimationOptions estimation;
  ModeRequest modes;
  /// Relative spread of the nominal model as the one-test chain fit's prior (used when the tests
  /// show fewer modes than masses).
  double prior_relative_sd = 0.2;
  /// A sensors file whose sensitivities state their uncertainty (sensitivity_uncertainty,
  /// coverage_factor): the intervals of m, k and c then carry the calibration part beside the
  /// statistical one (sensor_calibration.hpp). Empty: the statistical part only.
  std::string sensors;
};

/// IdentifyRequest with the board's force column and hammer-test defaults.
IdentifyRequest DefaultIdentifyRequest();

struct IdentifyRun {
  ident::IdentifyResult result;
  std::vector<ident::Frf> modal_frfs;  ///< Receptances of the modal tests, in order.
  /// The modal tests' driving point: kept as named or found from the data (DrivingPointOfTests).
  std::size_t driving_point = 0;
  ident::DrivingPointChoice driving_point_choice;
  std::vector<std::string> notes;  ///< EstimationNotes of every recording.
  /// What the estimations have to tell the user, in order: the processing note of a recording
  /// that did not look like a hammer test, and every warning (path first).
  struct Message {
    bool warning = false;
    std::string text;
  };
  std::vector<Message> messages;
};

/// The driving point of the modal tests (receptances), each test's kept or found by
/// ident::ChooseDrivingPoint on its modes; InputError when it refuses one, or when the tests were
/// hit at different responses (identify takes tests of one driving point). `ringdowns`, one per
/// test where given, let a refusal name dry friction (ChooseDrivingPointOf).
ident::DrivingPointChoice DrivingPointOfTests(const std::vector<ident::Frf>& modal_frfs,
                                              const ModeRequest& modes,
                                              const ident::ModeIdentificationOptions& options,
                                              const std::vector<ident::RingDowns>& ringdowns = {});

/// The whole identification; the driving point is DrivingPointOfTests' (its note and warnings
/// join `messages`), so a hammer on another mass than the one named is refused, never fitted.
IdentifyRun RunIdentify(const model::Model& nominal, const IdentifyRequest& request);

/// {"topology": "chain", "masses", "springs", "dampers"}: the updated model file.
nlohmann::json ChainJson(const ident::ChainParameters& chain, std::size_t n);
/// The validation table and, on its last line, "Verdict: OK" (or "Verdict: CAUTION: reason; ...",
/// "Verdict: FLAGGED: ..."): what `identify` prints and writes to validation.txt, what the bench
/// shows and Python's Identification.validation holds.
std::string ValidationText(const IdentifyRun& run);
/// The updated model file `identify` writes: ChainJson with the result's "verdict".
nlohmann::json UpdatedModelJson(const IdentifyRun& run, std::size_t n);
/// Writes the updated model to `path` unless the result is flagged and `accept_flagged` is false:
/// then FlaggedError naming the reasons and `option` (nothing is written). The file carries the
/// verdict either way.
void WriteUpdatedModel(const IdentifyRun& run, std::size_t n, const std::string& path,
                       bool accept_flagged, const std::string& option);
/// report.json: verdict, method, updated model, validation (nominal/updated/test with the test's
/// intervals, the modal deviation of both models, the chain fit beside), parameters with intervals,
/// the chain fit, test modes, mass tests, modal tests, stiffness (null when not every mode was
/// seen), warnings, notes.
nlohmann::json IdentifyReportJson(const IdentifyRun& run, std::size_t n);
/// Measured receptance of the first modal test beside the nominal and updated models'
/// receptances (hammer at the driving point), magnitudes per response, as CSV.
std::string FrfOverlayCsv(const IdentifyRun& run, const model::Model& nominal);

}  // namespace vibid::workflow
