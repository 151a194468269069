// The frequency band the pole estimators fit in, as their options give it.
#pragma once

#include <cmath>
#include <string>

#include "vibid/common/error.hpp"

namespace vibid::ident {

/// Checks the band [freq_min_hz, freq_max_hz] (a maximum of 0: up to the last line): InputError
/// "WHAT: band limits must be >= 0" for a negative or non-finite limit, "WHAT: band maximum must
/// exceed the minimum" for an empty band.
inline void RequireBand(double freq_min_hz, double freq_max_hz, const std::string& what) {
  Require(freq_min_hz >= 0.0 && freq_max_hz >= 0.0 && std::isfinite(freq_min_hz) &&
              std::isfinite(freq_max_hz),
          what + ": band limits must be >= 0");
  Require(freq_max_hz == 0.0 || freq_max_hz > freq_min_hz,
          what + ": band maximum must exceed the minimum");
}

}  // namespace vibid::ident
