// The JSON form of an iterative solver's summary, the same for every library's solver (ident and
// sysid each have their own Summary type with the same fields and a TerminationName beside it).
#pragma once

#include <nlohmann/json.hpp>

namespace vibid::cli {

/// {"termination", "iterations", "initial_cost", "final_cost", "message"}.
template <typename Summary>
nlohmann::json SolverSummaryJson(const Summary& s) {
  // TerminationName is found beside the summary's own Termination type.
  return {{"termination", TerminationName(s.termination)},
          {"iterations", s.iterations},
          {"initial_cost", s.initial_cost},
          {"final_cost", s.final_cost},
          {"message", s.message}};
}

}  // namespace vibid::cli
