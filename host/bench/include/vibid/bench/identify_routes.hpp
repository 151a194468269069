// The calibration view's first steps, from saved tests to the files the upload takes:
//   POST /api/cal/identify {nominal, mass_tests: [{position, file}], modal_tests: [file], output}
//        -> the identify run as `vibid identify --report` writes report.json (validation table,
//           parameters with intervals, warnings), its text table, and the updated model written
//           to `output`
//   POST /api/cal/design {model, output, fs_hz?, force_fs_n?}
//        -> the observer designed with `vibid dob design`'s defaults, written to `output`; the
//           force full scale defaults to the board's calibrated load cell 1 (the CLI's default of
//           100 N would be refused by the upload on a board whose cell is calibrated otherwise)
// Every file is inside the bench's directory; outputs are written atomically.
#pragma once

#include <string>

#include "vibid/bench/bench_board.hpp"
#include "vibid/bench/server.hpp"

namespace vibid::bench {

void AddIdentifyRoutes(BenchServer& server, BenchBoard& board, const std::string& directory);

}  // namespace vibid::bench
