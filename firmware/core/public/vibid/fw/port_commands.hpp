// Commands only one port understands (ids 0x70..0x7F: scenario selection in the emulator,
// sample injection on the QEMU image). The core validates the header and hands the payload over.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/shared/status.hpp"
#include "vibid/shared/wire/report.hpp"

namespace vibid::fw {

class PortCommandHandler {
 public:
  /// Handles `command` (wire::IsPortCommand) with its request payload. Writes up to
  /// wire::kMaxPayload response bytes into `response` and sets `response_length`.
  /// @returns the status sent back: kOk, or the refusal (kUnimplemented for an id this port
  ///          does not know, kInvalidArgument for a bad payload, ...). A refusal names its
  ///          reason with a wire::Refusal in `response` (response_length = Refusal::kBytes);
  ///          without one the core names it from the status (port-refused, unknown-command).
  virtual Status HandlePortCommand(std::uint8_t command, std::span<const std::uint8_t> request,
                                   std::span<std::uint8_t, wire::kMaxPayload> response,
                                   std::size_t& response_length) = 0;

 protected:
  ~PortCommandHandler() = default;
};

}  // namespace vibid::fw
