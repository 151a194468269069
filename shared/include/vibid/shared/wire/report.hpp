// The 64-byte HID report every exchange is made of, and the header at its start.
//
// Transport: USB HID interrupt IN/OUT, vendor usage page 0xFF00, no report IDs (so the 64 bytes
// on the wire are exactly these). The QEMU image carries the same 64 bytes over its USART.
//
// Header layout (little-endian, offsets in bytes):
//
//   0   u16  magic            kMagic: bytes 'V','B'; anything else is not ours
//   2   u8   protocol_major   kProtocolMajor; a request with another major is refused
//   3   u8   command          Command id (commands.hpp)
//   4   u8   status           vibid::Status; 0 in requests
//   5   u8   flags            kFlagResponse, kFlagStreamEnd
//   6   u16  token            chosen by the host, echoed by the device in every report it answers
//   8   u16  sequence         report index within a multi-report transfer or stream; else 0
//   10  u8   payload_length   0..kMaxPayload
//   11  u8   reserved         0
//   12  u8   payload[52]      command-specific; bytes past payload_length are zero
//
// Stream data reports (the data of log-read and cal-get streams, the bulk of the link's traffic)
// carry a 6-byte header instead, so 58 of the 64 bytes are payload (90.6 %, against 81.3 %):
//
//   0   u8   tag              kStreamDataTag (0xD5): never 'V', so no full report starts so
//   1   u8   payload_length   1..kMaxStreamPayload
//   2   u16  token            the token of the request the stream answers
//   4   u16  sequence         the data report's index in its stream (modulo 2^16)
//   6   u8   payload[58]      bytes past payload_length are zero
//
// They need no command, status, flags or protocol major: the token names the request (which
// passed the major check), and the stream's trailer is a full report again.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/shared/status.hpp"

namespace vibid::wire {

inline constexpr std::size_t kReportBytes = 64;
inline constexpr std::size_t kHeaderBytes = 12;
inline constexpr std::size_t kMaxPayload = kReportBytes - kHeaderBytes;
inline constexpr std::uint16_t kHidUsagePage = 0xFF00;

inline constexpr std::uint16_t kMagic = 0x4256;  // bytes 'V','B'
/// Protocol version. The major goes in every header; a host and a device with different majors
/// refuse each other. The minor grows with backward-compatible additions (new commands).
/// 2.1: refusals carry a reason (refusal.hpp); get-clips.
inline constexpr std::uint8_t kProtocolMajor = 2;
inline constexpr std::uint8_t kProtocolMinor = 1;

inline constexpr std::uint8_t kFlagResponse = 1u << 0;   ///< Set on every device-to-host report.
inline constexpr std::uint8_t kFlagStreamEnd = 1u << 1;  ///< Last report of a stream (its trailer).
inline constexpr std::uint8_t kKnownFlags = kFlagResponse | kFlagStreamEnd;

inline constexpr std::size_t kOffMagic = 0;
inline constexpr std::size_t kOffProtocolMajor = 2;
inline constexpr std::size_t kOffCommand = 3;
inline constexpr std::size_t kOffStatus = 4;
inline constexpr std::size_t kOffFlags = 5;
inline constexpr std::size_t kOffToken = 6;
inline constexpr std::size_t kOffSequence = 8;
inline constexpr std::size_t kOffPayloadLength = 10;
inline constexpr std::size_t kOffReserved = 11;
inline constexpr std::size_t kOffPayload = 12;
static_assert(kOffMagic + 2 == kOffProtocolMajor && kOffProtocolMajor + 1 == kOffCommand &&
                  kOffCommand + 1 == kOffStatus && kOffStatus + 1 == kOffFlags &&
                  kOffFlags + 1 == kOffToken && kOffToken + 2 == kOffSequence &&
                  kOffSequence + 2 == kOffPayloadLength && kOffPayloadLength + 1 == kOffReserved &&
                  kOffReserved + 1 == kOffPayload && kOffPayload == kHeaderBytes,
              "header fields are contiguous");
static_assert(kMaxPayload == 52);

inline constexpr std::uint8_t kStreamDataTag = 0xD5;
inline constexpr std::size_t kStreamHeaderBytes = 6;
inline constexpr std::size_t kMaxStreamPayload = kReportBytes - kStreamHeaderBytes;
static_assert(kMaxStreamPayload == 58 && kStreamDataTag != (kMagic & 0xFF));

/// One report as it crosses the link.
using Report = std::array<std::uint8_t, kReportBytes>;

/// The decoded header. `command` is kept as a raw byte so an unknown id can be answered.
struct Header {
  std::uint8_t protocol_major = kProtocolMajor;
  std::uint8_t command = 0;
  Status status = Status::kOk;
  std::uint8_t flags = 0;
  std::uint16_t token = 0;
  std::uint16_t sequence = 0;
  std::uint8_t payload_length = 0;
};

/// Writes magic, header and payload; zeroes the rest of the report.
/// @returns kOk; kOutOfRange if payload.size() > kMaxPayload (the report is left zeroed).
Status EncodeReport(const Header& header, std::span<const std::uint8_t> payload, Report& out);

/// Reads and checks the header of a received report.
/// @returns kOk;
///          kDataLoss if the magic is wrong (not a vibid report);
///          kVersionMismatch if protocol_major differs from kProtocolMajor (header still decoded);
///          kInvalidArgument for payload_length > kMaxPayload, unknown flags, a nonzero reserved
///            byte, or a status byte that is not a known Status.
Status DecodeHeader(const Report& report, Header& header);

/// The payload bytes the header announces (payload_length clamped to the report's maximum), for
/// full reports and stream data reports alike.
std::span<const std::uint8_t> PayloadOf(const Report& report);

/// A stream data report's header fields.
struct StreamDataHeader {
  std::uint16_t token = 0;
  std::uint16_t sequence = 0;
  std::uint8_t payload_length = 0;
};

/// True if the report is a stream data report (its first byte is kStreamDataTag).
constexpr bool IsStreamData(const Report& report) { return report[0] == kStreamDataTag; }

/// Writes a stream data report; zeroes the rest.
/// @returns kOk; kOutOfRange for an empty payload or one longer than kMaxStreamPayload.
Status EncodeStreamData(std::uint16_t token, std::uint16_t sequence,
                        std::span<const std::uint8_t> payload, Report& out);

/// @returns kOk; kDataLoss if the report is not a stream data report; kInvalidArgument for a
///          payload length of 0 or over kMaxStreamPayload.
Status DecodeStreamData(const Report& report, StreamDataHeader& header);

/// True if the byte is a defined vibid::Status value.
bool IsKnownStatus(std::uint8_t value);

}  // namespace vibid::wire
