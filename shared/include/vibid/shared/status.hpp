// Status codes shared by the firmware core, the wire protocol and the host's replay of firmware
// code. A plain enum so it travels in one byte on the wire and costs nothing on the board.
#pragma once

#include <cstdint>

namespace vibid {

/// Outcome of a firmware-side or shared operation. Values are part of the wire protocol: append
/// only, never renumber (the golden vectors in shared/wire/testdata pin them). [[nodiscard]]: a
/// function that returns one cannot be called as if it could not fail; code that may drop one
/// says so with (void).
enum class [[nodiscard]] Status : std::uint8_t{
    kOk = 0,
    kInvalidArgument = 1,     ///< A field is out of range or inconsistent with another.
    kOutOfRange = 2,          ///< An index or length exceeds a fixed capacity.
    kFailedPrecondition = 3,  ///< The request is valid but not in the current state.
    kDataLoss = 4,            ///< CRC or checksum mismatch; the data cannot be trusted.
    kUnavailable = 5,         ///< The resource is busy; the same request may succeed later.
    kUnimplemented = 6,       ///< Unknown command or capability.
    kResourceExhausted = 7,   ///< A buffer filled up; data was dropped and counted.
    kInternal = 8,            ///< An invariant broke; a defect, reported rather than hidden.
    kVersionMismatch = 9,     ///< Protocol or record version not supported.
    kUnstable = 10,           ///< A filter failed its stability check.
};

/// Short stable name, for logs and host messages.
constexpr const char* StatusName(Status s) {
  switch (s) {
    case Status::kOk: return "ok";
    case Status::kInvalidArgument: return "invalid-argument";
    case Status::kOutOfRange: return "out-of-range";
    case Status::kFailedPrecondition: return "failed-precondition";
    case Status::kDataLoss: return "data-loss";
    case Status::kUnavailable: return "unavailable";
    case Status::kUnimplemented: return "unimplemented";
    case Status::kResourceExhausted: return "resource-exhausted";
    case Status::kInternal: return "internal";
    case Status::kVersionMismatch: return "version-mismatch";
    case Status::kUnstable: return "unstable";
  }
  return "unknown";
}

}  // namespace vibid
