// A hammer test as the board delivers it, for the hammer session's tests: the synthetic hammer
// test on the example rig (examples/rig_nominal.json, hammer on mass 2, both masses measured) at
// 5 kHz, its signals turned into the converter codes of examples/sensors.json's scaling (12-bit
// codes that stop at the converter's range: an overload clips there, as on the board) and into the
// log records a streamed acquisition delivers (force1, acc1, acc2).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "vibid/shared/wire/log_record.hpp"
#include "vibid/workflow/hammer_session.hpp"

namespace vibid::workflow::testing {

struct BoardHammerTest {
  HammerSessionOptions options;  ///< Acquisition, calibration, instants, columns, hit options.
  std::vector<wire::LogRecord> records;
  std::vector<double> hit_times_s;
};

/// Ten hits of about 100 N, `record_s` + 1 to 1.5 s apart; hit 3 a double hit (a second pulse
/// 12 ms after, 60 % of it), hit 5 an overload (6x: the load cell's converter clips at 500 N),
/// hit 7 a light tap (20 %), hit 10 too close to the end for its record (half of it recorded).
/// Trigger at 2 % of the largest force, exponential window to 1 %, lscf modes with the hammer at
/// acc2.
BoardHammerTest MakeBoardHammerTest(const std::string& live_csv_path, double record_s);

/// Feeds `records` in blocks of random sizes (1 to `max_block`).
void FeedInBlocks(HammerSession& session, const std::vector<wire::LogRecord>& records,
                  std::uint64_t seed, std::size_t max_block = 700);

}  // namespace vibid::workflow::testing
