// The hammer test view's API: a workflow::HammerSession fed by the bench's acquisition, its state
// published on the live channel as it changes, the operator's choices and the saved test.
//   POST /api/hammer/preflight {settings}   -> the link budget `vibid acquire` checks
//   POST /api/hammer/start     {settings}   -> {name, dir}; 400 with the session's refusal
//   POST /api/hammer/stop      {}           -> the acquisition's state (the test keeps its hits)
//   POST /api/hammer/choose    {index, accept} -> the snapshot
//   POST /api/hammer/save      {}           -> {dir, files}
//   POST /api/hammer/snapshot  {}           -> {test, snapshot} (null before the first test)
//   POST /api/hammer/traces    {index}      -> hit `index`'s record (HitTracesJson)
// Settings: channels (force first, then the responses), sample_period_us, seconds, record_s,
// hammer_point (a response channel), and optionally trigger, pretrigger_s, force_window_s,
// exp_window, scenario, scenario_params (emulator).
// Live events: `hammer` (the whole snapshot, at once when a hit is judged or a choice changes
// the FRF) and `hammer-progress` (samples and hits pending, at most 10 a second).
#pragma once

#include <memory>
#include <string>

#include "vibid/bench/bench_board.hpp"
#include "vibid/bench/live_hub.hpp"
#include "vibid/bench/server.hpp"

namespace vibid::bench {

class HammerTests;

/// Registers the view and its routes; the returned object lives as long as the server.
std::shared_ptr<HammerTests> AddHammerRoutes(BenchServer& server, BenchBoard& board, LiveHub& hub,
                                             const std::string& directory);

}  // namespace vibid::bench
