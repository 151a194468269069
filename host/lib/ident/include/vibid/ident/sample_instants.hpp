// Channels sampled at different instants after the sample clock's edge (a board whose converters
// take turns) see a common signal with a phase difference of omega x (t_a - t_b). An FRF of such
// channels carries that phase on top of the structure's; knowing the instants, it comes off
// exactly. A recording from the board states them in a JSON sidecar beside its CSV (REC.csv.json,
// so that the CSV stays one header row and rows, which every CSV reader opens as it is):
//   {"format": "vibid-recording", "version": 1, "columns": ["t_s", "force1_n", "x1_m"],
//    "sample_instants_us": {"force1_n": 2.667, "x1_m": 2.667}}
// Recordings written before the sidecar carried them in an opening comment line, still read:
//   # vibid-recording sample_instants_us=force1_n:2.667,force2_n:5.905,x1_m:2.667
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "vibid/ident/spectral.hpp"

namespace vibid::ident {

/// A column and when it was sampled after the edge, in microseconds.
using InstantUs = std::pair<std::string, double>;

/// When each named column was sampled after the edge, as the recording states it (us).
struct SampleInstants {
  std::vector<InstantUs> instants_us;

  /// The column's instant in seconds (us x 1e-6); empty when the recording does not state it.
  std::optional<double> Of(std::string_view column) const;
};

/// Reads `sample_instants_us=` from the `# vibid-recording` line among the comment lines that open
/// `text` (the form recordings had before the sidecar). Empty when there is no such line.
/// @throws InputError naming `source` for a malformed list (a missing ':', a number that is not
/// finite or negative, a column named twice).
std::optional<SampleInstants> ParseSampleInstants(std::string_view text, const std::string& source);

/// The sidecar of a recording CSV: the CSV's path with ".json" added (REC.csv.json), which no
/// other file of vibid's is named.
std::string RecordingSidecarPath(const std::string& csv_path);

/// The sidecar's JSON text for a CSV of header `csv_columns` whose channel columns were sampled
/// at `instants_us` (each named in the header once).
std::string FormatRecordingSidecar(const std::vector<std::string>& csv_columns,
                                   const std::vector<InstantUs>& instants_us);

/// Reads a sidecar's text for the CSV whose header is `csv_columns`. @throws InputError naming
/// `source` for a file that is not a vibid-recording sidecar, an unknown key, a malformed instant,
/// or columns that are not the CSV's (a sidecar left from another recording at that path).
SampleInstants ParseRecordingSidecar(std::string_view json,
                                     const std::vector<std::string>& csv_columns,
                                     const std::string& source);

/// Writes the sidecar of `csv_path` (atomically), or, with no instants, removes one a recording
/// written earlier under that path left, so that it cannot describe this one.
void WriteRecordingSidecar(const std::string& csv_path, const std::vector<std::string>& csv_columns,
                           const std::vector<InstantUs>& instants_us);

/// The instants of the recording at `path`: from its sidecar when there is one, else from the
/// opening comment line of a recording written before (ParseSampleInstants); empty when neither
/// states them (a recording from elsewhere).
std::optional<SampleInstants> ReadSampleInstants(const std::string& path);

/// Moves every response to the force's instant: H_j(omega) x exp(j omega (t_force - t_j)).
/// A response sampled dt = t_j - t_force after the force shows H exp(j omega dt) (a delay in the
/// force's time frame); the factor takes it off. Coherence is unchanged. `response_instants_s`
/// has one entry per response.
void CompensateSampleInstants(Frf& frf, double force_instant_s,
                              const std::vector<double>& response_instants_s);

}  // namespace vibid::ident
