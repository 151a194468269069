// What every device command does around its work: open the board the global --device names,
// let Ctrl-C stop a transfer cleanly, and draw progress bars on a terminal.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <string>

#include "commands.hpp"
#include "vibid/device/connection.hpp"
#include "vibid/shared/wire/calibration_record.hpp"

namespace vibid::cli {

/// Set by the SIGINT handler while a device command runs.
const std::atomic<bool>& InterruptFlag();

/// Runs `body` with the connection `globals.device` selects. SIGINT is caught for the duration
/// (the body sees device::Interrupted from long transfers). A device::DeviceError goes on to main,
/// which prints it on one line with exit code kExitDevice.
void WithDevice(const GlobalOptions& globals, const std::function<void(device::Connection&)>& body);

/// The board's active calibration record; `has_record` false when it is uncalibrated.
wire::CalibrationRecord ActiveRecord(device::Connection& c, bool& has_record);

/// A progress bar on stderr, drawn only when stderr is a terminal.
class ProgressBar {
 public:
  explicit ProgressBar(std::string what);
  ~ProgressBar();
  void Update(std::uint64_t done, std::uint64_t total);
  device::Progress Callback() {
    return [this](std::uint64_t d, std::uint64_t t) { Update(d, t); };
  }

 private:
  std::string what_;
  bool tty_ = false;
  bool drawn_ = false;
  int last_permille_ = -1;
};

}  // namespace vibid::cli
