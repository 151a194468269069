// The JSON form of an iterative solver's summary: the workflow library's, the same for every
// command (ident, numerics and sysid solvers).
#pragma once

#include "vibid/workflow/result_json.hpp"

namespace vibid::cli {

using workflow::SolverSummaryJson;

}  // namespace vibid::cli
