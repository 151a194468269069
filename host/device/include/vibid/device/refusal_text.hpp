// A device's refusal as one sentence for the user: what the board refused, why, and the way out.
// The board names its reason on the wire (vibid/shared/wire/refusal.hpp, protocol 2.1); a 2.0
// board names none, and the status alone is said.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "vibid/shared/status.hpp"
#include "vibid/shared/wire/refusal.hpp"

namespace vibid::device {

/// "the device refused acq-configure: <cause>; <way out> [invalid-argument, observer-rate]".
/// `payload` is the refusal's payload as received (empty from a 2.0 device).
std::string RefusalMessage(std::uint8_t command, Status status,
                           std::span<const std::uint8_t> payload);

/// The part after "the device refused <command>: ".
std::string RefusalCause(Status status, std::span<const std::uint8_t> payload);

/// The cause and the way out of one reason with its detail, without the command.
std::string ReasonText(Status status, const wire::Refusal& refusal);

}  // namespace vibid::device
