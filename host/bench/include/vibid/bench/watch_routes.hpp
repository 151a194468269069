// The Watch view's API: the rig watched on the bench's board by the library's runner
// (workflow::WatchBoardRun, as `vibid watch --device` runs it), each block published on the live
// channel as it comes and journaled in the bench's directory as JSON lines.
//   POST /api/watch/start    {settings} -> {name, journal}; 400 with the library's refusal
//   POST /api/watch/stop     {}         -> the board's state (the journal is kept)
//   POST /api/watch/snapshot {}         -> {watch, blocks} (watch null before the first run)
//   POST /api/watch/journal  {}         -> {name, text}: the journal's JSON lines
// Settings (each optional, the library's default when left out, as `vibid watch` takes them):
// rate_hz (1000), log_rate_hz, channels (acc1, acc2), seconds (until stopped), responses,
// reference (a recording in the bench's directory) or reference_s, block_s, window_blocks,
// false_alarm_per_hour, fmax_hz, modes_s, order, no_dob (the observer's output not logged while
// it runs), scenario, scenario_params (emulator).
// Live events: `watch` (the run's state: the reference's progress, its modes and thresholds, the
// board's model test, the end) and `watch-block` (one block, as its journal line).
#pragma once

#include <memory>
#include <string>

#include "vibid/bench/bench_board.hpp"
#include "vibid/bench/live_hub.hpp"
#include "vibid/bench/server.hpp"
#include "vibid/workflow/watch_metrics.hpp"

namespace vibid::bench {

class WatchRuns;

/// Registers the view and its routes; the returned object lives as long as the server. With
/// `metrics`, each run's figures go there too (the bench's GET /metrics, server.AddMetrics).
std::shared_ptr<WatchRuns> AddWatchRoutes(BenchServer& server, BenchBoard& board, LiveHub& hub,
                                          const std::string& directory,
                                          std::shared_ptr<workflow::WatchMetrics> metrics = {});

}  // namespace vibid::bench
