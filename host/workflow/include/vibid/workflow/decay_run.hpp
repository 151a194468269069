// Free-decay analysis of pull-and-release records as `vibid decay` runs it: each record's fit,
// the repeats averaged, and with records carrying an added mass the spring and the base mass.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "vibid/ident/decay.hpp"

namespace vibid::workflow {

struct DecayRequest {
  std::vector<std::string> recordings;  ///< The base configuration.
  std::vector<std::string> loaded;      ///< The same spring with `added_kg` more (may be empty).
  std::string position;                 ///< NAME[:UNIT|*FACTOR] of the position column.
  double scale = 1.0;                   ///< Extra factor on the position.
  double fs_hz = 0.0;                   ///< When the files have no t_s column; 0: from it.
  double added_kg = 0.0;
  ident::DecayOptions options{.end_fraction = 0.1, .cycles = 3};
};

/// What `vibid decay --json` prints: {omega_d_rad_s, zeta, omega_n_rad_s, omega_d_std, zeta_std,
/// records: [...]} and, with loaded records, {loaded: {...}, added_kg, k_n_per_m, base_mass_kg}.
/// InputError naming the file of a record that cannot be analysed, or the missing option.
nlohmann::json RunDecay(const DecayRequest& request);

/// The text `vibid decay` prints for that JSON.
std::string DecayText(const nlohmann::json& result);

}  // namespace vibid::workflow
