// Channels sampled at different instants after the sample clock's edge (a board whose converters
// take turns) see a common signal with a phase difference of omega x (t_a - t_b). An FRF of such
// channels carries that phase on top of the structure's; knowing the instants, it comes off
// exactly. A recording from the board states them in its header line:
//   # vibid-recording sample_instants_us=force1_n:2.667,force2_n:5.905,x1_m:2.667
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "vibid/ident/spectral.hpp"

namespace vibid::ident {

/// When each named column was sampled after the edge, in seconds.
struct SampleInstants {
  std::vector<std::pair<std::string, double>> instants_s;

  /// The column's instant; empty when the recording does not state it.
  std::optional<double> Of(std::string_view column) const;
};

/// Reads `sample_instants_us=` from the `# vibid-recording` line among the comment lines that open
/// `text`. Empty when there is no such line (a recording from elsewhere). @throws InputError
/// naming `source` for a malformed list (a missing ':', a number that is not finite or negative,
/// a column named twice).
std::optional<SampleInstants> ParseSampleInstants(std::string_view text, const std::string& source);
/// The same from a file's opening comment lines.
std::optional<SampleInstants> ReadSampleInstants(const std::string& path);

/// The header line for `columns` and their instants in us (same length), with no newline.
std::string FormatSampleInstantsLine(const std::vector<std::string>& columns,
                                     const std::vector<double>& instants_us);

/// Moves every response to the force's instant: H_j(omega) x exp(j omega (t_force - t_j)).
/// A response sampled dt = t_j - t_force after the force shows H exp(j omega dt) (a delay in the
/// force's time frame); the factor takes it off. Coherence is unchanged. `response_instants_s`
/// has one entry per response.
void CompensateSampleInstants(Frf& frf, double force_instant_s,
                              const std::vector<double>& response_instants_s);

}  // namespace vibid::ident
