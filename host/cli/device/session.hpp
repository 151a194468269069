// What every device command does around its work: open the board the global --device names,
// let Ctrl-C stop a transfer cleanly, and draw progress bars on a terminal.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "vibid/device/connection.hpp"
#include "vibid/device/select.hpp"
#include "vibid/shared/wire/calibration_record.hpp"

namespace vibid::cli {

/// Set by the SIGINT handler (the first Ctrl-C) while a device command runs.
const std::atomic<bool>& InterruptFlag();

/// What Ctrl-C does to a device command.
enum class CtrlC {
  kInterrupts,        ///< The first interrupts long transfers (device::Interrupted).
  kStopsAcquisition,  ///< The first only sets InterruptFlag (the command stops the acquisition
                      ///< and keeps its record); a second interrupts.
};

/// Lets `command` (and the commands above it) take the global --device after its own name too:
/// an option it does not know goes on to the top level, where --device is defined once, so
/// `vibid --device X info` and `vibid info --device X` mean the same (given twice, it is refused).
void TakesDeviceOption(CLI::App* command);

/// The board --device or $VIBID_DEVICE names (the option wins), kAny when neither does.
device::DeviceSpec ChosenDevice(const GlobalOptions& globals);

/// Runs `body` with the connection ChosenDevice selects. SIGINT is caught for the duration
/// (`ctrl_c` says what it does). A device::DeviceError goes on to main, which prints it on one
/// line with exit code kExitDevice (kExitInterrupted for device::Interrupted).
void WithDevice(const GlobalOptions& globals, const std::function<void(device::Connection&)>& body,
                CtrlC ctrl_c = CtrlC::kInterrupts);

/// Waits for Ctrl-C (SIGINT caught meanwhile); returns at once when one already came.
void UntilCtrlC();

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
