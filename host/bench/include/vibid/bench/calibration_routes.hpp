// The calibration view's API: a record built from files in the bench's directory exactly as
// `vibid cal upload` builds it, shown against the board's active record before anything changes,
// then staged (cal upload) and committed (cal commit).
//   POST /api/cal/preview {model, design, sensors?, label?} -> {current, staged, changes, verdict}
//   POST /api/cal/upload  (the same body, accept_flagged?)   -> {staged, crc32, verdict}
//   POST /api/cal/commit  {} or {accept_flagged: true}       -> {slot, sequence, verdict?}
// The model's verdict (common/verdict.hpp) travels with each answer: a flagged model is staged
// only with "accept_flagged": true, and a flagged model this bench staged is committed only with
// it too (400 naming the reasons and the accept otherwise), as `cal upload --accept-flagged`.
// Files are named inside the bench's directory (bench_files.hpp: FileIn): the page cannot read
// other files through them.
#pragma once

#include <string>

#include "vibid/bench/bench_board.hpp"
#include "vibid/bench/server.hpp"

namespace vibid::bench {

void AddCalibrationRoutes(BenchServer& server, BenchBoard& board, const std::string& directory,
                          const std::string& host_version);

/// What differs between two records as RecordJson shows them: one entry per top-level field
/// ({"field", "from", "to"}), created_unix_s and host_version left out.
nlohmann::json RecordChanges(const nlohmann::json& current, const nlohmann::json& staged);

}  // namespace vibid::bench
