// The link the command server talks over: 64-byte reports in, 64-byte reports out.
//
// Implemented by the USB HID class (interrupt OUT/IN endpoints), by the QEMU image's framed
// USART, and by the emulator's USB/IP device. Both calls are non-blocking and are made from the
// main loop only; an implementation fed from an interrupt keeps its own small queue.
#pragma once

#include "vibid/shared/status.hpp"
#include "vibid/shared/wire/report.hpp"

namespace vibid::fw {

class ReportLink {
 public:
  /// Takes the oldest report the host sent and not yet taken.
  /// @returns kOk with `out` filled; kUnavailable if none is waiting (`out` untouched).
  virtual Status Receive(wire::Report& out) = 0;

  /// Offers one report to the host.
  /// @returns kOk if the link took a copy (it will be sent in order);
  ///          kUnavailable if the IN path is still busy with earlier reports: nothing was taken,
  ///            offer the same report again later.
  virtual Status Send(const wire::Report& report) = 0;

 protected:
  ~ReportLink() = default;
};

}  // namespace vibid::fw
