// Framing of 64-byte reports on a serial link (the QEMU board image's USART: a byte stream with no
// packet boundaries of its own). The board's USART link and the host's serial transport share
// this one codec. One frame:
//
//   offset  size  field
//   0       2     sync       0x56 0x46 ('V','F')
//   2       1     length     64, the report length (anything else is not a frame)
//   3       64    report     the report bytes, exactly as on USB HID
//   67      4     crc        CRC-32 (ISO-HDLC, wire::ComputeCrc32) of bytes 2..66, little-endian
//
// The receiver hunts for the sync bytes; a frame whose length or CRC is wrong costs one byte:
// the decoder drops the first sync byte and looks for the next sync in what it already has, so
// it regains step after noise or a partial frame without losing a following good frame.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/shared/wire/report.hpp"

namespace vibid::wire {

inline constexpr std::uint8_t kSerialSync0 = 0x56;
inline constexpr std::uint8_t kSerialSync1 = 0x46;
inline constexpr std::size_t kSerialFrameBytes = 2 + 1 + kReportBytes + 4;
static_assert(kSerialFrameBytes == 71);

using SerialFrameBytes = std::array<std::uint8_t, kSerialFrameBytes>;

/// Builds the frame carrying `report`.
SerialFrameBytes EncodeSerialFrame(std::span<const std::uint8_t, kReportBytes> report);

struct SerialFrameCounters {
  std::uint32_t frames = 0;         ///< Good frames delivered.
  std::uint32_t crc_errors = 0;     ///< Sync and length right, CRC wrong.
  std::uint32_t skipped_bytes = 0;  ///< Bytes discarded while hunting for sync.
};

class SerialFrameDecoder {
 public:
  /// Feeds one received byte.
  /// @returns true when this byte completed a good frame; its report is then in `report`.
  bool Push(std::uint8_t byte, Report& report);
  const SerialFrameCounters& counters() const { return counters_; }

 private:
  /// Drops bytes from the front until the buffer starts with a possible frame start.
  void Resync(std::size_t drop);

  SerialFrameBytes buffer_{};
  std::size_t fill_ = 0;
  SerialFrameCounters counters_{};
};

}  // namespace vibid::wire
